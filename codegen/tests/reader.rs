//! Reader rules of docs/eds-reader.md that the corpus does not pin down by
//! itself, each checked on a small hand-written file.

use std::path::{Path, PathBuf};

use eds2rust::diag::Severity;
use eds2rust::eds::{Options, read_bytes, read_file};
use eds2rust::ir::{Access, DataType, Device, ObjectKind, Value};

fn read(text: &str) -> (Device, Vec<&'static str>) {
    let loaded = read_bytes("t.eds", text.as_bytes(), &Options::default());
    let codes = loaded.diagnostics.iter().map(|d| d.code).collect();
    (loaded.device.expect("device"), codes)
}

fn default(device: &Device, index: u16, sub: u8) -> Option<Value> {
    device.objects[&index].entries[&sub]
        .default
        .as_ref()
        .map(|l| l.value.clone())
}

#[test]
fn sub_sections_before_their_parent_and_lower_case_names() {
    let (device, codes) = read(
        "[optionalobjects]\nsupportedobjects=1\n1=0x2000\n\
         [2000SUB1]\nparametername=Item\ndatatype=0x0006\naccesstype=RW\ndefaultvalue=017\n\
         [2000sub0]\nParameterName=Count\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n\
         [2000]\nParameterName=Table\nObjectType=0x8\nSubNumber=2\n",
    );
    assert!(codes.is_empty(), "{codes:?}");
    let table = &device.objects[&0x2000];
    assert_eq!(table.kind, ObjectKind::Array);
    assert_eq!(table.entries.len(), 2);
    assert_eq!(
        default(&device, 0x2000, 1),
        Some(Value::Integer(15)),
        "017 is octal"
    );
}

#[test]
fn compact_record_with_names_and_dcf_values() {
    let (device, codes) = read(
        "[OptionalObjects]\nSupportedObjects=1\n1=0x1016\n\
         [1016]\nParameterName=Consumer heartbeat time\nObjectType=0x9\nCompactSubObj=3\n\
         DataType=0x0007\nAccessType=rw\nDefaultValue=0\n\
         [1016Name]\nNrOfEntries=1\n2=Safety controller\n\
         [1016Value]\nNrOfEntries=2\n1=0x00050064\n3=$NODEID+0x10\n",
    );
    assert!(codes.is_empty(), "{codes:?}");
    let object = &device.objects[&0x1016];
    assert_eq!(
        (object.kind, object.compact_sub_obj),
        (ObjectKind::Record, Some(3))
    );
    assert_eq!(object.entries.len(), 4);
    assert_eq!(default(&device, 0x1016, 0), Some(Value::Integer(3)));
    assert_eq!(object.entries[&1].name, "Consumer heartbeat time1");
    assert_eq!(object.entries[&2].name, "Safety controller");
    let pv = |sub: u8| object.entries[&sub].parameter_value.clone();
    assert_eq!(pv(1).map(|l| l.value), Some(Value::Integer(0x0005_0064)));
    assert!(pv(2).is_none());
    let third = pv(3).expect("value of sub 3");
    assert!(third.plus_node_id);
    assert_eq!(third.resolve(Some(5)), Value::Integer(0x15));
}

#[test]
fn values_formulas_reals_and_dummies() {
    let (device, codes) = read(
        "[DummyUsage]\nDummy0002=1\nDummy0007=1\n\
         [OptionalObjects]\nSupportedObjects=4\n1=0x1800\n2=0x2001\n3=0x2002\n4=0x2003\n\
         [1800]\nParameterName=COB-ID\nDataType=0x0007\nAccessType=rw\nDefaultValue= 0x180 + $nodeid \n\
         [2001]\nParameterName=Gain\nDataType=0x0008\nAccessType=rw\nDefaultValue=0x3FC00000\n\
         [2002]\nParameterName=Offset\nDataType=0x0003\nAccessType=rw\nDefaultValue=0xFFFE\n\
         [2003]\nParameterName=Key\nDataType=0x000A\nAccessType=rw\nDefaultValue=01 0a FF\n",
    );
    assert!(codes.is_empty(), "{codes:?}");
    assert_eq!(
        device.dummy_usage,
        [DataType::Integer8, DataType::Unsigned32]
    );
    let cob = device.objects[&0x1800].entries[&0].default.clone().unwrap();
    assert!(cob.plus_node_id);
    assert_eq!(cob.resolve(Some(32)), Value::Integer(0x1A0));
    assert_eq!(default(&device, 0x2001, 0), Some(Value::Real(1.5)));
    assert_eq!(default(&device, 0x2002, 0), Some(Value::Integer(-2)));
    assert_eq!(
        default(&device, 0x2003, 0),
        Some(Value::Bytes(vec![1, 10, 255]))
    );
}

