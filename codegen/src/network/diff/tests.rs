//! The wiring rules on hand-built networks: each change alone, with its
//! kind and severity.

use super::*;
use crate::diff::Severity::{Additive, Breaking, Compatible};
use crate::ir::pdo::MappedObject;
use crate::network::config::Node;
use crate::network::config::test_pdo as pdo;
use crate::network::model::{At, BusOptions, MasterSection, SdoItem, SlaveSection, Spot};

fn at<T>(value: T) -> At<T> {
    At::new(value, Spot::default())
}

fn slave(name: &str) -> SlaveSection {
    let mut device = crate::ir::Device::default();
    device.identity.vendor_number = Some(0xB9);
    device.identity.product_number = Some(1);
    device.identity.revision_number = Some(2);
    SlaveSection {
        ..SlaveSection::new(
            name.into(),
            Spot::default(),
            at(format!("{name}.eds")),
            format!("{name}.eds").into(),
            Box::new(device),
        )
    }
}

fn node(name: &str, slave: usize, node_id: u8) -> Node {
    Node {
        name: name.into(),
        slave,
        node_id,
        rpdos: vec![pdo(1, 0x200 + u32::from(node_id), &[(0x6040, 0, 16)])],
        tpdos: vec![pdo(1, 0x180 + u32::from(node_id), &[(0x6041, 0, 16)])],
        disabled_rpdos: Vec::new(),
        disabled_tpdos: Vec::new(),
        concise: Vec::new(),
        heartbeat_producer: 100,
        guard_time: 0,
        life_time_factor: 0,
        heartbeat_consumer: true,
        emcy_cob_id: 0x80 + u32::from(node_id),
        time_cob_id: 0x100,
        device_type: 0x20192,
        vendor_id: 0xB9,
        product_code: 1,
        revision_number: 2,
        serial_number: 0,
        dcf_path: String::new(),
        configuration_file: String::new(),
    }
}

/// Two slaves, `axis` (id 2) and `lift` (id 3).
fn network() -> (Bus, Configured) {
    let bus = Bus {
        file: "bus.yml".into(),
        options: BusOptions::default(),
        master: MasterSection {
            node_id: 1,
            sync_period: 1000,
            heartbeat_producer: 50,
            ..MasterSection::default()
        },
        slaves: vec![slave("axis"), slave("lift")],
        extra_keys: Vec::new(),
    };
    let configured = Configured {
        nodes: vec![node("axis", 0, 2), node("lift", 1, 3)],
        master_concise: Vec::new(),
    };
    (bus, configured)
}

fn compare(old: &(Bus, Configured), new: &(Bus, Configured)) -> Vec<NetChange> {
    diff(
        Network {
            bus: &old.0,
            configured: &old.1,
        },
        Network {
            bus: &new.0,
            configured: &new.1,
        },
        &crate::diff::Options::default(),
    )
}

/// The changes as (node, kind, severity).
fn kinds(changes: &[NetChange]) -> Vec<(String, &'static str, Severity)> {
    changes
        .iter()
        .map(|c| (c.node.clone(), c.kind.as_str(), c.severity))
        .collect()
}

/// `old` against `old` changed by `edit`: exactly these changes.
fn check(edit: impl FnOnce(&mut (Bus, Configured)), expected: &[(&str, &str, Severity)]) {
    let old = network();
    let mut new = network();
    edit(&mut new);
    let changes = compare(&old, &new);
    let expected: Vec<(String, &str, Severity)> = expected
        .iter()
        .map(|&(n, k, s)| (n.to_string(), k, s))
        .collect();
    assert_eq!(kinds(&changes), expected, "{}", render::text(&changes));
}

#[test]
fn a_network_against_itself_has_no_changes() {
    let n = network();
    assert_eq!(compare(&n, &n), Vec::new());
    assert_eq!(
        render::text(&[]),
        "0 changes: 0 breaking, 0 additive, 0 compatible\n"
    );
}

