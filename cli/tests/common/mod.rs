//! Helpers of the command-line tests: run the binary, find inputs.

#![allow(dead_code)] // each test file uses some of them

use std::process::Command;

pub const BIN: &str = env!("CARGO_BIN_EXE_eds2rust");

pub fn example() -> String {
    format!("{}/../eds/example.eds", env!("CARGO_MANIFEST_DIR"))
}

pub fn run(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(BIN).args(args).output().expect("run eds2rust");
    (
        out.status.code().expect("exit code"),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

pub fn tempdir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("eds2rust-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn seed(name: &str) -> String {
    format!("{}/../eds/{name}.yaml", env!("CARGO_MANIFEST_DIR"))
}
