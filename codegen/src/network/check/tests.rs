//! The checks on buses built by hand (the fixtures under
//! tests/networks/check/ run them on bus files read from disk).

use std::path::Path;

use super::*;
use crate::diag::Severity;
use crate::input::{Options, read_device};
use crate::network::configure;
use crate::network::model::*;

fn spot(line: u32, key: &str) -> Spot {
    Spot {
        line,
        key: key.to_string(),
    }
}

fn at<T>(value: T, line: u32, key: &str) -> At<T> {
    At::new(value, spot(line, key))
}

fn device() -> Box<crate::ir::Device> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/networks/check/device.yaml");
    let loaded = read_device(&path, &Options::lenient());
    assert!(!loaded.diagnostics.has_errors(), "{}", loaded.diagnostics);
    Box::new(loaded.device.unwrap())
}

fn slave(name: &str, node_id: u8, line: u32) -> SlaveSection {
    SlaveSection {
        node_id: Some(at(node_id, line + 2, &format!("{name}.node_id"))),
        ..SlaveSection::new(
            name.to_string(),
            spot(line, name),
            at("device.yaml".into(), line + 1, &format!("{name}.dcf")),
            "device.yaml".into(),
            device(),
        )
    }
}

fn bus(slaves: Vec<SlaveSection>) -> Bus {
    let mut master = MasterSection {
        node_id: 1,
        sync_period: 10_000,
        ..MasterSection::default()
    };
    master
        .spots
        .insert("node_id".into(), spot(2, "master.node_id"));
    master
        .spots
        .insert("sync_period".into(), spot(3, "master.sync_period"));
    Bus {
        file: "bus.yml".into(),
        options: BusOptions::default(),
        master,
        slaves,
        extra_keys: Vec::new(),
    }
}

fn section(line: u32, key: &str) -> PdoSection {
    PdoSection {
        spot: spot(line, key),
        enabled: at(true, 0, ""),
        cob_id: None,
        transmission: None,
        inhibit_time: None,
        event_timer: None,
        event_deadline: None,
        sync_start: None,
        mapping: None,
    }
}

fn codes(bus: &Bus) -> Vec<(&'static str, String)> {
    let (configured, _) = configure(bus);
    check(bus, &configured, &CheckLimits::default())
        .iter()
        .map(|d| (d.code, d.location.key.clone().unwrap_or_default()))
        .collect()
}

#[test]
fn a_clean_bus_has_no_diagnostics() {
    let bus = bus(vec![slave("a", 2, 10), slave("b", 3, 20)]);
    assert_eq!(codes(&bus), []);
}

#[test]
fn node_ids_collide_and_leave_the_range() {
    let mut b = bus(vec![
        slave("a", 2, 10),
        slave("b", 2, 20),
        slave("c", 1, 30),
    ]);
    b.slaves.push(slave("d", 200, 40));
    let found = codes(&b);
    assert!(
        found.contains(&("net::node-id-collision", "b.node_id".into())),
        "{found:?}"
    );
    assert!(
        found.contains(&("net::node-id-collision", "c.node_id".into())),
        "{found:?}"
    );
    assert!(
        found.contains(&("net::node-id", "d.node_id".into())),
        "{found:?}"
    );
    // The services of a node whose id is taken are not reported again.
    assert!(
        !found.iter().any(|(c, _)| *c == "net::cob-id-collision"),
        "{found:?}"
    );
}

#[test]
fn a_pdo_on_another_nodes_cob_id_collides() {
    let mut a = slave("a", 2, 10);
    let mut tpdo = section(50, "a.tpdo.1");
    // 0x183 is TPDO 1 of node 3 (b).
    tpdo.cob_id = Some(at(CobIdSetting::Value(0x183), 51, "a.tpdo.1.cob_id"));
    a.tpdo.insert(1, tpdo);
    let found = codes(&bus(vec![a, slave("b", 3, 20)]));
    assert_eq!(found, [("net::cob-id-collision", "a.tpdo.1.cob_id".into())]);
}

