//! The CiA 302-2 boot fault matrix on the virtual bus: the master
//! (`blocking::Master::boot_network`) boots
//! tests/networks/boot/matrix.yml against the network's own simulation
//! (`eds2rust_sim::network`) with one fault at a time, in virtual time
//! (a manual clock the simulation moves in 1 ms steps, so the whole
//! matrix takes well under a second of CPU). Each case checks the boot
//! status (A–O), the events and what the slaves hold.
//!
//! The network: `left` (node 2, mandatory) and `right` (node 3,
//! optional), the same CiA 402 drive (tests/networks/boot/drive.yaml),
//! heartbeats every 50 ms consumed by the master, SYNC every 10 ms (each
//! drive sends TPDO 1 on it), boot time 1 s.

#[path = "network_boot/rig.rs"]
mod rig;

use rig::*;

#[test]
fn without_faults_every_slave_is_identified_configured_and_started() {
    let mut rig = Rig::new(&[]);
    let real = std::time::Instant::now();
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    for node in [LEFT, RIGHT] {
        assert_eq!(state(&report, node), SlaveState::Operational);
        let s = report.slaves.iter().find(|s| s.node == id(node)).unwrap();
        assert!(s.identity_checked);
        let n = entries(&rig.network, node);
        assert_eq!(s.configuration, Some(Configuration::Written(n)));
        assert_eq!(rig.steps(node), full_boot(n));
        // What the configuration wrote is in the slave.
        assert_eq!(rig.sim().get_uint(id(node), 0x6060, 0), Some(8));
        assert_eq!(rig.sim().get_uint(id(node), 0x1017, 0), Some(50));
    }
    assert!(rig.events.contains(&NetworkEvent::Started(id(LEFT))));
    assert!(rig.events.contains(&NetworkEvent::Started(id(RIGHT))));
    assert_eq!(report.errors().count(), 0);
    assert!(
        rig.now() < Instant::from_millis(1000),
        "booted at {:?}",
        rig.now()
    );
    assert!(real.elapsed() < Duration::from_secs(5));
}

#[test]
fn a_missing_mandatory_slave_fails_the_network_with_status_b() {
    let mut rig = Rig::new(&[(LEFT, Fault::Missing)]);
    let report = rig.boot();
    assert!(!report.booted);
    let e = error(&report, LEFT);
    assert_eq!(e.status, BootStatus::NoResponse);
    assert_eq!(e.status.letter(), 'B');
    assert_eq!(e.object, Some((0x1000, 0)));
    assert!(e.to_string().starts_with("node 2: boot error B"), "{e}");
    // Decided at the boot time's end, not before.
    assert_eq!(rig.now(), Instant::from_millis(1000));
    assert!(rig.events.contains(&NetworkEvent::Failed(e)));
    assert_eq!(report.errors().count(), 1);
    // The optional slave booted meanwhile (and was started, as each slave
    // is when it is booted).
    assert_eq!(state(&report, RIGHT), SlaveState::Operational);
}

#[test]
fn a_missing_optional_slave_is_listed_as_failed_and_the_network_runs() {
    let mut rig = Rig::new(&[(RIGHT, Fault::Missing)]);
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    assert_eq!(state(&report, LEFT), SlaveState::Operational);
    assert_eq!(state(&report, RIGHT), SlaveState::Failed);
    let e = error(&report, RIGHT);
    assert_eq!(e.status, BootStatus::NoResponse);
    assert_eq!(rig.events.last(), Some(&NetworkEvent::Failed(e)));
    assert_eq!(report.errors().count(), 1);
}

/// The mandatory slave holds `value` in `field`: its boot fails with
/// `letter`, naming the object and both values.
fn wrong_identity(field: IdentityField, value: u32, letter: char) {
    let mut rig = Rig::new(&[(LEFT, Fault::Identity(field, value))]);
    let report = rig.boot();
    assert!(!report.booted);
    let e = error(&report, LEFT);
    assert_eq!(e.status.letter(), letter, "{e}");
    assert_eq!(e.object, Some(field.object()));
    assert_eq!(e.found, Some(value));
    let expected = rig.network.plan().slave(id(LEFT)).unwrap().plan.clone();
    let expected = match field {
        IdentityField::DeviceType => expected.device_type,
        IdentityField::VendorId => expected.vendor_id,
        IdentityField::ProductCode => expected.product_code,
        IdentityField::RevisionNumber => expected.revision_number,
        IdentityField::SerialNumber => expected.serial_number,
    };
    assert_ne!(expected, 0, "{field:?} is checked");
    assert_eq!(e.expected, Some(expected));
    let text = e.to_string();
    let (index, sub) = field.object();
    for part in [
        format!("node 2: boot error {letter}"),
        format!("0x{index:04X} sub {sub}"),
        format!("expected 0x{expected:08X}"),
        format!("found 0x{value:08X}"),
    ] {
        assert!(text.contains(&part), "`{text}` lacks `{part}`");
    }
    // Nothing was written to a device that is not the expected one.
    assert_eq!(rig.downloads(LEFT), []);
    assert!(rig.events.contains(&NetworkEvent::Failed(e)));
    assert!(!rig.steps(LEFT).contains(&BootEvent::IdentityChecked));
}

