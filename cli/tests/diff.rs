//! `eds2rust diff`: exit codes by `--fail-on`, formats, overlays, errors.

mod common;

use common::{run, tempdir};
use serde_json::Value;

fn diff_fixture(pair: &str, side: &str) -> String {
    let dir = format!(
        "{}/../codegen/tests/fixtures/diff/{pair}",
        env!("CARGO_MANIFEST_DIR")
    );
    let file = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.file_stem().and_then(|s| s.to_str()) == Some(side))
        .unwrap_or_else(|| panic!("{dir}: no {side}.*"));
    file.to_str().unwrap().to_string()
}

const DIFF_HEAD: &str = "format: 1\ndevice: { vendor_name: T, product_name: P }\nobjects:\n  - { index: 0x2000, name: Speed, type: UNSIGNED16, access: rw, default: 1 }\n";

#[test]
fn diff_exit_codes_by_fail_on() {
    let dir = tempdir().join("diff-levels");
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, extra: &str| {
        let path = dir.join(name);
        std::fs::write(&path, format!("{DIFF_HEAD}{extra}")).unwrap();
        path.to_str().unwrap().to_string()
    };
    let base = write("base.yaml", "");
    let compatible = {
        let path = dir.join("compatible.yaml");
        std::fs::write(&path, DIFF_HEAD.replace("default: 1", "default: 2")).unwrap();
        path.to_str().unwrap().to_string()
    };
    let additive = write(
        "additive.yaml",
        "  - { index: 0x2001, name: Torque, type: INTEGER16, access: ro }\n",
    );
    let breaking = {
        let path = dir.join("breaking.yaml");
        std::fs::write(&path, DIFF_HEAD.replace("access: rw", "access: ro")).unwrap();
        path.to_str().unwrap().to_string()
    };
    // (new side, exit code for breaking / additive / any / never)
    let cases = [
        (&base, [0, 0, 0, 0]),
        (&compatible, [0, 0, 1, 0]),
        (&additive, [0, 1, 1, 0]),
        (&breaking, [1, 1, 1, 0]),
    ];
    for (new, codes) in cases {
        for (level, expected) in ["breaking", "additive", "any", "never"].iter().zip(codes) {
            let (code, stdout, stderr) = run(&["diff", "--fail-on", level, &base, new]);
            assert_eq!(code, expected, "{new} --fail-on {level}: {stdout}{stderr}");
        }
        // The default is --fail-on breaking.
        assert_eq!(run(&["diff", &base, new]).0, codes[0], "{new}");
    }
    let (_, stdout, _) = run(&["diff", &base, &breaking]);
    assert!(stdout.starts_with("breaking"), "{stdout}");
    assert!(
        stdout.contains("access-changed `od::Speed`: access rw → ro: loses write"),
        "{stdout}"
    );
    assert!(
        stdout.ends_with("1 change: 1 breaking, 0 additive, 0 compatible\n"),
        "{stdout}"
    );
    let (_, stdout, _) = run(&["diff", &base, &base]);
    assert_eq!(stdout, "0 changes: 0 breaking, 0 additive, 0 compatible\n");
}

#[test]
fn diff_formats() {
    let (old, new) = (
        diff_fixture("04_type_access", "old"),
        diff_fixture("04_type_access", "new"),
    );
    let (code, stdout, _) = run(&["diff", "--format", "json", &old, &new]);
    assert_eq!(code, 1);
    let doc: Value = serde_json::from_str(&stdout).expect("one JSON object");
    assert_eq!(doc["old"], old.as_str());
    assert_eq!(doc["new"], new.as_str());
    let changes = doc["changes"].as_array().unwrap();
    assert_eq!(changes.len(), 9);
    for c in changes {
        let keys: Vec<&str> = c.as_object().unwrap().keys().map(String::as_str).collect();
        let mut expected = vec![
            "index",
            "subindex",
            "kind",
            "severity",
            "rust_path",
            "old",
            "new",
            "message",
        ];
        expected.sort();
        let mut keys = keys;
        keys.sort();
        assert_eq!(keys, expected);
        assert!(c["index"].is_u64() && c["kind"].is_string() && c["message"].is_string());
        assert!(["breaking", "additive", "compatible"].contains(&c["severity"].as_str().unwrap()));
    }
    let first = &changes[0];
    assert_eq!(first["index"], 0x2000);
    assert_eq!(first["subindex"], 0);
    assert_eq!(first["kind"], "data-type-changed");
    assert_eq!(first["rust_path"], "od::Counter");
    assert_eq!(first["old"], "UNSIGNED16");
    assert_eq!(first["new"], "UNSIGNED32");

    let (code, stdout, _) = run(&["diff", "--format", "markdown", &old, &new]);
    assert_eq!(code, 1);
    assert!(
        stdout.contains("| severity | where | kind | Rust path | change |"),
        "{stdout}"
    );
    assert!(
        stdout.contains("| **breaking** | 0x2002 sub 0 | `access-changed` | `od::Command` |"),
        "{stdout}"
    );
    assert!(
        stdout
            .trim_end()
            .ends_with("9 changes: 5 breaking, 2 additive, 2 compatible"),
        "{stdout}"
    );

    let (code, text, _) = run(&["diff", "--format", "text", &old, &new]);
    assert_eq!(code, 1);
    assert_eq!(text.lines().count(), 10, "{text}");
}

