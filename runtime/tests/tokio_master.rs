//! The tokio composite master: SDO transfers (typed, segmented, block),
//! cancellation and timeouts, PDO configuration, the driver's lifetime.
#![cfg(feature = "tokio")]

#[macro_use]
mod support;

use support::tokio_rig::*;

use std::time::Duration;

use eds2rust_runtime::Frame;
use eds2rust_runtime::blocking::Error;
use eds2rust_runtime::master;
use eds2rust_runtime::nmt::{NmtCommand, NmtTarget};
use eds2rust_runtime::od::standard::EventTimer;
use eds2rust_runtime::od::{self, PdoDirection};
use eds2rust_runtime::pdo::{PdoCobId, PdoConfig, StepAction, TransmissionType};
use eds2rust_runtime::sdo::client::Method;
use eds2rust_runtime::sdo::{AbortCode, Channel, SdoError};
use eds2rust_runtime::tokio::{Driver, Master};
use eds2rust_runtime::transport::AsyncBus;
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use tokio::time::Instant as TokioInstant;

#[tokio::test(start_paused = true)]
async fn typed_segmented_and_block_transfers() {
    let rig = Rig::new(|_| {}).await;
    let m = &rig.master;
    let dev = node(DEVICE);
    assert_eq!(m.read::<ProducerHeartbeatTime>(dev).await.unwrap(), 50);
    m.write::<ProducerHeartbeatTime>(dev, 250).await.unwrap();
    assert_eq!(m.read::<ProducerHeartbeatTime>(dev).await.unwrap(), 250);
    // 20 bytes: a segmented upload.
    assert_eq!(
        m.read_string::<DeviceName>(dev).await.unwrap(),
        "eds2rust test device"
    );
    // Block upload and download of a 100-byte DOMAIN.
    let blob = m.upload_with(dev, 0x2100, 0, Method::Block).await.unwrap();
    assert_eq!(blob, [0xA5; 100]);
    let data: Vec<u8> = (0..100).collect();
    m.download_with(dev, 0x2100, 0, &data, Method::Block)
        .await
        .unwrap();
    assert_eq!(m.read_bytes::<Blob>(dev).await.unwrap(), data);
    // Segmented download, then read back.
    m.download_with(dev, 0x2100, 0, b"abc", Method::Segmented)
        .await
        .unwrap();
    assert_eq!(m.read_bytes::<Blob>(dev).await.unwrap(), b"abc");
    // A missing object: the device's abort comes back.
    assert!(matches!(
        m.upload(dev, 0x2001, 0).await,
        Err(Error::Sdo {
            error: SdoError::RemoteAbort(AbortCode::ObjectDoesNotExist),
            ..
        })
    ));
    // The expedited write of 0x1017 on the wire (CiA 301: 0x2B, 2 bytes).
    let writes: Vec<Frame> = rig
        .seen()
        .into_iter()
        .filter(|f| f.standard_id() == Some(0x620) && f.data().first() == Some(&0x2B))
        .collect();
    assert_eq!(writes[0].to_string(), "620#2B171000FA000000");
}

#[tokio::test(start_paused = true)]
async fn transfers_of_several_tasks_take_turns() {
    let rig = Rig::new(|_| {}).await;
    let tasks: Vec<_> = (0..4)
        .map(|_| {
            let m = rig.master.clone();
            tokio::spawn(async move { m.read_bytes::<DeviceName>(node(DEVICE)).await })
        })
        .collect();
    for task in tasks {
        assert_eq!(task.await.unwrap().unwrap(), b"eds2rust test device");
    }
}

