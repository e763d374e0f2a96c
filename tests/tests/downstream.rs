//! The crates under downstream/ are built and tested the way a user builds
//! them: outside this workspace, with path dependencies on its crates and
//! their own lock files (`--locked`), in a target directory of their own
//! (`target/downstream`, shared by them).
//!
//! - downstream/sim-device: the generic simulator of a device of its own,
//!   with no SocketCAN, tokio or seed drivers in its dependency graph;
//! - downstream/vendor-drive: a vendor DCF of ../shared/eds-corpus with an
//!   overlay and rule levels (not run without ../shared: it reads the DCF);
//! - downstream/api-lock: the listing of a generated API locked with insta;
//! - downstream/firmware-update: a CiA 302-3 program update, a 1 MiB image
//!   streamed by block download to the corpus bootloader slave, simulated
//!   (not run without ../shared: it reads the DCF);
//! - downstream/machine: the three seed devices as one machine, the typed
//!   network of eds/machine/bus.yml generated in its build script, booted
//!   from its generated plan against simulated devices, its process image
//!   run on the virtual bus.

use std::path::Path;
use std::process::Command;

use eds2rust_tests::{not_run, shared_dir, target_dir, workspace_root};

/// Runs `cargo <args>` in the downstream crate `name`, failing with its
/// output when it fails.
fn cargo(name: &str, args: &[&str]) -> String {
    cargo_env(name, args, &[])
}

/// [`cargo`] with variables set for it.
fn cargo_env(name: &str, args: &[&str], envs: &[(&str, &str)]) -> String {
    let dir = workspace_root().join("downstream").join(name);
    let target = target_dir().join("downstream");
    let out = Command::new(env!("CARGO"))
        .args(args)
        .envs(envs.iter().copied())
        .arg("--locked")
        .current_dir(&dir)
        .env("CARGO_TARGET_DIR", &target)
        // A build from scratch as a user's CI does it: no incremental caches
        // and line tables only, or the four crates take 2 GB of disk.
        .env("CARGO_INCREMENTAL", "0")
        .env("CARGO_PROFILE_DEV_DEBUG", "line-tables-only")
        // The variables cargo sets for this test must not leak into the
        // user's build.
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .env_remove("CARGO_MANIFEST_DIR")
        .env_remove("CARGO_PKG_NAME")
        .output()
        .unwrap_or_else(|e| panic!("cannot run cargo in {}: {e}", dir.display()));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "`cargo {}` in {} failed:\n{stdout}\n{stderr}",
        args.join(" "),
        dir.display()
    );
    stdout + &stderr
}

/// Its own tests include the check of its dependency graph
/// (downstream/sim-device/tests/lean_build.rs).
#[test]
fn sim_device_builds_and_runs_with_a_lean_graph() {
    let dir = workspace_root().join("downstream/sim-device");
    assert!(dir.join("Cargo.lock").is_file(), "a lock file of its own");
    let output = cargo("sim-device", &["test"]);
    assert!(output.contains("test result: ok"), "{output}");
    assert!(!output.contains("test result: FAILED"), "{output}");
}

#[test]
fn firmware_update_streams_a_program_to_the_corpus_bootloader() {
    if shared_dir().is_none() {
        not_run("downstream/firmware-update: ../shared/eds-corpus is not beside this checkout");
        return;
    }
    assert!(Path::new(&workspace_root().join("downstream/firmware-update/Cargo.lock")).is_file());
    let output = cargo("firmware-update", &["test"]);
    assert!(
        output.contains("a_mebibyte_program_is_streamed_confirmed_and_started ... ok")
            || output.contains("test result: ok. 1 passed"),
        "{output}"
    );
    assert!(!output.contains("test result: FAILED"), "{output}");
}

