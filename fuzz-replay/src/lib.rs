//! Replays the committed fuzz corpora (`<crate>/fuzz/corpus/<target>/`, the
//! minimized output of the cargo-fuzz campaign) through the bodies of the
//! fuzz targets on the stable toolchain, without a fuzzer. A missing or
//! empty corpus directory fails the test. See docs/fuzzing.md.
//!
//! Dev-only (the `fuzz_replay` tests of the code generator and the
//! runtime): one `#[test]` per target, written with [`replay_tests!`].

use std::path::{Path, PathBuf};

/// Every file of the corpus of `target` under `crate_dir/fuzz/corpus`,
/// sorted by name; panics when the directory is missing or empty.
pub fn corpus(crate_dir: &Path, target: &str) -> Vec<PathBuf> {
    let dir = crate_dir.join("fuzz/corpus").join(target);
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

/// Runs `body` on every corpus file of `target` (see [`corpus`]); fails
/// naming each file whose run panicked.
pub fn replay(crate_dir: &Path, target: &str, body: fn(&[u8])) {
    let mut failed = Vec::new();
    let files = corpus(crate_dir, target);
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

/// One `#[test]` per fuzz target: `name => body` replays the corpus
/// `fuzz/corpus/<name>` of the calling crate through `body` in a test
/// named `<name>_corpus`.
///
/// ```text
/// eds2rust_fuzz_replay::replay_tests! {
///     sdo_request_corpus: "sdo_request" => fuzz_checks::sdo_request,
/// }
/// ```
#[macro_export]
macro_rules! replay_tests {
    ($($test:ident: $target:literal => $body:path),* $(,)?) => {
        $(
            #[test]
            fn $test() {
                $crate::replay(
                    ::std::path::Path::new(env!("CARGO_MANIFEST_DIR")),
                    $target,
                    $body,
                );
            }
        )*
    };
}