#[test]
fn diff_overlays_and_semantics() {
    let pair = "14_overlay";
    let (old, new) = (diff_fixture(pair, "old"), diff_fixture(pair, "new"));
    let overlay = format!(
        "{}/../codegen/tests/fixtures/diff/{pair}/new_overlay.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    assert_eq!(run(&["diff", &old, &new]).0, 0, "the same file");
    // The overlay adds a manufacturer bit to the standard's statusword
    // bits: nothing breaking, exit 0.
    let (code, stdout, _) = run(&["diff", "--new-overlay", &overlay, &old, &new]);
    assert_eq!(code, 0, "{stdout}");
    assert!(stdout.contains("bit-field-added"), "{stdout}");
    // The overlay on both sides: equal again.
    let (code, stdout, _) = run(&[
        "diff",
        "--old-overlay",
        &overlay,
        "--new-overlay",
        &overlay,
        &old,
        &new,
    ]);
    assert_eq!(
        (code, stdout.as_str()),
        (0, "0 changes: 0 breaking, 0 additive, 0 compatible\n")
    );
    // The overlay on the old side only: the reverse.
    let (_, stdout, _) = run(&[
        "diff",
        "--old-overlay",
        &overlay,
        "--fail-on",
        "never",
        &old,
        &new,
    ]);
    assert!(stdout.contains("bit-field-removed"), "{stdout}");

    // A seed device's table against its EDS export: equal but for what an
    // EDS cannot say, which --ignore-semantics leaves aside.
    let table = format!("{}/../eds/linak_techline.yaml", env!("CARGO_MANIFEST_DIR"));
    let dir = tempdir();
    let eds = dir.join("linak_export.eds");
    let eds = eds.to_str().unwrap();
    assert_eq!(run(&["export", "-o", eds, &table]).0, 0);
    let (code, stdout, _) = run(&["diff", "--ignore-semantics", eds, &table]);
    assert_eq!(
        (code, stdout.as_str()),
        (0, "0 changes: 0 breaking, 0 additive, 0 compatible\n")
    );
    let (code, stdout, _) = run(&["diff", "--fail-on", "never", eds, &table]);
    assert_eq!(code, 0);
    assert!(
        stdout.contains("named-value-added") && stdout.contains("unit-changed"),
        "{stdout}"
    );
}

#[test]
fn diff_usage_and_input_errors() {
    let old = diff_fixture("01_objects", "old");
    assert_eq!(run(&["diff"]).0, 2, "no files");
    assert_eq!(run(&["diff", &old]).0, 2, "one file");
    assert_eq!(run(&["diff", "--format", "yaml", &old, &old]).0, 2);
    assert_eq!(run(&["diff", "--fail-on", "sometimes", &old, &old]).0, 2);
    assert_eq!(run(&["diff", "--allow", "no::such-rule", &old, &old]).0, 2);

    let dir = tempdir();
    let missing = dir.join("missing.eds");
    let (code, stdout, stderr) = run(&["diff", &old, missing.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(stdout.is_empty(), "{stdout}");
    assert!(
        stderr.contains("missing.eds") && stderr.contains("not compared"),
        "{stderr}"
    );

    let bad = dir.join("diff-bad.eds");
    std::fs::write(&bad, "[1000]\nParameterName=Device type\nObjectType=0x3\n").unwrap();
    let (code, _, stderr) = run(&["diff", bad.to_str().unwrap(), &old]);
    assert_eq!(code, 2);
    assert!(stderr.contains("eds::bad-object-type"), "{stderr}");

    // An overlay that is not YAML is an input error of that side.
    let (code, _, stderr) = run(&[
        "diff",
        "--new-overlay",
        &old.replace(".yaml", ".eds"),
        &old,
        &old,
    ]);
    assert_eq!(code, 2, "{stderr}");
    // A warning is an error with --strict (the EDS export has none, a
    // hand-written warning file does).
    let warn = dir.join("diff-warn.eds");
    std::fs::write(&warn, "[1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\nDefaultValue=017\nDefaultValue=0x10\n").unwrap();
    let warn = warn.to_str().unwrap();
    assert_eq!(run(&["diff", warn, warn]).0, 0);
    assert_eq!(run(&["diff", "--strict", warn, warn]).0, 2);
}
