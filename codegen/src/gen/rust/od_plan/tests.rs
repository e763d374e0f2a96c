//! The stability guarantee of Rust names (docs/generated-code.md, "Stable
//! names"), checked over the EDS corpus: removing an object changes no other
//! entry's path, except entries whose name it shared (a reported collision
//! among vendor names); renaming a standard object changes no path at all.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{DeviceNames, device_names};
use crate::ir::Device;
use crate::profiles::{Canonical, Profile};
use crate::read::Options;

fn corpus() -> Option<Vec<PathBuf>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/eds-corpus/files");
    let Ok(listing) = std::fs::read_dir(&dir) else {
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "NOT RUN: name stability over the corpus: {} is absent",
            dir.display()
        );
        return None;
    };
    let mut files: Vec<PathBuf> = listing
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    Some(files)
}

fn eds(text: &str) -> Device {
    crate::eds::read_bytes("t.eds", text.as_bytes(), &Options::lenient())
        .device
        .expect("readable")
}

/// Up to `n` elements of `all`, spread evenly.
fn sample<T: Copy>(all: &[T], n: usize) -> Vec<T> {
    if all.len() <= n {
        return all.to_vec();
    }
    (0..n).map(|i| all[i * all.len() / n]).collect()
}

/// The names an object's entries shared with other vendor names.
fn shared_by(names: &DeviceNames, index: u16) -> BTreeSet<&str> {
    names
        .collided
        .range((index, 0)..=(index, u8::MAX))
        .flat_map(|(_, v)| v.iter().map(String::as_str))
        .collect()
}

#[test]
fn removing_or_renaming_objects_keeps_other_paths() {
    let Some(files) = corpus() else { return };
    let start = Instant::now();
    let (mut removals, mut renames, mut skipped) = (0, 0, 0);
    for file in files {
        let read = crate::input::read_device(&file, &Options::lenient());
        let Some(device) = read.device else {
            panic!("{}: no device: {:?}", file.display(), read.diagnostics);
        };
        let before = device_names(&device);
        let profile = Profile::of(&device);
        let indices: Vec<u16> = device.objects.keys().copied().collect();
        for index in sample(&indices, 40) {
            let mut smaller = device.clone();
            smaller.objects.remove(&index);
            if Profile::of(&smaller) != profile {
                // The profile is chosen by 0x1000 (or 0x6040 and 0x6041):
                // removing those is outside the guarantee.
                skipped += 1;
                continue;
            }
            removals += 1;
            let after = device_names(&smaller);
            let gone = shared_by(&before, index);
            for (key, path) in &before.entries {
                if key.0 == index {
                    continue;
                }
                let allowed = before
                    .collided
                    .get(key)
                    .is_some_and(|v| v.iter().any(|n| gone.contains(n.as_str())));
                if !allowed {
                    assert_eq!(
                        after.entries.get(key),
                        Some(path),
                        "{}: removing 0x{index:04X} changed 0x{:04X} sub {}",
                        file.display(),
                        key.0,
                        key.1
                    );
                }
            }
        }
        let canonical = Canonical::of(&device);
        let standard: Vec<u16> = indices
            .iter()
            .copied()
            .filter(|&i| canonical.object(i).is_some())
            .collect();
        for index in sample(&standard, 20) {
            let mut renamed = device.clone();
            let object = renamed.objects.get_mut(&index).expect("present");
            object.name = format!("Renamed by the test {index}");
            let single = object.entries.len() == 1;
            for entry in object.entries.values_mut() {
                if canonical.sub(index, entry.subindex).is_some() || single {
                    entry.name = format!("Renamed sub {}", entry.subindex);
                }
            }
            renames += 1;
            assert_eq!(
                device_names(&renamed),
                before,
                "{}: renaming standard object 0x{index:04X} changed a path",
                file.display()
            );
        }
    }
    eprintln!(
        "name stability: {removals} removals, {renames} renames of standard objects, \
         {skipped} profile-changing removals skipped, in {:?}",
        start.elapsed()
    );
    assert!(removals > 0);
}

const DRIVE: &str = "\
[DeviceInfo]
VendorName=Test
[MandatoryObjects]
SupportedObjects=2
1=0x1000
2=0x1001
[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00020192
[1001]
ParameterName=Error register
ObjectType=0x7
DataType=0x0005
AccessType=ro
[OptionalObjects]
SupportedObjects=2
1=0x6064
2=0x6067
[6064]
ParameterName=Istposition
ObjectType=0x7
DataType=0x0004
AccessType=ro
[6067]
ParameterName=Position window
ObjectType=0x7
DataType=0x0007
AccessType=rw
[ManufacturerObjects]
SupportedObjects=3
1=0x373A
2=0x2000
3=0x2001
[373A]
ParameterName=Position window
ObjectType=0x7
DataType=0x0007
AccessType=rw
[2000]
ParameterName=Speed
ObjectType=0x7
DataType=0x0007
AccessType=rw
[2001]
ParameterName=Speed
ObjectType=0x7
DataType=0x0007
AccessType=rw
";

#[test]
fn standard_names_win_and_are_reserved() {
    let device = eds(DRIVE);
    let names = device_names(&device);
    let path = |index: u16| names.entries[&(index, 0)].0.clone();
    assert_eq!(path(0x1000), "od::DeviceType");
    assert_eq!(path(0x6064), "od::PositionActualValue");
    assert_eq!(path(0x6067), "od::PositionWindow");
    assert_eq!(path(0x373A), "od::PositionWindowX373A");
    // Two vendor objects of one name: both qualified, and marked.
    assert_eq!(path(0x2000), "od::SpeedX2000");
    assert_eq!(names.collided[&(0x2000, 0)], vec!["Speed".to_string()]);
    // Without 0x6067 the vendor object keeps its name.
    let mut smaller = device.clone();
    smaller.objects.remove(&0x6067);
    assert_eq!(
        device_names(&smaller).entries[&(0x373A, 0)].0,
        "od::PositionWindowX373A"
    );
}
