//! The boot benchmark's harness with a few slaves (`benches/boot_network.rs`
//! runs 126): the network boots on the timed bus, every slave is
//! operational, and the figures are consistent. Not a check of the timing.

use std::path::PathBuf;

use eds2rust_runtime::boot::SlaveState;
use eds2rust_sim::boot_bench::{Scenario, run};

fn device() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../eds/example.eds")
}

#[test]
fn a_few_slaves_boot_on_the_timed_bus() {
    for heartbeat_ms in [0, 100] {
        let scenario = Scenario::new(4, heartbeat_ms);
        let outcome = run(&device(), scenario).unwrap_or_else(|e| panic!("{e}"));
        let summary = outcome.summary();
        assert!(outcome.report.booted, "{summary}\n{:#?}", outcome.report);
        assert_eq!(outcome.report.slaves.len(), 4);
        for slave in &outcome.report.slaves {
            assert_eq!(slave.state, SlaveState::Operational, "{slave:#?}");
            assert!(slave.identity_checked, "{slave:#?}");
        }
        // Per slave at least: reset, boot-up, 0x1000 read and answer,
        // start.
        assert!(outcome.needed_frames >= 4 * 5, "{summary}");
        assert!(outcome.boot_time >= outcome.needed_time, "{summary}");
        assert!(outcome.ratio() >= 1.0, "{summary}");
        for line in [
            "boot time on the bus",
            "least time",
            "ratio",
            "host time per node",
        ] {
            assert!(summary.contains(line), "{summary}");
        }
    }
}

#[test]
fn too_many_slaves_are_refused() {
    let scenario = Scenario::new(127, 0);
    let e = run(&device(), scenario).expect_err("127 slaves do not fit");
    assert!(e.contains("1 to 126"), "{e}");
}
