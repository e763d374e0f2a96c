//! `network::configure` against dcfgen's own output for the corpus
//! networks: the concise DCF of each slave, entry by entry, from a bus
//! built by hand (the bus reader has tests of its own).

use std::collections::BTreeMap;
use std::path::Path;

use eds2rust::input::{Options, read_device};
use eds2rust::network::configure;
use eds2rust::network::model::*;

fn spot(key: &str) -> Spot {
    Spot {
        line: 1,
        key: key.to_string(),
    }
}

fn at<T>(value: T) -> At<T> {
    At::new(value, spot("x"))
}

fn slave(name: &str, dir: &Path, dcf: &str, node_id: u8) -> SlaveSection {
    let path = dir.join(dcf);
    let loaded = read_device(&path, &Options::lenient());
    SlaveSection {
        node_id: Some(at(node_id)),
        ..SlaveSection::new(
            name.to_string(),
            spot(name),
            at(dcf.to_string()),
            path.clone(),
            Box::new(loaded.device.expect("device reads")),
        )
    }
}

fn sdo(index: u16, sub_index: u8, value: i128) -> SdoItem {
    SdoItem {
        spot: spot("sdo"),
        index,
        sub_index,
        value,
    }
}

fn pdo(
    line: u32,
    cob_auto: bool,
    transmission: Option<u8>,
    mapping: Option<&[(u16, u8)]>,
    enabled: bool,
) -> PdoSection {
    PdoSection {
        spot: Spot {
            line,
            key: "pdo".into(),
        },
        enabled: at(enabled),
        cob_id: cob_auto.then(|| at(CobIdSetting::Auto)),
        transmission: transmission.map(at),
        inhibit_time: None,
        event_timer: None,
        event_deadline: None,
        sync_start: None,
        mapping: mapping.map(|m| {
            m.iter()
                .map(|&(index, sub_index)| MappingItem {
                    spot: spot("m"),
                    index,
                    sub_index,
                })
                .collect()
        }),
    }
}

/// A concise DCF file as (index, sub-index, data) in order.
fn decode_bin(bytes: &[u8]) -> Vec<(u16, u8, Vec<u8>)> {
    let count = u32::from_le_bytes(bytes[..4].try_into().unwrap());
    let mut out = Vec::new();
    let mut at = 4;
    for _ in 0..count {
        let index = u16::from_le_bytes([bytes[at], bytes[at + 1]]);
        let sub = bytes[at + 2];
        let size = u32::from_le_bytes(bytes[at + 3..at + 7].try_into().unwrap()) as usize;
        out.push((index, sub, bytes[at + 7..at + 7 + size].to_vec()));
        at += 7 + size;
    }
    assert_eq!(at, bytes.len());
    out
}

fn bus(file: &Path, master_node: u8, slaves: Vec<SlaveSection>) -> Bus {
    Bus {
        file: file.to_path_buf(),
        options: BusOptions {
            dcf_path: "@BUS_CONFIG_PATH@".into(),
            ..BusOptions::default()
        },
        master: MasterSection {
            node_id: master_node,
            ..MasterSection::default()
        },
        slaves,
        extra_keys: Vec::new(),
    }
}

fn compare(bus: &Bus, out: &Path) {
    let (configured, diagnostics) = configure(bus);
    assert!(!diagnostics.has_errors(), "{diagnostics:?}");
    for node in &configured.nodes {
        let expected = decode_bin(&std::fs::read(out.join(format!("{}.bin", node.name))).unwrap());
        let ours: Vec<_> = node
            .concise
            .iter()
            .map(|e| (e.index, e.sub_index, e.data.clone()))
            .collect();
        assert_eq!(ours, expected, "{}", node.name);
    }
    let master_bin = out.join("master.bin");
    let ours: Vec<_> = configured
        .master_concise
        .iter()
        .map(|e| (e.index, e.sub_index, e.data.clone()))
        .collect();
    if master_bin.exists() {
        assert_eq!(ours, decode_bin(&std::fs::read(master_bin).unwrap()));
    } else {
        assert!(ours.is_empty());
    }
}

#[test]
fn trinamic_pd42_concise_dcf_equals_dcfgens() {
    let Some(corpus) = eds2rust_tests::network_corpus("network_configure") else {
        return;
    };
    let dir = corpus.join("trinamic_pd42");
    let mut s = slave("trinamic_pd42", &dir, "TMCM-1270.eds", 1);
    s.heartbeat_producer = Some(at(1000));
    s.sdo = vec![
        sdo(0x6081, 0, 500000),
        sdo(0x6083, 0, 1000000),
        sdo(0x6083, 0, 1000000),
        sdo(0x6085, 0, 1000000),
        sdo(0x6098, 0, 35),
        sdo(0x60C2, 1, 50),
        sdo(0x60C2, 2, -3),
    ];
    compare(
        &bus(&dir.join("bus.yml"), 2, vec![s]),
        &dir.join("dcfgen-out"),
    );
}

#[test]
fn prbt_pilz6_concise_dcf_equals_dcfgens() {
    let Some(corpus) = eds2rust_tests::network_corpus("network_configure") else {
        return;
    };
    let dir = corpus.join("prbt_pilz6");
    let slaves = (1..=6)
        .map(|j| {
            let mut s = slave(&format!("prbt_joint_{j}"), &dir, "prbt_0_1.dcf", j + 2);
            s.heartbeat_producer = Some(at(1000));
            s.sdo = vec![sdo(0x6081, 0, 1000), sdo(0x60C2, 1, 15), sdo(0x6060, 0, 7)];
            s.tpdo = BTreeMap::from([
                (
                    1,
                    pdo(10, true, Some(1), Some(&[(0x6041, 0), (0x6061, 0)]), true),
                ),
                (
                    2,
                    pdo(11, true, Some(1), Some(&[(0x6064, 0), (0x606C, 0)]), true),
                ),
                (3, pdo(12, false, None, None, false)),
                (4, pdo(13, false, None, None, false)),
            ]);
            s.rpdo = BTreeMap::from([
                (
                    1,
                    pdo(
                        14,
                        true,
                        None,
                        Some(&[(0x6040, 0), (0x6060, 0), (0x60C1, 1)]),
                        true,
                    ),
                ),
                (2, pdo(15, true, None, Some(&[(0x607A, 0)]), true)),
            ]);
            s
        })
        .collect();
    compare(
        &bus(&dir.join("bus.yml"), 1, slaves),
        &dir.join("dcfgen-out"),
    );
}

/// The corpus networks read from their files (`bus.yml` with
/// `defaults:`/`nodes:`, and the expanded file dcfgen read) and configured:
/// the concise DCFs equal dcfgen's.
#[test]
fn corpus_read_from_bus_files_equals_dcfgens() {
    let Some(corpus) = eds2rust_tests::network_corpus("network_configure (read)") else {
        return;
    };
    for network in ["trinamic_pd42", "prbt_pilz6"] {
        let dir = corpus.join(network);
        for file in ["bus.yml", "bus.expanded.yml"] {
            let loaded = eds2rust::network::read_file(&dir.join(file), &Options::lenient());
            assert!(
                !loaded.diagnostics.has_errors(),
                "{network}/{file}: {}",
                loaded.diagnostics.render()
            );
            compare(&loaded.bus.expect("a bus"), &dir.join("dcfgen-out"));
        }
    }
}