#[test]
fn a_slave_rpdo_listening_to_another_slave_collides_with_the_master() {
    let mut a = slave("a", 2, 10);
    let mut rpdo = section(50, "a.rpdo.1");
    rpdo.cob_id = Some(at(CobIdSetting::Value(0x183), 51, "a.rpdo.1.cob_id"));
    a.rpdo.insert(1, rpdo);
    let b = bus(vec![slave("b", 3, 20), a]);
    let (configured, _) = configure(&b);
    let d = check(&b, &configured, &CheckLimits::default());
    let d: Vec<_> = d.iter().collect();
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(
        d[0].notes[0].contains("listens to TPDO 1 of slave `b`"),
        "{d:?}"
    );
}

#[test]
fn restricted_cob_ids_are_warned() {
    let mut a = slave("a", 2, 10);
    let mut tpdo = section(50, "a.tpdo.1");
    tpdo.cob_id = Some(at(CobIdSetting::Value(0x6E5), 51, "a.tpdo.1.cob_id"));
    a.tpdo.insert(1, tpdo);
    assert_eq!(
        codes(&bus(vec![a])),
        [("net::cob-id-restricted", "a.tpdo.1.cob_id".into())]
    );
}

fn mapping(items: &[(u16, u8)], line: u32, key: &str) -> Option<Vec<MappingItem>> {
    Some(
        items
            .iter()
            .enumerate()
            .map(|(i, &(index, sub_index))| MappingItem {
                spot: spot(line + i as u32, &format!("{key}.mapping[{i}]")),
                index,
                sub_index,
            })
            .collect(),
    )
}

#[test]
fn mappings_are_checked_for_mappability_direction_and_length() {
    let mut a = slave("a", 2, 10);
    let mut rpdo = section(50, "a.rpdo.1");
    rpdo.mapping = mapping(&[(0x2000, 0), (0x6041, 0)], 51, "a.rpdo.1");
    a.rpdo.insert(1, rpdo);
    let mut tpdo = section(60, "a.tpdo.1");
    tpdo.mapping = mapping(
        &[(0x2001, 0), (0x6064, 0), (0x606C, 0), (0x6041, 0)],
        61,
        "a.tpdo.1",
    );
    a.tpdo.insert(1, tpdo);
    let found = codes(&bus(vec![a]));
    assert_eq!(
        found,
        [
            ("net::pdo-mapping", "a.rpdo.1.mapping[0]".into()),
            ("net::pdo-direction", "a.rpdo.1.mapping[1]".into()),
            ("net::pdo-direction", "a.tpdo.1.mapping[0]".into()),
            ("net::pdo-too-long", "a.tpdo.1.mapping[0]".into()),
        ]
    );
}

fn sdo(index: u16, sub_index: u8, value: i128, line: u32) -> SdoItem {
    SdoItem {
        spot: spot(line, &format!("a.sdo[{line}]")),
        index,
        sub_index,
        value,
    }
}

#[test]
fn sdo_writes_to_pdo_objects() {
    let mut a = slave("a", 2, 10);
    let mut tpdo = section(50, "a.tpdo.1");
    tpdo.transmission = Some(at(1, 51, "a.tpdo.1.transmission"));
    a.tpdo.insert(1, tpdo);
    a.sdo = vec![
        // The same as the section: redundant.
        sdo(0x1800, 2, 1, 70),
        // Against the section.
        sdo(0x1800, 2, 5, 71),
        // Behind the sections: TPDO 2's mapping.
        sdo(0x1A01, 1, 0x6041_0010, 72),
        // The device file's value: nothing changes.
        sdo(0x1801, 2, 1, 73),
    ];
    let b = bus(vec![a]);
    let (configured, _) = configure(&b);
    let d = check(&b, &configured, &CheckLimits::default());
    let found: Vec<_> = d
        .iter()
        .map(|d| (d.code, d.severity, d.location.line))
        .collect();
    assert_eq!(
        found,
        [
            ("net::sdo-pdo-conflict", Severity::Warning, Some(70)),
            ("net::sdo-pdo-conflict", Severity::Error, Some(71)),
            ("net::sdo-pdo-conflict", Severity::Error, Some(72)),
        ]
    );
}