#[tokio::test(start_paused = true)]
async fn a_cancelled_transfer_is_aborted_and_the_next_succeeds() {
    let rig = Rig::new(|_| {}).await;
    // Node 0x31 is a scripted peer: it answers the first upload with a
    // segmented initiate, then falls silent.
    let mut peer = rig.bus.attach();
    let m = rig.master.clone();
    let read = tokio::spawn(async move { m.upload(node(0x31), 0x1008, 0).await });
    start_segmented_upload(&mut peer).await;
    // The caller gives up mid-transfer.
    tokio::time::sleep(Duration::from_millis(100)).await;
    read.abort();
    assert!(read.await.unwrap_err().is_cancelled());
    let abort = tokio::time::timeout(Duration::from_millis(10), recv_from(&mut peer, 0x631))
        .await
        .expect("no abort frame")
        .unwrap();
    // Abort 0x05040000 for (0x1008, 0).
    assert_eq!(abort.to_string(), "631#8008100000000405");
    // The next transfer with that node is not refused as busy.
    let m = rig.master.clone();
    let read = tokio::spawn(async move { m.read::<ProducerHeartbeatTime>(node(0x31)).await });
    let request = recv_from(&mut peer, 0x631).await.unwrap();
    assert_eq!(request.to_string(), "631#4017100000000000");
    let response = frame(0x5B1, &[0x4B, 0x17, 0x10, 0x00, 0x34, 0x12, 0, 0]);
    AsyncBus::send(&mut peer, &response).await.unwrap();
    assert_eq!(read.await.unwrap().unwrap(), 0x1234);
    // Nor with the device.
    assert_eq!(
        rig.master
            .read::<ProducerHeartbeatTime>(node(DEVICE))
            .await
            .unwrap(),
        50
    );
}

#[tokio::test(start_paused = true)]
async fn a_transfer_past_its_bound_times_out_cleanly() {
    let rig = Rig::new(|core| {
        let mut config =
            eds2rust_runtime::sdo::client::ClientConfig::new(Channel::default_for(node(0x32)));
        config.timeout = Duration::from_millis(200);
        core.add_sdo_client(node(0x32), config);
    })
    .await;
    let start = TokioInstant::now();
    // No node 0x32 on the bus.
    let e = rig.master.upload(node(0x32), 0x1000, 0).await.unwrap_err();
    assert_sdo_timeout(&e);
    assert_eq!(start.elapsed(), Duration::from_millis(200));
    let aborts: Vec<String> = rig.seen_on(0x632);
    assert_eq!(aborts, ["632#4000100000000000", "632#8000100000000405"]);
    // A later call works (and times out the same way).
    let e = rig.master.upload(node(0x32), 0x1000, 0).await.unwrap_err();
    assert_sdo_timeout(&e);
    rig.seen();
    // A future dropped in place (a `timeout` around it) is aborted at once.
    let start = TokioInstant::now();
    let cut = Duration::from_millis(50);
    let upload = rig.master.upload(node(0x32), 0x1018, 1);
    assert!(tokio::time::timeout(cut, upload).await.is_err());
    rig.master.flush().await.unwrap();
    assert_eq!(start.elapsed(), cut);
    let sent: Vec<String> = rig.seen_on(0x632);
    assert_eq!(sent, ["632#4018100100000000", "632#8018100100000405"]);
}

