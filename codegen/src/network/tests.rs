//! The bus file reader on small and hostile files: what it keeps, and each
//! error's file, line, key and rule.

use std::path::{Path, PathBuf};

use super::model::CobIdSetting;
use super::{BusLoaded, read_bytes, read_file};
use crate::diag::Severity;
use crate::read::Options;

/// A directory holding a small valid EDS, `base_ok.eds`.
fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/malformed_yaml")
}

fn read(text: &str) -> BusLoaded {
    read_bytes("bus.yml", text.as_bytes(), &dir(), &Options::default())
}

/// Every diagnostic of the bus file as `line code key: message`.
fn diags(loaded: &BusLoaded) -> Vec<String> {
    loaded
        .diagnostics
        .iter()
        .filter(|d| d.file == "bus.yml")
        .map(|d| {
            format!(
                "{} {} {}",
                d.location.line.unwrap_or(0),
                d.code,
                d.headline()
            )
        })
        .collect()
}

/// The one diagnostic of the file, which must be an error.
fn one_error(text: &str) -> String {
    let loaded = read(text);
    let all = diags(&loaded);
    assert_eq!(all.len(), 1, "{all:#?}");
    assert!(loaded.diagnostics.has_errors(), "{all:#?}");
    all.into_iter().next().unwrap()
}

const MASTER: &str = "master:\n  node_id: 1\n";

#[test]
fn a_small_bus() {
    let text = format!(
        "{MASTER}  driver: x\noptions:\n  dcf_path: \"@BUS_CONFIG_PATH@\"\n  heartbeat_multiplier: 2\n\
         .hidden: {{a: 1}}\nb:\n  dcf: base_ok.eds\n  node_id: 0x05\n  heartbeat_producer: 500\n  \
         tpdo:\n    1: {{enabled: false}}\n    0x2:\n      cob_id: 0x80000281\n      mapping: []\n  \
         sdo:\n    - {{index: 0x2000, value: 3}}\n  error_behavior: {{1: 2}}\n  polling: yes\n\
         a:\n  dcf: base_ok.eds\n  node_id: 6\n"
    );
    let loaded = read(&text);
    assert!(diags(&loaded).is_empty(), "{:#?}", diags(&loaded));
    assert_eq!(loaded.files, [dir().join("base_ok.eds")]);
    let bus = loaded.bus.unwrap();
    assert_eq!(bus.options.dcf_path, "@BUS_CONFIG_PATH@");
    assert_eq!(bus.options.heartbeat_multiplier, 2.0);
    assert_eq!(bus.master.heartbeat_multiplier, 2.0);
    assert_eq!(bus.master.node_id, 1);
    // Without `nodes:`, file order.
    let names: Vec<_> = bus.slaves.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["b", "a"]);
    let b = &bus.slaves[0];
    assert_eq!(b.effective_node_id(), Some(5));
    assert_eq!(b.node_id.as_ref().unwrap().spot.line, 10);
    assert_eq!(b.node_id.as_ref().unwrap().spot.key, "b.node_id");
    assert!(!b.tpdo[&1].enabled.value);
    assert_eq!(
        b.tpdo[&2].cob_id.as_ref().unwrap().value,
        CobIdSetting::Value(0x8000_0281)
    );
    assert_eq!(b.tpdo[&2].mapping.as_deref(), Some(&[][..]));
    assert_eq!(b.sdo[0].index, 0x2000);
    assert_eq!(b.sdo[0].sub_index, 0);
    assert_eq!(b.sdo[0].spot.key, "b.sdo[0]");
    assert_eq!(b.error_behavior[&1].value, 2);
    assert_eq!(b.device.identity.product_name.as_deref(), Some("Fixture"));
    let extra: Vec<_> = bus
        .extra_keys
        .iter()
        .map(|k| format!("{}:{} {} = {}", k.spot.line, k.section, k.key, k.value))
        .collect();
    assert_eq!(extra, ["3:master driver = \"x\"", "20:b polling = true"]);
}

