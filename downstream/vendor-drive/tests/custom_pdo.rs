//! A custom mapping for the vendor drive, declared with `#[derive(Pdo)]`
//! over its generated objects, as an integrator writes it: statusword,
//! position actual value and mode of operation in TPDO2, controlword and
//! target velocity in RPDO1. Configured with `configure_pdo` (CiA 301
//! order, read-back) on a simulated drive built from the DCF's own object
//! table, on the in-process virtual bus; the RPDO is applied by the drive
//! and the TPDO received and decoded into the struct. Then the same drive
//! (same store, same clock) on python-canopen's bus: `RemoteNode` with the
//! vendor's DCF reads the mapping back over SDO (`tpdo.read(from_od=False)`)
//! and decodes a TPDO2 to the values the struct gives for the same bytes.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant as WallClock};

use eds2rust_runtime::cia402;
use eds2rust_runtime::blocking::{self, SdoClient};
use eds2rust_runtime::od::{NodeId, Pdo as _};
use eds2rust_runtime::od::standard::EventTimer;
use eds2rust_runtime::pdo::{PdoConfig, TransmissionType};
use eds2rust_runtime::pdo::blocking::configure_pdo;
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::client::ClientConfig;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{CanId, Frame};
use eds2rust_sim::{Device, DeviceConfig};
use eds2rust_tests::peer::PyPeer;
use serde_json::{Value, json};
use vendor_drive::drive::od;

use vendor_drive::mapping::{ControlVelocity, StatusPosition};

#[test]
fn configured_over_sdo_applied_and_received() {
    let drive = NodeId::new(3).unwrap();
    let clock = Clock::new();
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let device_clock = clock.clone();
    let serving = std::thread::spawn(move || {
        let clock = device_clock;
        let mut device = Device::new(od::OBJECTS, DeviceConfig::node(drive), (), clock.now());
        blocking::serve(&mut port, &clock, &mut device, &flag, None, |_| {}).unwrap();
        device
    });
    let mut sdo = SdoClient::new(bus.attach(), ClientConfig::new(Channel::default_for(drive)));
    let mut watch = bus.attach();

    let tpdo = PdoConfig::from_pdo::<StatusPosition>(drive)
        .unwrap()
        .with_transmission_type(TransmissionType::EventDrivenProfile)
        .with_event_timer(EventTimer(10));
    configure_pdo(&mut sdo, &tpdo).expect("TPDO2 configured");
    let rpdo = PdoConfig::from_pdo::<ControlVelocity>(drive)
        .unwrap()
        .with_transmission_type(TransmissionType::EventDrivenProfile);
    configure_pdo(&mut sdo, &rpdo).expect("RPDO1 configured");
    assert_eq!(sdo.upload(0x1A01, 0).unwrap(), [3]);
    assert_eq!(sdo.upload(0x1A01, 1).unwrap(), 0x6041_0010u32.to_le_bytes());
    assert_eq!(sdo.upload(0x1600, 0).unwrap(), [2]);
    assert_eq!(sdo.upload(0x1600, 2).unwrap(), 0x60FF_0020u32.to_le_bytes());

    // A value the TPDO will carry: the mode of operation, set over SDO.
    sdo.write::<od::ModesOfOperation>(od::ModesOfOperationValue::from_raw(3))
        .unwrap();
    watch
        .send(&Frame::new(CanId::Standard(0), &[0x01, drive.get()]).unwrap())
        .unwrap();

    // The RPDO is written into the drive's objects. The device takes its
    // frames in send order on its one port: it is operational before the
    // RPDO, and has written the RPDO before it answers the SDO reads.
    let command = ControlVelocity {
        // Enable operation, as the runtime's CiA 402 command says it.
        control: cia402::Controlword::from_command(cia402::Command::EnableOperation).into(),
        velocity: -2500,
    };
    watch
        .send(&Frame::new(ControlVelocity::can_id(drive), &command.encode()).unwrap())
        .unwrap();
    assert_eq!(sdo.read::<od::Controlword>().unwrap(), command.control);
    assert_eq!(sdo.read::<od::TargetVelocity>().unwrap(), command.velocity);

    // The TPDO arrives (event timer 10 ms) and decodes into the struct.
    let status_id = StatusPosition::can_id(drive);
    let deadline = WallClock::now() + Duration::from_secs(3);
    let received = loop {
        assert!(WallClock::now() < deadline, "no TPDO2");
        if let Some(f) = watch.recv(Duration::from_millis(100)).unwrap() {
            if f.id() == status_id {
                break StatusPosition::decode(f.data()).unwrap();
            }
        }
    };
    assert_eq!(received.mode.to_raw(), 3);
    assert_eq!(received.status, sdo.read::<od::Statusword>().unwrap());
    assert_eq!(
        received.position,
        sdo.read::<od::PositionActualValue>().unwrap()
    );
    assert_eq!(StatusPosition::LEN, 7);
    assert_eq!(
        StatusPosition::MAPPING,
        [0x6041_0010, 0x6064_0020, 0x6060_0008]
    );

    stop.store(true, Ordering::Relaxed);
    let device = serving.join().unwrap();

    // python-canopen reads the mapping back and decodes a TPDO2.
    let py = PyPeer::spawn().unwrap_or_else(|e| panic!("{e}"));
    let mut py_port = py.port();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let serving = std::thread::spawn(move || {
        let mut device = device;
        blocking::serve(&mut py_port, &clock, &mut device, &flag, None, |_| {})
    });
    let node = drive.get();
    py.command_ok(json!({"op": "remote_node_eds", "node": node, "eds": dcf()}))
        .unwrap_or_else(|e| panic!("{e}"));
    let maps = py
        .command_ok(json!({"op": "tpdo_read", "node": node, "timeout": 2.0}))
        .unwrap_or_else(|e| panic!("{e}"));
    let tpdo2 = maps["maps"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["number"] == 2)
        .unwrap_or_else(|| panic!("python-canopen read no TPDO2: {maps}"));
    assert_eq!(tpdo2["enabled"], Value::Bool(true), "{tpdo2}");
    assert_eq!(
        tpdo2["cob_id"].as_u64(),
        StatusPosition::default_cob_id(drive).map(|cob| u64::from(cob.to_raw()))
    );
    let mapped: Vec<u32> = tpdo2["map"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| {
            (v[0].as_u64().unwrap() << 16 | v[1].as_u64().unwrap() << 8 | v[2].as_u64().unwrap())
                as u32
        })
        .collect();
    assert_eq!(mapped, StatusPosition::MAPPING);
    let reply = py
        .command_ok(json!({"op": "tpdo_wait", "node": node, "number": 2, "timeout": 3.0}))
        .unwrap_or_else(|e| panic!("{e}"));
    let data: Vec<u8> = {
        let text = reply["data"].as_str().unwrap();
        (0..text.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap())
            .collect()
    };
    let theirs: Vec<i64> = reply["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v[2].as_i64().unwrap())
        .collect();
    let p = StatusPosition::decode(&data).unwrap();
    let ours = vec![
        i64::from(p.status.to_raw()),
        i64::from(p.position),
        i64::from(p.mode.to_raw()),
    ];
    assert_eq!(theirs, ours, "data {data:02X?}");
    stop.store(true, Ordering::Relaxed);
    serving.join().unwrap().unwrap();
}

/// The vendor DCF the build script generates from.
fn dcf() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/eds-corpus/files/elmo_gold-drive_ros-test-utils.dcf")
}
