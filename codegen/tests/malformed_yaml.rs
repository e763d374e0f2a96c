//! Every hand-written malformed YAML object table in
//! tests/fixtures/malformed_yaml is read without a panic, gives at least one
//! error naming the file and a line, and its rendered diagnostics are locked
//! by an insta snapshot. A changed or missing snapshot fails the test.
//!
//! Each fixture has one kind of defect, said by its first line
//! (`# defect: …`); the `several_errors_*` fixtures have several different
//! semantic errors, which the reader must report all at once.

use std::path::Path;

use eds2rust::input::Options;
use eds2rust::table::read_bytes;

/// Fixtures with several different semantic errors, and the least number of
/// errors each must report (one per different defect).
const SEVERAL: &[(&str, usize)] = &[("several_errors_objects", 6), ("several_errors_device", 6)];

/// Diagnostics that name another file than the fixture: the EDS reader's
/// own report on a `base:` it cannot read names the base file and no line.
/// (The table reader adds its own `table::base` error at the `base:` line.)
const BASE_FILE: &[(&str, &str)] = &[(
    "overlay_base_missing",
    "tests/fixtures/malformed_yaml/no_such_device.eds",
)];

#[test]
fn malformed_yaml_fixtures() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/malformed_yaml");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("fixture directory")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".yaml"))
        .collect();
    names.sort();
    assert!(
        names.len() >= 20,
        "at least 20 fixtures, found {}",
        names.len()
    );
    // Relative to the package directory, where cargo runs integration tests,
    // so that a message naming a `base:` path names no absolute path.
    let base_dir = Path::new("tests/fixtures/malformed_yaml");
    assert!(
        base_dir.is_dir(),
        "integration tests run in the package directory"
    );
    for name in names {
        let bytes = std::fs::read(dir.join(&name)).expect("read fixture");
        assert!(
            bytes.starts_with(b"# defect: "),
            "{name}: the first line says the defect"
        );
        let file = format!("tests/fixtures/malformed_yaml/{name}");
        let loaded = read_bytes(&file, &bytes, base_dir, &Options::default());
        let d = &loaded.diagnostics;
        let stem = name.strip_suffix(".yaml").unwrap_or(&name);
        assert!(
            d.error_count() >= 1,
            "{name}: the defect is not reported as an error"
        );
        for diag in d.iter() {
            if BASE_FILE.contains(&(stem, diag.file.as_str())) {
                continue;
            }
            assert_eq!(diag.file, file, "{name}: every diagnostic names the file");
            assert!(
                diag.location.line.is_some(),
                "{name}: `{}` names no line",
                diag.headline()
            );
        }
        if let Some(&(_, least)) = SEVERAL.iter().find(|(s, _)| *s == stem) {
            assert!(
                d.error_count() >= least,
                "{name}: {least} different errors, {} reported",
                d.error_count()
            );
        }
        let rendered = format!(
            "{}\n{} errors, {} warnings\n",
            d.render(),
            d.error_count(),
            d.warning_count()
        );
        insta::assert_snapshot!(stem, rendered);
        // Strict mode turns every warning into an error.
        let strict = read_bytes(&file, &bytes, base_dir, &Options::strict());
        assert_eq!(
            strict.diagnostics.error_count(),
            d.len(),
            "{name}: --strict"
        );
    }
}

/// A table beyond the YAML reader's node limit, generated here (too big to
/// commit): one error in a sentence for people, not the reader's debug
/// output, at the line where the reader stopped.
#[test]
fn yaml_too_many_nodes() {
    let mut text = String::from("format: 1\nnotes:\n");
    for _ in 0..260_000 {
        text.push_str("  - x\n");
    }
    let file = "generated/yaml_too_many_nodes.yaml";
    let loaded = read_bytes(file, text.as_bytes(), Path::new("."), &Options::default());
    let d = &loaded.diagnostics;
    assert_eq!(d.error_count(), 1, "{}", d.render());
    let diag = d.iter().next().expect("one diagnostic");
    assert!(diag.location.line.is_some(), "names a line");
    assert!(!diag.message.contains("budget"), "{}", diag.message);
    insta::assert_snapshot!("yaml_too_many_nodes", d.render());
}