#[test]
fn defaults_win_and_nodes_are_sorted() {
    let text = format!(
        "{MASTER}zeta:\n  dcf: base_ok.eds\n  node_id: 9\ndefaults:\n  dcf: base_ok.eds\n  \
         heartbeat_producer: 100\n  tpdo:\n    2: {{enabled: true}}\nnodes:\n  b:\n    node_id: 3\n    \
         heartbeat_producer: 7\n    tpdo:\n      1: {{enabled: false}}\n  a:\n    node_id: 2\n"
    );
    let loaded = read(&text);
    assert_eq!(
        diags(&loaded),
        [
            "3 net::dropped-section zeta: a file with `nodes:` (line 11) is expanded by \
          ros2_canopen, which keeps only options:, master: and the nodes: this section is not \
          on the bus"
        ]
    );
    let bus = loaded.bus.unwrap();
    let names: Vec<_> = bus.slaves.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["a", "b"]);
    let b = &bus.slaves[1];
    let hb = b.heartbeat_producer.as_ref().unwrap();
    assert_eq!(
        (hb.value, hb.spot.line, hb.spot.key.as_str()),
        (100, 8, "b.heartbeat_producer")
    );
    // A nested map of the defaults replaces the node's whole.
    assert_eq!(b.tpdo.keys().copied().collect::<Vec<_>>(), [2]);
    assert_eq!(b.tpdo[&2].spot.key, "b.tpdo.2");
    assert_eq!(b.spot.line, 12);
}

#[test]
fn missing_master_dcf_and_index() {
    assert_eq!(
        one_error("a:\n  dcf: base_ok.eds\n  node_id: 2\n"),
        "1 net::missing-key master: the bus file has no `master:` section, which dcfgen needs \
         (write at least `master: {node_id: 1}`)"
    );
    assert_eq!(
        one_error(&format!("{MASTER}slave_1:\n  node_id: 2\n")),
        "3 net::missing-key slave_1: the slave has no `dcf:` (its device file: EDS, DCF or YAML \
         table), which dcfgen needs"
    );
    let e = one_error(&format!(
        "{MASTER}a:\n  dcf: base_ok.eds\n  rpdo:\n    1:\n      mapping:\n        - {{sub_index: 1}}\n"
    ));
    assert_eq!(
        e,
        "8 net::missing-key a.rpdo.1.mapping[0]: the item has no `index`, which dcfgen needs"
    );
    let e = one_error(&format!(
        "{MASTER}a:\n  dcf: base_ok.eds\n  sdo:\n  - value: 1\n"
    ));
    assert!(e.starts_with("6 net::missing-key a.sdo[0]:"), "{e}");
}

#[test]
fn device_file_that_cannot_be_read() {
    let loaded = read(&format!("{MASTER}a:\n  dcf: nothing.eds\n  node_id: 2\n"));
    let all = diags(&loaded);
    assert_eq!(all.len(), 1, "{all:#?}");
    assert!(
        all[0].starts_with("4 net::device-file a.dcf: cannot read the device file ")
            && all[0].contains("nothing.eds"),
        "{all:#?}"
    );
    assert!(
        all[0].ends_with(": No such file or directory (os error 2)"),
        "{all:#?}"
    );
    assert!(loaded.bus.unwrap().slaves.is_empty());
    // That error stands for the device file's.
    assert_eq!(loaded.diagnostics.len(), 1);
    // A device file's own diagnostics name the device file.
    let loaded = read(&format!(
        "{MASTER}a:\n  dcf: ../malformed/bad_access_type.eds\n  node_id: 2\n"
    ));
    assert!(
        loaded
            .diagnostics
            .iter()
            .any(|d| d.file.ends_with("bad_access_type.eds") && d.location.line.is_some())
    );
}

#[test]
fn a_yaml_table_as_device_file() {
    let loaded = read(&format!(
        "{MASTER}linak:\n  dcf: ../../../../eds/linak_techline.yaml\n  node_id: 32\n"
    ));
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}",
        loaded.diagnostics.render()
    );
    let bus = loaded.bus.unwrap();
    assert!(bus.slaves[0].device.objects.contains_key(&0x2000));
    assert!(loaded.files[0].ends_with("eds/linak_techline.yaml"));
}

#[test]
fn node_id_from_a_dcf() {
    let loaded = read(&format!("{MASTER}a:\n  dcf: ../diff/06_dcf/old.dcf\n"));
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}",
        loaded.diagnostics.render()
    );
    let a = &loaded.bus.unwrap().slaves[0];
    assert!(a.node_id.is_none());
    // The DCF's [DeviceComissioning] NodeID.
    assert_eq!(a.effective_node_id(), Some(5));
}

