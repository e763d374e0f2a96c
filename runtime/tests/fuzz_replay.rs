//! Replays the committed fuzz corpora (runtime/fuzz/corpus/<target>/, the
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
fn sdo_request_corpus() {
    replay("sdo_request", fuzz_checks::sdo_request);
}

#[test]
fn sdo_response_corpus() {
    replay("sdo_response", fuzz_checks::sdo_response);
}

#[test]
fn block_segment_corpus() {
    replay("block_segment", fuzz_checks::block_segment);
}

#[test]
fn sdo_server_corpus() {
    replay("sdo_server", fuzz_checks::sdo_server);
}

#[test]
fn sdo_client_corpus() {
    replay("sdo_client", fuzz_checks::sdo_client);
}

#[test]
fn nmt_and_error_control_corpus() {
    replay("nmt_and_error_control", fuzz_checks::nmt_and_error_control);
}

#[test]
fn emcy_and_sync_corpus() {
    replay("emcy_and_sync", fuzz_checks::emcy_and_sync);
}

#[test]
fn lss_frames_corpus() {
    replay("lss_frames", fuzz_checks::lss_frames);
}

#[test]
fn pdo_receiver_corpus() {
    replay("pdo_receiver", fuzz_checks::pdo_receiver);
}

#[test]
fn candump_line_corpus() {
    replay("candump_line", fuzz_checks::candump_line);
}
