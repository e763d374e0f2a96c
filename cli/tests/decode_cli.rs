//! `eds2rust decode` as a user runs it: the LINAK manual's start-up trace
//! recorded in every supported form (candump log, candump text, compact
//! lines, PCAN-View .trc 1.1 and 2.1) decodes to the same values; a corpus
//! drive DCF names its PDO fields; standard input; usage and input errors.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use serde_json::Value as Json;

/// The manual's frames (p. 28, node 32): identifier and data bytes.
const FRAMES: [(u16, &[u8]); 8] = [
    (0x701, &[0x05]),
    (0x720, &[0x00]),
    (0x620, &[0x23, 0x16, 0x10, 0x01, 0xC8, 0x00, 0x01, 0x00]),
    (0x5A0, &[0x60, 0x16, 0x10, 0x01, 0x00, 0x00, 0x00, 0x00]),
    (0x000, &[0x01, 0x20]),
    (0x1A0, &[0x00, 0x00, 0x00, 0x81, 0x01, 0x00, 0x00, 0xC0]),
    (0x220, &[0x03, 0xFB, 0xFB, 0xFB, 0xFB, 0xFB, 0x00, 0x00]),
    (0x1A0, &[0x1A, 0x00, 0x06, 0x88, 0x00, 0x31, 0x00, 0xC0]),
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn hex(data: &[u8], sep: &str) -> String {
    data.iter()
        .map(|b| format!("{b:02X}"))
        .collect::<Vec<_>>()
        .join(sep)
}

/// The trace in each form, with its header where the form has one.
fn forms() -> Vec<(&'static str, String)> {
    let mut log = String::new();
    let mut text = String::new();
    let mut compact = String::new();
    let mut trc11 = String::from(
        ";$FILEVERSION=1.1\n;$STARTTIME=46023.5\n;   Message Number\n;   |         Time Offset (ms)\n",
    );
    let mut trc21 =
        String::from(";$FILEVERSION=2.1\n;$STARTTIME=46023.5\n;$COLUMNS=N,O,T,B,I,d,R,L,D\n;\n");
    for (i, (id, data)) in FRAMES.iter().enumerate() {
        let ms = 100 * i;
        log += &format!(
            "(1764673200.{:06}) can0 {id:03X}#{}\n",
            ms * 1000,
            hex(data, "")
        );
        text += &format!("  can0  {id:03X}   [{}]  {}\n", data.len(), hex(data, " "));
        compact += &format!("{id:03X}#{}\n", hex(data, ""));
        trc11 += &format!(
            "{:>6})  {:>10.1}  Rx         {id:04X}  {}  {}\n",
            i + 1,
            ms as f64,
            data.len(),
            hex(data, " ")
        );
        trc21 += &format!(
            "{:>7} {:>13.3} DT {:>1} {:>10X} Rx - {:>2}  {}\n",
            i + 1,
            ms as f64,
            1,
            id,
            data.len(),
            hex(data, " ")
        );
    }
    vec![
        ("candump -l", log),
        ("candump text", text),
        ("compact", compact),
        ("trc 1.1", trc11),
        ("trc 2.1", trc21),
    ]
}

fn eds2rust(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_eds2rust"))
        .args(args)
        .current_dir(root())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run eds2rust");
    let mut input = child.stdin.take().expect("stdin");
    input
        .write_all(stdin.unwrap_or("").as_bytes())
        .expect("write stdin");
    drop(input);
    child.wait_with_output().expect("eds2rust output")
}

fn json_lines(out: &Output) -> Vec<Json> {
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect()
}

/// What must not depend on the form: per record everything but the line
/// numbers and the time.
fn essence(records: &[Json]) -> Vec<Json> {
    records
        .iter()
        .map(|r| {
            let mut r = r.clone();
            let m = r.as_object_mut().expect("an object");
            m.remove("line");
            m.remove("time");
            r
        })
        .collect()
}

#[test]
fn every_trace_form_decodes_to_the_same_values() {
    let dir = std::env::temp_dir().join(format!("eds2rust-decode-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut decoded = Vec::new();
    for (name, trace) in forms() {
        let path = dir.join(format!("{}.trace", name.replace([' ', '.'], "_")));
        std::fs::write(&path, &trace).unwrap();
        let out = eds2rust(
            &[
                "decode",
                "--node",
                "32=eds/linak_techline.yaml",
                "--format",
                "json",
                path.to_str().unwrap(),
            ],
            None,
        );
        let records = json_lines(&out);
        assert!(
            records.iter().all(|r| r["event"] != "diagnostic"),
            "{name}: {records:#?}"
        );
        assert_eq!(
            records.len(),
            FRAMES.len() + 1,
            "{name}: 8 frames and one SDO transfer"
        );
        decoded.push((name, records));
    }
    let (_, first) = &decoded[0];
    // The values the manual states.
    let last = &first[first.len() - 1];
    let position = last["fields"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["name"] == "Feedback.Position")
        .unwrap();
    assert_eq!(
        (position["value"].as_f64(), position["unit"].as_str()),
        (Some(2.6), Some("mm"))
    );
    assert_eq!(first[1]["text"], "boot-up node 32");
    // Times: candump's seconds, .trc offsets in seconds.
    assert_eq!(decoded[0].1[7]["time"], 1_764_673_200.6);
    assert_eq!(decoded[3].1[7]["time"], 0.6);
    assert_eq!(decoded[4].1[7]["time"], 0.6);
    assert_eq!(decoded[1].1[7]["time"], Json::Null);
    for (name, records) in &decoded[1..] {
        assert_eq!(essence(records), essence(first), "{name}");
    }
    // And the text form of the same trace, from standard input.
    let out = eds2rust(
        &["decode", "--node", "32=eds/linak_techline.yaml", "-"],
        Some(&forms()[2].1),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        text.contains("TPDO1 node 32 (feedback): Feedback.Position=26 (0x001A) = 2.6 mm"),
        "{text}"
    );
    assert!(text.contains("\"power up lock\""), "{text}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_lines_are_diagnostics_and_decoding_goes_on() {
    let trace = "701#05\n123#11223\nthis is not a frame\n(12.5) can0 080#\n";
    let out = eds2rust(&["decode", "--format", "json"], Some(trace));
    let records = json_lines(&out);
    let kinds: Vec<String> = records
        .iter()
        .map(|r| {
            r["event"]
                .as_str()
                .or(r["protocol"].as_str())
                .unwrap()
                .to_string()
        })
        .collect();
    assert_eq!(kinds, ["heartbeat", "diagnostic", "diagnostic", "sync"]);
    assert_eq!(
        (records[1]["line"].as_u64(), records[2]["line"].as_u64()),
        (Some(2), Some(3))
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("2 lines could not be read"));
}

#[test]
fn a_corpus_drive_names_its_pdo_fields() {
    let corpus = root().join("../shared/eds-corpus/files");
    if !corpus.is_dir() {
        println!(
            "NOT RUN: decode of a corpus drive: ../shared/eds-corpus is not beside this checkout"
        );
        return;
    }
    let dcf = corpus.join("maxon_epos4-50-15_ec90flat_node1.dcf");
    let node = format!("1={}", dcf.display());
    // Boot-up, NMT start, then TPDO1 (0x181) as the DCF maps it: statusword
    // and modes of operation display, 24 bits.
    let out = eds2rust(
        &["decode", "--node", &node, "--format", "json"],
        Some("701#00\n000#0101\n181#370608\n"),
    );
    let records = json_lines(&out);
    let tpdo = &records[2];
    assert_eq!(
        (tpdo["protocol"].as_str(), tpdo["pdo"].as_str()),
        (Some("pdo"), Some("tpdo1")),
        "{tpdo}"
    );
    let fields = tpdo["fields"].as_array().unwrap();
    assert!(!fields.is_empty(), "{tpdo}");
    assert!(
        fields
            .iter()
            .any(|f| f["name"].as_str().unwrap().contains("Statusword")),
        "{tpdo}"
    );
}

#[test]
fn usage_and_input_errors() {
    let code = |args: &[&str]| eds2rust(args, Some("")).status.code();
    assert_eq!(
        code(&["decode", "--node", "0=eds/linak_techline.yaml"]),
        Some(2)
    );
    assert_eq!(code(&["decode", "--node", "32"]), Some(2));
    assert_eq!(code(&["decode", "--overlay", "5=eds/x.yaml"]), Some(2));
    assert_eq!(code(&["decode", "--node", "5=no/such/file.eds"]), Some(1));
    assert_eq!(code(&["decode", "no/such/trace.log"]), Some(1));
}

/// `--bus`: the nodes and their files from a bus file, the PDOs as the
/// network configures them: the Zimmer axis's TPDO2 (node 40, 0x2A8)
/// carries velocity and torque in the seed machine, velocity only by its
/// file's default.
#[test]
fn a_bus_file_decodes_the_pdos_the_network_configures() {
    let trace = "(0.000000) can0 2A8#E8030000FBFF\n";
    let fields = |args: &[&str]| -> Vec<String> {
        let records = json_lines(&eds2rust(args, Some(trace)));
        records[0]["fields"]
            .as_array()
            .expect("fields")
            .iter()
            .map(|f| f["name"].as_str().expect("a name").to_string())
            .collect()
    };
    assert_eq!(
        fields(&["decode", "--bus", "eds/machine/bus.yml", "--format", "json"]),
        ["Velocity actual value", "Torque actual value"]
    );
    assert_eq!(
        fields(&[
            "decode",
            "--node",
            "40=eds/zimmer_acs.yaml",
            "--format",
            "json"
        ]),
        ["Velocity actual value"]
    );
    let code = |args: &[&str]| eds2rust(args, Some("")).status.code();
    assert_eq!(
        code(&[
            "decode",
            "--bus",
            "eds/machine/bus.yml",
            "--node",
            "5=eds/x.yaml"
        ]),
        Some(2)
    );
    assert_eq!(code(&["decode", "--bus", "no/such/bus.yml"]), Some(1));
}
