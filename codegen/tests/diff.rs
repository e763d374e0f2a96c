//! `eds2rust::diff` on the fixture pairs in tests/fixtures/diff: each
//! directory holds `old.*` and `new.*` (EDS, DCF or YAML table) and
//! optionally `old_overlay.yaml`/`new_overlay.yaml` applied on that side.
//! The text and JSON renderings of every pair are locked by insta
//! snapshots (a changed or missing snapshot fails the test), and together
//! the fixtures produce every change kind. The EDS export of a seed device
//! diffs against its YAML table only in what an EDS cannot say.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use eds2rust::diff::{self, Change, Kind, Severity, render};
use eds2rust::input::Options;
use eds2rust::ir::Device;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/diff")
}

/// The file of `dir` whose name starts with `stem.` (old.yaml, new.eds…).
fn side(dir: &Path, stem: &str) -> PathBuf {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("fixture directory")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.file_stem().and_then(|s| s.to_str()) == Some(stem))
        .collect();
    assert_eq!(found.len(), 1, "{}: one {stem}.* file", dir.display());
    found.remove(0)
}

/// Loads a side with its overlay (if any) the way `eds2rust diff` does;
/// a fixture must load without errors.
fn load(dir: &Path, stem: &str) -> (Device, String) {
    let path = side(dir, stem);
    let overlay = dir.join(format!("{stem}_overlay.yaml"));
    let overlays: Vec<PathBuf> = if overlay.exists() {
        vec![overlay]
    } else {
        Vec::new()
    };
    let loaded = eds2rust::build::load_device(&path, &overlays, &Options::default());
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}: {}",
        path.display(),
        loaded.diagnostics.render()
    );
    let name = path
        .strip_prefix(Path::new(env!("CARGO_MANIFEST_DIR")))
        .expect("inside the crate")
        .display()
        .to_string();
    (loaded.device.expect("a device"), name)
}

#[test]
fn fixture_pairs() {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(fixtures())
        .expect("fixtures")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    assert!(
        dirs.len() >= 12,
        "at least 12 fixture pairs, found {}",
        dirs.len()
    );
    let mut kinds = BTreeSet::new();
    let mut severities = BTreeSet::new();
    for dir in &dirs {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let (old, old_name) = load(dir, "old");
        let (new, new_name) = load(dir, "new");
        let changes = diff::diff(&old, &new);
        assert!(!changes.is_empty(), "{name}: the pair differs");
        check_invariants(&name, &changes);
        for c in &changes {
            kinds.insert(c.kind);
            severities.insert((c.kind, c.severity));
        }
        // Each side against itself: nothing.
        assert_eq!(
            diff::diff(&old, &old),
            Vec::<Change>::new(),
            "{name}: old vs old"
        );
        assert_eq!(
            diff::diff(&new, &new),
            Vec::<Change>::new(),
            "{name}: new vs new"
        );
        insta::assert_snapshot!(format!("{name}_text"), render::text(&changes));
        insta::assert_snapshot!(
            format!("{name}_json"),
            render::json(&old_name, &new_name, &changes)
        );
    }
    let missing: Vec<&str> = Kind::ALL
        .iter()
        .filter(|k| !kinds.contains(k))
        .map(|k| k.as_str())
        .collect();
    assert!(missing.is_empty(), "kinds no fixture produces: {missing:?}");
    // The graded kinds show each of their severities somewhere.
    for (kind, expected) in [
        (
            Kind::AccessChanged,
            &[Severity::Breaking, Severity::Additive, Severity::Compatible][..],
        ),
        (
            Kind::NameChanged,
            &[Severity::Breaking, Severity::Compatible],
        ),
        (
            Kind::DefaultChanged,
            &[Severity::Breaking, Severity::Additive, Severity::Compatible],
        ),
        (
            Kind::PdoMappableChanged,
            &[Severity::Breaking, Severity::Additive],
        ),
        (
            Kind::ObjectKindChanged,
            &[Severity::Breaking, Severity::Compatible],
        ),
        (
            Kind::NamedValueChanged,
            &[Severity::Breaking, Severity::Compatible],
        ),
        (
            Kind::ErrorCodeChanged,
            &[Severity::Breaking, Severity::Compatible],
        ),
        (
            Kind::PdoLabelChanged,
            &[Severity::Breaking, Severity::Compatible],
        ),
    ] {
        for s in expected {
            assert!(
                severities.contains(&(kind, *s)),
                "{} is never {}",
                kind.as_str(),
                s.as_str()
            );
        }
    }
}

/// Sorted by index and subindex; removals name the old side's path.
fn check_invariants(name: &str, changes: &[Change]) {
    let keys: Vec<(u16, i32)> = changes
        .iter()
        .map(|c| (c.index, c.subindex.map_or(-1, i32::from)))
        .collect();
    let mut sorted = keys.clone();
    sorted.sort();
    assert_eq!(keys, sorted, "{name}: ordered by index and subindex");
    for c in changes {
        assert!(!c.message.is_empty(), "{name}: {c:?}");
        if matches!(c.kind, Kind::ObjectRemoved | Kind::SubRemoved) {
            assert!(c.new.is_none() && c.old.is_some(), "{name}: {c:?}");
        }
        if matches!(c.kind, Kind::ObjectAdded | Kind::SubAdded) {
            assert!(c.old.is_none() && c.new.is_some(), "{name}: {c:?}");
        }
    }
}

