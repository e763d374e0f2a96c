//! Every hand-written malformed EDS/DCF fixture in tests/fixtures/malformed is
//! read without a panic, gives at least one diagnostic naming the file (and a
//! line where the problem has one), and its rendered diagnostics are locked by
//! an insta snapshot. A changed or missing snapshot fails the test.

use std::path::Path;

use eds2rust::eds::{Options, read_bytes};

/// Fixtures whose defect concerns the whole file, so no line is named.
const WHOLE_FILE: &[&str] = &["empty", "comments_only", "binary_garbage"];

#[test]
fn malformed_fixtures() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/malformed");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("fixture directory")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".eds") || n.ends_with(".dcf"))
        .collect();
    names.sort();
    assert!(
        names.len() >= 30,
        "at least 30 fixtures, found {}",
        names.len()
    );
    for name in names {
        let bytes = std::fs::read(dir.join(&name)).expect("read fixture");
        let file = format!("tests/fixtures/malformed/{name}");
        let loaded = read_bytes(&file, &bytes, &Options::default());
        let d = &loaded.diagnostics;
        assert!(!d.is_empty(), "{name}: the defect is not reported");
        let stem = name.rsplit_once('.').map_or(name.as_str(), |(s, _)| s);
        for diag in d.iter() {
            assert_eq!(diag.file, file, "{name}: every diagnostic names the file");
            if !WHOLE_FILE.contains(&stem) {
                assert!(
                    diag.location.line.is_some(),
                    "{name}: `{}` names no line",
                    diag.headline()
                );
            }
        }
        let rendered = format!(
            "{}\n{} errors, {} warnings\n",
            d.render(),
            d.error_count(),
            d.warning_count()
        );
        insta::assert_snapshot!(stem, rendered);
        // Strict mode turns every warning into an error.
        let strict = read_bytes(&file, &bytes, &Options::strict());
        assert_eq!(
            strict.diagnostics.error_count(),
            d.len(),
            "{name}: --strict"
        );
    }
}
