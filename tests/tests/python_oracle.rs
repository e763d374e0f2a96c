//! Differential test against python-canopen 2.4.1 (`tests/python/od_dump.py`):
//! for every corpus file python-canopen loads with `import_od(path, node_id=5)`,
//! every entry it models must agree with `eds2rust dump --node-id 5` on data
//! type, access, PDO mapping, default, limits and DCF parameter value.
//!
//! Where python-canopen deviates from CiA 306, the difference is attributed to
//! one of the rules in [`RULES`] (by what the entry is, never by file name) and
//! listed with its count. The rule-adjusted agreement must be at least 99.5 %.

use std::path::Path;

use eds2rust::diag::Diagnostics;
use eds2rust::dump::json::to_json;
use eds2rust::eds::ini::Document;
use eds2rust::eds::{Options, read_file};
use eds2rust::ir::{DataType, Device, Entry, Literal, ObjectKind, ValueKind};
use eds2rust_tests::python::{Agreement, run_per_file};
use serde_json::Value;

/// Known python-canopen 2.4.1 behaviours that differ from CiA 306, with the reason.
const RULES: &[(&str, &str)] = &[
    (
        "dummy-objects",
        "python-canopen models [DummyUsage] as VAR objects 0x0001-0x0007; eds2rust keeps it as Device::dummy_usage, not as entries",
    ),
    (
        "compact-sub0",
        "python-canopen gives the CompactSubObj sub 0 no default and access rw; CiA 306 defines it as the number of sub-objects, ro",
    ),
    (
        "octal",
        "python-canopen reads values with int(x, 0), which rejects CiA 306 octal literals with a leading 0 (e.g. 0644); eds2rust reads them as octal",
    ),
    (
        "real-hex",
        "python-canopen reads REAL values with float(x), which rejects hex bit patterns (0x3F800000); eds2rust decodes the pattern",
    ),
    (
        "real-limit",
        "python-canopen reads limits with int(x, 0) whatever the type: decimal REAL limits (1.5) are dropped and hex bit patterns (0x461C4000) become integers",
    ),
    (
        "signed-hex-default",
        "python-canopen keeps a hex default/parameter value of a signed type unsigned (0xFFFF = 65535 for INTEGER16); eds2rust reads it as the two's-complement bit pattern, as python-canopen itself does for limits",
    ),
    (
        "signed-limit-width",
        "python-canopen converts signed limits only for INTEGER8/16/32/64; for INTEGER24/40/48/56 its bit-length lookup raises and the limit is dropped",
    ),
    (
        "unknown-type",
        "python-canopen turns data types above 0x1B into DOMAIN (or the type named by a CANFestival [XXsub1] section); eds2rust keeps the code and reports it",
    ),
    (
        "compact-values",
        "python-canopen ignores [xxxxValue] sections of CompactSubObj objects; eds2rust reads them as the DCF parameter values",
    ),
    (
        "key-case",
        "python-canopen matches keys case-sensitively (optionxform = str), so a key such as `PdoMapping=1` is not seen; CiA 306 keys are case-insensitive",
    ),
    (
        "nodeid-limit",
        "python-canopen reads limits with int(x, 0), so a $NODEID formula in a limit is dropped; eds2rust resolves it",
    ),
];

fn literal<'a>(entry: &'a Entry, field: &str) -> Option<&'a Literal> {
    match field {
        "default" => entry.default.as_ref(),
        "low_limit" => entry.low_limit.as_ref(),
        "high_limit" => entry.high_limit.as_ref(),
        "parameter_value" => entry.parameter_value.as_ref(),
        _ => None,
    }
}

/// The CiA 306 spelling of the key a field is read from.
fn key_of(field: &str) -> &'static str {
    match field {
        "data_type" => "DataType",
        "access" => "AccessType",
        "pdo_mappable" => "PDOMapping",
        "default" => "DefaultValue",
        "low_limit" => "LowLimit",
        "high_limit" => "HighLimit",
        _ => "ParameterValue",
    }
}