#[test]
fn nodes_added_removed_and_renumbered() {
    check(
        |n| {
            n.0.slaves.push(slave("gripper"));
            n.1.nodes.push(node("gripper", 2, 4));
        },
        &[("gripper", "node-added", Additive)],
    );
    check(
        |n| {
            n.1.nodes.remove(0);
        },
        &[("axis", "node-removed", Breaking)],
    );
    check(
        |n| n.1.nodes[1].node_id = 9,
        &[("lift", "node-id-changed", Breaking)],
    );
}

#[test]
fn device_identity_and_file() {
    check(
        |n| n.1.nodes[0].product_code = 7,
        &[("axis", "node-identity-changed", Breaking)],
    );
    check(
        |n| n.1.nodes[0].revision_number = 3,
        &[("axis", "node-identity-changed", Compatible)],
    );
    check(
        |n| n.0.slaves[0].dcf = at("axis-v2.eds".into()),
        &[("axis", "node-device-file-changed", Compatible)],
    );
}

#[test]
fn pdos_enabled_disabled_remapped_moved_retimed() {
    check(
        |n| n.1.nodes[0].tpdos.push(pdo(2, 0x282, &[(0x6064, 0, 32)])),
        &[("axis", "pdo-enabled", Additive)],
    );
    check(
        |n| n.1.nodes[0].rpdos.clear(),
        &[("axis", "pdo-disabled", Breaking)],
    );
    check(
        |n| {
            n.1.nodes[0].tpdos[0].mapping.push(MappedObject {
                index: 0x6064,
                subindex: 0,
                bits: 32,
            })
        },
        &[("axis", "pdo-remapped", Breaking)],
    );
    check(
        |n| n.1.nodes[0].tpdos[0].cob_id = 0x682,
        &[("axis", "pdo-cob-id-moved", Breaking)],
    );
    check(
        |n| {
            let p = &mut n.1.nodes[1].tpdos[0];
            p.transmission = 0xFF;
            p.inhibit_time = 10;
            p.event_timer = 20;
            p.sync_start = 2;
        },
        &[
            ("lift", "pdo-transmission-changed", Compatible),
            ("lift", "pdo-inhibit-time-changed", Compatible),
            ("lift", "pdo-event-timer-changed", Compatible),
            ("lift", "pdo-sync-start-changed", Compatible),
        ],
    );
}

#[test]
fn error_control_graded_by_on_and_off() {
    check(
        |n| n.1.nodes[0].heartbeat_producer = 200,
        &[("axis", "heartbeat-producer-changed", Compatible)],
    );
    check(
        |n| n.1.nodes[0].heartbeat_producer = 0,
        &[("axis", "heartbeat-producer-changed", Breaking)],
    );
    check(
        |n| n.1.nodes[0].heartbeat_consumer = false,
        &[("axis", "heartbeat-consumer-changed", Breaking)],
    );
    check(
        |n| n.0.slaves[1].heartbeat_multiplier = Some(at(2.0)),
        &[("lift", "heartbeat-consumer-changed", Compatible)],
    );
    check(
        |n| {
            n.1.nodes[1].guard_time = 100;
            n.1.nodes[1].life_time_factor = 3;
        },
        &[("lift", "guarding-changed", Additive)],
    );
    check(
        |n| n.0.master.heartbeat_producer = 0,
        &[("master", "heartbeat-producer-changed", Breaking)],
    );
    check(
        |n| n.0.master.heartbeat_multiplier = 2.0,
        &[("master", "heartbeat-consumer-changed", Compatible)],
    );
}

#[test]
fn master_sync_baudrate_and_settings() {
    check(
        |n| n.0.master.sync_period = 2000,
        &[("master", "sync-period-changed", Compatible)],
    );
    check(
        |n| n.0.master.sync_period = 0,
        &[("master", "sync-period-changed", Breaking)],
    );
    check(
        |n| {
            n.0.master.sync_window = 500;
            n.0.master.sync_overflow = 16;
        },
        &[
            ("master", "sync-window-changed", Compatible),
            ("master", "sync-overflow-changed", Compatible),
        ],
    );
    check(
        |n| n.0.master.baudrate = 500,
        &[("master", "baudrate-changed", Breaking)],
    );
    check(
        |n| n.0.master.node_id = 5,
        &[("master", "node-id-changed", Breaking)],
    );
    check(
        |n| {
            n.0.options.retry_factor = 5;
            n.0.master.boot_time = 1000;
            n.0.slaves[0].boot = Some(at(false));
            n.0.slaves[0].error_behavior.insert(1, at(2));
        },
        &[
            ("options", "setting-changed", Compatible),
            ("master", "setting-changed", Compatible),
            ("axis", "setting-changed", Compatible),
            ("axis", "setting-changed", Compatible),
        ],
    );
}

