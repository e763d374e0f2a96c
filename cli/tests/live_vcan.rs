//! The live-bus commands of the `eds2rust` binary over the kernel's
//! SocketCAN stack: each test runs a seed-device simulator (or a
//! python-canopen LocalNode) on its own vcan interface and the CLI against
//! it, and checks the output and the effect on the device.
//!
//! Ignored by default: `tests/vm/run.sh` runs them with `--ignored` in a VM
//! whose kernel has vcan. `CAN_IFACES` names the interfaces (one per test,
//! by index); `EDS2RUST_CLI` the binary (default: the one cargo built);
//! `VCAN_PYTHON` the python with python-canopen (default: the venv the
//! python oracle tests create). Nothing is skipped: a missing interface,
//! binary or interpreter fails the test that needs it.
#![cfg(target_os = "linux")]

mod vcan;

use vcan::{Sim, fails, iface, ok, python, rig, scratch, write_file};

use std::io::{BufRead, BufReader, Write};
use std::process::Stdio;

use eds2rust_runtime::lss::{BitRate, Identity};
use eds2rust_sim::DeviceConfig;
use eds2rust_sim::models::{interroll_ec5000bi, linak_techline, zimmer_acs};
use serde_json::{Value, json};

/// Interface indices in `CAN_IFACES`, one per test.
const SDO: usize = 0;
const NMT_SCAN: usize = 1;
const LSS: usize = 2;
const BACKUP: usize = 3;
const PYTHON: usize = 4;

const ZIMMER: &str = include_str!("../../eds/zimmer_acs.yaml");
const LINAK: &str = include_str!("../../eds/linak_techline.yaml");
const INTERROLL: &str = include_str!("../../eds/interroll_ec5000bi.yaml");
const EXAMPLE_EDS: &str = include_str!("../../eds/example.eds");

/// The text of section `[name]` of an EDS/DCF, up to the next section.
fn section<'a>(text: &'a str, name: &str) -> &'a str {
    let head = format!("[{name}]\n");
    let Some(start) = text.find(&head) else {
        panic!("no [{name}] in:\n{text}");
    };
    let body = &text[start + head.len()..];
    &body[..body.find("\n[").map_or(body.len(), |e| e + 1)]
}

#[test]
#[ignore = "needs vcan: tests/vm/run.sh"]
fn sdo_read_write_typed_and_raw() {
    let (i, dir, od, _sim) = rig(
        SDO,
        ("live-vcan", "sdo"),
        ("zimmer_acs.yaml", ZIMMER),
        zimmer_acs::simulator,
    );
    let base = ["--iface", i.as_str(), "--node", "40", "--timeout", "2s"];
    let sdo = |verb: &str, rest: &[&str]| -> Vec<String> {
        ["sdo", verb]
            .iter()
            .chain(&base)
            .chain(rest)
            .map(|s| s.to_string())
            .collect()
    };

    let v = sdo("read", &["--od", &od, "0x6060", "identity::VendorId"]);
    let out = ok(&v);
    assert_eq!(
        out.lines().next(),
        Some("0x6060 Modes of operation = 1 \"profile position\"")
    );
    assert!(
        out.lines()
            .nth(1)
            .unwrap()
            .starts_with("0x1018.1 Identity object.Vendor-ID = "),
        "{out}"
    );

    let v = sdo(
        "write",
        &[
            "--od",
            &od,
            "--verify",
            "ModesOfOperation",
            "cyclic synchronous position",
        ],
    );
    let out = ok(&v);
    assert!(
        out.ends_with(
            "0x6060 Modes of operation = 8 \"cyclic synchronous position\" (read back)\n"
        ),
        "{out}"
    );

    // Raw: bytes in hex; a write with --type.
    let v = sdo("read", &["0x6060"]);
    assert_eq!(ok(&v), "0x6060 = 08\n");
    let v = sdo("write", &["--type", "i8", "0x6060", "1"]);
    assert_eq!(ok(&v), "0x6060 := 1\n");
    let v = sdo("read", &["-q", "--type", "i8", "0x6060"]);
    assert_eq!(ok(&v), "1\n");

    // Errors: an abort names node, object and code (exit 1); an unknown
    // name gets a suggestion (exit 2).
    let v = sdo("write", &["--type", "u16", "0x6041", "1"]);
    let err = fails(1, &v);
    assert_eq!(
        err,
        "error: node 40, 0x6041: write failed: the SDO peer aborted the transfer: 0x06010002 \
         (attempt to write a read only object)\n"
    );
    let v = sdo("read", &["--od", &od, "Statuswort"]);
    let err = fails(2, &v);
    assert!(err.contains("did you mean `Statusword` (0x6041)"), "{err}");

    // A program download into a DOMAIN by block transfer: 0x1F50 is not in
    // this device, so the abort is the result to check.
    let file = write_file(&dir, "program.bin", &"x".repeat(1000));
    let v = sdo("download-file", &["0x1F50.1", &file]);
    let err = fails(1, &v);
    assert!(err.contains("node 40, 0x1F50.1: download failed"), "{err}");
}

