//! The protocol cores build without `std`: the crate is checked with no
//! default features (cores without SDO buffers) and with `alloc` alone (the
//! SDO client and server too), in a target directory of its own.

use std::path::Path;
use std::process::Command;

fn check(features: &[&str]) {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/no-std-check");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut command = Command::new(cargo);
    command
        .args([
            "check",
            "--quiet",
            "--lib",
            "--no-default-features",
            "--manifest-path",
        ])
        .arg(&manifest)
        .arg("--target-dir")
        .arg(&target)
        .env("RUSTFLAGS", "-D warnings");
    if !features.is_empty() {
        command.args(["--features", &features.join(",")]);
    }
    let output = command.output().expect("cannot run cargo");
    assert!(
        output.status.success(),
        "cargo check --no-default-features {features:?} failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

#[test]
fn cores_build_without_std() {
    check(&[]);
    check(&["alloc"]);
}