/// The rule that explains a difference on `field`, if any. `doc` is the file's
/// INI structure, to see how a key was spelled.
fn explain(
    doc: &Document,
    device: &Device,
    index: u16,
    entry: &Entry,
    field: &str,
    ours: &Value,
    theirs: &Value,
) -> Option<&'static str> {
    let object = &device.objects[&index];
    if matches!(entry.data_type, DataType::Other(_)) {
        return Some("unknown-type");
    }
    let key = key_of(field);
    let section = doc.sections.iter().find(|s| s.line == entry.origin.line);
    if section
        .and_then(|s| s.get(key))
        .is_some_and(|p| p.key != key)
    {
        return Some("key-case");
    }
    if matches!(entry.data_type.value_kind(), Some(ValueKind::Real { .. }))
        && field.ends_with("limit")
    {
        return Some("real-limit");
    }
    if object.compact_sub_obj.is_some()
        && entry.subindex == 0
        && object.kind == ObjectKind::Array
        && matches!(field, "default" | "access")
    {
        return Some("compact-sub0");
    }
    let lit = literal(entry, field)?;
    let raw = lit.text.trim();
    let hex = raw.to_ascii_lowercase().starts_with("0x");
    if field == "parameter_value" && object.compact_sub_obj.is_some() && theirs.is_null() {
        return Some("compact-values");
    }
    if theirs.is_null() {
        let digits = raw.trim_start_matches(['-', '+']);
        if digits.len() > 1 && digits.starts_with('0') && digits.bytes().all(|b| b.is_ascii_digit())
        {
            return Some("octal");
        }
        match entry.data_type.value_kind() {
            Some(ValueKind::Real { .. }) if hex => return Some("real-hex"),
            Some(ValueKind::Integer { signed: true, bits })
                if field.ends_with("limit") && ![8, 16, 32, 64].contains(&bits) =>
            {
                return Some("signed-limit-width");
            }
            _ => {}
        }
        if lit.plus_node_id && field.ends_with("limit") {
            return Some("nodeid-limit");
        }
    }
    if let (Some(ValueKind::Integer { signed: true, bits }), true) =
        (entry.data_type.value_kind(), hex)
        && matches!(field, "default" | "parameter_value")
        && let (Some(a), Some(b)) = (ours.as_i64(), theirs.as_i64())
        && i128::from(b) - i128::from(a) == 1i128 << bits
    {
        return Some("signed-hex-default");
    }
    None
}

#[derive(Default)]
struct Tally {
    entries: Agreement,
    python_failed: Vec<String>,
}

fn compare_file(path: &Path, python: &Value, tally: &mut Tally) {
    let name = path.display().to_string();
    if python["ok"] != true {
        tally
            .python_failed
            .push(format!("{name}: {}", python["error"]));
        return;
    }
    let loaded = read_file(path, &Options::default());
    let device = loaded.device.as_ref().expect("device");
    let ours = to_json(&name, Some(device), &loaded.diagnostics, Some(5));
    let bytes = std::fs::read(path).expect("read corpus file");
    let mut scratch = Diagnostics::new();
    let text = eds2rust::eds::ini::decode(&name, &bytes, &mut scratch);
    let doc = eds2rust::eds::ini::parse(&name, &text, &mut scratch);
    tally.entries.compare(
        &name,
        device,
        &ours,
        &python["entries"],
        |index, entry, field, a, b| explain(&doc, device, index, entry, field, a, b),
    );
}

#[test]
fn python_canopen_agrees_with_dump() {
    let Some(files) = eds2rust_tests::corpus_files("python-canopen differential test") else {
        return;
    };
    let paths: Vec<&Path> = files.iter().map(|p| p.as_path()).collect();
    let results = run_per_file("od_dump.py", &paths, 5);
    let mut tally = Tally::default();
    for (path, python) in files.iter().zip(&results) {
        compare_file(path, python, &mut tally);
    }
    let explained: usize = tally.entries.by_rule.values().sum();
    let rate = 100.0 * (tally.entries.agreed + explained) as f64 / tally.entries.compared as f64;
    println!(
        "python-canopen 2.4.1 differential test over {} files",
        files.len()
    );
    println!(
        "  files python-canopen could not load: {}",
        tally.python_failed.len()
    );
    for f in &tally.python_failed {
        println!("    {f}");
    }
    println!("  entries compared: {}", tally.entries.compared);
    println!(
        "  agree on every field: {} ({:.2} %)",
        tally.entries.agreed,
        100.0 * tally.entries.agreed as f64 / tally.entries.compared as f64
    );
    println!("  differences explained by a python-canopen rule: {explained}");
    for (rule, reason) in RULES {
        if let Some(n) = tally.entries.by_rule.get(rule) {
            println!("    {rule:<20} {n:>5}  {reason}");
        }
    }
    println!(
        "  unexplained differences: {}",
        tally.entries.unexplained.len()
    );
    for u in &tally.entries.unexplained {
        println!("    {u}");
    }
    println!("  agreement (agree + explained): {rate:.2} %");
    assert!(
        tally.entries.compared > 10_000,
        "the corpus should give over 10 000 comparable entries, got {}",
        tally.entries.compared
    );
    assert!(
        rate >= 99.5,
        "agreement {rate:.2} % is below 99.5 %; unexplained:\n{}",
        tally.entries.unexplained.join("\n")
    );
}