#[test]
#[ignore = "needs vcan: tests/vm/run.sh"]
fn nmt_and_scan_find_the_node_with_its_identity() {
    let (i, _, od, _sim) = rig(
        NMT_SCAN,
        ("live-vcan", "nmt"),
        ("linak.yaml", LINAK),
        linak_techline::simulator,
    );
    ok(&[
        "sdo",
        "write",
        "-i",
        &i,
        "-n",
        "32",
        "--timeout",
        "2s",
        "--od",
        &od,
        "0x1017",
        "100",
    ]);
    let out = ok(&[
        "scan",
        "-i",
        &i,
        "--listen",
        "500ms",
        "--probe-timeout",
        "300ms",
        "--timeout",
        "2s",
    ]);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "{out}");
    let identity = linak_row();
    assert!(
        lines[1].starts_with(&format!("  32  pre-operational  {identity}")),
        "{out}"
    );
    assert_eq!(
        lines[2],
        "1 node found (1 answered SDO, 1 sent boot-up or heartbeat)"
    );

    assert_eq!(
        ok(&["nmt", "start", "-i", &i, "--node", "32", "--confirm"]),
        "sent NMT start to node 32\nnode 32: operational (heartbeat)\n"
    );
    assert_eq!(
        ok(&["nmt", "preop", "-i", &i, "--node", "32", "--confirm"]),
        "sent NMT enter pre-operational to node 32\nnode 32: pre-operational (heartbeat)\n"
    );
    assert_eq!(
        ok(&["nmt", "reset-comm", "-i", &i, "--node", "32", "--confirm"]),
        "sent NMT reset communication to node 32\nnode 32: boot-up seen\n"
    );
    assert_eq!(
        ok(&["nmt", "stop", "-i", &i, "--all"]),
        "sent NMT stop to all nodes\n"
    );
    // No node 33: nothing confirms.
    let err = fails(1, &["nmt", "reset", "-i", &i, "--node", "33", "--confirm"]);
    assert_eq!(err, "error: node 33 sent no boot-up message within 2 s\n");
}

/// The scan line of the simulated LINAK actuator up to its product code.
fn linak_row() -> String {
    use eds2rust_drivers::linak_techline as l;
    format!("0x00000000   0x{:08X}  0x", l::VENDOR_ID)
}

#[test]
#[ignore = "needs vcan: tests/vm/run.sh"]
fn lss_fastscan_and_set_node_id() {
    let i = iface(LSS);
    let identity = Identity::new(
        eds2rust_drivers::interroll_ec5000bi::VENDOR_ID,
        eds2rust_drivers::interroll_ec5000bi::PRODUCT_CODE,
        eds2rust_drivers::interroll_ec5000bi::REVISION_NUMBER,
        interroll_ec5000bi::DEFAULT_SERIAL,
    );
    let config = DeviceConfig {
        node: None,
        lss: Some(identity),
        bit_rate: BitRate::Kbit250,
    };
    let _sim = Sim::start(&i, |now| {
        interroll_ec5000bi::simulator_with(interroll_ec5000bi::Ec5000Bi::new(), config, now)
    });
    let out = ok(&["lss", "scan", "-i", &i, "--lss-timeout", "100ms"]);
    assert_eq!(
        out,
        format!(
            "vendor id   product code  revision    serial\n\
             0x{:08X}  0x{:08X}    0x{:08X}  0x{:08X}\n\
             1 LSS slave without a node id\n",
            identity.vendor_id, identity.product_code, identity.revision, identity.serial
        )
    );
    let address = format!(
        "{}:{}:{}:{}",
        identity.vendor_id, identity.product_code, identity.revision, identity.serial
    );
    let out = ok(&[
        "lss",
        "set-node-id",
        "-i",
        &i,
        "--lss-timeout",
        "200ms",
        "--identity",
        &address,
        "--store",
        "--activate",
        "5",
    ]);
    assert!(
        out.ends_with(
            "node id 5 configured\nstored\nsent NMT reset communication to all nodes\n\
             node 5: boot-up seen\n"
        ),
        "{out}"
    );
    let out = ok(&[
        "sdo",
        "read",
        "-i",
        &i,
        "-n",
        "5",
        "--timeout",
        "2s",
        "--type",
        "u32",
        "0x1018.4",
    ]);
    assert_eq!(
        out,
        format!("0x1018.4 = {0} (0x{0:08X})\n", identity.serial)
    );
    // A file into a string entry by block transfer, read back.
    let dir = scratch("live-vcan", "lss");
    let od = write_file(&dir, "interroll.yaml", INTERROLL);
    let file = write_file(&dir, "catalogue.txt", "CAT-0123456789-ABCDEFGHIJ");
    let common = [
        "-i",
        i.as_str(),
        "-n",
        "5",
        "--timeout",
        "2s",
        "--od",
        od.as_str(),
    ];
    assert_eq!(
        ok(&[
            &["sdo", "download-file"][..],
            &common,
            &["Motor Catalogue Number", &file]
        ]
        .concat()),
        format!(
            "0x6403 Motor Catalogue Number: downloaded 25 bytes from {file} (block transfer)\n"
        )
    );
    assert_eq!(
        ok(&[&["sdo", "read"][..], &common, &["0x6403"]].concat()),
        "0x6403 Motor Catalogue Number = \"CAT-0123456789-ABCDEFGHIJ\"\n"
    );
    // Configured now: fastscan finds nobody.
    let err = fails(1, &["lss", "scan", "-i", &i, "--lss-timeout", "100ms"]);
    assert_eq!(
        err,
        "error: fastscan found no LSS slave without a node id\n"
    );
}

