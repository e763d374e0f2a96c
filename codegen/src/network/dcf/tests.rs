//! master.dcf and the `.bin` files from hand-built buses.

use std::collections::BTreeMap;
use std::path::PathBuf;

use super::*;
use crate::ir::{Access, DataType, Device, Entry, Literal, Object, ObjectKind, Origin, Value};
use crate::network::config::ConciseEntry;
use crate::network::config::test_pdo as pdo;
use crate::network::model::{At, BusOptions, MasterSection, SlaveSection, Spot};

fn entry(sub: u8, name: &str, data_type: DataType, default: Option<i128>) -> Entry {
    Entry {
        subindex: sub,
        name: name.to_string(),
        data_type,
        access: Access::Rw,
        pdo_mappable: true,
        default: default.map(|v| Literal {
            value: Value::Integer(v),
            plus_node_id: false,
            text: v.to_string(),
        }),
        low_limit: None,
        high_limit: None,
        parameter_value: None,
        obj_flags: None,
        denotation: None,
        semantics: Box::default(),
        rust_name: None,
        origin: Origin::default(),
    }
}

fn var(index: u16, name: &str, data_type: DataType, default: Option<i128>) -> Object {
    Object {
        index,
        name: name.to_string(),
        kind: ObjectKind::Var,
        entries: BTreeMap::from([(0, Box::new(entry(0, name, data_type, default)))]),
        obj_flags: None,
        denotation: None,
        compact_sub_obj: None,
        rust_name: None,
        origin: Origin::default(),
    }
}

fn device() -> Device {
    let mut device = Device::default();
    for object in [
        var(
            0x1000,
            "Device type",
            DataType::Unsigned32,
            Some(0x0002_0192),
        ),
        var(0x6040, "Controlword", DataType::Unsigned16, None),
        var(0x6041, "Statusword", DataType::Unsigned16, None),
        var(0x6064, "Position actual value", DataType::Integer32, None),
    ] {
        device.objects.insert(object.index, object);
    }
    let mut identity = var(0x1018, "Identity", DataType::Unsigned32, None);
    identity.kind = ObjectKind::Record;
    identity.entries = BTreeMap::from([
        (
            1,
            Box::new(entry(1, "Vendor-ID", DataType::Unsigned32, Some(0x1234))),
        ),
        (
            2,
            Box::new(entry(2, "Product code", DataType::Unsigned32, Some(0x99))),
        ),
    ]);
    device.objects.insert(0x1018, identity);
    device.identity.vendor_number = Some(0x1234);
    device.identity.product_number = Some(0x99);
    device
}

fn slave(name: &str) -> SlaveSection {
    SlaveSection {
        ..SlaveSection::new(
            name.to_string(),
            Spot::default(),
            At::new("dev.eds".to_string(), Spot::default()),
            PathBuf::from("dev.eds"),
            Box::new(device()),
        )
    }
}

fn node(name: &str, slave: usize, node_id: u8) -> Node {
    Node {
        name: name.to_string(),
        slave,
        node_id,
        rpdos: vec![pdo(1, 0x200 + u32::from(node_id), &[(0x6040, 0, 16)])],
        tpdos: vec![
            pdo(
                1,
                0x180 + u32::from(node_id),
                &[(0x6041, 0, 16), (0x6064, 0, 32)],
            ),
            pdo(2, 0x280 + u32::from(node_id), &[(0x6041, 0, 16)]),
        ],
        disabled_rpdos: Vec::new(),
        disabled_tpdos: Vec::new(),
        concise: vec![ConciseEntry {
            index: 0x1017,
            sub_index: 0,
            data: vec![0xE8, 0x03],
            spot: None,
        }],
        heartbeat_producer: 1000,
        guard_time: 0,
        life_time_factor: 0,
        heartbeat_consumer: false,
        emcy_cob_id: 0x80 + u32::from(node_id),
        time_cob_id: 0x100,
        device_type: 0x0002_0192,
        vendor_id: 0x1234,
        product_code: 0x99,
        revision_number: 0,
        serial_number: 0,
        dcf_path: "@DIR@".to_string(),
        configuration_file: format!("@DIR@/{name}.bin"),
    }
}

fn bus() -> (Bus, Configured) {
    let bus = Bus {
        file: PathBuf::from("bus.yml"),
        options: BusOptions {
            dcf_path: "@DIR@".to_string(),
            ..BusOptions::default()
        },
        master: MasterSection {
            node_id: 1,
            sync_period: 10000,
            ..MasterSection::default()
        },
        slaves: vec![slave("a"), slave("b")],
        extra_keys: Vec::new(),
    };
    let configured = Configured {
        nodes: vec![node("a", 0, 3), node("b", 1, 4)],
        master_concise: Vec::new(),
    };
    (bus, configured)
}

