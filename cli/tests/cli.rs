//! The `eds2rust` binary: exit codes of `check`, the `dump --format json`
//! schema on the repository's example file, export and generate.

mod common;

use common::{example, run, seed, temp_file, tempdir};
use serde_json::Value;

#[test]
fn check_exit_codes() {
    let (code, stdout, _) = run(&["check", &example()]);
    assert_eq!(code, 0, "{stdout}");
    assert!(stdout.contains("0 errors, 0 warnings"), "{stdout}");

    let dir = tempdir();
    let bad = dir.join("bad.eds");
    std::fs::write(&bad, "[1000]\nParameterName=Device type\nObjectType=0x3\n").unwrap();
    let (code, stdout, _) = run(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 1, "{stdout}");
    assert!(stdout.contains("eds::bad-object-type"), "{stdout}");
    assert!(
        stdout.contains("bad.eds:3:"),
        "names file and line: {stdout}"
    );

    // A warning only: 0 in lenient mode, 1 with --strict.
    let warn = dir.join("warn.eds");
    std::fs::write(&warn, "[1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\nDefaultValue=017\nDefaultValue=0x10\n").unwrap();
    assert_eq!(run(&["check", warn.to_str().unwrap()]).0, 0);
    assert_eq!(run(&["check", "--strict", warn.to_str().unwrap()]).0, 1);

    assert_eq!(run(&["check"]).0, 2, "no file is a usage error");
    assert_eq!(run(&["dump", "--format", "yaml", &example()]).0, 2);
    assert_eq!(run(&["dump", "--node-id", "200", &example()]).0, 2);
    assert_eq!(
        run(&["check", dir.join("missing.eds").to_str().unwrap()]).0,
        1
    );
}

#[test]
fn allow_and_deny_rules() {
    let dir = tempdir();
    let warn = dir.join("levels.eds");
    std::fs::write(&warn, "[1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\nDefaultValue=017\nDefaultValue=0x10\n").unwrap();
    let warn = warn.to_str().unwrap();
    let (code, stdout, _) = run(&["check", warn]);
    assert_eq!(code, 0, "{stdout}");
    let mut rules: Vec<String> = stdout
        .lines()
        .filter_map(|l| Some(l.strip_prefix("warning[")?.split(']').next()?.to_string()))
        .collect();
    rules.sort();
    rules.dedup();
    assert!(!rules.is_empty(), "{stdout}");
    let rule = rules[0].clone();
    let mut allow_all: Vec<&str> = vec!["check"];
    for r in &rules {
        allow_all.extend(["--allow", r]);
    }
    allow_all.push(warn);
    let (code, stdout, _) = run(&allow_all);
    assert_eq!(code, 0);
    assert!(stdout.contains("0 errors, 0 warnings"), "{stdout}");
    // Allowed rules are spared by --strict.
    allow_all.insert(1, "--strict");
    assert_eq!(run(&allow_all).0, 0);

    let (code, stdout, _) = run(&["check", "--deny", &rule, warn]);
    assert_eq!(code, 1, "{stdout}");
    assert!(stdout.contains(&format!("error[{rule}]")), "{stdout}");
    assert!(stdout.contains("is denied by --deny"), "{stdout}");

    let (code, _, stderr) = run(&["check", "--allow", "eds::duplicate-keys", warn]);
    assert_eq!(code, 2, "an unknown rule is a usage error");
    assert!(
        stderr.contains("did you mean `eds::duplicate-key`?"),
        "{stderr}"
    );
}

fn entry(doc: &Value, index: u64, sub: u64) -> &Value {
    doc["entries"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["index"] == index && e["subindex"] == sub)
        .unwrap_or_else(|| panic!("entry {index:#x} sub {sub}"))
}

