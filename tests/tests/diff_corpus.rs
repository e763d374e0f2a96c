//! `eds2rust::diff` on every file of ../shared/eds-corpus: a file against
//! itself has no changes; against a copy mutated in the IR (an object
//! removed, an access right narrowed, a default changed, a standard object
//! renamed, with and without changing its Rust path) and in the text (an
//! access right rewritten in its EDS export) the diff finds exactly that
//! change with the expected severity.

use eds2rust::diff::{self, Change, Kind, Severity};
use eds2rust::eds::{Options, read_bytes, read_file};
use eds2rust::ir::{Access, Device, ObjectKind, Value, pdo::is_mapping_object};

fn pdo_object(index: u16) -> bool {
    (0x1400..=0x1BFF).contains(&index)
}

/// The changes other than the Rust paths that naming shifted around.
fn without_path_shifts(changes: &[Change]) -> Vec<&Change> {
    changes
        .iter()
        .filter(|c| c.kind != Kind::RustPathChanged)
        .collect()
}

/// A copy of `device` with (index, sub) made read-only.
fn read_only(device: &Device, index: u16, sub: u8) -> Device {
    let mut mutated = device.clone();
    let entry = mutated
        .objects
        .get_mut(&index)
        .and_then(|o| o.entries.get_mut(&sub))
        .expect("the entry exists");
    entry.access = Access::Ro;
    mutated
}

fn one(changes: &[Change], what: &str) -> Change {
    assert_eq!(changes.len(), 1, "{what}: {changes:#?}");
    changes[0].clone()
}

/// `change` is a `kind` change of `severity` at (index, sub) `at`.
fn assert_change(
    change: &Change,
    at: (u16, Option<u8>),
    kind: Kind,
    severity: Severity,
    what: &str,
) {
    assert_eq!(
        (change.index, change.subindex, change.kind, change.severity),
        (at.0, at.1, kind, severity),
        "{what}"
    );
}

