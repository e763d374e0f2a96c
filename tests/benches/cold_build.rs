//! What a build script costs a user: the cold `cargo build` of a crate that
//! generates a vendor drive's object dictionary (one DCF) in its build
//! script, beside the same crate written by hand over the runtime alone.
//!
//! `cargo bench -p eds2rust-tests --bench cold_build`
//! (`COLD_BUILD_RUNS=5 COLD_BUILD_JOBS=2 cargo bench …` to choose)
//!
//! The crates, each outside the workspace with its own lock file:
//! - `generated` (tests/cold-build/generated): the build script generates
//!   the DCF with eds2rust as `cargo add --build eds2rust` adds it (no
//!   features: what one DCF needs, no YAML tables, no networks);
//! - `yaml+network`: the same crate with eds2rust's `yaml` and `network`
//!   features (`--features eds2rust-yaml-network`);
//! - `runtime-only` (tests/cold-build/runtime-only): the same PDO mapping
//!   over hand-written entries, the runtime alone.
//!
//! Each is built `--offline --locked` from scratch, in a fresh target
//! directory under `<target>/cold-build/`, `COLD_BUILD_RUNS` times (default
//! 3), in turn, with `CARGO_INCREMENTAL=0` and none of the variables cargo
//! sets for this benchmark: as a user's CI builds it, in the dev profile.
//! `COLD_BUILD_JOBS` passes `-j` to cargo (default: cargo's, one job per
//! core). Printed: the wall time and the CPU time (user + system of cargo
//! and everything it ran) of each build, the medians, the ratios to
//! runtime-only, and the critical path of the last `generated` build (from
//! `cargo build --timings`; the report is left in its target directory).
//! The crates need the registry's sources of their dependencies on disk (a
//! `cargo fetch` in each, once). Wall times on a machine busy with other
//! builds mean little, CPU times less so. Prints a `NOT RUN` line and exits
//! 0 when `../shared` (the drive's DCF) is absent.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// One cold build: seconds of wall clock and of CPU.
#[derive(Clone, Copy)]
struct Sample {
    wall: f64,
    cpu: Option<f64>,
}

/// User and system time of this process's waited-for children, in seconds
/// (Linux: /proc/self/stat; `None` elsewhere).
fn children_cpu() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) in parentheses.
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    // cutime and cstime are fields 16 and 17 of the whole line.
    let ticks: f64 = fields.get(13)?.parse::<f64>().ok()? + fields.get(14)?.parse::<f64>().ok()?;
    Some(ticks / clock_ticks()?)
}

fn clock_ticks() -> Option<f64> {
    let out = Command::new("getconf").arg("CLK_TCK").output().ok()?;
    String::from_utf8(out.stdout).ok()?.trim().parse().ok()
}

/// Builds `crate_dir` (with `args`) from scratch in `target`.
fn cold_build(crate_dir: &Path, args: &[&str], target: &Path, jobs: Option<&str>) -> Sample {
    if target.exists() {
        std::fs::remove_dir_all(target).expect("remove the previous target directory");
    }
    let mut command = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    command
        .current_dir(crate_dir)
        .args(["build", "--offline", "--locked", "--quiet", "--timings"])
        .args(args)
        .env("CARGO_TARGET_DIR", target)
        .env("CARGO_INCREMENTAL", "0")
        // What cargo sets for this benchmark is not the user's build.
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .env_remove("CARGO_BUILD_RUSTFLAGS")
        .env_remove("CARGO_MANIFEST_DIR")
        .env_remove("CARGO_PKG_NAME")
        .env_remove("CARGO_PRIMARY_PACKAGE");
    if let Some(jobs) = jobs {
        command.args(["-j", jobs]);
    }
    let cpu_before = children_cpu();
    let start = Instant::now();
    let output = command.output().expect("run cargo");
    let wall = start.elapsed().as_secs_f64();
    let cpu = children_cpu()
        .zip(cpu_before)
        .map(|(after, before)| after - before);
    assert!(
        output.status.success(),
        "cargo build failed in {}:\n{}",
        crate_dir.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    Sample { wall, cpu }
}

/// The median (the mean of the middle two of an even count).
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n.is_multiple_of(2) {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    } else {
        values[n / 2]
    }
}

/// One unit of `cargo build --timings`.
struct Unit {
    /// Its number in the report.
    id: u64,
    name: String,
    target: String,
    start: f64,
    duration: f64,
    /// When its front end was done (its metadata ready: dependents that
    /// need only that may start), from its start.
    rmeta: Option<f64>,
    /// The units that could start when it finished (it was the last of
    /// their dependencies), and when its metadata was ready.
    unblocks: Vec<u64>,
    unblocks_rmeta: Vec<u64>,
}

/// The units of the last timings report in `target`.
fn timings(target: &Path) -> Option<Vec<Unit>> {
    let html = std::fs::read_to_string(target.join("cargo-timings/cargo-timing.html")).ok()?;
    let data = html
        .split("const UNIT_DATA = ")
        .nth(1)?
        .split(";\n")
        .next()?;
    let units: serde_json::Value = serde_json::from_str(data).ok()?;
    let list = |v: &serde_json::Value| -> Vec<u64> {
        v.as_array()
            .map(|a| a.iter().filter_map(|i| i.as_u64()).collect())
            .unwrap_or_default()
    };
    // `sections`: [["frontend", {"start": …, "end": …}], ["codegen", …]].
    let frontend_end = |v: &serde_json::Value| -> Option<f64> {
        v.as_array()?
            .iter()
            .find(|s| s[0] == "frontend")
            .and_then(|s| s[1]["end"].as_f64())
    };
    units
        .as_array()?
        .iter()
        .map(|u| {
            Some(Unit {
                id: u["i"].as_u64()?,
                name: u["name"].as_str()?.to_string(),
                target: u["target"].as_str().unwrap_or("").trim().to_string(),
                start: u["start"].as_f64()?,
                duration: u["duration"].as_f64()?,
                rmeta: frontend_end(&u["sections"]),
                unblocks: list(&u["unblocked_units"]),
                unblocks_rmeta: list(&u["unblocked_rmeta_units"]),
            })
        })
        .collect()
}