#[test]
fn dump_json_schema_and_node_id() {
    let (code, stdout, stderr) = run(&["dump", "--format", "json", "--node-id", "5", &example()]);
    assert_eq!(code, 0, "{stderr}");
    let doc: Value = serde_json::from_str(&stdout).unwrap();
    let keys: Vec<&str> = doc
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(keys, ["file", "device", "entries", "diagnostics"]);
    assert_eq!(doc["device"]["vendor_number"], 0xE2D);
    assert_eq!(doc["device"]["product_name"], "Example Drive");
    let e = entry(&doc, 0x1400, 1);
    let keys: Vec<&str> = e.as_object().unwrap().keys().map(String::as_str).collect();
    assert_eq!(
        keys,
        [
            "index",
            "subindex",
            "object_type",
            "parent_name",
            "name",
            "data_type",
            "access",
            "pdo_mappable",
            "default",
            "low_limit",
            "high_limit",
            "parameter_value",
            "node_relative"
        ]
    );
    assert_eq!(e["default"], 0x205);
    assert_eq!(e["node_relative"], true);
    assert_eq!(e["object_type"], "RECORD");
    assert_eq!(e["parent_name"], "RPDO1 communication parameter");
    assert_eq!(
        entry(&doc, 0x1800, 1)["default"],
        0x185,
        "`0x180 + $NODEID` with spaces"
    );
    // CompactSubObj: sub 0 and two named subs.
    assert_eq!(entry(&doc, 0x1016, 0)["default"], 2);
    assert_eq!(
        entry(&doc, 0x1016, 2)["name"],
        "Heartbeat of the safety controller"
    );
    assert_eq!(entry(&doc, 0x1016, 2)["access"], "rw");
    // REAL32 from a hex bit pattern and decimals.
    let gear = entry(&doc, 0x2000, 0);
    assert_eq!(
        (gear["default"].as_f64(), gear["low_limit"].as_f64()),
        (Some(12.5), Some(1.0))
    );
    assert_eq!(entry(&doc, 0x6060, 0)["low_limit"], -4);
    assert_eq!(entry(&doc, 0x1F50, 0)["object_type"], "DOMAIN");
    assert_eq!(entry(&doc, 0x1F50, 0)["default"], Value::Null);
    // Sorted by index then subindex.
    let order: Vec<(u64, u64)> = doc["entries"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["index"].as_u64().unwrap(),
                e["subindex"].as_u64().unwrap(),
            )
        })
        .collect();
    let mut sorted = order.clone();
    sorted.sort();
    assert_eq!(order, sorted);

    // Without --node-id the formula stays unresolved.
    let (_, stdout, _) = run(&["dump", "--format", "json", &example()]);
    let doc: Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(entry(&doc, 0x1400, 1)["default"], 0x200);
}

