//! The built-in meanings of the standard objects: a plain vendor EDS of a
//! CiA 402 drive gets the statusword bits and states, the modes of
//! operation and the CiA 301 bit fields without an overlay; an overlay's
//! own meaning wins; `profiles: none` switches them off.

use std::path::{Path, PathBuf};

use eds2rust::input::{Options, read_device};
use eds2rust::ir::{Device, Entry, ProfileChoice};
use eds2rust::table;

fn example_eds() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../eds/example.eds")
}

fn entry(device: &Device, index: u16, sub: u8) -> &Entry {
    &device.objects[&index].entries[&sub]
}

fn bit_names(entry: &Entry) -> Vec<(u32, &str)> {
    let s = &entry.semantics;
    s.bits.iter().map(|b| (b.lsb, b.name.as_str())).collect()
}

/// An overlay of the example drive, written next to a copy of nothing: the
/// overlay is applied on the device read already.
fn overlay(device: Device, name: &str, yaml: &str) -> eds2rust::input::Loaded {
    let dir = std::env::temp_dir().join(format!("eds2rust-profiles-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, yaml).unwrap();
    table::apply_overlay(device, &path, &Options::default())
}

#[test]
fn a_plain_eds_drive_gets_the_cia_402_and_301_meanings() {
    let device = read_device(&example_eds(), &Options::default())
        .device
        .unwrap();
    let status = entry(&device, 0x6041, 0);
    let bits = bit_names(status);
    assert_eq!(bits.len(), 13, "{bits:?}");
    assert!(bits.contains(&(10, "target reached")));
    assert!(bits.contains(&(12, "set-point acknowledge")));
    assert!(
        status
            .semantics
            .bits
            .iter()
            .all(|b| b.origin.file == "CiA 402")
    );
    let state = |raw: u64| {
        let patterns = &status.semantics.patterns;
        let p = patterns.iter().find(|p| raw & p.mask == p.value)?;
        Some(p.name.as_str())
    };
    assert_eq!(state(0x0637), Some("operation enabled"));
    assert_eq!(state(0x0250), Some("switch on disabled"));
    assert_eq!(state(0x0008), Some("fault"));
    assert_eq!(state(0x0007), Some("quick stop active"));
    let modes = entry(&device, 0x6060, 0).semantics.values.as_ref().unwrap();
    let name = |v: i128| {
        let n = modes.named.iter().find(|n| n.low <= v && v <= n.high)?;
        Some(n.name.as_str())
    };
    assert_eq!(name(1), Some("profile position"));
    assert_eq!(name(8), Some("cyclic synchronous position"));
    assert_eq!(name(-3), Some("manufacturer specific"));
    assert_eq!(name(5), None, "5 is reserved");
    assert_eq!(modes.other, "reserved");
    // CiA 301: error register bits, a TPDO's COB-ID bits and transmission
    // types.
    assert!(bit_names(entry(&device, 0x1001, 0)).contains(&(4, "communication error")));
    let cob = bit_names(entry(&device, 0x1800, 1));
    assert_eq!(
        cob,
        [
            (0, "CAN-ID"),
            (29, "extended frame"),
            (30, "no RTR"),
            (31, "not valid")
        ]
    );
    let types = entry(&device, 0x1800, 2).semantics.values.as_ref().unwrap();
    assert_eq!(types.numeric, Some((1, 240)));
    assert!(
        types
            .named
            .iter()
            .any(|n| n.low == 254 && n.name.contains("event driven"))
    );
}

#[test]
fn an_overlay_wins_bit_by_bit_and_kind_by_kind() {
    let device = read_device(&example_eds(), &Options::default())
        .device
        .unwrap();
    let yaml = r"format: 1
semantics:
  - index: 0x6041
    bits:
      - { bit: 13, name: lag error }
      - { bit: 14, name: axis homed }
  - index: 0x6060
    values:
      named:
        - { value: 1, name: positioning }
      other: unknown
";
    let loaded = overlay(device, "wins.yaml", yaml);
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}",
        loaded.diagnostics.render()
    );
    let device = loaded.device.unwrap();
    let bits = bit_names(entry(&device, 0x6041, 0));
    assert!(bits.contains(&(13, "lag error")), "{bits:?}");
    assert!(bits.contains(&(14, "axis homed")), "{bits:?}");
    assert!(!bits.contains(&(13, "following error")), "{bits:?}");
    assert!(
        bits.contains(&(0, "ready to switch on")),
        "the standard's other bits stay"
    );
    assert_eq!(entry(&device, 0x6041, 0).semantics.patterns.len(), 8);
    let modes = entry(&device, 0x6060, 0).semantics.values.as_ref().unwrap();
    assert_eq!(
        modes.named.len(),
        1,
        "the overlay's table replaces the standard's"
    );
    assert_eq!(modes.other, "unknown");
}

#[test]
fn profiles_none_switches_them_off() {
    let device = read_device(&example_eds(), &Options::default())
        .device
        .unwrap();
    let loaded = overlay(device, "none.yaml", "format: 1\nprofiles: none\n");
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}",
        loaded.diagnostics.render()
    );
    let device = loaded.device.unwrap();
    assert_eq!(device.profiles, ProfileChoice::None);
    for (index, sub) in [
        (0x6041, 0),
        (0x6060, 0),
        (0x1001, 0),
        (0x1800, 1),
        (0x1800, 2),
    ] {
        let s = &entry(&device, index, sub).semantics;
        assert!(
            s.bits.is_empty() && s.patterns.is_empty() && s.values.is_none(),
            "{index:#X}"
        );
    }
}

#[test]
fn an_unknown_profiles_value_names_file_line_and_key() {
    let device = read_device(&example_eds(), &Options::default())
        .device
        .unwrap();
    let loaded = overlay(device, "bad.yaml", "format: 1\nprofiles: cia402\n");
    let rendered = loaded.diagnostics.render();
    assert!(loaded.diagnostics.has_errors(), "{rendered}");
    assert!(rendered.contains("table::bad-profiles"), "{rendered}");
    assert!(rendered.contains("bad.yaml:2"), "{rendered}");
    assert!(rendered.contains("`none`"), "{rendered}");
}