#[tokio::test(start_paused = true)]
async fn configure_pdo_writes_in_the_cia_301_order_and_reads_back() {
    let rig = Rig::new(|_| {}).await;
    let config = PdoConfig::new(
        PdoDirection::Tpdo,
        1,
        PdoCobId(0x1A0),
        <Counter as od::Pdo>::MAPPING,
    )
    .unwrap()
    .with_transmission_type(TransmissionType::from_raw(1))
    .with_event_timer(EventTimer(100));
    rig.seen();
    rig.master
        .configure_pdo(node(DEVICE), &config)
        .await
        .unwrap();
    // Every initiate request to the device, as (action, index, sub, data).
    let requests: Vec<(StepAction, u16, u8, Vec<u8>)> = rig
        .seen()
        .iter()
        .filter(|f| f.standard_id() == Some(0x620))
        .filter_map(|f| {
            let d = f.data();
            let index = u16::from_le_bytes([d[1], d[2]]);
            match d[0] & 0xE0 {
                0x20 => {
                    let n = 4 - usize::from((d[0] >> 2) & 3);
                    Some((StepAction::Write, index, d[3], d[4..4 + n].to_vec()))
                }
                0x40 => Some((StepAction::ReadBack, index, d[3], Vec::new())),
                _ => None,
            }
        })
        .collect();
    let expected: Vec<(StepAction, u16, u8, Vec<u8>)> = config
        .steps()
        .map(|s| {
            let data = match s.action() {
                StepAction::Write => s.bytes().to_vec(),
                StepAction::ReadBack => Vec::new(),
            };
            (s.action(), s.index(), s.sub(), data)
        })
        .collect();
    assert_eq!(requests, expected);
    // The first write disables the PDO, the last write enables it again.
    assert_eq!(requests[0].3, 0x8000_01A0u32.to_le_bytes());
    assert_eq!(requests[1], (StepAction::Write, 0x1A00, 0, vec![0]));

    // Invalid: refused before anything is sent.
    let mut bad = config;
    bad.mapping_index = 0x1600;
    let e = rig
        .master
        .configure_pdo(node(DEVICE), &bad)
        .await
        .unwrap_err();
    assert!(
        e.to_string().starts_with("invalid PDO configuration"),
        "{e}"
    );
    assert!(rig.seen().iter().all(|f| f.standard_id() != Some(0x620)));

    // A device that refuses a write: the step and the abort are reported.
    let mut refused = config;
    refused.communication_index = 0x1801;
    let e = rig
        .master
        .configure_pdo(node(DEVICE), &refused)
        .await
        .unwrap_err();
    let Error::PdoConfig(e) = e else {
        panic!("{e:?}")
    };
    assert_eq!(e.abort_code(), Some(AbortCode::ObjectDoesNotExist));
    assert_eq!(e.step().map(|s| (s.index(), s.sub())), Some((0x1801, 1)));
}

#[tokio::test(start_paused = true)]
async fn the_driver_ends_with_the_last_handle_and_calls_fail_after_it_stopped() {
    let Rig {
        master,
        mut events,
        driver,
        ..
    } = Rig::new(|_| {}).await;
    let other = master.clone();
    drop(master);
    // One handle is left: the driver runs on.
    assert_eq!(
        other
            .read::<ProducerHeartbeatTime>(node(DEVICE))
            .await
            .unwrap(),
        50
    );
    drop(other);
    driver.await.unwrap().unwrap();
    // The stream ends once its queued events are taken.
    while events.next().await.is_some() {}
    assert!(events.is_closed());

    // A driver dropped without running: calls fail at once.
    let bus = VirtualBus::new();
    let core = master::Master::new(node(1), None);
    let (master, driver): (Master, Driver<VirtualPort>) = Master::new(bus.attach(), core);
    drop(driver);
    assert!(!master.is_running());
    let e = master.upload(node(DEVICE), 0x1000, 0).await.unwrap_err();
    assert!(matches!(e, Error::DriverStopped { .. }), "{e}");
    assert!(e.to_string().contains("the driver was dropped"), "{e}");
    assert!(master.start().await.is_err());
    assert!(matches!(
        master.nmt(NmtCommand::Start, NmtTarget::All).await,
        Err(Error::DriverStopped { .. })
    ));
}

#[test]
fn futures_are_send() {
    fn assert_send<T: Send>(_: &T) {}
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .build()
        .unwrap();
    let _guard = rt.enter();
    let bus = VirtualBus::new();
    let core = master::Master::new(node(1), None);
    let (m, driver) = Master::new(bus.attach(), core);
    assert_send(&m.read::<ProducerHeartbeatTime>(node(DEVICE)));
    assert_send(&m.upload(node(DEVICE), 0x1000, 0));
    assert_send(&m.lss_inquire_node_id());
    assert_send(&m.nmt(NmtCommand::Start, NmtTarget::All));
    let config = PdoConfig::new(
        PdoDirection::Tpdo,
        1,
        PdoCobId(0x1A0),
        <Counter as od::Pdo>::MAPPING,
    )
    .unwrap();
    assert_send(&m.configure_pdo(node(DEVICE), &config));
    assert_send(&driver.run());
}
