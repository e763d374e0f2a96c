//! The three seed devices working end to end, one after the other, each
//! through its generated driver and the runtime's master against its
//! simulator (or real devices with `--iface NAME`):
//!
//! 1. Zimmer ACS: the manual's enable sequence and a profile-position move.
//! 2. LINAK TECHLINE: the manual's start-up sequence, out to the end stop and
//!    back.
//! 3. Interroll EC5000 BI: LSS assigns node id 5 (and stores it), then
//!    velocity mode runs and halts.
//!
//! `cargo run --example demo [-- --trace] [--time-scale F]`; the scenarios
//! are the examples `zimmer_acs`, `linak_techline` and
//! `interroll_ec5000bi`, included here as modules.

use std::io::Write;
use std::process::ExitCode;

use eds2rust_sim::harness::Args;

#[allow(clippy::duplicate_mod, reason = "the demo includes the three examples")]
#[path = "common/mod.rs"]
mod common;

#[allow(dead_code)]
#[path = "zimmer_acs.rs"]
mod zimmer_acs;

#[allow(dead_code)]
#[path = "linak_techline.rs"]
mod linak_techline;

#[allow(dead_code)]
#[path = "interroll_ec5000bi.rs"]
mod interroll_ec5000bi;

/// Runs the three scenarios in order; stops at the first failure.
fn run_all(args: &Args, out: &mut dyn Write) -> common::Res<()> {
    writeln!(out, "== Zimmer ACS40/60 compact axis ==")?;
    zimmer_acs::run(args, out)?;
    writeln!(out, "\n== LINAK TECHLINE actuator ==")?;
    linak_techline::run(args, out)?;
    writeln!(out, "\n== Interroll RollerDrive EC5000 BI ==")?;
    interroll_ec5000bi::run(args, out)?;
    writeln!(out, "\nAll three devices worked end to end.")?;
    Ok(())
}

fn main() -> ExitCode {
    common::main("demo", run_all)
}

#[cfg(test)]
mod demo_tests {
    use super::*;

    /// The README's main command, on the virtual bus with fast mechanics.
    #[test]
    fn the_demo_runs_all_three_devices() {
        let ((), text) = common::run_at(20.0, run_all);
        assert!(
            text.ends_with("All three devices worked end to end.\n"),
            "{text}"
        );
    }
}