#[test]
fn a_wrong_device_type_is_status_c() {
    wrong_identity(IdentityField::DeviceType, 0x0002_0191, 'C');
}

#[test]
fn a_wrong_vendor_id_is_status_d() {
    wrong_identity(IdentityField::VendorId, 0x0000_0E2E, 'D');
}

#[test]
fn a_wrong_product_code_is_status_m() {
    wrong_identity(IdentityField::ProductCode, 0x0000_0004, 'M');
}

#[test]
fn a_wrong_revision_number_is_status_n() {
    wrong_identity(IdentityField::RevisionNumber, 0x0001_0001, 'N');
}

#[test]
fn a_wrong_serial_number_is_status_o() {
    wrong_identity(IdentityField::SerialNumber, 0x00BA_D000, 'O');
}

#[test]
fn an_sdo_abort_during_configuration_is_status_j_naming_object_and_abort() {
    let code = AbortCode::from_code(0x0609_0030);
    let mut rig = Rig::new(&[(
        LEFT,
        Fault::SdoAbort {
            index: 0x6060,
            sub: 0,
            code,
        },
    )]);
    let report = rig.boot();
    assert!(!report.booted);
    let e = error(&report, LEFT);
    assert_eq!(e.status, BootStatus::ConfigurationFailed);
    assert_eq!(e.status.letter(), 'J');
    assert_eq!(e.object, Some((0x6060, 0)));
    assert_eq!(e.abort, Some(code));
    let text = e.to_string();
    assert!(
        text.contains("boot error J") && text.contains("0x6060 sub 0"),
        "{text}"
    );
    assert!(text.contains(&code.to_string()), "{text}");
    // The write refused is the last one tried.
    assert_eq!(rig.downloads(LEFT).last(), Some(&(0x6060, 0)));
    assert!(rig.events.contains(&NetworkEvent::Failed(e)));
    assert!(rig.steps(LEFT).contains(&BootEvent::IdentityChecked));
}

#[test]
fn a_current_configuration_is_not_downloaded() {
    let mut rig = Rig::new(&[(LEFT, Fault::ConfigurationCurrent)]);
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    let left = report.slaves.iter().find(|s| s.node == id(LEFT)).unwrap();
    assert_eq!(left.configuration, Some(Configuration::Current));
    assert_eq!(left.state, SlaveState::Operational);
    assert!(rig.steps(LEFT).contains(&BootEvent::ConfigurationCurrent));
    assert_eq!(
        rig.downloads(LEFT),
        [],
        "nothing written to the current slave"
    );
    // The other one is configured as usual.
    assert_eq!(rig.downloads(RIGHT).len(), entries(&rig.network, RIGHT));
    // The current slave holds its configuration (saved before).
    assert_eq!(rig.sim().get_uint(id(LEFT), 0x6060, 0), Some(8));
    assert_eq!(rig.sim().get_uint(id(LEFT), 0x1017, 0), Some(50));
}

#[test]
fn a_heartbeat_that_never_starts_is_status_k() {
    let stops = Fault::HeartbeatStops {
        at: Duration::ZERO,
        resume: None,
    };
    let mut rig = Rig::new(&[(LEFT, stops)]);
    let report = rig.boot();
    assert!(!report.booted);
    let e = error(&report, LEFT);
    assert_eq!(e.status, BootStatus::HeartbeatNotStarted);
    assert_eq!(e.status.letter(), 'K');
    assert_eq!(e.object, Some((0x1017, 0)));
    // Identified and configured first.
    let steps = rig.steps(LEFT);
    let n = entries(&rig.network, LEFT);
    assert_eq!(steps, full_boot(n)[..3].to_vec());
}

#[test]
fn a_slave_booting_late_within_the_boot_time_is_booted() {
    let mut rig = Rig::new(&[(LEFT, Fault::LateBoot(Duration::from_millis(600)))]);
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    assert_eq!(state(&report, LEFT), SlaveState::Operational);
    let left = report.slaves.iter().find(|s| s.node == id(LEFT)).unwrap();
    assert!(left.boot_ended.unwrap() >= Instant::from_millis(600));
    assert_eq!(rig.steps(LEFT), full_boot(entries(&rig.network, LEFT)));
}

#[test]
fn a_mandatory_slave_booting_after_the_boot_time_fails_the_network_then_boots() {
    let mut rig = Rig::new(&[(LEFT, Fault::LateBoot(Duration::from_millis(1500)))]);
    let report = rig.boot();
    assert!(!report.booted);
    assert_eq!(error(&report, LEFT).status, BootStatus::NoResponse);
    assert_eq!(rig.now(), Instant::from_millis(1000));
    // When it finally comes, it is booted (the failed network does not
    // start it).
    rig.run(Duration::from_millis(1000));
    rig.rebooted(LEFT);
    let status = rig.slave(LEFT);
    assert_eq!(status.state, SlaveState::Booted, "{status:#?}");
    assert_eq!(status.error, None);
}