/// `[section]` → key → value of a rendered DCF.
fn parse(text: &str) -> BTreeMap<String, BTreeMap<String, String>> {
    let mut out: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    let mut section = String::new();
    for line in text.lines().filter(|l| !l.is_empty()) {
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            section = name.to_string();
            assert!(
                out.insert(section.clone(), BTreeMap::new()).is_none(),
                "[{name}] twice"
            );
        } else {
            let (key, value) = line.split_once('=').expect("key=value");
            let keys = out.get_mut(&section).expect("a section");
            assert!(
                keys.insert(key.to_string(), value.to_string()).is_none(),
                "{section}.{key} twice"
            );
        }
    }
    out
}

fn master_of(
    bus: &Bus,
    configured: &Configured,
    remote: bool,
) -> BTreeMap<String, BTreeMap<String, String>> {
    let written = files(bus, configured, remote);
    let dcf = written
        .files
        .iter()
        .find(|f| f.name == "master.dcf")
        .unwrap();
    parse(std::str::from_utf8(&dcf.bytes).unwrap())
}

#[test]
fn writes_bins_then_master_dcf_then_master_bin() {
    let (bus, mut configured) = bus();
    configured.nodes[1].concise.clear();
    configured.nodes[1].configuration_file.clear();
    let names: Vec<_> = files(&bus, &configured, false)
        .files
        .into_iter()
        .map(|f| f.name)
        .collect();
    assert_eq!(names, ["a.bin", "master.dcf"]);
    configured.master_concise = vec![ConciseEntry {
        index: 0x1F88,
        sub_index: 3,
        data: vec![1, 0, 0, 0],
        spot: None,
    }];
    let written = files(&bus, &configured, false);
    let names: Vec<_> = written.files.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["a.bin", "master.dcf", "master.bin"]);
    let bin = concise::decode(&written.files[0].bytes).unwrap();
    assert_eq!(
        bin,
        [concise::Write {
            index: 0x1017,
            sub_index: 0,
            data: vec![0xE8, 0x03]
        }]
    );
}

#[test]
fn master_pdos_mirror_the_slaves_in_slave_order() {
    let (bus, configured) = bus();
    let dcf = master_of(&bus, &configured, true);
    assert_eq!(dcf["DeviceInfo"]["NrOfRxPDO"], "4");
    assert_eq!(dcf["DeviceInfo"]["NrOfTxPDO"], "2");
    // b's TPDO 1 is the master's RPDO 3.
    assert_eq!(dcf["1402sub1"]["DefaultValue"], "0x00000184");
    assert_eq!(dcf["5802"]["DefaultValue"], "0x00000104");
    assert!(!dcf.contains_key("1802"));
    assert_eq!(dcf["1801sub1"]["DefaultValue"], "0x00000204");
    // An object a slave maps twice lands once in the master.
    assert_eq!(dcf["1600Value"]["1"], "0x20000110");
    assert_eq!(dcf["1600Value"]["2"], "0x20000220");
    assert_eq!(dcf["1601Value"]["1"], "0x20000110");
    assert_eq!(dcf["1601"]["CompactSubObj"], "1");
    assert!(!dcf.contains_key("2001"));
    assert_eq!(dcf["2002sub1"]["ParameterName"], "b: Statusword");
    assert_eq!(dcf["2002sub2"]["DataType"], "0x0004");
    assert_eq!(dcf["2002sub2"]["AccessType"], "rww");
    assert_eq!(dcf["2200sub1"]["AccessType"], "rwr");
    assert_eq!(dcf["5A00Value"]["2"], "0x60640020");
    assert_eq!(dcf["5E01Value"]["1"], "0x60400010");
    let manufacturer = &dcf["ManufacturerObjects"];
    assert_eq!(manufacturer["SupportedObjects"], "16");
    assert_eq!(manufacturer["1"], "0x2000");
    assert_eq!(manufacturer["2"], "0x2002");
    // Without -r: no remote mappings.
    let plain = master_of(&bus, &configured, false);
    assert_eq!(plain["ManufacturerObjects"]["SupportedObjects"], "4");
    assert!(!plain.contains_key("5800"));
}