fn sdo(index: u16, sub_index: u8, value: i128) -> SdoItem {
    SdoItem {
        spot: Spot::default(),
        index,
        sub_index,
        value,
    }
}

#[test]
fn sdo_writes_added_removed_changed_reordered() {
    let with =
        |items: Vec<SdoItem>| move |n: &mut (Bus, Configured)| n.0.slaves[0].sdo = items.clone();
    let mut old = network();
    old.0.slaves[0].sdo = vec![sdo(0x6060, 0, 1), sdo(0x6081, 0, 100), sdo(0x2000, 1, 5)];
    let run = |edit: &dyn Fn(&mut (Bus, Configured))| {
        let mut new = network();
        new.0.slaves[0].sdo = old.0.slaves[0].sdo.clone();
        edit(&mut new);
        kinds(&compare(&old, &new))
            .into_iter()
            .map(|(_, k, s)| (k, s))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        run(&with(vec![
            sdo(0x6060, 0, 3),
            sdo(0x6081, 0, 100),
            sdo(0x2000, 1, 5),
            sdo(0x6083, 0, 9)
        ])),
        [
            ("sdo-write-changed", Compatible),
            ("sdo-write-added", Compatible)
        ]
    );
    assert_eq!(
        run(&with(vec![sdo(0x6060, 0, 1), sdo(0x6081, 0, 100)])),
        [("sdo-write-removed", Compatible)]
    );
    assert_eq!(
        run(&with(vec![
            sdo(0x6081, 0, 100),
            sdo(0x6060, 0, 1),
            sdo(0x2000, 1, 5)
        ])),
        [("sdo-writes-reordered", Compatible)]
    );
}

/// A device of one object 0x2000 with the given access.
fn device(access: &str) -> crate::ir::Device {
    let yaml = format!(
        "format: 1\ndevice: {{ vendor_name: T, product_name: P }}\nobjects:\n  - {{ index: 0x2000, name: Speed, type: UNSIGNED16, access: {access} }}\n"
    );
    let options = crate::read::Options::default();
    crate::table::read_bytes(
        "t.yaml",
        yaml.as_bytes(),
        std::path::Path::new("."),
        &options,
    )
    .device
    .expect("a device")
}

#[test]
fn device_changes_are_tagged_with_their_node() {
    let mut old = network();
    *old.0.slaves[1].device = device("rw");
    let mut new = network();
    *new.0.slaves[1].device = device("ro");
    let changes = compare(&old, &new);
    assert_eq!(
        kinds(&changes),
        [("lift".to_string(), "access-changed", Breaking)]
    );
    let c = &changes[0];
    assert_eq!(
        (c.index, c.subindex, c.kind.scope()),
        (0x2000, Some(0), "device")
    );
    assert_eq!(c.place, "0x2000 sub 0");
    assert!(c.rust_path.is_some());
}

#[test]
fn text_lists_node_and_place() {
    let old = network();
    let mut new = network();
    new.1.nodes[0].tpdos[0].cob_id = 0x682;
    new.0.master.sync_period = 2000;
    let text = render::text(&compare(&old, &new));
    assert_eq!(
        text,
        "compatible master SYNC           sync-period-changed: SYNC period 1000 → 2000 µs\n\
         breaking   axis   TPDO1          pdo-cob-id-moved: TPDO1 COB-ID 0x182 → 0x682\n\
         2 changes: 1 breaking, 0 additive, 1 compatible\n"
    );
}

#[test]
fn every_wiring_kind_has_a_distinct_name() {
    let mut names: Vec<&str> = Wiring::ALL.iter().map(|w| w.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), Wiring::ALL.len());
}
