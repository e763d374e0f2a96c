//! Shared helpers of eds2rust's cross-crate tests: where the workspace, the
//! shared corpus and the python-canopen oracle are, and the python-canopen
//! peer process of the interop tests ([`peer`]).
#![forbid(unsafe_code)]

pub mod peer;
pub mod python;
pub mod recording;
pub mod seed_sim;
pub mod served;
pub mod vcan;

use std::path::{Path, PathBuf};

/// The workspace root.
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ has a parent")
        .to_path_buf()
}

/// The directory `../shared` beside the workspace, when it is there.
pub fn shared_dir() -> Option<PathBuf> {
    let dir = workspace_root().join("..").join("shared");
    dir.is_dir().then_some(dir)
}

/// Every file of `../shared/eds-corpus/files`, sorted; `None` (after printing
/// one line that names what did not run) when `../shared` is absent.
pub fn corpus_files(what: &str) -> Option<Vec<PathBuf>> {
    let Some(shared) = shared_dir() else {
        // Written to stderr directly: the test harness captures eprintln!, and this line must be seen.
        not_run(&format!(
            "{what}: ../shared/eds-corpus is not beside this checkout"
        ));
        return None;
    };
    let dir = shared.join("eds-corpus").join("files");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "{} holds no files", dir.display());
    Some(files)
}

/// `../shared/network-corpus`; `None` (after printing one line that names
/// what did not run) when it is absent.
pub fn network_corpus(what: &str) -> Option<PathBuf> {
    let Some(shared) = shared_dir() else {
        not_run(&format!(
            "{what}: ../shared/network-corpus is not beside this checkout"
        ));
        return None;
    };
    Some(shared.join("network-corpus"))
}

/// The bus file at `path` read and configured, neither with an error
/// (the test fails with the diagnostics otherwise).
pub fn configured_network(
    path: &Path,
) -> (
    eds2rust::network::model::Bus,
    eds2rust::network::config::Configured,
) {
    let loaded = eds2rust::network::read_file(path, &eds2rust::read::Options::default());
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}:\n{}",
        path.display(),
        loaded.diagnostics.render()
    );
    let bus = loaded.bus.expect("a bus");
    let (configured, diagnostics) = eds2rust::network::configure(&bus);
    assert!(
        !diagnostics.has_errors(),
        "{}:\n{}",
        path.display(),
        diagnostics.render()
    );
    (bus, configured)
}

/// The target directory cargo uses for this workspace.
pub fn target_dir() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) => PathBuf::from(dir),
        None => workspace_root().join("target"),
    }
}

/// Prints one `NOT RUN:` line that stays visible under the test harness, which
/// captures `println!`/`eprintln!` of passing tests (a direct write to stderr
/// is not captured).
pub fn not_run(what: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "NOT RUN: {what}");
}
