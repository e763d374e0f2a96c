//! This crate builds the simulator with eds2rust-sim's default features:
//! no SocketCAN, no tokio, no seed-device drivers.

use std::process::Command;

use eds2rust_sim::harness::{Args, Harness};

/// What the default features of eds2rust-sim must not bring in.
const NOT_WANTED: [&str; 6] = [
    "socketcan",
    "tokio",
    "nix",
    "mio",
    "futures",
    "eds2rust-drivers",
];

#[test]
fn the_dependency_tree_has_no_socketcan_tokio_or_drivers() {
    let output = Command::new(env!("CARGO"))
        .args([
            "tree",
            "--locked",
            "--target",
            "all",
            "-e",
            "normal,build",
            "--prefix",
            "none",
        ])
        .arg("--manifest-path")
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml"))
        .output()
        .expect("cargo tree runs");
    let tree = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let found: Vec<&str> = tree
        .lines()
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| NOT_WANTED.contains(name))
        .collect();
    assert!(
        found.is_empty(),
        "unwanted dependencies {found:?} in\n{tree}"
    );
    assert!(
        tree.lines().any(|l| l.starts_with("eds2rust-sim ")),
        "{tree}"
    );
}

#[test]
fn an_interface_needs_the_socketcan_feature() {
    let args = Args {
        iface: Some("vcan0".into()),
        ..Args::default()
    };
    let node = eds2rust_runtime::od::NodeId::new(12).expect("node id");
    let error = Harness::start(&args, |now| sim_device::simulator(node, now))
        .expect_err("no SocketCAN without the feature");
    assert_eq!(error.kind(), std::io::ErrorKind::Unsupported);
    assert!(error.to_string().contains("feature `socketcan`"), "{error}");
}
