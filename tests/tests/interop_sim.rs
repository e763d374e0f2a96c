//! python-canopen 2.4.1 against our simulators of the three seed devices.
//!
//! A `RemoteNode` with the device's EDS (exported by eds2rust from the YAML
//! table) reads every TPDO's configuration over SDO from the simulator,
//! which must equal the generated PDO structs' default COB-IDs and mappings;
//! then, with the node operational, python-canopen decodes received TPDOs,
//! and our generated structs must give the same values for the same bytes.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant as StdInstant};

use eds2rust_drivers::{interroll_ec5000bi, linak_techline, zimmer_acs};
use eds2rust_runtime::od::standard::EventTimer;
use eds2rust_runtime::od::{NodeId, Pdo};
use eds2rust_runtime::pdo::TransmissionType;
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::{Instant, blocking};
use eds2rust_sim::models;
use eds2rust_sim::{Behaviour, Device};
use eds2rust_tests::peer::PyPeer;
use eds2rust_tests::seed_sim;
use eds2rust_tests::served::Served;
use serde_json::{Value, json};

/// The EDS of a seed device, exported from its YAML table.
fn export_eds(name: &str) -> PathBuf {
    seed_sim::export_eds(name, "interop_sim")
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// What python-canopen read of one TPDO.
#[derive(Debug)]
struct PyMap {
    cob_id: u32,
    enabled: bool,
    trans_type: u64,
    map: Vec<u32>,
}

fn read_maps(py: &PyPeer, node: u8) -> BTreeMap<u64, PyMap> {
    let reply = py
        .command_ok(json!({"op": "tpdo_read", "node": node, "timeout": 2.0}))
        .unwrap_or_else(|e| panic!("{e}"));
    let mut maps = BTreeMap::new();
    for m in reply["maps"].as_array().expect("maps") {
        let map = m["map"]
            .as_array()
            .expect("map")
            .iter()
            .map(|v| {
                let index = v[0].as_u64().expect("index") as u32;
                let sub = v[1].as_u64().expect("sub") as u32;
                let bits = v[2].as_u64().expect("bits") as u32;
                index << 16 | sub << 8 | bits
            })
            .collect();
        maps.insert(
            m["number"].as_u64().expect("number"),
            PyMap {
                cob_id: m["cob_id"].as_u64().expect("cob id") as u32,
                enabled: m["enabled"].as_bool().expect("enabled"),
                trans_type: m["trans_type"].as_u64().unwrap_or(255),
                map,
            },
        );
    }
    maps
}

/// The mapping and COB-ID python read for TPDO `number` equal the generated
/// struct's.
fn check_map<P: Pdo>(maps: &BTreeMap<u64, PyMap>, number: u64, node: NodeId) {
    let map = maps
        .get(&number)
        .unwrap_or_else(|| panic!("python-canopen read no TPDO {number}: {maps:?}"));
    assert!(map.enabled, "TPDO {number} disabled: {map:?}");
    assert_eq!(
        Some(map.cob_id),
        P::default_cob_id(node).map(|cob| cob.to_raw()),
        "TPDO {number} COB-ID"
    );
    let mapped: Vec<u32> = P::MAPPING.to_vec();
    assert_eq!(map.map, mapped, "TPDO {number} mapping");
}

/// Starts waiting in python-canopen for the next reception of each TPDO in
/// `numbers`, then starts the node (TPDOs go out on entering operational),
/// sending SYNCs meanwhile when `synchronous`; returns, per TPDO, the data
/// and python's decoded raw values.
fn start_and_receive(
    py: &PyPeer,
    node: u8,
    numbers: &[u64],
    synchronous: bool,
) -> Vec<(Vec<u8>, Vec<i128>)> {
    // Armed before the node starts: each wait returns on the first
    // reception after this, however late its thread starts waiting.
    for number in numbers {
        py.command_ok(json!({"op": "tpdo_arm", "node": node, "number": number}))
            .unwrap_or_else(|e| panic!("{e}"));
    }
    let ids: Vec<u64> = numbers
        .iter()
        .map(|number| {
            py.start(json!({"op": "tpdo_wait", "node": node, "number": number, "timeout": 3.0}))
                .unwrap_or_else(|e| panic!("{e}"))
        })
        .collect();
    py.command_ok(json!({"op": "nmt_command", "node": node, "command": 1}))
        .unwrap_or_else(|e| panic!("{e}"));
    let deadline = StdInstant::now() + Duration::from_secs(5);
    let mut replies: Vec<Option<Value>> = vec![None; ids.len()];
    while replies.iter().any(Option::is_none) {
        if synchronous {
            py.command_ok(json!({"op": "send", "frame": "080#"}))
                .unwrap_or_else(|e| panic!("{e}"));
        }
        for (id, reply) in ids.iter().zip(replies.iter_mut()) {
            if reply.is_none() {
                *reply = py.try_reply(*id).unwrap_or_else(|e| panic!("{e}"));
            }
        }
        assert!(StdInstant::now() < deadline, "{}", py.failure("no TPDO"));
        std::thread::sleep(Duration::from_millis(20));
    }
    replies
        .into_iter()
        .flatten()
        .map(|reply| {
            assert_eq!(
                reply["ok"],
                Value::Bool(true),
                "{reply}\n{}",
                py.failure("tpdo_wait")
            );
            let data = hex(reply["data"].as_str().expect("data"));
            let values = reply["values"]
                .as_array()
                .expect("values")
                .iter()
                .map(|v| i128::from(v[2].as_i64().expect("an integer value")))
                .collect();
            (data, values)
        })
        .collect()
}

fn hex(text: &str) -> Vec<u8> {
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&text[i..i + 2], 16).expect("hex"))
        .collect()
}

