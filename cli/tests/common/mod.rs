//! Helpers of the command-line tests: run the binary, find inputs.

#![allow(dead_code)] // each test file uses some of them

use std::path::{Path, PathBuf};
use std::process::Command;

pub const BIN: &str = env!("CARGO_BIN_EXE_eds2rust");

pub fn example() -> String {
    format!("{}/../eds/example.eds", env!("CARGO_MANIFEST_DIR"))
}

pub fn run(args: &[&str]) -> (i32, String, String) {
    output(Command::new(BIN).args(args))
}

/// The workspace root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Runs the binary in `dir` (paths in the output are as given): exit
/// code, stdout, stderr.
pub fn run_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    output(Command::new(BIN).args(args).current_dir(dir))
}

fn output(command: &mut Command) -> (i32, String, String) {
    let out = command.output().expect("run eds2rust");
    (
        out.status.code().expect("exit code"),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

pub fn tempdir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("eds2rust-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn seed(name: &str) -> String {
    format!("{}/../eds/{name}.yaml", env!("CARGO_MANIFEST_DIR"))
}

/// Writes `text` to `name` (a file name or a relative path) in [`tempdir`];
/// its path.
pub fn temp_file(name: &str, text: impl AsRef<[u8]>) -> String {
    let path = tempdir().join(name);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// Each command line exits 2 (a usage error) with nothing on stdout and
/// its message on stderr.
pub fn assert_usage_errors(cases: &[(Vec<&str>, &str)]) {
    for (args, says) in cases {
        let (code, out, err) = run(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}: {out}");
        assert!(err.contains(says), "{args:?}: no {says:?} in {err}");
    }
}

/// The cells of the table row (`| a | b |`) whose first cell is `first`.
pub fn row(table: &str, first: &str) -> Vec<String> {
    table
        .lines()
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect::<Vec<_>>()
        })
        .find(|cells| cells.first().is_some_and(|c| c == first))
        .unwrap_or_else(|| panic!("no row of node {first}:\n{table}"))
}