#[test]
fn yaml_tables_are_checked_dumped_and_exported_like_eds() {
    let linak = seed("linak_techline");
    let (code, stdout, _) = run(&["check", "--strict", &linak]);
    assert_eq!(code, 0, "{stdout}");
    assert!(stdout.contains("0 errors, 0 warnings"), "{stdout}");

    // Same JSON schema as for an EDS: same keys at the top, in the device
    // and in every entry.
    let keys = |v: &Value| -> Vec<String> { v.as_object().unwrap().keys().cloned().collect() };
    let (_, eds_json, _) = run(&["dump", "--format", "json", "--node-id", "32", &example()]);
    let (code, yaml_json, _) = run(&["dump", "--format", "json", "--node-id", "32", &linak]);
    assert_eq!(code, 0);
    let (eds_json, yaml_json): (Value, Value) = (
        serde_json::from_str(&eds_json).unwrap(),
        serde_json::from_str(&yaml_json).unwrap(),
    );
    assert_eq!(keys(&eds_json), keys(&yaml_json));
    assert_eq!(keys(&eds_json["device"]), keys(&yaml_json["device"]));
    assert_eq!(
        keys(&eds_json["entries"][0]),
        keys(&yaml_json["entries"][0])
    );
    // $NODEID resolved: TPDO1's COB-ID for node 32.
    let cob_id = yaml_json["entries"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["index"] == 0x1800 && e["subindex"] == 1)
        .unwrap();
    assert_eq!(cob_id["default"], 0x1A0);

    // export: an EDS on stdout that reads back without a diagnostic.
    let dir = tempdir();
    let out = dir.join("linak.eds");
    let (code, _, stderr) = run(&[
        "export",
        "--format",
        "eds",
        "-o",
        out.to_str().unwrap(),
        &linak,
    ]);
    assert_eq!(code, 0, "{stderr}");
    let (code, stdout, _) = run(&["check", "--strict", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{stdout}");

    // A table with errors: exit 1, the diagnostics on stderr, nothing written.
    let bad = temp_file(
        "bad.yaml",
        "format: 1\ndevice: { vendor_name: V, product_name: P }\nobjects:\n  - { index: 0x2000, name: A, type: UINT16, access: rw }\n",
    );
    let kept = temp_file("kept.eds", "previous");
    let (code, stdout, stderr) = run(&["export", "-o", &kept, &bad]);
    assert_eq!(code, 1);
    assert!(stdout.is_empty(), "{stdout}");
    assert!(
        stderr.contains("bad.yaml:4:") && stderr.contains("table::bad-type"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_to_string(&kept).unwrap(), "previous");

    // An unknown variant is an error naming the known ones.
    let (code, _, stderr) = run(&["export", "--variant", "ACS99", &seed("zimmer_acs")]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("ACS40") && stderr.contains("ACS60"),
        "{stderr}"
    );
}

#[test]
fn generate_prints_code_or_errors() {
    let linak = seed("linak_techline");
    let (code, stdout, stderr) = run(&["generate", &linak]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.starts_with("// @generated"), "{stdout}");

    let dir = tempdir();
    let out = dir.join("linak.rs");
    let (code, written, stderr) = run(&[
        "generate",
        "--runtime-path",
        "::my::runtime",
        "-o",
        out.to_str().unwrap(),
        &linak,
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(written.is_empty(), "{written}");
    assert!(
        std::fs::read_to_string(&out)
            .unwrap()
            .starts_with("// @generated")
    );

    // An overlay without `base:` on the example EDS.
    let overlay = dir.join("gen_overlay.yaml");
    std::fs::write(
        &overlay,
        "format: 1\nmodify:\n  - { index: 0x6060, default: 3 }\n",
    )
    .unwrap();
    let (code, stdout, stderr) = run(&[
        "generate",
        "--overlay",
        overlay.to_str().unwrap(),
        &example(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.starts_with("// @generated"), "{stdout}");

    // Errors: exit 1, diagnostics on stderr, nothing on stdout, -o untouched.
    let bad = dir.join("gen_bad.yaml");
    std::fs::write(
        &bad,
        "format: 1\ndevice: { vendor_name: V, product_name: P }\nobjects:\n  - { index: 0x2000, name: A, type: UINT16, access: rw }\n",
    )
    .unwrap();
    let kept = dir.join("kept.rs");
    std::fs::write(&kept, "previous").unwrap();
    for args in [
        vec!["generate", bad.to_str().unwrap()],
        vec![
            "generate",
            "-o",
            kept.to_str().unwrap(),
            bad.to_str().unwrap(),
        ],
        vec!["generate", "--overlay", bad.to_str().unwrap(), &example()],
    ] {
        let (code, stdout, stderr) = run(&args);
        assert_eq!(code, 1, "{args:?}: {stderr}");
        assert!(stdout.is_empty(), "{stdout}");
        assert!(stderr.contains("gen_bad.yaml:"), "{stderr}");
    }
    assert_eq!(std::fs::read_to_string(&kept).unwrap(), "previous");

    assert_eq!(run(&["generate"]).0, 2, "no input is a usage error");
}

/// `dump --node-id` never prints a `$NODEID` value its type cannot hold:
/// the value is null and an error names the entry (exit code 1).
#[test]
fn dump_node_id_reports_values_out_of_range() {
    let file = format!(
        "{}/../codegen/tests/fixtures/malformed/nodeid_formula_overflow_u8.eds",
        env!("CARGO_MANIFEST_DIR")
    );
    let (code, stdout, stderr) = run(&["dump", "--node-id", "5", &file]);
    assert_eq!(code, 1, "{stderr}");
    let doc: Value = serde_json::from_str(&stdout).unwrap();
    let mode = entry(&doc, 0x2000, 0);
    assert_eq!(mode["default"], Value::Null, "not 305");
    assert_eq!(mode["low_limit"], 255, "$NODEID+250 fits node 5");
    let errors: Vec<&str> = doc["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["severity"] == "error")
        .map(|d| d["message"].as_str().unwrap())
        .collect();
    assert_eq!(
        errors,
        [
            "[0x2000 sub 0] DefaultValue: `$NODEID+300` gives 305 for node id 5, out of range for UNSIGNED8 (0..=255)"
        ]
    );
    // Node 6 is past the ids `$NODEID+250` fits.
    let (_, stdout, _) = run(&["dump", "--node-id", "6", &file]);
    let doc: Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(entry(&doc, 0x2000, 0)["low_limit"], Value::Null);
}