#[test]
#[ignore = "needs vcan: tests/vm/run.sh"]
fn od_upload_then_download_restores_a_changed_value() {
    let (i, dir, od, _sim) = rig(
        BACKUP,
        ("live-vcan", "backup"),
        ("zimmer_acs.yaml", ZIMMER),
        zimmer_acs::simulator,
    );
    let dcf = dir.join("node40.dcf").display().to_string();
    let common = ["-i", i.as_str(), "--timeout", "2s"];
    ok(&[
        &["od", "upload"][..],
        &common,
        &["-n", "40", "--od", &od, "-o", &dcf],
    ]
    .concat());
    let text = std::fs::read_to_string(&dcf).unwrap();
    assert!(text.contains("[DeviceComissioning]\nNodeID=40\n"), "{text}");
    assert!(
        section(&text, "1800sub1").contains("\nParameterValue=$NODEID+0x180\n"),
        "{text}"
    );
    eprintln!("{}", section(&text, "1800sub1"));
    // The plan, without a bus.
    let plan = ok(&["od", "download", "--dry-run", &dcf]);
    assert!(plan.starts_with("download to node 40 ("), "{plan}");
    assert!(
        plan.contains(
            "\n  disable PDO: set bit 31 of 0x1800.1 TPDO1 communication parameter.COB-ID\n"
        ),
        "{plan}"
    );
    // Change three values (two of them in a PDO), then restore them.
    ok(&[
        &["sdo", "write"][..],
        &common,
        &["-n", "40", "--od", &od, "0x6060", "8"],
    ]
    .concat());
    ok(&[
        &["sdo", "write"][..],
        &common,
        &["-n", "40", "--type", "u32", "0x1800.1", "0x800001A8"],
    ]
    .concat());
    ok(&[
        &["sdo", "write"][..],
        &common,
        &["-n", "40", "--type", "u16", "0x1800.5", "250"],
    ]
    .concat());
    let out = ok(&[&["od", "download"][..], &common, &[dcf.as_str()]].concat());
    // The DCF carries no YAML meaning, but the built-in CiA 301/402 ones.
    assert!(
        out.contains("0x6060 Modes of operation: ok 1 \"profile position\"\n"),
        "{out}"
    );
    assert!(
        out.contains("0x1800.5 TPDO1 communication parameter.Event timer: ok 0 (0x0000) = 0 ms\n"),
        "{out}"
    );
    assert!(
        out.contains(
            "0x1800.1 TPDO1 communication parameter.COB-ID: ok 424 (0x000001A8) bits: \"CAN-ID\"=424\n"
        ),
        "{out}"
    );
    let summary = out.lines().last().unwrap();
    assert!(summary.contains(" 0 differed, 0 refused, "), "{out}");
    assert_eq!(
        ok(&[
            &["sdo", "read"][..],
            &common,
            &["-n", "40", "-q", "--type", "u32", "0x1800.1"]
        ]
        .concat()),
        "424\n"
    );
    assert_eq!(
        ok(&[
            &["sdo", "read"][..],
            &common,
            &["-n", "40", "-q", "--od", &od, "0x6060"]
        ]
        .concat()),
        "1\n"
    );
}

