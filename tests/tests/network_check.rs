//! `net check` on bus files read from disk:
//! - every fixture under tests/networks/check/<rule>/bus.yml reports its
//!   rule (`net::<rule>`), and the rendered diagnostics of each are locked
//!   by an insta snapshot (paths relative to the repository);
//! - the corpus networks of ../shared/network-corpus check with no error
//!   (warnings are printed, not failures).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use eds2rust::input::Options;
use eds2rust::network::check::{CheckLimits, bus_load, check};
use eds2rust::network::{configure, read_file};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the tests crate is in the workspace")
        .to_path_buf()
}

/// Reads, configures and checks `bus`: the rendered diagnostics (with the
/// bus load report when the file reads), the error count, the warnings.
fn run(bus: &Path) -> (String, usize, usize) {
    let loaded = read_file(bus, &Options::default());
    let mut diagnostics = loaded.diagnostics;
    let mut load = String::new();
    if let Some(bus) = &loaded.bus {
        let (configured, found) = configure(bus);
        diagnostics.extend(found);
        diagnostics.extend(check(bus, &configured, &CheckLimits::default()));
        load = bus_load(bus, &configured).to_string();
    }
    diagnostics.span_lines();
    let text = format!("{}{load}", diagnostics.render());
    (text, diagnostics.error_count(), diagnostics.warning_count())
}

/// `text` without the repository's absolute path.
fn relative(text: &str) -> String {
    let root = format!("{}/", repo().display());
    text.replace(&root, "")
}

#[test]
fn every_fixture_reports_its_rule() {
    let dir = repo().join("tests/networks/check");
    let mut fixtures: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/networks/check")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.join("bus.yml").is_file())
        .collect();
    fixtures.sort();
    assert!(fixtures.len() >= 15, "{fixtures:?}");
    let mut changed = Vec::new();
    for fixture in &fixtures {
        let rule = fixture.file_name().unwrap().to_string_lossy().to_string();
        let (text, _, _) = run(&fixture.join("bus.yml"));
        let text = relative(&text);
        assert!(
            text.contains(&format!("[net::{rule}]")),
            "{rule}: the fixture does not report net::{rule}:\n{text}"
        );
        assert!(!text.contains(&repo().display().to_string()), "{text}");
        let name = rule.replace('-', "_");
        let checked = catch_unwind(AssertUnwindSafe(|| {
            insta::with_settings!({ omit_expression => true }, {
                insta::assert_snapshot!(name.as_str(), text.as_str());
            });
        }));
        if checked.is_err() {
            changed.push(rule);
        }
    }
    assert!(changed.is_empty(), "changed snapshots: {changed:?}");
}

#[test]
fn the_corpus_networks_check_without_errors() {
    let Some(dir) = eds2rust_tests::network_corpus("network check of the corpus") else {
        return;
    };
    let mut networks: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| e.expect("entry").path())
        .filter(|p| p.join("bus.yml").is_file())
        .collect();
    networks.sort();
    assert!(!networks.is_empty(), "{} holds no networks", dir.display());
    let mut failures = Vec::new();
    for network in &networks {
        let (text, errors, warnings) = run(&network.join("bus.yml"));
        println!(
            "{}: {errors} errors, {warnings} warnings\n{text}",
            network.display()
        );
        if errors > 0 {
            failures.push(format!("{}:\n{text}", network.display()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