#[test]
fn vendor_drive_builds_from_its_dcf_without_warnings() {
    if shared_dir().is_none() {
        not_run("downstream/vendor-drive: ../shared/eds-corpus is not beside this checkout");
        return;
    }
    assert!(Path::new(&workspace_root().join("downstream/vendor-drive/Cargo.lock")).is_file());
    let output = cargo("vendor-drive", &["test"]);
    assert!(output.contains("test result: ok"), "{output}");
    assert!(
        !output.contains("warning: vendor-drive"),
        "the overlay fixes and allows what the DCF warns about:\n{output}"
    );
    // The build dependency stays light: no command-line parser, one syn.
    let build = cargo(
        "vendor-drive",
        &["tree", "-e", "normal,build", "--prefix", "none"],
    );
    for cli in [
        "clap ",
        "clap_builder ",
        "clap_lex ",
        "anstream ",
        "colorchoice ",
    ] {
        assert!(
            !build.lines().any(|l| l.starts_with(cli)),
            "{cli}in:\n{build}"
        );
    }
    let mut syn: Vec<&str> = build
        .lines()
        .filter(|l| l.starts_with("syn v"))
        .map(|l| l.split('.').next().unwrap_or(l))
        .collect();
    syn.sort();
    syn.dedup();
    assert_eq!(syn.len(), 1, "one syn major: {syn:?}");
    let library = cargo(
        "vendor-drive",
        &[
            "tree",
            "-p",
            "eds2rust",
            "-e",
            "normal,build",
            "--prefix",
            "depth",
        ],
    );
    // What `[build-dependencies] eds2rust` compiles, itself not counted,
    // nor the runtime with what it needs there (a network's boot plan is
    // the runtime's plain data): the generated code depends on the runtime,
    // so every user's crate compiles it anyway.
    let mut crates: Vec<&str> = Vec::new();
    let mut runtime_depth = None;
    for line in library.lines().filter(|l| l.contains(" v")) {
        let depth_len = line.chars().take_while(char::is_ascii_digit).count();
        let depth: usize = line[..depth_len].parse().unwrap_or(0);
        let name = line[depth_len..].split(" (").next().unwrap_or(line);
        if runtime_depth.is_some_and(|d| depth > d) {
            continue;
        }
        runtime_depth = None;
        if name.starts_with("eds2rust-runtime v") {
            runtime_depth = Some(depth);
        } else if !name.starts_with("eds2rust v") {
            crates.push(name);
        }
    }
    crates.sort();
    crates.dedup();
    assert!(crates.len() <= 32, "{} crates: {crates:?}", crates.len());
}

/// Its snapshot test locks the listing of the generated API of the LINAK
/// table (downstream/api-lock/tests/api.rs). With `CI` set, insta fails on a
/// mismatch and writes nothing, whatever `INSTA_UPDATE` the caller has.
#[test]
fn api_lock_matches_its_committed_snapshot() {
    let dir = workspace_root().join("downstream/api-lock");
    assert!(dir.join("Cargo.lock").is_file(), "a lock file of its own");
    let snapshots = dir.join("tests/snapshots");
    assert!(snapshots.join("api__linak_api.snap").is_file());
    let output = cargo_env(
        "api-lock",
        &["test"],
        &[
            ("CI", "true"),
            ("INSTA_UPDATE", "no"),
            ("INSTA_FORCE_PASS", "0"),
            ("INSTA_FORCE_UPDATE", "0"),
        ],
    );
    assert!(
        output.contains("test the_generated_api_is_locked ... ok"),
        "{output}"
    );
    assert!(!output.contains("test result: FAILED"), "{output}");
    let pending: Vec<_> = std::fs::read_dir(&snapshots)
        .expect("snapshots directory")
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "new"))
        .collect();
    assert!(pending.is_empty(), "{pending:?}");
}

/// The typed network of the seed machine builds (strict: the bus file gives
/// no warning), its plan is `boot_plan` of the bus file, the master boots
/// the network from it and its process image works on the virtual bus.
#[test]
fn machine_generates_its_network_and_runs_its_process_image() {
    let dir = workspace_root().join("downstream/machine");
    assert!(dir.join("Cargo.lock").is_file(), "a lock file of its own");
    let output = cargo("machine", &["test"]);
    for test in [
        "one_sync_cycle_on_the_virtual_bus",
        "the_plan_is_boot_plan_of_the_bus_file",
        "the_machine_boots_from_its_plan_and_exchanges_its_process_image",
    ] {
        assert!(
            output.contains(&format!("{test} ... ok")),
            "{test}\n{output}"
        );
    }
    assert!(!output.contains("test result: FAILED"), "{output}");
}