fn start_node(py: &PyPeer, node: u8, eds: &PathBuf) {
    py.command_ok(json!({"op": "remote_node_eds", "node": node, "eds": eds}))
        .unwrap_or_else(|e| panic!("{e}"));
}

fn node(id: u8) -> NodeId {
    NodeId::new(id).expect("node id")
}

/// python-canopen with a `RemoteNode` of the seed device `name` at `id`
/// (its exported EDS) against our simulator from `make`: the peer, the
/// running simulator and the TPDO maps python-canopen read.
fn seed_node<B>(
    name: &str,
    id: u8,
    make: impl FnOnce(Instant) -> Device<B>,
) -> (PyPeer, Served, BTreeMap<u64, PyMap>)
where
    B: Behaviour + Send + 'static,
    B::Event: Send,
{
    let py = PyPeer::spawn().unwrap_or_else(|e| panic!("{e}"));
    let eds = export_eds(name);
    let sim = Served::start(py.port(), make);
    start_node(&py, id, &eds);
    let maps = read_maps(&py, id);
    (py, sim, maps)
}

/// A received TPDO (its bytes and python-canopen's values) decodes to the
/// same values with our struct (`ours`).
fn assert_decodes_alike(
    (data, values): &(Vec<u8>, Vec<i128>),
    ours: impl FnOnce(&[u8]) -> Vec<i128>,
) {
    assert_eq!(values, &ours(data), "data {data:02X?}");
}

#[test]
fn linak_tpdo_feedback_reads_and_decodes_alike() {
    use linak_techline::pdo::Tpdo1Feedback;
    let id = linak_techline::DEFAULT_NODE_ID;
    let (py, _sim, maps) = seed_node("linak_techline", id, models::linak_techline::simulator);
    check_map::<Tpdo1Feedback>(&maps, 1, node(id));
    let received = start_and_receive(&py, id, &[1], maps[&1].trans_type <= 240);
    assert_decodes_alike(&received[0], |data| {
        let p = Tpdo1Feedback::decode(data).expect("8 bytes");
        vec![
            i128::from(p.position.0),
            i128::from(p.current.0),
            i128::from(p.status_flags.0),
            i128::from(p.error_code.0),
            i128::from(p.speed.0),
            i128::from(p.aux_inputs.0),
        ]
    });
}

#[test]
fn zimmer_tpdos_read_and_decode_alike() {
    use zimmer_acs::pdo::{Tpdo1StatusAndPosition, Tpdo2Velocity, Tpdo3FollowingErrorAndTorque};
    let id = zimmer_acs::DEFAULT_NODE_ID;
    let (py, _sim, maps) = seed_node("zimmer_acs", id, models::zimmer_acs::simulator);
    check_map::<Tpdo1StatusAndPosition>(&maps, 1, node(id));
    check_map::<Tpdo2Velocity>(&maps, 2, node(id));
    check_map::<Tpdo3FollowingErrorAndTorque>(&maps, 3, node(id));
    let synchronous = maps[&1].trans_type <= 240 || maps[&3].trans_type <= 240;
    let received = start_and_receive(&py, id, &[1, 3], synchronous);
    assert_decodes_alike(&received[0], |data| {
        let p = Tpdo1StatusAndPosition::decode(data).expect("6 bytes");
        vec![
            i128::from(p.statusword.0),
            i128::from(p.position_actual_value.0),
        ]
    });
    assert_decodes_alike(&received[1], |data| {
        let p = Tpdo3FollowingErrorAndTorque::decode(data).expect("TPDO3 length");
        vec![
            i128::from(p.following_error_actual_value.0),
            i128::from(p.torque_actual_value.0),
        ]
    });
}

