//! A YAML overlay on a real CiA 402 drive EDS of ../shared/eds-corpus
//! (tests/overlays/cia402_stepper.yaml): every stage (delete → modify → add
//! → semantics → PDO defaults) takes effect, and nothing else of the base
//! changes.

use eds2rust::input::{Options, read_device};
use eds2rust::ir::{Device, Entry, PdoDirection, Value};
use eds2rust_tests::{not_run, shared_dir, workspace_root};

fn load() -> Option<(Device, Device)> {
    let shared = match shared_dir() {
        Some(dir) => dir,
        None => {
            not_run("overlay test: ../shared/eds-corpus is not beside this checkout");
            return None;
        }
    };
    let base_path = shared.join("eds-corpus/files/esacademy_cia402-stepper-node8.eds");
    let overlay_path = workspace_root().join("tests/overlays/cia402_stepper.yaml");
    let base = read_device(&base_path, &Options::default());
    // The overlay's `base:` lies outside the checkout, in ../shared.
    let overlay = read_device(
        &overlay_path,
        &Options {
            allow_base_dirs: vec![shared.clone()],
            ..Options::default()
        },
    );
    assert!(
        !overlay.diagnostics.has_errors() && overlay.diagnostics.warning_count() == 0,
        "{}",
        overlay.diagnostics.render()
    );
    Some((
        base.device.expect("base device"),
        overlay.device.expect("overlay device"),
    ))
}

fn entry(device: &Device, index: u16, sub: u8) -> &Entry {
    device
        .objects
        .get(&index)
        .and_then(|o| o.entries.get(&sub))
        .unwrap_or_else(|| panic!("0x{index:04X} sub {sub} is missing"))
}

fn default_int(entry: &Entry) -> Option<i128> {
    match entry.default.as_ref().map(|l| &l.value) {
        Some(Value::Integer(v)) => Some(*v),
        _ => None,
    }
}

#[test]
fn overlay_stages_take_effect_and_leave_the_rest_alone() {
    let Some((base, overlay)) = load() else {
        return;
    };
    // delete
    assert!(base.objects.contains_key(&0x5FF5));
    assert!(!overlay.objects.contains_key(&0x5FF5));
    // modify
    assert_eq!(entry(&base, 0x6041, 0).name, "Status Word");
    assert_eq!(entry(&overlay, 0x6041, 0).name, "Statusword");
    assert_eq!(default_int(entry(&base, 0x6060, 0)), None);
    assert_eq!(default_int(entry(&overlay, 0x6060, 0)), Some(1));
    // add, with an error table reference
    assert!(!base.objects.contains_key(&0x603F));
    let error_code = entry(&overlay, 0x603F, 0);
    assert_eq!(
        error_code.semantics.error_table.as_deref(),
        Some("cia402_errors")
    );
    let table = &overlay.error_tables[0];
    assert_eq!(
        table.codes.iter().find(|c| c.code == 0x8611).unwrap().name,
        "following error"
    );
    assert_eq!(
        overlay.identity.order_code.as_deref(),
        Some("CiA402-STEPPER-NODE8")
    );
    // semantics: statusword bits and states, modes of operation
    let status = &entry(&overlay, 0x6041, 0).semantics;
    assert_eq!(status.bits.len(), 12);
    assert_eq!(status.bits[3].name, "fault");
    assert_eq!((status.bits[11].lsb, status.bits[11].width), (12, 2));
    let mut matched = 0usize;
    for raw in 0..=u16::MAX {
        let states: Vec<&str> = status
            .patterns
            .iter()
            .filter(|p| u64::from(raw) & p.mask == p.value)
            .map(|p| p.name.as_str())
            .collect();
        assert!(states.len() <= 1, "0x{raw:04X} is in states {states:?}");
        matched += states.len();
    }
    assert!(matched > 0);
    let state = |raw: u64| {
        status
            .patterns
            .iter()
            .find(|p| raw & p.mask == p.value)
            .map(|p| p.name.as_str())
    };
    assert_eq!(state(0x0237), Some("operation enabled"));
    assert_eq!(state(0x0250), Some("switch on disabled"));
    assert_eq!(state(0x0218), Some("fault"));
    for index in [0x6060, 0x6061] {
        let values = entry(&overlay, index, 0).semantics.values.as_ref().unwrap();
        assert_eq!(values.other, "reserved");
        let homing = values.named.iter().find(|n| n.low == 6).unwrap();
        assert_eq!(homing.name, "homing");
    }
    // The base EDS has the built-in CiA 402 meaning only.
    let base_status = &entry(&base, 0x6041, 0).semantics;
    assert!(!base_status.bits.is_empty());
    assert!(base_status.bits.iter().all(|b| b.origin.file == "CiA 402"));
    // PDO defaults: TPDO2 named, event timer set, mapping kept
    let label = &overlay.pdo_labels[0];
    assert_eq!(
        (label.direction, label.number, label.name.as_str()),
        (PdoDirection::Tpdo, 2, "status and mode")
    );
    assert_eq!(default_int(entry(&overlay, 0x1801, 5)), Some(100));
    assert_eq!(default_int(entry(&overlay, 0x1A01, 0)), Some(2));
    assert_eq!(default_int(entry(&overlay, 0x1A01, 1)), Some(0x6041_0010));
    assert_eq!(default_int(entry(&overlay, 0x1A01, 2)), Some(0x6061_0008));

    // Nothing else changed: every other entry of the base is identical.
    let touched = [
        (0x6041, 0),
        (0x6040, 0),
        (0x6060, 0),
        (0x6061, 0),
        (0x1801, 5),
        (0x1A01, 0),
        (0x1A01, 1),
        (0x1A01, 2),
    ];
    let mut compared = 0;
    for (index, object) in &base.objects {
        if *index == 0x5FF5 {
            continue;
        }
        let other = &overlay.objects[index];
        // A variable renamed by `modify:` is renamed as an object too.
        let renamed = matches!(*index, 0x6040 | 0x6041);
        if renamed {
            assert_eq!(other.name, other.entries[&0].name, "0x{index:04X} name");
        } else {
            assert_eq!(object.name, other.name, "0x{index:04X} name");
        }
        for (sub, e) in &object.entries {
            if touched.contains(&(*index, *sub)) {
                continue;
            }
            // The same file, reached through two relative paths.
            let mut theirs = other.entries[sub].clone();
            assert_eq!(canonical(&theirs.origin.file), canonical(&e.origin.file));
            theirs.origin.file = e.origin.file.clone();
            assert_eq!(e, &theirs, "0x{index:04X} sub {sub} changed");
            compared += 1;
        }
    }
    assert!(compared > 100, "compared only {compared} entries");
}