#[test]
fn node_ids_and_ranges() {
    let slave = |key: &str| format!("{MASTER}a:\n  dcf: base_ok.eds\n  {key}\n");
    assert_eq!(
        one_error(&slave("node_id: 0")),
        "5 net::node-id a.node_id: 0 is out of range: node_id takes 1..=127"
    );
    assert_eq!(
        one_error(&slave("node_id: 128")),
        "5 net::node-id a.node_id: 128 is out of range: node_id takes 1..=127"
    );
    assert_eq!(
        one_error("master:\n  node_id: 200\n"),
        "2 net::node-id master.node_id: 200 is out of range: node_id takes 1..=127"
    );
    assert_eq!(
        one_error(&slave("heartbeat_producer: 65536")),
        "5 net::bad-value a.heartbeat_producer: 65536 is out of range: heartbeat_producer \
         takes 0..=65535"
    );
    assert_eq!(
        one_error(&slave("node_id: abc")),
        "5 net::bad-value a.node_id: an integer is needed here, not the text \"abc\""
    );
    // Python's int() of a boolean.
    let loaded = read(&slave("node_id: true"));
    assert!(diags(&loaded).is_empty());
    assert_eq!(loaded.bus.unwrap().slaves[0].effective_node_id(), Some(1));
    assert_eq!(
        one_error(&slave("guard_time: [1]")),
        "5 net::bad-value a.guard_time: an integer is needed here, not a list"
    );
    let loaded = read(&slave("node_id: \"0x10\""));
    let d = loaded.diagnostics.iter().next().unwrap();
    assert!(d.notes[0].contains("Python's int()"), "{d:?}");
    // A quoted decimal number is what Python's int() reads.
    let loaded = read(&slave("node_id: \" 12 \""));
    assert!(diags(&loaded).is_empty());
    assert_eq!(loaded.bus.unwrap().slaves[0].effective_node_id(), Some(12));
    assert_eq!(
        one_error(&slave("heartbeat_multiplier: -1")),
        "5 net::bad-value a.heartbeat_multiplier: -1 is out of range: a finite number, 0 or \
         more, is needed"
    );
}

#[test]
fn pdo_numbers_and_cob_ids() {
    let pdo = |body: &str| format!("{MASTER}a:\n  dcf: base_ok.eds\n  tpdo:\n    {body}\n");
    assert_eq!(
        one_error(&pdo("0: {}")),
        "6 net::pdo-number a.tpdo.0: PDO 0 does not exist: PDOs are numbered 1..=512"
    );
    assert_eq!(
        one_error(&pdo("513: {}")),
        "6 net::pdo-number a.tpdo.513: PDO 513 does not exist: PDOs are numbered 1..=512"
    );
    assert_eq!(
        one_error(&pdo("\"1\": {}")),
        "6 net::pdo-number a.tpdo.1: a PDO is named by its number (1..=512), not text"
    );
    assert_eq!(
        one_error(&pdo("1: {cob_id: Auto}")),
        "6 net::bad-value a.tpdo.1.cob_id: a COB-ID is a number or `auto`, not the text \"Auto\""
    );
    assert_eq!(
        one_error(&pdo("1: {cob_id: 0x100000000}")),
        "6 net::bad-value a.tpdo.1.cob_id: 4294967296 is out of range: cob_id takes 0..=4294967295"
    );
    assert_eq!(
        one_error(&pdo("1: {mapping: }")),
        "6 net::bad-value a.tpdo.1.mapping: a list is needed here, not nothing"
    );
    assert_eq!(
        one_error(&pdo("1: {mapping: [5]}")),
        "6 net::bad-value a.tpdo.1.mapping[0]: an item here is a map such as {index: 0x6041, \
         sub_index: 0}, not an integer"
    );
    assert_eq!(
        one_error(&pdo("1: {transmission: 256}")),
        "6 net::bad-value a.tpdo.1.transmission: 256 is out of range: transmission takes 0..=255"
    );
}