#[test]
#[ignore = "needs vcan and python-canopen: tests/vm/run.sh"]
fn against_a_python_canopen_local_node() {
    let i = iface(PYTHON);
    let dir = scratch("live-vcan", "python");
    // python-canopen reads the EDS as our exporter writes it (example.eds
    // itself lacks the DummyUsage keys python-canopen requires).
    let source = write_file(&dir, "example.eds", EXAMPLE_EDS);
    let eds = dir.join("exported.eds").display().to_string();
    ok(&["export", "-o", &eds, &source]);
    let command = json!({
        "channel": i,
        "node": 9,
        "eds": eds,
        // Statusword and position have no default in the EDS.
        "data": {"6041:00": "5002", "6064:00": "D2040000"},
        "report": ["2000:00", "6060:00", "1F50:00", "1017:00"],
    });
    let peer = Peer::spawn(&command);
    let common = ["-i", i.as_str(), "-n", "9", "--timeout", "3s"];
    let sdo = |verb: &str, rest: &[&str]| ok(&[&["sdo", verb][..], &common, rest].concat());

    let out = sdo(
        "read",
        &["--od", &eds, "Statusword", "Gear ratio", "0x1018"],
    );
    assert_eq!(
        out,
        "0x6041 Statusword = 592 (0x0250) state \"switch on disabled\"; bits: \"voltage enabled\", \"switch on disabled\", \"remote\"\n\
         0x2000 Gear ratio = 12.5\n\
         0x1018 Identity object.Highest sub-index supported = 3 (0x03)\n\
         0x1018.1 Identity object.Vendor-ID = 3629 (0x00000E2D)\n\
         0x1018.2 Identity object.Product code = 1 (0x00000001)\n\
         0x1018.3 Identity object.Revision number = 65536 (0x00010000)\n"
    );
    assert_eq!(
        sdo("write", &["--od", &eds, "--verify", "0x2000", "2.25"]),
        "0x2000 Gear ratio := 2.25\n0x2000 Gear ratio = 2.25 (read back)\n"
    );
    assert_eq!(
        sdo("write", &["--od", &eds, "Modes of operation", "-3"]),
        "0x6060 Modes of operation := -3 \"manufacturer specific\"\n"
    );
    let program = write_file(&dir, "program.bin", &"0123456789".repeat(30));
    assert_eq!(
        sdo("download-file", &["--segmented", "0x1F50", &program]),
        format!("0x1F50: downloaded 300 bytes from {program} (segmented transfer)\n")
    );

    // The backup, then a changed value, then the download restores it.
    let dcf = dir.join("node9.dcf").display().to_string();
    ok(&[&["od", "upload"][..], &common, &["--od", &eds, "-o", &dcf]].concat());
    let text = std::fs::read_to_string(&dcf).unwrap();
    assert!(
        section(&text, "2000").contains("\nParameterValue=2.25\n"),
        "{text}"
    );
    sdo("write", &["--od", &eds, "0x1017", "500"]);
    sdo("write", &["--od", &eds, "0x2000", "7"]);
    sdo("write", &["--od", &eds, "0x6060", "1"]);
    let out = ok(&[&["od", "download"][..], &common, &[dcf.as_str()]].concat());
    assert!(
        out.contains("0x1017 Producer heartbeat time: ok 1000 (0x03E8) = 1000 ms\n"),
        "{out}"
    );
    assert!(out.contains("0x2000 Gear ratio: ok 2.25\n"), "{out}");
    assert!(
        out.contains("0x6060 Modes of operation: ok -3 \"manufacturer specific\"\n"),
        "{out}"
    );
    assert!(
        out.lines()
            .last()
            .unwrap()
            .contains(" 0 differed, 0 refused, "),
        "{out}"
    );

    let values = peer.finish();
    assert_eq!(
        values,
        json!({
            "2000:00": "00001040",
            "6060:00": "FD",
            "1F50:00": "30313233343536373839".repeat(30),
            "1017:00": "E803",
        })
    );
}

/// cli/tests/python/local_node.py.
struct Peer {
    child: std::process::Child,
    stdout: BufReader<std::process::ChildStdout>,
}

impl Peer {
    fn spawn(command: &Value) -> Peer {
        let mut child = python("local_node.py")
            .arg(command.to_string())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap_or_else(|e| panic!("starting python for local_node.py: {e}"));
        let stdout = BufReader::new(child.stdout.take().unwrap());
        let mut peer = Peer { child, stdout };
        assert_eq!(peer.read(), json!({"ready": true}));
        peer
    }

    fn read(&mut self) -> Value {
        let mut line = String::new();
        let n = self.stdout.read_line(&mut line).unwrap();
        assert!(
            n > 0,
            "local_node.py ended without a reply (its stderr is above)"
        );
        let value: Value = serde_json::from_str(&line)
            .unwrap_or_else(|e| panic!("local_node.py printed {line:?}: {e}"));
        assert!(
            value.get("error").is_none(),
            "local_node.py failed: {value}"
        );
        value
    }

    /// Closes stdin; the values the node holds at the end.
    fn finish(mut self) -> Value {
        if let Some(mut stdin) = self.child.stdin.take() {
            let _ = stdin.flush();
        }
        let value = self.read();
        let status = self.child.wait().unwrap();
        assert!(status.success(), "local_node.py exited with {status}");
        value["values"].clone()
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
