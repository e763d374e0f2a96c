//! `eds2rust diff` and `eds2rust api` on bus files (docs/network.md,
//! Reviewing a network change), on the fixture pair tests/networks/diff.

mod common;

use common::{example, run, temp_file};
use serde_json::Value;

fn bus(side: &str) -> String {
    format!(
        "{}/../tests/networks/diff/{side}/bus.yml",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn diff_of_two_bus_files_in_every_format_and_level() {
    let (old, new) = (bus("old"), bus("new"));
    let (code, text, stderr) = run(&["diff", &old, &new]);
    assert_eq!(code, 1, "breaking changes fail by default: {text}{stderr}");
    assert!(
        text.contains("breaking   axis    TPDO1          pdo-remapped: TPDO1 remapped:"),
        "{text}"
    );
    assert!(
        text.contains(" lift    0x2001         object-added `od::"),
        "{text}"
    );
    let summary = text.lines().last().unwrap();
    assert!(summary.contains(" breaking, "), "{summary}");
    // The same as the library's rendering is checked by the snapshot
    // tests; here the levels and formats.
    for (level, expected) in [("breaking", 1), ("additive", 1), ("any", 1), ("never", 0)] {
        assert_eq!(
            run(&["diff", "--fail-on", level, &old, &new]).0,
            expected,
            "{level}"
        );
    }
    let (code, same, _) = run(&["diff", "--fail-on", "any", &old, &old]);
    assert_eq!(
        (code, same.as_str()),
        (0, "0 changes: 0 breaking, 0 additive, 0 compatible\n")
    );

    let (code, json, _) = run(&["diff", "--format", "json", &old, &new]);
    assert_eq!(code, 1);
    let doc: Value = serde_json::from_str(&json).expect("one JSON object");
    assert_eq!(doc["old"], old.as_str());
    let changes = doc["changes"].as_array().unwrap();
    assert_eq!(changes.len() + 1, text.lines().count());
    for c in changes {
        let mut keys: Vec<&str> = c.as_object().unwrap().keys().map(String::as_str).collect();
        keys.sort_unstable();
        assert_eq!(
            keys,
            [
                "index",
                "kind",
                "message",
                "new",
                "node",
                "old",
                "rust_path",
                "scope",
                "severity",
                "subindex",
                "where"
            ]
        );
        assert!(["wiring", "device"].contains(&c["scope"].as_str().unwrap()));
    }
    assert!(
        changes
            .iter()
            .any(|c| c["kind"] == "node-added" && c["node"] == "gripper")
    );

    let (code, md, _) = run(&["diff", "--format", "markdown", &old, &new]);
    assert_eq!(code, 1);
    assert!(
        md.contains("| severity | node | where | kind | Rust path | change |"),
        "{md}"
    );
    assert!(
        md.contains("| **breaking** | `io` | node | `node-removed` |"),
        "{md}"
    );
}

#[test]
fn diff_refuses_a_bus_file_against_a_device_and_overlays() {
    let (code, _, stderr) = run(&["diff", &bus("old"), &example()]);
    assert_eq!(code, 2);
    assert!(stderr.contains("is a bus file and"), "{stderr}");
    let (code, _, stderr) = run(&[
        "diff",
        "--new-overlay",
        &example(),
        &bus("old"),
        &bus("new"),
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("not to bus files"), "{stderr}");
    // A broken bus file: its diagnostics, exit 2 as for a broken device.
    let broken = temp_file(
        "net-review/bus.yml",
        "master:\n  node_id: 1\naxis:\n  dcf: absent.eds\n  node_id: 2\n",
    );
    let (code, stdout, stderr) = run(&["diff", &bus("old"), &broken]);
    assert_eq!(code, 2, "{stdout}");
    assert!(
        stdout.is_empty() && stderr.contains("not compared"),
        "{stderr}"
    );
}

#[test]
fn api_of_a_bus_file() {
    let (code, stdout, stderr) = run(&["api", &bus("old")]);
    assert_eq!(code, 0, "{stderr}");
    let options = eds2rust::read::Options::default();
    let library = eds2rust::network::api::api_listing_file(bus("old").as_ref(), &options);
    assert_eq!(stdout, library.expect("lists").text);
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(
        lines[0].starts_with("master\tnetwork\tnode_id=1\t"),
        "{stdout}"
    );
    assert!(stdout.contains("\naxis\tnode\tid=2\t"), "{stdout}");
    assert!(
        stdout.contains("\naxis\ttpdo 1\tcob_id=0x182\ttransmission=1\t"),
        "{stdout}"
    );
    assert!(
        stdout.contains("\naxis\tod::Statusword\t0x6041\t"),
        "{stdout}"
    );
    let (code, _, stderr) = run(&["api", "--overlay", &example(), &bus("old")]);
    assert_eq!(code, 2);
    assert!(stderr.contains("not to bus files"), "{stderr}");
}