#[test]
fn corpus_files_against_themselves_and_mutations() {
    let Some(files) = eds2rust_tests::corpus_files("diff corpus test") else {
        return;
    };
    let mut counts = [0usize; 6];
    for path in &files {
        let name = path.display().to_string();
        let device = read_file(path, &Options::default())
            .device
            .expect("a readable file gives a device");
        assert_eq!(
            diff::diff(&device, &device),
            Vec::<Change>::new(),
            "{name}: against itself"
        );
        let generated: Vec<u16> = device
            .objects
            .values()
            .filter(|o| !matches!(o.kind, ObjectKind::DefType | ObjectKind::DefStruct))
            .filter(|o| !o.entries.is_empty() && !pdo_object(o.index))
            .map(|o| o.index)
            .collect();

        // An object removed: breaking, at its index, named by the old path.
        if let Some(&index) = generated.last() {
            let mut mutated = device.clone();
            mutated.objects.remove(&index);
            let changes = diff::diff(&device, &mutated);
            let removed = without_path_shifts(&changes);
            assert_eq!(removed.len(), 1, "{name}: {removed:#?}");
            let c = removed[0];
            assert_eq!(
                (c.index, c.kind, c.severity),
                (index, Kind::ObjectRemoved, Severity::Breaking),
                "{name}"
            );
            assert!(
                c.rust_path
                    .as_deref()
                    .is_some_and(|p| p.starts_with("od::")),
                "{name}: {c:?}"
            );
            assert!(
                changes.iter().all(|c| c.severity == Severity::Breaking),
                "{name}"
            );
            counts[0] += 1;
        }

        // An access right narrowed (rw → ro): breaking, nothing else.
        // (Not in an ARRAY: narrowing one element splits its indexed type,
        // checked below.)
        let rw = device
            .objects
            .values()
            .filter(|o| o.kind != ObjectKind::Array && !is_mapping_object(o.index))
            .flat_map(|o| o.entries.values().map(move |e| (o.index, e)))
            .find(|(_, e)| e.access == Access::Rw);
        if let Some((index, entry)) = rw {
            let mutated = read_only(&device, index, entry.subindex);
            let c = one(&diff::diff(&device, &mutated), &name);
            let at = (index, Some(entry.subindex));
            assert_change(&c, at, Kind::AccessChanged, Severity::Breaking, &name);
            // The other way it widens.
            let c = one(&diff::diff(&mutated, &device), &name);
            assert_eq!(
                (c.kind, c.severity),
                (Kind::AccessChanged, Severity::Additive),
                "{name}"
            );
            counts[1] += 1;
        }

        // One element of an array narrowed (rw → ro): its array is no
        // longer one indexed type, so the paths of its elements change
        // (breaking), and nothing outside that object does.
        let element = device
            .objects
            .values()
            .filter(|o| o.kind == ObjectKind::Array && o.entries.len() > 2)
            .flat_map(|o| o.entries.values().map(move |e| (o.index, e)))
            .find(|(_, e)| e.subindex > 0 && e.access == Access::Rw);
        if let Some((index, entry)) = element {
            let mutated = read_only(&device, index, entry.subindex);
            let changes = diff::diff(&device, &mutated);
            assert!(
                changes
                    .iter()
                    .any(|c| c.kind == Kind::AccessChanged && c.subindex == Some(entry.subindex)),
                "{name}: {changes:#?}"
            );
            assert!(
                changes
                    .iter()
                    .all(|c| c.index == index && c.severity == Severity::Breaking),
                "{name}: {changes:#?}"
            );
            counts[5] += 1;
        }

        // A plain integer default changed: compatible.
        let with_default = device
            .objects
            .values()
            // Not 0x1000: its default picks the device profile, and with it
            // the canonical names of 0x6000–0x9FFF (docs/generated-code.md).
            .filter(|o| o.index != 0x1000)
            .filter(|o| !is_mapping_object(o.index) && !pdo_object(o.index))
            .flat_map(|o| o.entries.values().map(move |e| (o.index, e)))
            .find(|(_, e)| {
                e.parameter_value.is_none()
                    && e.default
                        .as_ref()
                        .is_some_and(|d| !d.plus_node_id && matches!(d.value, Value::Integer(_)))
            });
        if let Some((index, entry)) = with_default {
            let mut mutated = device.clone();
            let target = mutated
                .objects
                .get_mut(&index)
                .unwrap()
                .entries
                .get_mut(&entry.subindex)
                .unwrap();
            let literal = target.default.as_mut().unwrap();
            if let Value::Integer(v) = &mut literal.value {
                *v ^= 1;
            }
            let c = one(&diff::diff(&device, &mutated), &name);
            let at = (index, Some(entry.subindex));
            assert_change(&c, at, Kind::DefaultChanged, Severity::Compatible, &name);
            counts[2] += 1;
        }

        // A standard object renamed: compatible, however much the source name
        // changes, since its Rust name is its canonical CiA name.
        if let Some(object) = [0x1018u16, 0x1000, 0x1001, 0x1017]
            .iter()
            .find_map(|i| device.objects.get(i))
        {
            let index = object.index;
            let mut renamed = device.clone();
            renamed.objects.get_mut(&index).unwrap().name = format!("{} renamed", object.name);
            let changes = diff::diff(&device, &renamed);
            let c = without_path_shifts(&changes);
            assert_eq!(c.len(), 1, "{name}: {c:#?}");
            assert_eq!(
                (c[0].index, c[0].subindex, c[0].kind, c[0].severity),
                (index, None, Kind::NameChanged, Severity::Compatible),
                "{name}"
            );
            let mut respelled = device.clone();
            respelled.objects.get_mut(&index).unwrap().name = format!("{}!", object.name);
            let c = one(&diff::diff(&device, &respelled), &name);
            assert_eq!(
                (c.kind, c.severity),
                (Kind::NameChanged, Severity::Compatible),
                "{name}: {c:?}"
            );
            counts[3] += 1;
        }

        // A text mutation: the device exported as EDS, one `AccessType=rw`
        // of an object outside the PDO range rewritten as `wo`, read back.
        let text = eds2rust::r#gen::to_eds(&device);
        let base = read_bytes("export.eds", text.as_bytes(), &Options::default());
        let Some(base) = base.device else {
            panic!(
                "{name}: the exported EDS does not read back: {:?}",
                base.diagnostics
            );
        };
        if let Some(mutated_text) = narrow_in_text(&text) {
            let mutated = read_bytes("mutated.eds", mutated_text.as_bytes(), &Options::default())
                .device
                .expect("device");
            let c = one(&diff::diff(&base, &mutated), &name);
            assert_eq!(
                (c.kind, c.severity),
                (Kind::AccessChanged, Severity::Breaking),
                "{name}: {c:?}"
            );
            assert_eq!(c.old, Some(diff::Val::Text("rw".into())), "{name}");
            counts[4] += 1;
        }
    }
    println!(
        "{} files: {} removals, {} narrowed, {} defaults, {} renames, {} text mutations, {} array elements narrowed",
        files.len(),
        counts[0],
        counts[1],
        counts[2],
        counts[3],
        counts[4],
        counts[5]
    );
    assert!(
        counts.iter().all(|&n| n > 0),
        "every mutation ran on some file: {counts:?}"
    );
}

