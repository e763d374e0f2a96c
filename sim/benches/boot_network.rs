//! The network boot benchmark: 126 simulated slaves (every node id but the
//! master's) booted by the composite master on one bus in virtual time at
//! 1 Mbit/s, where each frame takes its bit time; the boot's time on the
//! bus against the least time of the frames it needs, and the host time
//! per node (see `eds2rust_sim::boot_bench`).
//!
//! `cargo bench -p eds2rust-sim --bench boot_network [-- SLAVES]`

use std::path::PathBuf;

use eds2rust_sim::boot_bench::{Scenario, run};

fn main() {
    let slaves = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(126);
    let device = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../eds/example.eds");
    let mut failed = false;
    for heartbeat_ms in [0, 100] {
        let scenario = Scenario {
            slaves,
            bit_rate: 1_000_000,
            heartbeat_ms,
        };
        match run(&device, scenario) {
            Ok(outcome) => {
                print!("{}", outcome.summary());
                failed |= !outcome.report.booted;
            }
            Err(e) => {
                eprintln!("boot_network: {e}");
                failed = true;
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}