fn canonical(path: &str) -> std::path::PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// `modify:` renaming a manufacturer variable renames the object as a
/// whole: `od::OBJECTS` and the entry's `NAME` say the new name, and its
/// Rust name follows the new name unless `rust_name:` pins it (as a
/// renamed sub-entry's does). Nothing else of the listing changes.
#[test]
fn renaming_a_variable_renames_its_object_and_rust_name_unless_pinned() {
    let Some(shared) = shared_dir() else {
        not_run("overlay rename test: ../shared/eds-corpus is not beside this checkout");
        return;
    };
    let base = shared.join("eds-corpus/files/canfestival_led.eds");
    let dir = std::env::temp_dir().join(format!("eds2rust-rename-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let rename = write(
        "rename.yaml",
        "format: 1\nmodify:\n  - { index: 0x2001, name: Bus speed }\n",
    );
    let pin = write(
        "pin.yaml",
        "format: 1\nmodify:\n  - { index: 0x2001, name: Bus speed, rust_name: CanBitrateKbit }\n",
    );
    let listing = |overlay: Option<&std::path::PathBuf>| {
        let overlays: Vec<std::path::PathBuf> = overlay.cloned().into_iter().collect();
        eds2rust::build::api_listing_files(&base, &overlays, &Options::lenient())
            .unwrap_or_else(|d| panic!("{}", d.render()))
            .text
    };
    let before = listing(None);
    let renamed = listing(Some(&rename));
    let pinned = listing(Some(&pin));
    let line = |text: &str| {
        text.lines()
            .find(|l| l.contains("\t0x2001\t"))
            .expect("0x2001 listed")
            .to_string()
    };
    assert!(
        line(&before).starts_with("od::CanBitrateKbit\t"),
        "{}",
        line(&before)
    );
    assert!(
        line(&renamed).starts_with("od::BusSpeed\t"),
        "{}",
        line(&renamed)
    );
    assert_eq!(line(&pinned), line(&before));
    let others = |text: &str| -> Vec<String> {
        text.lines()
            .filter(|l| !l.contains("\t0x2001\t"))
            .map(String::from)
            .collect()
    };
    assert_eq!(others(&renamed), others(&before));
    assert_eq!(pinned, before);

    // The object table and the decoder's name are the new one too.
    let loaded =
        eds2rust::build::load_device(&base, std::slice::from_ref(&rename), &Options::lenient());
    let device = loaded.device.expect("reads");
    assert_eq!(device.objects[&0x2001].name, "Bus speed");
    assert_eq!(device.objects[&0x2001].entries[&0].name, "Bus speed");
    let _ = std::fs::remove_dir_all(&dir);
}