#[test]
fn interroll_tpdos_read_and_decode_alike() {
    use interroll_ec5000bi::pdo::{Tpdo1Status, Tpdo2Position, Tpdo3Velocity};
    let id = interroll_ec5000bi::DEFAULT_NODE_ID;
    let (py, _sim, maps) = seed_node(
        "interroll_ec5000bi",
        id,
        models::interroll_ec5000bi::simulator,
    );
    check_map::<Tpdo1Status>(&maps, 1, node(id));
    check_map::<Tpdo2Position>(&maps, 2, node(id));
    check_map::<Tpdo3Velocity>(&maps, 3, node(id));
    let synchronous = maps[&1].trans_type <= 240 || maps[&2].trans_type <= 240;
    let received = start_and_receive(&py, id, &[1, 2], synchronous);
    assert_decodes_alike(&received[0], |data| {
        let p = Tpdo1Status::decode(data).expect("TPDO1 length");
        vec![
            i128::from(p.statusword.0),
            i128::from(p.modes_of_operation_display.0),
            i128::from(p.error_register.0),
            i128::from(p.actual_temperature.0),
            i128::from(p.torque_actual_value.0),
        ]
    });
    assert_decodes_alike(&received[1], |data| {
        let p = Tpdo2Position::decode(data).expect("TPDO2 length");
        vec![
            i128::from(p.statusword.0),
            i128::from(p.position_actual_value.0),
        ]
    });
}