#[test]
fn unknown_keys_in_items_are_warnings() {
    let loaded = read(&format!(
        "{MASTER}a:\n  dcf: base_ok.eds\n  tpdo:\n    1:\n      transmision: 1\n      mapping:\n\
         \x20       - {{index: 0x2000, subindex: 1}}\n  sdo:\n    - {{index: 0x2000, vale: 1}}\n"
    ));
    assert!(!loaded.diagnostics.has_errors());
    let all: Vec<_> = loaded
        .diagnostics
        .iter()
        .map(|d| {
            format!(
                "{} {} {:?}",
                d.location.line.unwrap(),
                d.headline(),
                d.notes
            )
        })
        .collect();
    assert_eq!(
        all,
        [
            "7 a.tpdo.1.transmision: unknown key in a PDO; dcfgen ignores it \
             [\"did you mean `transmission`?\"]",
            "9 a.tpdo.1.mapping[0].subindex: unknown key in a mapping item; dcfgen ignores it \
             [\"did you mean `sub_index`?\"]",
            "11 a.sdo[0].vale: unknown key in an sdo item; dcfgen ignores it \
             [\"did you mean `value`?\"]",
        ]
    );
}

#[test]
fn duplicates() {
    let e = one_error(&format!(
        "{MASTER}defaults:\n  dcf: base_ok.eds\nnodes:\n  a: {{node_id: 2}}\n  .b: {{}}\n  \
         a: {{node_id: 3}}\n"
    ));
    assert_eq!(
        e,
        "8 net::duplicate-node a: a slave of this name is given already (line 6); this one is \
         not read"
    );
    let e = one_error(&format!(
        "{MASTER}a:\n  dcf: base_ok.eds\nb: {{dcf: base_ok.eds}}\na:\n  dcf: base_ok.eds\n"
    ));
    assert!(e.starts_with("6 net::duplicate-node a: "), "{e}");
    let loaded = read(&format!(
        "{MASTER}a:\n  dcf: base_ok.eds\n  node_id: 2\n  node_id: 3\n"
    ));
    assert_eq!(
        diags(&loaded),
        [
            "6 net::duplicate-key a.node_id: key given again (first at line 5); this later value \
          wins, as in dcfgen"
        ]
    );
    assert_eq!(loaded.bus.unwrap().slaves[0].effective_node_id(), Some(3));
}

#[test]
fn booleans_as_dcfgen_reads_them() {
    let loaded = read(&format!(
        "{MASTER}  start: 0\n  heartbeat_consumer: no\na:\n  dcf: base_ok.eds\n  \
         boot: \"false\"\n  tpdo: {{1: {{enabled: 0}}}}\n  node_id: 2.5\n"
    ));
    assert!(!loaded.diagnostics.has_errors());
    assert_eq!(
        diags(&loaded),
        [
            "7 net::truthy-text a.boot: the text \"false\" is true for dcfgen (Python's bool() \
             of any non-empty text), and so for this reader",
            "9 net::truncated a.node_id: an integer is needed; dcfgen cuts 2.5 to 2, and so \
             does this reader",
        ]
    );
    let bus = loaded.bus.unwrap();
    assert!(!bus.master.start && !bus.master.heartbeat_consumer);
    let a = &bus.slaves[0];
    assert!(a.boot.as_ref().unwrap().value);
    assert!(!a.tpdo[&1].enabled.value);
    assert_eq!(a.effective_node_id(), Some(2));
}

#[test]
fn yaml_errors_and_odd_shapes() {
    let e = one_error("master:\n  node_id: [1\n");
    assert_eq!(e, "2 net::syntax unclosed bracket '['");
    let e = one_error("- 1\n- 2\n");
    assert!(
        e.starts_with("1 net::syntax a bus file is a map of sections"),
        "{e}"
    );
    let e = one_error(&format!("{MASTER}---\nb: 1\n"));
    assert!(
        e.contains("several YAML documents") && e.contains("a bus file is one"),
        "{e}"
    );
    let e = one_error(&format!("{MASTER}a: 5\n"));
    assert_eq!(
        e,
        "3 net::bad-value a: a map of keys is needed here, not an integer"
    );
    let e = one_error(&format!("{MASTER}7: {{dcf: base_ok.eds}}\n"));
    assert!(
        e.starts_with("3 net::bad-value 7: a section name must be text"),
        "{e}"
    );
    // Empty file: only the missing master.
    assert!(one_error("").contains("no `master:`"));
    let loaded = read_bytes(
        "bus.yml",
        b"master:\n  a: \xff\n",
        &dir(),
        &Options::default(),
    );
    assert_eq!(
        diags(&loaded),
        ["2 net::syntax a bus file must be UTF-8; byte 13 is not"]
    );
    assert!(loaded.bus.is_none());
    let loaded = read(&format!("{MASTER}defaults:\n  dcf: x.eds\n"));
    assert_eq!(
        diags(&loaded),
        ["3 net::unused-defaults defaults: `defaults:` without `nodes:` applies to no slave"]
    );
}

