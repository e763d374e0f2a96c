//! The tokio composite master: heartbeat, EMCY, NMT and PDO events as
//! streams, their bounded queues, and LSS.
#![cfg(feature = "tokio")]

#[macro_use]
mod support;

use support::tokio_rig::*;

use std::time::Duration;

use eds2rust_runtime::CanId;
use eds2rust_runtime::emcy::EmcyEvent;
use eds2rust_runtime::heartbeat::HeartbeatEvent;
use eds2rust_runtime::lss::{IdentityField, LssState};
use eds2rust_runtime::master::MasterEvent;
use eds2rust_runtime::nmt::{NmtCommand, NmtEvent, NmtState, NmtTarget};
use eds2rust_runtime::od::PdoLengthError;
use eds2rust_runtime::pdo::PdoCobId;
use eds2rust_runtime::sync::SyncProducer;
use tokio::time::Instant as TokioInstant;

#[tokio::test(start_paused = true)]
async fn heartbeat_timeout_comes_at_the_right_virtual_time() {
    let mut rig = Rig::new(|core| {
        core.consumer
            .monitor(node(DEVICE), Some(Duration::from_millis(120)));
    })
    .await;
    let start = TokioInstant::now();
    // The device's boot-up at 0, heartbeats at 50, 100, 150, 200 ms.
    tokio::time::sleep(Duration::from_millis(210)).await;
    rig.device.abort();
    let at = rig
        .wait_for(|e| match e {
            MasterEvent::Heartbeat(HeartbeatEvent::Timeout { node: n }) => {
                Some((*n, TokioInstant::now()))
            }
            _ => None,
        })
        .await;
    assert_eq!(at.0, node(DEVICE));
    // The last heartbeat at 200 ms plus the consumer time of 120 ms.
    assert_eq!(at.1 - start, Duration::from_millis(320));
    assert!(
        rig.master
            .with_core(|c| c.consumer.is_timed_out(node(DEVICE)))
    );
}

#[tokio::test(start_paused = true)]
async fn emcy_and_nmt_events_and_command_frames() {
    let mut rig = Rig::new(|_| {}).await;
    rig.master
        .nmt(NmtCommand::Start, node(DEVICE))
        .await
        .unwrap();
    let to = rig
        .wait_for(|e| match e {
            MasterEvent::Nmt(NmtEvent::StateChanged { node: n, to, .. })
                if n.get() == DEVICE && *to == NmtState::Operational =>
            {
                Some(*to)
            }
            _ => None,
        })
        .await;
    assert_eq!(to, NmtState::Operational);
    rig.master
        .nmt(NmtCommand::ResetNode, NmtTarget::All)
        .await
        .unwrap();
    tokio::time::sleep(Duration::from_millis(1)).await;
    let nmt: Vec<String> = rig.seen_on(0x000);
    // CiA 301: start remote node 0x20, reset all nodes.
    assert_eq!(nmt, ["000#0120", "000#8100"]);

    // EMCY 0x8110 (CAN overrun), error register 0x11, from node 0x21.
    let peer = rig.bus.attach();
    peer.transmit(&frame(0x0A1, &[0x10, 0x81, 0x11, 0, 0, 0, 0, 0]));
    let emcy = rig
        .wait_for(|e| match e {
            MasterEvent::Emcy(EmcyEvent::Emergency { node: n, emcy }) => Some((*n, *emcy)),
            _ => None,
        })
        .await;
    assert_eq!(emcy.0, node(0x21));
    assert_eq!(emcy.1.code, 0x8110);
    assert_eq!(rig.events.dropped(), 0);
}

#[tokio::test(start_paused = true)]
async fn pdo_stream_yields_decoded_values() {
    let rig = Rig::new(|core| {
        core.sync = Some(SyncProducer::new(Some(Duration::from_millis(10)), None).unwrap());
    })
    .await;
    let mut pdos = rig.master.pdos::<Counter>(node(DEVICE)).unwrap();
    assert_eq!(pdos.can_id(), CanId::Standard(0x1A0));
    let first = pdos.next().await.unwrap().unwrap();
    let second = pdos.next().await.unwrap().unwrap();
    let third = pdos.next().await.unwrap().unwrap();
    assert_eq!(second.0, first.0 + 1);
    assert_eq!(third.0, first.0 + 2);
    // A frame of another length on the COB-ID: its length error.
    let peer = rig.bus.attach();
    // Let the SYNC-driven PDOs queued so far be taken first.
    while pdos.try_next().is_some() {}
    peer.transmit(&frame(0x1A0, &[1, 2, 3]));
    let mut saw_error = false;
    for _ in 0..4 {
        if let Err(e) = pdos.next().await.unwrap() {
            assert_eq!(
                e,
                PdoLengthError {
                    expected: 2,
                    actual: 3
                }
            );
            saw_error = true;
            break;
        }
    }
    assert!(saw_error);
    assert_eq!(pdos.dropped(), 0);
}

#[tokio::test(start_paused = true)]
async fn a_full_event_stream_drops_the_oldest_and_counts_them() {
    let rig = Rig::new(|core| {
        core.pdo_rx.watch(PdoCobId(0x1A5), 1, None).unwrap();
    })
    .await;
    // After the device's boot-up, before its first heartbeat.
    tokio::time::sleep(Duration::from_millis(10)).await;
    let mut events = rig.master.events_with_capacity(2);
    let peer = rig.bus.attach();
    for b in 1..=5 {
        peer.transmit(&frame(0x1A5, &[b]));
    }
    tokio::time::sleep(Duration::from_millis(1)).await;
    let mut got = Vec::new();
    while let Some(event) = events.try_next() {
        got.push(event);
    }
    assert_eq!(got.len(), 2);
    assert!(matches!(
        got[1],
        MasterEvent::Pdo(eds2rust_runtime::pdo::PdoEvent::Received { data: [5, ..], .. })
    ));
    assert_eq!(events.dropped(), 3);
}

#[tokio::test(start_paused = true)]
async fn lss_switch_and_inquire() {
    let rig = Rig::new(|_| {}).await;
    let m = &rig.master;
    m.lss_switch_global(LssState::Configuration).await.unwrap();
    assert_eq!(
        m.lss_inquire_identity(IdentityField::VendorId)
            .await
            .unwrap(),
        IDENTITY.vendor_id
    );
    assert_eq!(
        m.lss_inquire_identity(IdentityField::Serial).await.unwrap(),
        IDENTITY.serial
    );
    assert_eq!(m.lss_inquire_node_id().await.unwrap(), DEVICE);
    m.lss_switch_global(LssState::Waiting).await.unwrap();
    // In the waiting state the slave does not answer: the core's timeout.
    let e = m.lss_inquire_node_id().await.unwrap_err();
    assert!(
        matches!(
            e,
            eds2rust_runtime::tokio::Error::Lss(
                eds2rust_runtime::tokio::LssRequestError::NoResponse
            )
        ),
        "{e}"
    );
    let lss: Vec<String> = rig.seen_on(0x7E5);
    // CiA 305: switch state global (0x04) configuration, inquire vendor
    // id (0x5A), serial (0x5D), node id (0x5E).
    assert_eq!(lss[0], "7E5#0401000000000000");
    assert_eq!(lss[1], "7E5#5A00000000000000");
    assert_eq!(lss[2], "7E5#5D00000000000000");
    assert_eq!(lss[3], "7E5#5E00000000000000");
}
