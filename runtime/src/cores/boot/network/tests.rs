use alloc::borrow::Cow;
use alloc::vec;
use alloc::vec::Vec;
use core::time::Duration;

use super::*;
use crate::boot::{MasterPlan, SlavePlan};

fn id(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

fn slave(n: u8, mandatory: bool) -> SlaveConfig {
    SlaveConfig {
        name: Cow::Borrowed("slave"),
        plan: SlavePlan {
            node: id(n),
            device_type: 0,
            vendor_id: 0,
            product_code: 0,
            revision_number: 0,
            serial_number: 0,
            software_version: 0,
            configuration_date_time: None,
            configuration: Cow::Owned(vec![ConfigWrite {
                index: 0x1017,
                sub_index: 0,
                data: Cow::Owned(vec![100, 0]),
            }]),
            reset: Some(NmtCommand::ResetCommunication),
            heartbeat: false,
            start: false,
        },
        boot: true,
        mandatory,
        supervision: Supervision::None,
    }
}

fn plan(slaves: Vec<SlaveConfig>) -> NetworkPlan {
    NetworkPlan {
        master: MasterPlan {
            node: id(1),
            heartbeat: None,
            sync_period: None,
            sync_overflow: 0,
        },
        slaves: Cow::Owned(slaves),
        boot_time: None,
        response_time: NetworkPlan::DEFAULT_RESPONSE_TIME,
        start_nodes: true,
        start_all_nodes: false,
        start_master: true,
        reset_all_nodes: false,
        stop_all_nodes: false,
        receive: Cow::Borrowed(&[]),
        transmit: Cow::Borrowed(&[]),
    }
}

fn boot_up(n: u8) -> Frame {
    Frame::standard(0x700 + u16::from(n), [0; 8], 1)
}

fn actions(boot: &mut NetworkBoot) -> Vec<Action> {
    core::iter::from_fn(|| boot.poll_action()).collect()
}

fn uploaded(index: u16, sub: u8, value: u32) -> ClientEvent {
    ClientEvent::Uploaded {
        index,
        sub,
        data: value.to_le_bytes().to_vec(),
        padded: false,
    }
}

fn read(node: u8, index: u16, sub_index: u8) -> Action {
    Action::Read {
        node: id(node),
        index,
        sub_index,
    }
}

#[test]
fn a_second_boot_up_during_the_device_type_read_keeps_the_read() {
    let now = Instant::ZERO;
    let mut boot = NetworkBoot::new(plan(vec![slave(5, true)]));
    boot.start(now);
    assert_eq!(
        actions(&mut boot),
        [Action::Nmt(
            NmtCommand::ResetCommunication,
            NmtTarget::Node(id(5))
        )]
    );
    // A boot-up sent before the reset arrives, then the reset's own.
    boot.handle_frame(now, &boot_up(5));
    assert_eq!(actions(&mut boot), [read(5, 0x1000, 0)]);
    boot.handle_frame(now, &boot_up(5));
    assert_eq!(actions(&mut boot), [], "no cancel, no second read");
    // The answer to the one read moves the boot on.
    assert!(boot.sdo_event(now, id(5), &uploaded(0x1000, 0, 0x192)));
    let next = actions(&mut boot);
    assert!(
        matches!(next.as_slice(), [Action::Write { node, .. }] if *node == id(5)),
        "{next:?}"
    );
    assert_eq!(boot.slave(id(5)).unwrap().boots, 1);
}

/// Slave 5 answers 0x1000 and takes its one configuration write at `at`.
fn identify_and_configure(boot: &mut NetworkBoot, at: Instant) {
    boot.handle_frame(at, &boot_up(5));
    assert_eq!(actions(boot), [read(5, 0x1000, 0)]);
    boot.sdo_event(at, id(5), &uploaded(0x1000, 0, 0x192));
    actions(boot);
    let done = ClientEvent::Downloaded {
        index: 0x1017,
        sub: 0,
    };
    assert!(boot.sdo_event(at, id(5), &done));
}

/// A started boot of node 5 (`mandatory` or not), heartbeat-supervised
/// (150 ms), with a boot time of 1 s.
fn heartbeat_boot(mandatory: bool) -> NetworkBoot {
    let mut config = slave(5, mandatory);
    config.plan.heartbeat = true;
    config.supervision = Supervision::Heartbeat(Duration::from_millis(150));
    let mut p = plan(vec![config]);
    p.boot_time = Some(Duration::from_millis(1000));
    let mut boot = NetworkBoot::new(p);
    boot.start(Instant::ZERO);
    actions(&mut boot);
    boot
}

#[test]
fn the_wait_for_the_first_heartbeat_ends_with_the_boot_time() {
    let mut boot = heartbeat_boot(true);
    // The boot-up comes late, just within the boot time.
    identify_and_configure(&mut boot, Instant::from_millis(990));
    assert_eq!(
        actions(&mut boot),
        [Action::Supervise(
            id(5),
            Supervision::Heartbeat(Duration::from_millis(150))
        )]
    );
    // Not 2 s (the response time) after it: at the boot time's end.
    assert_eq!(boot.poll_timeout(), Some(Instant::from_millis(1000)));
    boot.handle_timeout(Instant::from_millis(1000));
    let events: Vec<NetworkEvent> = core::iter::from_fn(|| boot.poll_event()).collect();
    let failed = events.iter().find_map(|e| match e {
        NetworkEvent::Failed(error) => Some(error.status),
        _ => None,
    });
    assert_eq!(failed, Some(BootStatus::HeartbeatNotStarted));
    assert!(matches!(
        events.last(),
        Some(NetworkEvent::BootFailed { .. })
    ));
    assert_eq!(boot.outcome(), Some(false));
}

#[test]
fn after_the_first_boot_the_heartbeat_wait_is_the_response_time() {
    let mut boot = heartbeat_boot(false);
    // No boot-up within the boot time: the optional slave fails (B).
    boot.handle_timeout(Instant::from_millis(1000));
    assert_eq!(boot.outcome(), Some(true));
    assert_eq!(actions(&mut boot), [Action::MasterOperational]);
    // It comes later: booted again, with the response time to wait.
    let later = Instant::from_millis(5000);
    identify_and_configure(&mut boot, later);
    assert_eq!(
        boot.poll_timeout(),
        Some(later + NetworkPlan::DEFAULT_RESPONSE_TIME)
    );
}