#[test]
fn object_lists_both_ways_and_identity_from_1018() {
    let (device, codes) = read(
        "[MandatoryObjects]\nSupportedObjects=2\n1=0x1000\n2=0x1018\n\
         [1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\n\
         [1018]\nParameterName=Identity\nObjectType=0x9\nSubNumber=2\n\
         [1018sub0]\nParameterName=Count\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n\
         [1018sub1]\nParameterName=Vendor-ID\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x0000ABCD\n\
         [2000]\nParameterName=Unlisted\nDataType=0x0005\nAccessType=rw\n",
    );
    assert_eq!(codes, ["eds::unlisted-object"]);
    assert!(
        device.objects.contains_key(&0x2000),
        "an unlisted object is read"
    );
    assert_eq!(device.identity.vendor_number, Some(0xABCD));
    let (device, codes) = read(
        "[OptionalObjects]\nSupportedObjects=2\n1=0x2000\n2=0x2001\n[2000]\nParameterName=A\nDataType=0x0005\nAccessType=rw\n",
    );
    assert_eq!(codes, ["eds::missing-object-section"]);
    assert!(
        !device.objects.contains_key(&0x2001),
        "a listed object without a section is left out"
    );
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

#[test]
fn access_type_not_in_cia306_is_a_warning_read_as_ro() {
    let path = fixture("malformed/access_type_not_cia306.eds");
    let loaded = read_file(&path, &Options::default());
    let d = &loaded.diagnostics;
    assert!(!d.has_errors(), "{}", d.render());
    let bad: Vec<_> = d.iter().filter(|d| d.code == "eds::bad-access").collect();
    assert_eq!(bad.len(), d.len(), "{}", d.render());
    assert_eq!(bad.len(), 2, "`rwx` and `READONLY`");
    assert!(bad.iter().all(|d| d.severity == Severity::Warning));
    assert!(
        bad[0]
            .notes
            .iter()
            .any(|n| n.contains("`modify: [{ index: 0x2000, sub: 1, access: rw }]`")),
        "the note shows the overlay: {:?}",
        bad[0].notes
    );
    let device = loaded.device.expect("device");
    let access = |device: &Device, sub: u8| device.objects[&0x2000].entries[&sub].access;
    assert_eq!(access(&device, 1), Access::Ro, "`rwx` is read as `ro`");
    assert_eq!(access(&device, 2), Access::Ro, "`READONLY` is read as `ro`");

    // --strict keeps it an error, at the same place.
    let strict = read_file(&path, &Options::strict());
    let errors: Vec<_> = strict
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .map(|d| (d.code, d.location.line))
        .collect();
    let lenient: Vec<_> = bad.iter().map(|d| (d.code, d.location.line)).collect();
    assert_eq!(errors, lenient);

    // An overlay sets the right access (the note's `modify`).
    let overlay = fixture("access_type_overlay.yaml");
    let fixed = eds2rust::table::apply_overlay(device, &overlay, &Options::default());
    assert!(
        !fixed.diagnostics.has_errors(),
        "{}",
        fixed.diagnostics.render()
    );
    let device = fixed.device.expect("device");
    assert_eq!(access(&device, 1), Access::Rw, "set by the overlay");
    assert_eq!(access(&device, 2), Access::Ro, "not named by the overlay");
}

#[test]
fn access_type_not_in_cia306_on_compact_sub_objects() {
    let loaded = read_bytes(
        "t.eds",
        b"[OptionalObjects]\nSupportedObjects=1\n1=0x1016\n\
          [1016]\nParameterName=Consumer heartbeat time\nObjectType=0x8\nCompactSubObj=2\n\
          DataType=0x0007\nAccessType=r/w\nDefaultValue=0\n",
        &Options::default(),
    );
    let d: Vec<_> = loaded.diagnostics.iter().collect();
    assert_eq!(d.len(), 1, "one warning for the template");
    assert_eq!(
        (d[0].code, d[0].severity),
        ("eds::bad-access", Severity::Warning)
    );
    assert!(
        d[0].notes[1].contains("sub: 1, access: rw }]`, one item per sub-index"),
        "{:?}",
        d[0].notes
    );
    let device = loaded.device.expect("device");
    let entries = &device.objects[&0x1016].entries;
    assert_eq!(entries[&0].access, Access::Ro, "sub 0 is always ro");
    assert!((1..=2).all(|sub| entries[&sub].access == Access::Ro));
}

/// An ARRAY 0x2000 of UNSIGNED8 with `SubNumber` (when given) and one
/// sub-section per name in `subs` (`[2000sub<name>]`, named `Gain <name>`).
fn array_with_subs(sub_number: Option<usize>, subs: &[String]) -> String {
    let mut text = String::from(
        "[OptionalObjects]\nSupportedObjects=1\n1=0x2000\n\
         [2000]\nParameterName=Gains\nObjectType=0x8\n",
    );
    if let Some(n) = sub_number {
        text.push_str(&format!("SubNumber={n}\n"));
    }
    for sub in subs {
        text.push_str(&format!(
            "[2000sub{sub}]\nParameterName=Gain {sub}\nDataType=0x0005\nAccessType=rw\n"
        ));
    }
    text
}

fn names(range: std::ops::RangeInclusive<u32>) -> Vec<String> {
    range.map(|n| n.to_string()).collect()
}

#[test]
fn decimal_sub_section_names_are_read_as_decimal_with_one_warning() {
    let path = fixture("malformed/sub_index_decimal.eds");
    let loaded = read_file(&path, &Options::default());
    let d = &loaded.diagnostics;
    let codes: Vec<_> = d.iter().map(|d| d.code).collect();
    assert_eq!(codes, ["eds::decimal-subindex"], "{}", d.render());
    let warning = d.iter().next().expect("the warning");
    assert_eq!(warning.severity, Severity::Warning);
    assert_eq!(warning.location.section.as_deref(), Some("2000sub100"));
    assert!(
        warning
            .notes
            .iter()
            .any(|n| n.contains("[2000sub64] instead of [2000sub100]")),
        "{:?}",
        warning.notes
    );
    let device = loaded.device.expect("device");
    let array = &device.objects[&0x2000];
    assert!(array.entries.keys().copied().eq(0..=100u8));
    assert_eq!(array.entries[&10].name, "Gain 10");
    assert_eq!(array.entries[&100].name, "Gain 100");
    assert_eq!(
        read_file(&path, &Options::strict())
            .diagnostics
            .error_count(),
        1
    );

    // The same from text, with a second object written in hex as CiA 306
    // says: only the decimal object is read as decimal.
    let mut text = array_with_subs(Some(101), &names(0..=100));
    text.push_str(
        "[2001]\nParameterName=Hex\nObjectType=0x9\nSubNumber=2\n\
         [2001sub0]\nParameterName=Count\nDataType=0x0005\nAccessType=ro\n\
         [2001sub10]\nParameterName=Sixteen\nDataType=0x0005\nAccessType=ro\n",
    );
    let (device, codes) = read(&text);
    assert_eq!(codes, ["eds::decimal-subindex", "eds::unlisted-object"]);
    assert!(
        device.objects[&0x2000]
            .entries
            .keys()
            .copied()
            .eq(0..=100u8)
    );
    assert!(device.objects[&0x2001].entries.contains_key(&0x10));
}

#[test]
fn sub_section_names_stay_hex_unless_decimal_beyond_doubt() {
    // A hex letter among the names: hex, and [2000sub100] is not a section
    // CiA 306 defines (as before).
    let mut subs = names(0..=9);
    subs.extend(["1A".to_string(), "100".to_string()]);
    let (device, codes) = read(&array_with_subs(Some(12), &subs));
    assert_eq!(codes, ["eds::sub-number", "eds::unknown-section"]);
    let keys: Vec<u8> = device.objects[&0x2000].entries.keys().copied().collect();
    assert_eq!(keys, [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 0x1A]);

    // Decimal-looking names whose count does not match SubNumber: hex.
    let (device, codes) = read(&array_with_subs(Some(100), &names(0..=100)));
    assert_eq!(codes, ["eds::unknown-section"]);
    let array = &device.objects[&0x2000];
    assert_eq!(array.entries[&0x10].name, "Gain 10");
    assert_eq!(array.entries[&0x99].name, "Gain 99");
    assert_eq!(array.entries[&100].name, "Gain 64", "0x64");
    assert_eq!(array.entries.len(), 100, "[2000sub100] is left out");

    // No SubNumber: hex.
    let (device, codes) = read(&array_with_subs(None, &names(0..=100)));
    assert_eq!(codes, ["eds::unknown-section"]);
    assert_eq!(device.objects[&0x2000].entries[&0x10].name, "Gain 10");

    // Every name fits hex: hex, whatever SubNumber says.
    let (device, codes) = read(&array_with_subs(Some(3), &names(0..=2)));
    assert!(codes.is_empty(), "{codes:?}");
    assert_eq!(device.objects[&0x2000].entries.len(), 3);
}
