//! What the tests of the two network examples check (`network_blocking`,
//! `network_tokio`). docs/network.md shows each example up to its tests
//! as a complete program, so the programs stay whole; their tests share
//! this.

use std::path::{Path, PathBuf};

use eds2rust_runtime::boot::{NetworkReport, SlaveState};

/// docs/network.md shows the program `name` (its `source` up to the
/// tests) verbatim.
pub fn assert_docs_show(name: &str, source: &str) {
    let docs = include_str!("../../../docs/network.md");
    let program = source.split("#[cfg(test)]").next().unwrap().trim_end();
    assert!(
        docs.contains(program),
        "docs/network.md does not show {name}"
    );
}

/// The seed machine's bus file (eds/machine/bus.yml).
pub fn seed_machine() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../eds/machine/bus.yml")
}

/// The three slaves of the seed machine booted: each operational, its
/// identity checked.
pub fn assert_booted(report: &NetworkReport) {
    assert!(report.booted, "{report:?}");
    assert_eq!(report.slaves.len(), 3);
    for slave in &report.slaves {
        assert_eq!(slave.state, SlaveState::Operational, "{slave:?}");
        assert!(slave.identity_checked, "{slave:?}");
    }
}
