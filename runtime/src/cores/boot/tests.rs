use alloc::vec;
use alloc::vec::Vec;

use super::*;

fn node() -> NodeId {
    NodeId::new(5).unwrap()
}

fn plan() -> SlavePlan {
    SlavePlan {
        node: node(),
        device_type: 0x0002_0192,
        vendor_id: 0x0000_00AB,
        product_code: 0x1234,
        revision_number: 0,
        serial_number: 0,
        software_version: 0,
        configuration_date_time: None,
        configuration: Vec::from([
            ConfigWrite {
                index: 0x1017,
                sub_index: 0,
                data: vec![0xE8, 0x03].into(),
            },
            ConfigWrite {
                index: 0x6060,
                sub_index: 0,
                data: vec![1].into(),
            },
        ])
        .into(),
        reset: Some(NmtCommand::ResetCommunication),
        heartbeat: true,
        start: true,
    }
}

fn read(boot: &mut SlaveBoot, index: u16, sub_index: u8, value: u32) -> Vec<BootEvent> {
    assert_eq!(
        boot.poll_request(),
        Some(Request::Read { index, sub_index })
    );
    boot.read_done(Ok(&value.to_le_bytes())).unwrap()
}

#[test]
fn a_slave_boots_step_by_step() {
    let mut boot = SlaveBoot::new(plan());
    assert_eq!(
        boot.poll_request(),
        Some(Request::Nmt(NmtCommand::ResetCommunication))
    );
    assert_eq!(boot.poll_request(), Some(Request::AwaitBootUp));
    assert_eq!(boot.poll_request(), None, "one request at a time");
    assert_eq!(boot.boot_up(NmtState::BootUp), [BootEvent::BootedUp]);
    read(&mut boot, 0x1000, 0, 0x0002_0192);
    read(&mut boot, 0x1018, 1, 0xAB);
    // Revision and serial number are 0: not read.
    let events = read(&mut boot, 0x1018, 2, 0x1234);
    assert_eq!(events, [BootEvent::IdentityChecked]);
    for (i, expected) in plan().configuration.iter().cloned().enumerate() {
        assert_eq!(boot.poll_request(), Some(Request::Write(expected)));
        let events = boot.write_done(Ok(())).unwrap();
        if i == 1 {
            assert_eq!(events, [BootEvent::Configured { entries: 2 }]);
        }
    }
    assert_eq!(boot.poll_request(), Some(Request::AwaitHeartbeat));
    assert_eq!(
        boot.heartbeat(),
        [BootEvent::HeartbeatStarted, BootEvent::Booted]
    );
    assert!(!boot.is_finished());
    assert_eq!(boot.poll_request(), Some(Request::Nmt(NmtCommand::Start)));
    assert!(boot.is_finished());
    assert_eq!(boot.poll_request(), None);
}

/// A boot that has seen the boot-up, the device type and the vendor id.
fn identified() -> SlaveBoot {
    let mut boot = SlaveBoot::new(plan());
    boot.poll_request();
    boot.poll_request();
    boot.boot_up(NmtState::BootUp);
    read(&mut boot, 0x1000, 0, 0x0002_0192);
    read(&mut boot, 0x1018, 1, 0xAB);
    boot
}

#[test]
fn a_wrong_product_code_is_status_m_with_both_values() {
    let mut boot = identified();
    assert_eq!(
        boot.poll_request(),
        Some(Request::Read {
            index: 0x1018,
            sub_index: 2
        })
    );
    let error = boot.read_done(Ok(&0x9999u32.to_le_bytes())).unwrap_err();
    assert_eq!(error.status, BootStatus::ProductCode);
    assert_eq!(error.status.letter(), 'M');
    assert_eq!(
        error.to_string(),
        "node 5: boot error M: the product code (0x1018 sub 2) is not the expected one \
         (0x1018 sub 2: expected 0x00001234, found 0x00009999)"
    );
    assert!(boot.is_finished());
    assert_eq!(boot.poll_request(), None);
}

#[test]
fn no_boot_up_is_status_b() {
    let mut plan = plan();
    plan.reset = None;
    let mut boot = SlaveBoot::new(plan);
    assert_eq!(boot.poll_request(), Some(Request::AwaitBootUp));
    let error = boot.timed_out().unwrap_err();
    assert_eq!(error.status, BootStatus::NoResponse);
    assert_eq!(error.node, node());
}