#[test]
fn hostile_inputs_do_not_panic() {
    let deep = format!("master: {}{}\n", "[".repeat(5000), "]".repeat(5000));
    let bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a]\n\
                c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c, *c]\n\
                e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d, *d]\nf: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e, *e]\n\
                g: &g [*f, *f, *f, *f, *f, *f, *f, *f, *f, *f]\n";
    let mut many = String::from(MASTER);
    for n in 0..130 {
        many.push_str(&format!("s{n:03}: {{dcf: base_ok.eds, node_id: 1}}\n"));
    }
    let mut wide = String::from("master: {node_id: 1}\ndefaults:\n  sdo:\n");
    for _ in 0..20_000 {
        wide.push_str("  - {index: 0x2000}\n");
    }
    wide.push_str("nodes:\n");
    for n in 0..100 {
        wide.push_str(&format!("  n{n}: {{}}\n"));
    }
    // Quadratic work on many keys would show here.
    let mut keys = String::from("master: {node_id: 1}\na:\n  dcf: base_ok.eds\n");
    let mut sections = String::from("master: {node_id: 1}\n");
    for n in 0..50_000 {
        keys.push_str(&format!("  k{n}: 1\n"));
        sections.push_str(&format!("s{n}: 1\n"));
    }
    let started = std::time::Instant::now();
    assert_eq!(read(&keys).bus.unwrap().extra_keys.len(), 50_000);
    assert!(read(&sections).diagnostics.has_errors());
    assert!(started.elapsed().as_secs() < 20, "{:?}", started.elapsed());
    for (text, code) in [
        (deep.as_str(), "net::syntax"),
        (bomb, "net::syntax"),
        (many.as_str(), "net::too-large"),
        (wide.as_str(), "net::too-large"),
        (
            "master: {node_id: 1}\na: {dcf: /dev/zero}\n",
            "net::device-file",
        ),
        ("master: {node_id: 1}\na: {dcf: .}\n", "net::device-file"),
        (
            "master: {node_id: 1}\na: {dcf: \"\\0\"}\n",
            "net::device-file",
        ),
        ("master: {node_id: 1e400}\n", "net::bad-value"),
        (
            "master: {node_id: 99999999999999999999999999999999999999999}\n",
            "net::bad-value",
        ),
    ] {
        let loaded = read(text);
        assert!(
            loaded
                .diagnostics
                .iter()
                .any(|d| d.code == code && d.severity == Severity::Error),
            "{code} in {}",
            loaded.diagnostics.render()
        );
    }
    let loaded = read(&many);
    assert_eq!(loaded.bus.unwrap().slaves.len(), 127);
}

#[test]
fn read_file_bounds_and_lists_files() {
    let tmp = std::env::temp_dir().join(format!("eds2rust-net-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    std::fs::copy(dir().join("base_ok.eds"), tmp.join("dev.eds")).unwrap();
    let bus = tmp.join("bus.yml");
    std::fs::write(&bus, format!("{MASTER}a:\n  dcf: dev.eds\n  node_id: 4\n")).unwrap();
    let loaded = read_file(&bus, &Options::default());
    assert!(
        loaded.diagnostics.is_empty(),
        "{}",
        loaded.diagnostics.render()
    );
    assert_eq!(loaded.files, [bus.clone(), tmp.join("dev.eds")]);
    assert_eq!(loaded.bus.as_ref().unwrap().file, bus);
    let small = Options {
        max_input_size: 10,
        ..Options::default()
    };
    let loaded = read_file(&bus, &small);
    assert!(loaded.bus.is_none());
    assert!(
        loaded
            .diagnostics
            .iter()
            .any(|d| d.code == "input::too-large")
    );
    let loaded = read_file(&tmp.join("absent.yml"), &Options::default());
    assert!(loaded.bus.is_none() && loaded.diagnostics.has_errors());
    // Strict: the bus file's warnings are errors.
    std::fs::write(
        &bus,
        format!("{MASTER}a:\n  dcf: dev.eds\n  sdo: [{{index: 1, x: 1}}]\n"),
    )
    .unwrap();
    assert!(
        !read_file(&bus, &Options::default())
            .diagnostics
            .has_errors()
    );
    assert!(read_file(&bus, &Options::strict()).diagnostics.has_errors());
    let _ = std::fs::remove_dir_all(&tmp);
}
