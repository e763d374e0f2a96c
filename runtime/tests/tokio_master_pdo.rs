//! The tokio master's PDO calls on the virtual bus under tokio's paused
//! clock: the same names and arguments as the blocking master's.
#![cfg(feature = "tokio")]

#[macro_use]
mod support;

use support::tokio_rig::*;

use std::time::Duration;

use eds2rust_runtime::CanId;
use eds2rust_runtime::blocking::Error;
use eds2rust_runtime::pdo::{PdoCobId, PdoError};
use eds2rust_runtime::sync::SyncProducer;
use tokio::time::Instant as TokioInstant;

// The device's RPDO1 as the master sends it: a 16-bit word.
word_pdo!(Command, Rpdo, 0x1400, 0x200, 0x2002_0010);

#[tokio::test(start_paused = true)]
async fn send_pdo_sends_the_typed_rpdo() {
    let mut rig = Rig::new(|_| {}).await;
    rig.master.send_pdo(node(DEVICE), &Command(0x1234)).unwrap();
    let frame = recv_from(&mut rig.monitor, 0x220).await.unwrap();
    assert_eq!(frame.to_string(), "220#3412");
    let extended = PdoCobId::new(CanId::Extended(0x0123_4567));
    rig.master.send_pdo_on(extended, &Command(0xBEEF)).unwrap();
    let frame = loop {
        let frame = eds2rust_runtime::transport::AsyncBus::recv(&mut rig.monitor)
            .await
            .unwrap();
        if frame.id() == CanId::Extended(0x0123_4567) {
            break frame;
        }
    };
    assert_eq!(frame.data(), [0xEF, 0xBE]);
    assert_eq!(rig.master.with_core(|c| c.pdo_tx.len()), 2);
}

#[tokio::test(start_paused = true)]
async fn next_pdo_and_latest_pdo_receive_the_typed_tpdo() {
    let rig = Rig::new(|core| {
        core.sync = Some(SyncProducer::new(Some(Duration::from_millis(10)), None).unwrap());
    })
    .await;
    assert!(
        rig.master
            .latest_pdo::<Counter>(node(DEVICE))
            .unwrap()
            .is_none()
    );
    let first = rig
        .master
        .next_pdo::<Counter>(node(DEVICE), Duration::from_millis(100))
        .await
        .unwrap();
    let second = rig
        .master
        .next_pdo::<Counter>(node(DEVICE), Duration::from_millis(100))
        .await
        .unwrap();
    // One TPDO per SYNC, counted up after each.
    assert_eq!(second.0, first.0 + 1);
    assert_eq!(
        rig.master.latest_pdo::<Counter>(node(DEVICE)).unwrap(),
        Some(second)
    );
}

#[tokio::test(start_paused = true)]
async fn next_pdo_times_out_in_virtual_time() {
    // No SYNC: the device's synchronous TPDO never comes.
    let rig = Rig::new(|_| {}).await;
    let start = TokioInstant::now();
    let waited = Duration::from_millis(250);
    match rig.master.next_pdo::<Counter>(node(DEVICE), waited).await {
        Err(Error::Pdo(PdoError::Timeout { can_id, waited: w })) => {
            assert_eq!((can_id, w), (CanId::Standard(0x1A0), waited));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(TokioInstant::now() - start, waited);
}
