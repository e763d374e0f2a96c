//! Replays the committed fuzz corpora (codegen/fuzz/corpus/<target>/, the
//! minimized output of the cargo-fuzz campaign) through the bodies of the
//! fuzz targets on the stable toolchain, without a fuzzer. A missing or empty
//! corpus directory fails the test. See docs/fuzzing.md.

mod fuzz_checks;

use std::path::{Path, PathBuf};

/// Every file of the target's corpus, sorted by name.
fn corpus(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let entries = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("corpus directory {}: {e}", dir.display()));
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    assert!(
        !files.is_empty(),
        "corpus directory {} has no files",
        dir.display()
    );
    files
}

/// Runs `body` on every corpus file of `target`; fails naming each file
/// whose run panicked.
fn replay(target: &str, body: fn(&[u8])) {
    let mut failed = Vec::new();
    let files = corpus(target);
    for path in &files {
        let data = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        if std::panic::catch_unwind(|| body(&data)).is_err() {
            failed.push(path.display().to_string());
        }
    }
    assert!(
        failed.is_empty(),
        "{} of {} {target} corpus files panicked:\n{}",
        failed.len(),
        files.len(),
        failed.join("\n")
    );
}

#[test]
fn eds_reader_corpus() {
    replay("eds_reader", fuzz_checks::eds_reader);
}

#[test]
fn yaml_reader_corpus() {
    replay("yaml_reader", fuzz_checks::yaml_reader);
}

#[test]
fn bus_reader_corpus() {
    replay("bus_reader", fuzz_checks::bus_reader);
}
