//! The network diff and the network API listing on the fixture pair
//! tests/networks/diff/{old,new}/bus.yml: every wiring change the new side
//! makes is found with its severity (snapshots of the text, JSON and
//! Markdown), a network against itself has no changes, and the listing of
//! each side is locked.

use std::collections::BTreeSet;
use std::path::PathBuf;

use eds2rust::diff::Severity;
use eds2rust::input::Options;
use eds2rust::network::config::Configured;
use eds2rust::network::diff::{self, NetChange, NetKind, Network, render};
use eds2rust::network::model::Bus;

fn fixture(side: &str) -> PathBuf {
    eds2rust_tests::workspace_root()
        .join("tests/networks/diff")
        .join(side)
        .join("bus.yml")
}

/// Reads and configures one side; no errors, no warnings.
fn load(side: &str) -> (Bus, Configured) {
    load_path(&fixture(side), side, false)
}

/// Reads and configures a bus file; no errors (and, unless
/// `warnings_allowed`, no warnings of the configuration).
fn load_path(path: &std::path::Path, side: &str, warnings_allowed: bool) -> (Bus, Configured) {
    assert!(eds2rust::network::is_bus_file(path), "{side}: a bus file");
    let loaded = eds2rust::network::read_file(path, &Options::default());
    let bus = loaded
        .bus
        .unwrap_or_else(|| panic!("{side}: {}", loaded.diagnostics.render()));
    assert!(
        !loaded.diagnostics.has_errors(),
        "{side}: {}",
        loaded.diagnostics.render()
    );
    let (configured, diagnostics) = eds2rust::network::configure(&bus);
    assert!(
        diagnostics.error_count() == 0 && (warnings_allowed || diagnostics.warning_count() == 0),
        "{side}: {}",
        diagnostics.render()
    );
    (bus, configured)
}

fn network((bus, configured): &(Bus, Configured)) -> Network<'_> {
    Network { bus, configured }
}

fn changes(old: &(Bus, Configured), new: &(Bus, Configured)) -> Vec<NetChange> {
    diff::diff(network(old), network(new), &Default::default())
}

#[test]
fn a_network_against_itself_has_no_changes() {
    for side in ["old", "new"] {
        let n = load(side);
        assert_eq!(changes(&n, &n), Vec::new(), "{side}");
    }
}

/// The corpus networks (../shared/network-corpus) against themselves: no
/// changes; their API listings list every node and its PDOs.
#[test]
fn corpus_networks_against_themselves() {
    let Some(corpus) = eds2rust_tests::network_corpus("network diff of the corpus networks") else {
        return;
    };
    for name in ["prbt_pilz6", "trinamic_pd42"] {
        let path = corpus.join(name).join("bus.yml");
        let n = load_path(&path, name, true);
        assert_eq!(changes(&n, &n), Vec::new(), "{name}");
        let listing = eds2rust::network::api::api_listing(&n.0, &n.1, &Default::default())
            .unwrap_or_else(|d| panic!("{name}: {}", d.render()));
        for node in &n.1.nodes {
            let line = format!("\n{}\tnode\tid={}\t", node.name, node.node_id);
            assert!(listing.text.contains(&line), "{name}: {line:?}");
            let pdos = listing
                .text
                .lines()
                .filter(|l| l.starts_with(&format!("{}\ttpdo ", node.name)))
                .count();
            assert_eq!(pdos, node.tpdos.len(), "{name}: {}", node.name);
        }
    }
}

#[test]
fn every_wiring_change_of_the_fixture_is_found() {
    let (old, new) = (load("old"), load("new"));
    let changes = changes(&old, &new);
    let found: BTreeSet<(String, &str, Severity)> = changes
        .iter()
        .map(|c| (c.node.clone(), c.kind.as_str(), c.severity))
        .collect();
    let expected = [
        ("master", "sync-period-changed", Severity::Compatible),
        ("master", "setting-changed", Severity::Compatible),
        ("axis", "heartbeat-producer-changed", Severity::Compatible),
        ("axis", "pdo-cob-id-moved", Severity::Breaking),
        ("axis", "pdo-remapped", Severity::Breaking),
        ("axis", "pdo-event-timer-changed", Severity::Compatible),
        ("axis", "pdo-disabled", Severity::Breaking),
        ("axis", "sdo-write-changed", Severity::Compatible),
        ("axis", "sdo-write-added", Severity::Compatible),
        ("axis", "sdo-write-removed", Severity::Compatible),
        ("lift", "node-id-changed", Severity::Breaking),
        ("lift", "node-device-file-changed", Severity::Compatible),
        ("lift", "heartbeat-consumer-changed", Severity::Additive),
        ("lift", "pdo-enabled", Severity::Additive),
        ("lift", "pdo-transmission-changed", Severity::Compatible),
        ("lift", "object-added", Severity::Additive),
        ("gripper", "node-added", Severity::Additive),
        ("io", "node-removed", Severity::Breaking),
        ("sensor", "node-identity-changed", Severity::Breaking),
        ("sensor", "setting-changed", Severity::Compatible),
    ];
    for (node, kind, severity) in expected {
        assert!(
            found.contains(&(node.to_string(), kind, severity)),
            "{node} {kind} {severity:?} not found in\n{}",
            render::text(&changes)
        );
    }
    // Device changes come from the device diff, tagged with their node.
    assert!(
        changes
            .iter()
            .any(|c| matches!(c.kind, NetKind::Device(_)) && c.rust_path.is_some())
    );
    insta::assert_snapshot!("network_diff_text", render::text(&changes));
    docs_block_is(&render::text(&changes));
    insta::assert_snapshot!(
        "network_diff_json",
        render::json("old/bus.yml", "new/bus.yml", &changes)
    );
    insta::assert_snapshot!(
        "network_diff_markdown",
        render::markdown("old/bus.yml", "new/bus.yml", &changes)
    );
}

#[test]
fn the_api_listing_of_each_side() {
    for side in ["old", "new"] {
        let (bus, configured) = load(side);
        let listing = eds2rust::network::api::api_listing(&bus, &configured, &Default::default())
            .unwrap_or_else(|d| panic!("{side}: {}", d.render()));
        insta::assert_snapshot!(format!("network_api_{side}"), listing.text);
    }
}

/// The block after `<!-- output: network-diff-text -->` in docs/network.md
/// is `text`; `UPDATE_DOCS=1` rewrites it instead.
fn docs_block_is(text: &str) {
    let path = eds2rust_tests::workspace_root().join("docs/network.md");
    let doc = std::fs::read_to_string(&path).expect("docs/network.md");
    let marker = "<!-- output: network-diff-text -->\n```text\n";
    let start = doc.find(marker).expect("the marker in docs/network.md") + marker.len();
    let end = start + doc[start..].find("```\n").expect("the block's end");
    if std::env::var_os("UPDATE_DOCS").is_some() {
        let updated = format!("{}{text}{}", &doc[..start], &doc[end..]);
        std::fs::write(&path, updated).unwrap();
        return;
    }
    assert_eq!(
        &doc[start..end],
        text,
        "docs/network.md does not show the real output; run with UPDATE_DOCS=1 and review"
    );
}