#[test]
fn per_slave_arrays() {
    let (mut bus, configured) = bus();
    bus.slaves[1].mandatory = Some(At::new(true, Spot::default()));
    bus.slaves[1].retry_factor = Some(At::new(5, Spot::default()));
    let dcf = master_of(&bus, &configured, false);
    assert_eq!(dcf["1016Value"]["NrOfEntries"], "2");
    assert_eq!(dcf["1016Value"]["2"], "0x00040BB8");
    assert_eq!(dcf["1028Value"]["3"], "0x00000083");
    assert_eq!(dcf["1F81Value"]["3"], "0x00000305");
    assert_eq!(dcf["1F81Value"]["4"], "0x0000050D");
    assert_eq!(dcf["1F84Value"]["4"], "0x00020192");
    assert_eq!(dcf["1F85Value"]["3"], "0x00001234");
    assert_eq!(dcf["1F86Value"]["NrOfEntries"], "2");
    assert_eq!(dcf["1F22sub3"]["UploadFile"], "@DIR@/a.bin");
    assert_eq!(dcf["1F22sub4"]["UploadFile"], "@DIR@/b.bin");
    assert_eq!(dcf["1F80"]["DefaultValue"], "0x00000001");
    assert_eq!(dcf["1006"]["DefaultValue"], "10000");
    let optional = &dcf["OptionalObjects"];
    assert_eq!(
        optional["SupportedObjects"],
        (8 + 1 + 5 + 2 * 4 + 2 * 2 + 1 + 2 + 10).to_string()
    );
    assert!(!dcf.contains_key("1F58"));
}

#[test]
fn deliberate_differences_are_reported() {
    let (mut bus, mut configured) = bus();
    let disabled = configured.nodes[0].tpdos.remove(1);
    configured.nodes[0].disabled_tpdos.push(disabled);
    configured.nodes[1].heartbeat_producer = 30000;
    bus.slaves[1].configuration_file = Some(At::new("cfg/b.bin".to_string(), Spot::default()));
    configured.nodes[1].configuration_file = "cfg/b.bin".to_string();
    let written = files(&bus, &configured, false);
    let text = std::str::from_utf8(&written.files.last().unwrap().bytes).unwrap();
    let dcf = parse(text);
    assert_eq!(dcf["1401sub1"]["DefaultValue"], "0x80000283");
    assert_eq!(dcf["1016Value"]["2"], "0x0004FFFF");
    assert_eq!(dcf["1F22sub4"]["UploadFile"], "cfg/b.bin");
    assert_eq!(
        written.differences,
        [
            Difference::ConfigurationFile {
                node: "b".into(),
                node_id: 4,
                file: "cfg/b.bin".into()
            },
            Difference::HeartbeatClamped {
                node: "b".into(),
                entry: 2,
                time: 90000
            },
            Difference::DisabledPdoInvalid {
                index: 0x1401,
                node: "a".into(),
                number: 2
            },
        ]
    );
}

#[test]
fn dcf_path_expands_environment_variables_as_posix_does() {
    use crate::network::configure::expand_vars;
    let var = |name: &str| (name == "HOME").then(|| "/h".to_string());
    assert_eq!(expand_vars("$HOME/x", var), "/h/x");
    assert_eq!(expand_vars("${HOME}/x", var), "/h/x");
    assert_eq!(expand_vars("$NOPE/${NOPE}/$/${", var), "$NOPE/${NOPE}/$/${");
    assert_eq!(expand_vars("@BUS_CONFIG_PATH@", var), "@BUS_CONFIG_PATH@");
}

#[test]
fn heartbeat_product_truncates_like_python() {
    assert_eq!(heartbeat_product(1000, 3.0), 3000);
    assert_eq!(heartbeat_product(333, 1.5), 499);
    assert_eq!(heartbeat_product(100, -1.0), 0);
    assert_eq!(heartbeat_product(100, f64::NAN), 0);
}

#[test]
fn a_product_code_without_0x1018_2_is_neither_listed_nor_counted() {
    let (mut bus, configured) = bus();
    let identity = bus.slaves[0].device.objects.get_mut(&0x1018).unwrap();
    identity.entries.remove(&2);
    let written = files(&bus, &configured, false);
    let dcf = parse(std::str::from_utf8(&written.files.last().unwrap().bytes).unwrap());
    assert_eq!(dcf["1F86Value"]["NrOfEntries"], "1");
    assert!(!dcf["1F86Value"].contains_key("3"));
    assert_eq!(dcf["1F86Value"]["4"], "0x00000099");
    assert_eq!(
        written.differences,
        [Difference::UnlistedProductCode { node: "a".into() }]
    );
}