#[test]
fn diff_is_deterministic_and_reversible_in_severity() {
    let dir = fixtures().join("01_objects");
    let (old, _) = load(&dir, "old");
    let (new, _) = load(&dir, "new");
    assert_eq!(diff::diff(&old, &new), diff::diff(&old, &new));
    // Swapping the sides turns additions into removals.
    let forward = diff::diff(&old, &new);
    let backward = diff::diff(&new, &old);
    assert_eq!(forward.len(), backward.len());
    for (f, b) in forward.iter().zip(&backward) {
        match f.kind {
            Kind::ObjectAdded => assert_eq!(
                (b.kind, b.severity),
                (Kind::ObjectRemoved, Severity::Breaking)
            ),
            Kind::ObjectRemoved => assert_eq!(
                (b.kind, b.severity),
                (Kind::ObjectAdded, Severity::Additive)
            ),
            _ => {}
        }
    }
}

/// Kinds of what a YAML table says and an EDS cannot: the value type, the
/// kinds of `Kind::ALL` from the description to the error codes, and PDO
/// labels.
fn semantic_kinds() -> Vec<Kind> {
    let at = |kind| Kind::ALL.iter().position(|&k| k == kind).expect("a kind");
    let (first, last) = (at(Kind::DescriptionChanged), at(Kind::ErrorCodeChanged));
    let mut kinds = vec![Kind::ValueTypeChanged];
    kinds.extend_from_slice(&Kind::ALL[first..=last]);
    kinds.push(Kind::PdoLabelChanged);
    kinds
}

#[test]
fn eds_export_of_a_seed_device_differs_only_in_semantics() {
    for file in [
        "linak_techline.yaml",
        "zimmer_acs.yaml",
        "interroll_ec5000bi.yaml",
    ] {
        let yaml = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../eds")
            .join(file);
        let table = eds2rust::input::read_device(&yaml, &Options::default());
        assert!(
            !table.diagnostics.has_errors(),
            "{}",
            table.diagnostics.render()
        );
        let table = table.device.expect("device");
        let text = eds2rust::r#gen::to_eds(&table);
        let eds = eds2rust::eds::read_bytes(
            "export.eds",
            text.as_bytes(),
            &eds2rust::eds::Options::default(),
        );
        assert!(
            !eds.diagnostics.has_errors(),
            "{}",
            eds.diagnostics.render()
        );
        let eds = eds.device.expect("device");

        let changes = diff::diff(&eds, &table);
        assert!(
            !changes.is_empty(),
            "{file}: the table has a semantic layer"
        );
        for c in &changes {
            assert!(
                semantic_kinds().contains(&c.kind),
                "{file}: not a semantic change: {c:?}"
            );
            // Semantics only appear going from the EDS to the table: nothing
            // the EDS had is lost, but for the built-in meanings of the
            // standard objects, which the table may name otherwise.
            let built_in = eds
                .objects
                .get(&c.index)
                .and_then(|o| o.entries.get(&c.subindex?))
                .is_some_and(|e| {
                    let from_standard = |o: &eds2rust::ir::Origin| o.file.starts_with("CiA ");
                    e.semantics.bits.iter().any(|b| from_standard(&b.origin))
                        || e.semantics
                            .patterns
                            .iter()
                            .any(|p| from_standard(&p.origin))
                        || e.semantics
                            .values
                            .iter()
                            .flat_map(|v| &v.named)
                            .any(|n| from_standard(&n.origin))
                });
            assert!(
                built_in
                    || !matches!(
                        c.kind,
                        Kind::NamedValueRemoved
                            | Kind::BitFieldRemoved
                            | Kind::PatternRemoved
                            | Kind::ErrorTableRemoved
                            | Kind::ErrorCodeRemoved
                    ),
                "{file}: {c:?}"
            );
        }
        if file == "linak_techline.yaml" {
            for kind in [
                Kind::UnitChanged,
                Kind::NamedValueAdded,
                Kind::BitFieldAdded,
                Kind::ErrorTableAdded,
                Kind::PdoLabelChanged,
            ] {
                assert!(
                    changes.iter().any(|c| c.kind == kind),
                    "expected a {}",
                    kind.as_str()
                );
            }
        }
        // What an EDS cannot say left aside, they are equal, both ways.
        let options = diff::Options {
            ignore_semantics: true,
        };
        assert_eq!(
            diff::diff_with(&eds, &table, &options),
            Vec::<Change>::new(),
            "{file}"
        );
        assert_eq!(
            diff::diff_with(&table, &eds, &options),
            Vec::<Change>::new(),
            "{file}"
        );
    }
}

#[test]
fn rust_paths_are_the_generated_ones() {
    // Every path the diff names for a seed device is an item of its
    // generated code: the type `od::X` or module `od::m` and its type `Y`.
    for file in [
        "linak_techline.yaml",
        "zimmer_acs.yaml",
        "interroll_ec5000bi.yaml",
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../eds")
            .join(file);
        let device = eds2rust::input::read_device(&path, &Options::default())
            .device
            .expect("device");
        let code = eds2rust::generate(&path, &[], &Default::default()).expect("generates");
        let empty = Device::default();
        let changes = diff::diff(&empty, &device);
        assert!(!changes.is_empty());
        for c in changes.iter().filter(|c| c.kind == Kind::ObjectAdded) {
            let p = c
                .rust_path
                .as_deref()
                .expect("generated objects have a path");
            let last = p.rsplit("::").next().unwrap();
            let item =
                if p.matches("::").count() == 1 && last.starts_with(|ch: char| ch.is_lowercase()) {
                    format!("pub mod {last} {{")
                } else {
                    format!("pub struct {last};")
                };
            assert!(
                code.contains(&item),
                "{file}: {p} ({item}) is not generated"
            );
        }
    }
}