/// A custom TPDO and RPDO declared with `#[derive(Pdo)]` for the Interroll
/// drive's free PDO 4 (chapter 8: "can be used freely"): configured on the
/// simulator with the runtime's `configure_pdo` (CiA 301 order, read-back)
/// over the in-process virtual bus, the RPDO applied by the device, the
/// TPDO received and decoded into the struct; then the same simulator (same
/// store, same clock) on python-canopen's bus, where `RemoteNode` reads the
/// mapping back over SDO (`tpdo.read(from_od=False)`) and decodes a TPDO
/// to the values the derived struct gives for the same bytes.
#[test]
fn derived_pdos_are_configured_and_read_back_by_python() {
    use eds2rust_runtime::Pdo;
    use eds2rust_runtime::blocking::SdoClient;
    use eds2rust_runtime::od::Entry;
    use eds2rust_runtime::pdo::PdoConfig;
    use eds2rust_runtime::sdo::Channel;
    use eds2rust_runtime::sdo::client::ClientConfig;
    use eds2rust_runtime::transport::Bus;
    use eds2rust_runtime::transport::virtual_bus::VirtualBus;
    use eds2rust_runtime::{CanId, Frame};
    use interroll_ec5000bi::od;

    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 4)]
    struct StatusVelocity {
        #[pdo(entry = od::Statusword)]
        status: <od::Statusword as Entry>::Value,
        #[pdo(entry = od::VelocityActualValue)]
        velocity: od::VelocityActualValueValue,
        #[pdo(entry = od::ModesOfOperationDisplay)]
        mode: od::ModesOfOperationDisplayValue,
    }

    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(rpdo = 4)]
    struct ControlVelocity {
        #[pdo(entry = od::Controlword)]
        control: <od::Controlword as Entry>::Value,
        #[pdo(entry = od::TargetVelocity)]
        velocity: od::TargetVelocityValue,
    }

    let id = interroll_ec5000bi::DEFAULT_NODE_ID;
    let drive = node(id);
    let clock = Clock::new();
    let device = models::interroll_ec5000bi::simulator(clock.now());

    // Phase 1: the runtime configures both PDOs on the in-process bus.
    let bus = VirtualBus::new();
    let mut device_port = bus.attach();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let device_clock = clock.clone();
    let serving = std::thread::spawn(move || {
        let mut device = device;
        blocking::serve(
            &mut device_port,
            &device_clock,
            &mut device,
            &flag,
            None,
            |_| {},
        )
        .expect("the simulator's bus");
        device
    });
    let mut sdo = SdoClient::new(bus.attach(), ClientConfig::new(Channel::default_for(drive)));
    let mut watch = bus.attach();
    let tpdo = PdoConfig::from_pdo::<StatusVelocity>(drive)
        .expect("TPDO4 has a predefined COB-ID")
        .with_transmission_type(TransmissionType::EventDrivenProfile)
        .with_event_timer(EventTimer(20));
    eds2rust_runtime::pdo::blocking::configure_pdo(&mut sdo, &tpdo).expect("TPDO4 configured");
    let rpdo = PdoConfig::from_pdo::<ControlVelocity>(drive)
        .expect("RPDO4 has a predefined COB-ID")
        .with_transmission_type(TransmissionType::EventDrivenProfile);
    eds2rust_runtime::pdo::blocking::configure_pdo(&mut sdo, &rpdo).expect("RPDO4 configured");
    assert_eq!(sdo.upload(0x1A03, 0).expect("0x1A03 sub 0"), [3]);
    assert_eq!(
        sdo.upload(0x1A03, 2).expect("0x1A03 sub 2"),
        0x606C_0020u32.to_le_bytes()
    );

    // Operational: an RPDO4 from the master is written into 0x6040/0x60FF.
    let start = Frame::new(CanId::Standard(0x000), &[0x01, id]).expect("NMT start");
    watch.send(&start).expect("send NMT start");
    let command = ControlVelocity {
        control: <od::Controlword as Entry>::Value::from_raw(0x0006),
        velocity: od::TargetVelocityValue::from_raw(1200),
    };
    let frame = Frame::new(ControlVelocity::can_id(drive), &command.encode()).expect("RPDO4 frame");
    // The device takes its frames in send order on its one port: it is
    // operational before the RPDO, and has written the RPDO before it
    // answers the SDO reads below.
    watch.send(&frame).expect("send RPDO4");
    assert_eq!(
        sdo.read::<od::TargetVelocity>().expect("0x60FF"),
        command.velocity
    );
    assert_eq!(
        sdo.read::<od::Controlword>().expect("0x6040"),
        command.control
    );

    // TPDO4 frames (event timer 20 ms) decode into the derived struct, and
    // come to agree with the objects read over SDO (the drive has left
    // "switch on disabled" on the shutdown command; TPDOs sent before that
    // still say so).
    let status = sdo.read::<od::Statusword>().expect("0x6041");
    let mode = sdo.read::<od::ModesOfOperationDisplay>().expect("0x6061");
    let tpdo4 = StatusVelocity::can_id(drive);
    let deadline = StdInstant::now() + Duration::from_secs(3);
    let mut last = None;
    loop {
        assert!(
            StdInstant::now() < deadline,
            "no TPDO4 with statusword {status:?} on the in-process bus; last {last:?}"
        );
        if let Some(f) = watch.recv(Duration::from_millis(100)).expect("receive")
            && f.id() == tpdo4
        {
            let p = StatusVelocity::decode(f.data()).expect("TPDO4 length");
            last = Some(p);
            if p.status == status {
                assert_eq!(p.mode, mode);
                break;
            }
        }
    }
    stop.store(true, Ordering::Relaxed);
    let device = serving.join().expect("the simulator thread");

    // Phase 2: python-canopen reads the mapping back and decodes a TPDO4.
    let py = PyPeer::spawn().unwrap_or_else(|e| panic!("{e}"));
    let eds = export_eds("interroll_ec5000bi");
    let mut py_port = py.port();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let serving = std::thread::spawn(move || {
        let mut device = device;
        blocking::serve(&mut py_port, &clock, &mut device, &flag, None, |_| {})
    });
    start_node(&py, id, &eds);
    let maps = read_maps(&py, id);
    check_map::<StatusVelocity>(&maps, 4, drive);
    let received = start_and_receive(&py, id, &[4], false);
    let (data, values) = &received[0];
    let p = StatusVelocity::decode(data).expect("TPDO4 length");
    let ours = [
        i128::from(p.status.to_raw()),
        i128::from(p.velocity.to_raw()),
        i128::from(p.mode.to_raw()),
    ];
    assert_eq!(values, &ours, "data {data:02X?}");
    stop.store(true, Ordering::Relaxed);
    serving
        .join()
        .expect("the simulator thread")
        .expect("the simulator's bus");
}
