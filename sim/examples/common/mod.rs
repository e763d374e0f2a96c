//! What the seed examples (and the demo and machine examples that run
//! them) share: their `main` (the command line of
//! [`eds2rust_sim::harness::Args`], the exit codes), the run of a scenario
//! with the blocking master on the harness's bus, and, for their tests, a
//! run on the virtual bus and the decoding of the recorded trace with the
//! seed table ([`decoded`]).
//!
//! Each example includes this module (`#[path = "common/mod.rs"]`) and
//! uses only a part of it.

#![allow(dead_code)]

use std::error::Error;
use std::io::Write;
use std::process::ExitCode;

use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::{blocking, master};
use eds2rust_sim::harness::{Args, Harness, MasterPort};

/// Decoding the recorded trace with the seed table (the tests).
#[cfg(test)]
pub mod decoded;

/// What a scenario returns.
pub type Res<T> = Result<T, Box<dyn Error>>;

/// The blocking master on the harness's bus.
pub type Master = blocking::Master<MasterPort>;

/// Node id `id`, or an error naming it.
pub fn node(id: u8) -> Res<NodeId> {
    NodeId::new(id).ok_or_else(|| format!("{id} is not a node id").into())
}

/// An example's `main`: the arguments (a bad command line prints the
/// usage, exit code 2), then `run` printing to stdout (a failure prints
/// `name: error`, exit code 1).
pub fn main<T>(name: &str, run: impl FnOnce(&Args, &mut dyn Write) -> Res<T>) -> ExitCode {
    let args = match Args::from_env() {
        Ok(args) => args,
        Err(e) => {
            eprintln!("{name}: {e}");
            return ExitCode::from(2);
        }
    };
    match run(&args, &mut std::io::stdout()) {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{name}: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Runs `scenario` with the master `core` on the harness's bus, then
/// stops the harness: what the scenario returned and the trace of every
/// frame (candump's compact form).
pub fn run_master<T>(
    mut harness: Harness,
    core: master::Master,
    scenario: impl FnOnce(&mut Master) -> Res<T>,
) -> Res<(T, Vec<String>)> {
    let mut m = Master::with_clock(harness.take_port()?, core, harness.clock());
    let result = scenario(&mut m);
    drop(m);
    let trace = harness.stop()?;
    Ok((result?, trace))
}

/// Runs `run` on the virtual bus with the mechanics `time_scale` times
/// faster than real time: what it returned and what it printed. A failure
/// panics with the output so far.
#[cfg(test)]
pub fn run_at<T>(
    time_scale: f64,
    run: impl FnOnce(&Args, &mut dyn Write) -> Res<T>,
) -> (T, String) {
    let args = Args {
        time_scale,
        ..Args::default()
    };
    let mut out = Vec::new();
    let summary =
        run(&args, &mut out).unwrap_or_else(|e| panic!("{e}\n{}", String::from_utf8_lossy(&out)));
    (summary, String::from_utf8(out).expect("utf-8"))
}