#[test]
fn pdos_that_never_go_out() {
    let mut a = slave("a", 2, 10);
    let mut empty = section(50, "a.tpdo.4");
    empty.mapping = Some(Vec::new());
    a.tpdo.insert(4, empty);
    let mut b = bus(vec![a]);
    b.master.sync_period = 0;
    let found = codes(&b);
    // TPDO 2 and 3 are synchronous by default; TPDO 4 is empty.
    assert_eq!(
        found,
        [
            ("net::pdo-unproduced", "a".into()),
            ("net::pdo-unproduced", "a".into()),
            ("net::pdo-unconsumed", "a.tpdo.4".into()),
        ]
    );
}

#[test]
fn heartbeat_times() {
    let mut a = slave("a", 2, 10);
    a.heartbeat_producer = Some(at(100, 11, "a.heartbeat_producer"));
    a.heartbeat_multiplier = Some(at(1.0, 12, "a.heartbeat_multiplier"));
    let mut c = slave("c", 3, 20);
    c.heartbeat_consumer = Some(at(true, 21, "c.heartbeat_consumer"));
    let mut b = bus(vec![a, c]);
    b.master.heartbeat_producer = 0;
    let found = codes(&b);
    assert_eq!(
        found,
        [
            ("net::heartbeat-timing", "a.heartbeat_multiplier".into()),
            ("net::heartbeat-no-producer", "c.heartbeat_consumer".into()),
        ]
    );
    assert_eq!(heartbeat_consumer_time(50_000, 3.0), 18_928);
}

fn heartbeat_consumer_time(producer: u16, multiplier: f64) -> u16 {
    super::heartbeat::consumer_time_for_tests(producer, multiplier)
}

#[test]
fn frame_lengths_with_worst_case_stuffing() {
    assert_eq!(frame_bits(0, false), 47 + 8);
    assert_eq!(frame_bits(8, false), 47 + 64 + (34 + 64 - 1) / 4);
    assert_eq!(frame_bits(8, true), 67 + 64 + (54 + 64 - 1) / 4);
}

#[test]
fn bus_load_counts_sync_pdos_and_heartbeats() {
    let mut a = slave("a", 2, 10);
    a.heartbeat_producer = Some(at(100, 11, "a.heartbeat_producer"));
    let b = bus(vec![a]);
    let (configured, _) = configure(&b);
    let load = bus_load(&b, &configured);
    // SYNC 100/s, TPDO 1 10/s, TPDO 2 and 3 100/s each, TPDO 4 1/s,
    // heartbeat 10/s; the RPDOs are event-driven without a timer.
    assert!((load.frames_per_second() - 321.0).abs() < 1e-9, "{load}");
    assert_eq!(load.not_counted.len(), 4, "{load}");
    let limits = CheckLimits {
        max_bus_load_percent: 1.0,
    };
    let d = check(&b, &configured, &limits);
    assert_eq!(
        d.iter().map(|d| d.code).collect::<Vec<_>>(),
        ["net::bus-load"]
    );
}

#[test]
fn pdos_on_sync_time_emcy_and_lss_collide() {
    for (cob, with) in [
        (0x080, "SYNC (the master)"),
        (0x100, "TIME"),
        (0x083, "EMCY of slave `b` (node 3)"),
        (0x7E5, "LSS (the master's requests)"),
    ] {
        let mut a = slave("a", 2, 10);
        let mut tpdo = section(50, "a.tpdo.1");
        tpdo.cob_id = Some(at(CobIdSetting::Value(cob), 51, "a.tpdo.1.cob_id"));
        a.tpdo.insert(1, tpdo);
        let b = bus(vec![slave("b", 3, 20), a]);
        let (configured, _) = configure(&b);
        let d = check(&b, &configured, &CheckLimits::default());
        let collisions: Vec<_> = d
            .iter()
            .filter(|d| d.code == "net::cob-id-collision")
            .collect();
        assert_eq!(collisions.len(), 1, "0x{cob:03X}: {d}");
        assert!(
            collisions[0].message.contains(with),
            "{}",
            collisions[0].message
        );
        assert_eq!(
            collisions[0].location.key.as_deref(),
            Some("a.tpdo.1.cob_id")
        );
    }
}