#[test]
fn an_abort_while_configuring_is_status_j_naming_the_entry() {
    let mut boot = identified();
    read(&mut boot, 0x1018, 2, 0x1234);
    boot.poll_request();
    boot.write_done(Ok(())).unwrap();
    boot.poll_request();
    let error = boot
        .write_done(Err(AbortCode::from_code(0x0609_0030)))
        .unwrap_err();
    assert_eq!(error.status, BootStatus::ConfigurationFailed);
    assert_eq!(error.object, Some((0x6060, 0)));
    assert_eq!(
        error.to_string(),
        "node 5: boot error J: the configuration download failed (0x6060 sub 0, the write \
         was aborted: 0x06090030 (invalid value for parameter (download only)))"
    );
}

#[test]
fn a_current_configuration_is_not_written_again() {
    let mut plan = plan();
    plan.configuration_date_time = Some((7000, 1234));
    plan.heartbeat = false;
    plan.start = false;
    plan.vendor_id = 0;
    plan.product_code = 0;
    let mut boot = SlaveBoot::new(plan);
    boot.poll_request();
    boot.poll_request();
    boot.boot_up(NmtState::BootUp);
    // The device type is read even when it is not checked... and here it is.
    let events = read(&mut boot, 0x1000, 0, 0x0002_0192);
    assert_eq!(events, [BootEvent::IdentityChecked]);
    read(&mut boot, 0x1020, 1, 7000);
    let events = read(&mut boot, 0x1020, 2, 1234);
    assert_eq!(events, [BootEvent::ConfigurationCurrent, BootEvent::Booted]);
    assert!(boot.is_finished(), "the master starts all nodes at the end");
    assert_eq!(boot.poll_request(), None);
}

#[test]
fn an_operational_node_is_reported_and_booted_on() {
    let mut plan = plan();
    plan.reset = None;
    let mut boot = SlaveBoot::new(plan);
    boot.poll_request();
    assert_eq!(
        boot.boot_up(NmtState::Operational),
        [BootEvent::BootedUp, BootEvent::WasOperational]
    );
    assert_eq!(
        boot.poll_request(),
        Some(Request::Read {
            index: 0x1000,
            sub_index: 0
        })
    );
}

#[test]
fn the_statuses_are_a_to_o() {
    let letters: Vec<char> = BootStatus::ALL.iter().map(|s| s.letter()).collect();
    assert_eq!(letters, ('A'..='O').collect::<Vec<_>>());
}

#[test]
fn a_refused_device_type_read_is_an_answer_unless_one_is_expected() {
    // Expected 0: the node answered (a device without 0x1000); boot on.
    let mut unchecked = plan();
    unchecked.device_type = 0;
    let mut boot = SlaveBoot::new(unchecked);
    boot.poll_request();
    boot.poll_request();
    boot.boot_up(NmtState::BootUp);
    boot.poll_request();
    let events = boot.read_done(Err(AbortCode::ObjectDoesNotExist)).unwrap();
    assert!(events.is_empty());
    assert_eq!(
        boot.poll_request(),
        Some(Request::Read {
            index: 0x1018,
            sub_index: 1
        })
    );
    // Expected: the refusal is status C with the abort, not B.
    let mut boot = SlaveBoot::new(plan());
    boot.poll_request();
    boot.poll_request();
    boot.boot_up(NmtState::BootUp);
    boot.poll_request();
    let error = boot
        .read_done(Err(AbortCode::ObjectDoesNotExist))
        .unwrap_err();
    assert_eq!(error.status, BootStatus::DeviceType);
    assert_eq!(error.abort, Some(AbortCode::ObjectDoesNotExist));
    // A timeout is no answer: B.
    let mut boot = SlaveBoot::new(plan());
    boot.poll_request();
    boot.poll_request();
    boot.boot_up(NmtState::BootUp);
    boot.poll_request();
    let error = boot.read_done(Err(AbortCode::Timeout)).unwrap_err();
    assert_eq!(error.status, BootStatus::NoResponse);
}