/// The EDS text with the first `AccessType=rw` of an object section
/// outside 0x1400–0x1BFF turned into `wo`.
fn narrow_in_text(text: &str) -> Option<String> {
    let mut section_ok = false;
    let mut out = String::with_capacity(text.len());
    let mut done = false;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim();
        if let Some(name) = trimmed.strip_prefix('[').and_then(|s| s.strip_suffix(']')) {
            // A VAR object's own section (not a sub-entry: an ARRAY element
            // narrowed alone splits the array's indexed type).
            section_ok =
                name.len() == 4 && u16::from_str_radix(name, 16).is_ok_and(|i| !pdo_object(i));
        }
        if !done && section_ok && trimmed.eq_ignore_ascii_case("AccessType=rw") {
            out.push_str(&line.replacen("rw", "wo", 1));
            done = true;
        } else {
            out.push_str(line);
        }
    }
    done.then_some(out)
}

#[test]
fn device_without_objects_against_itself() {
    assert!(diff::diff(&Device::default(), &Device::default()).is_empty());
}

/// The Rust paths the diff names are those of the generated code: for
/// every corpus file, each added object's path (against an empty device)
/// is a `pub struct` or `pub mod` of the code generated from the file.
#[test]
fn rust_paths_match_generated_code() {
    let Some(files) = eds2rust_tests::corpus_files("diff rust-path test") else {
        return;
    };
    let mut refused = Vec::new();
    for path in &files {
        let name = path.display().to_string();
        let code = match eds2rust::generate(path, &[], &Default::default()) {
            Ok(code) => code,
            Err(e) => {
                refused.push((name, e.to_string()));
                continue;
            }
        };
        let device = read_file(path, &Options::default()).device.expect("device");
        for c in diff::diff(&Device::default(), &device) {
            if c.kind != Kind::ObjectAdded {
                continue;
            }
            let Some(p) = c.rust_path.as_deref() else {
                continue;
            };
            let last = p.rsplit("::").next().unwrap();
            let item = if last.starts_with(|ch: char| ch.is_ascii_lowercase()) {
                format!("pub mod {last} {{")
            } else {
                format!("pub struct {last};")
            };
            assert!(
                code.contains(&item),
                "{name}: {p} (`{item}`) is not generated"
            );
        }
    }
    // Every corpus file generates: one that does not fails here with its
    // error rather than leaving its paths unchecked.
    assert!(refused.is_empty(), "no code generated for: {refused:#?}");
}