/// The chain of units that ends last: from the last unit to finish, back
/// through the dependency whose completion (or metadata) let it start.
fn critical_path(units: &[Unit]) -> Vec<&Unit> {
    let end = |u: &Unit| u.start + u.duration;
    let Some(mut at) = units.iter().max_by(|a, b| end(a).total_cmp(&end(b))) else {
        return Vec::new();
    };
    let mut path = vec![at];
    // The unit that unblocked `at`, and when it did.
    while let Some((by, _)) = units
        .iter()
        .filter_map(|u| {
            if u.unblocks.contains(&at.id) {
                Some((u, end(u)))
            } else if u.unblocks_rmeta.contains(&at.id) {
                Some((u, u.start + u.rmeta.unwrap_or(u.duration)))
            } else {
                None
            }
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
    {
        if path.len() > units.len() {
            break; // a report that loops: print what there is
        }
        at = by;
        path.push(at);
    }
    path.reverse();
    path
}

fn print_critical_path(target: &Path) {
    let Some(units) = timings(target) else {
        println!("(no timings report in {})", target.display());
        return;
    };
    let path = critical_path(&units);
    println!("critical path of the last `generated` build (start + duration, s):");
    for unit in path {
        let what = if unit.target.is_empty() {
            unit.name.clone()
        } else {
            format!("{} ({})", unit.name, unit.target)
        };
        println!("  {what:48} {:6.2} + {:5.2}", unit.start, unit.duration);
    }
    let mut longest: Vec<&Unit> = units.iter().collect();
    longest.sort_by(|a, b| b.duration.total_cmp(&a.duration));
    let top: Vec<String> = longest
        .iter()
        .take(6)
        .map(|u| format!("{} {:.2}", u.name, u.duration))
        .collect();
    println!("longest units (s): {}", top.join(", "));
    println!(
        "report: {}",
        target.join("cargo-timings/cargo-timing.html").display()
    );
}

fn format_samples(samples: &[Sample]) -> String {
    samples
        .iter()
        .map(|s| match s.cpu {
            Some(cpu) => format!("{:.2} s (CPU {cpu:.2} s)", s.wall),
            None => format!("{:.2} s", s.wall),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn main() {
    if eds2rust_tests::shared_dir().is_none() {
        eds2rust_tests::not_run(
            "cold_build benchmark: ../shared/eds-corpus (the drive's DCF) is not beside this checkout",
        );
        return;
    }
    // `cargo test --benches` runs bench binaries without `--bench`: this takes minutes.
    if !std::env::args().any(|a| a == "--bench") {
        eds2rust_tests::not_run("cold_build benchmark: only under `cargo bench`");
        return;
    }
    let runs: usize = std::env::var("COLD_BUILD_RUNS")
        .ok()
        .and_then(|r| r.parse().ok())
        .filter(|&r| r > 0)
        .unwrap_or(3);
    let jobs = std::env::var("COLD_BUILD_JOBS").ok();
    let fixtures = eds2rust_tests::workspace_root().join("tests/cold-build");
    let scratch = eds2rust_tests::target_dir().join("cold-build");
    // (name, crate directory, cargo arguments); runtime-only last: the ratios' base.
    let crates: [(&str, &str, &[&str]); 3] = [
        ("generated", "generated", &[]),
        (
            "yaml+network",
            "generated",
            &["--features", "eds2rust-yaml-network"],
        ),
        ("runtime-only", "runtime-only", &[]),
    ];
    let mut samples: Vec<Vec<Sample>> = vec![Vec::new(); crates.len()];
    for run in 0..runs {
        for (i, (name, dir, args)) in crates.iter().enumerate() {
            let sample = cold_build(
                &fixtures.join(dir),
                args,
                &scratch.join(name),
                jobs.as_deref(),
            );
            println!(
                "run {}/{runs} {name:12} {:6.2} s wall{}",
                run + 1,
                sample.wall,
                sample
                    .cpu
                    .map(|c| format!(", {c:6.2} s CPU"))
                    .unwrap_or_default()
            );
            samples[i].push(sample);
        }
    }
    println!();
    let mut medians: Vec<(f64, Option<f64>)> = Vec::new();
    for ((name, _, _), samples) in crates.iter().zip(&samples) {
        let wall = median(samples.iter().map(|s| s.wall).collect());
        let cpu: Option<Vec<f64>> = samples.iter().map(|s| s.cpu).collect();
        let cpu = cpu.map(median);
        println!(
            "{name:12} cold build: median {wall:.2} s wall{} ({})",
            cpu.map(|c| format!(", {c:.2} s CPU")).unwrap_or_default(),
            format_samples(samples)
        );
        medians.push((wall, cpu));
    }
    let runtime_only = medians[crates.len() - 1];
    for ((name, _, _), (wall, cpu)) in crates.iter().zip(&medians).take(crates.len() - 1) {
        println!(
            "{name} / runtime-only: {:.2}× wall{}",
            wall / runtime_only.0,
            cpu.zip(runtime_only.1)
                .map(|(g, r)| format!(", {:.2}× CPU", g / r))
                .unwrap_or_default()
        );
    }
    println!();
    print_critical_path(&scratch.join("generated"));
}
