//! `rust_name:` pins the Rust name of an object, a sub-entry, a bit field
//! or a named value (docs/yaml-tables.md): the generated code has the pinned
//! names, a pin wins over a canonical name, a pin of the wrong case is a
//! `table::rust-name` error with the converted form, and a pin equal to
//! another name of its scope is a `gen::rust-name-collision` error.

use std::collections::BTreeSet;
use std::path::Path;

use eds2rust::diag::{Diagnostics, Severity};
use eds2rust::r#gen::rust::{Options as GenOptions, generate};
use eds2rust::input::Options;
use eds2rust::ir::Device;
use eds2rust::table::{read_bytes, read_file};

const FIXTURE: &str = "tests/fixtures/rust_name.yaml";

fn read(name: &str, text: &str) -> (Option<Device>, Diagnostics) {
    let loaded = read_bytes(name, text.as_bytes(), Path::new("."), &Options::default());
    (loaded.device, loaded.diagnostics)
}

fn code_of(device: &Device) -> String {
    generate(device, &GenOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()))
        .code
}

/// Every item path of the generated file (`od::feedback::PositionActual`),
/// enum variants as `Enum::Variant` and inherent methods as `Type::method`.
fn paths(code: &str) -> BTreeSet<String> {
    fn walk(items: &[syn::Item], prefix: &str, out: &mut BTreeSet<String>) {
        for item in items {
            let path = |name: &syn::Ident| format!("{prefix}{name}");
            match item {
                syn::Item::Mod(m) => {
                    out.insert(path(&m.ident));
                    if let Some((_, items)) = &m.content {
                        walk(items, &format!("{}::", path(&m.ident)), out);
                    }
                }
                syn::Item::Struct(s) => {
                    out.insert(path(&s.ident));
                }
                syn::Item::Enum(e) => {
                    out.insert(path(&e.ident));
                    for v in &e.variants {
                        out.insert(format!("{}::{}", path(&e.ident), v.ident));
                    }
                }
                syn::Item::Impl(i) if i.trait_.is_none() => {
                    if let syn::Type::Path(ty) = &*i.self_ty {
                        let ty = ty.path.segments.last().expect("a type").ident.clone();
                        for item in &i.items {
                            match item {
                                syn::ImplItem::Fn(f) => {
                                    out.insert(format!("{}::{}", path(&ty), f.sig.ident));
                                }
                                syn::ImplItem::Const(c) => {
                                    out.insert(format!("{}::{}", path(&ty), c.ident));
                                }
                                _ => {}
                            }
                        }
                    }
                }
                _ => {}
            }
        }
    }
    let file = syn::parse_file(code).expect("generated code parses");
    let mut out = BTreeSet::new();
    walk(&file.items, "", &mut out);
    out
}

fn errors<'d>(diags: &'d Diagnostics, code: &str) -> Vec<&'d eds2rust::diag::Diagnostic> {
    diags
        .iter()
        .filter(|d| d.code == code && d.severity == Severity::Error)
        .collect()
}

#[test]
fn pinned_names_are_generated() {
    let loaded = read_file(Path::new(FIXTURE), &Options::default());
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}",
        loaded.diagnostics.render()
    );
    let device = loaded.device.expect("a device");
    let output =
        generate(&device, &GenOptions::default()).unwrap_or_else(|d| panic!("{}", d.render()));
    assert_eq!(output.warnings.len(), 0, "{}", output.warnings.render());
    let paths = paths(&output.code);
    for expected in [
        // A pin wins over the canonical name of 0x6041 (`Statusword`), and
        // its value types follow the pin.
        "od::DriveStatus",
        "od::DriveStatusValue",
        // Pinned bit fields: the getter, and the enum of a field with values.
        "od::DriveStatusValue::ready",
        "od::DriveStatusValue::with_ready",
        "od::DriveStatusValue::switched_on",
        "od::DriveStatusValue::op_mode",
        "od::DriveStatusOpMode",
        // A pinned named value of a bit field, and an unpinned one.
        "od::DriveStatusOpMode::Parked",
        "od::DriveStatusOpMode::Run",
        // A pinned var.
        "od::MotorTemp",
        "od::MotorTempValue",
        // A pinned record module, a pinned sub and its named value.
        "od::feedback",
        "od::feedback::PositionActual",
        "od::feedback::PositionActualValue",
        "od::feedback::PositionActualKind::Home",
        "od::feedback::PositionActualKind::EndStop",
        "od::feedback::PositionActualValue::HOME",
        "od::feedback::Current",
        // Pins given in `semantics:`: a var, an array's module, a sub.
        "od::MaxSpeed",
        "od::gains",
        "od::gains::GainOne",
        "od::gains::SecondGain",
    ] {
        assert!(
            paths.contains(expected),
            "`{expected}` is not generated; the items are:\n{paths:#?}"
        );
    }
    for gone in [
        "od::Statusword",
        "od::MotorTemperature",
        "od::feedback_block",
        "od::feedback::Position",
        "od::DriveStatusValue::ready_to_switch_on",
        "od::DriveStatusOpMode::Idle",
        "od::feedback::PositionActualKind::HomePosition",
        "od::SpeedLimit",
        "od::tuning",
        "od::gains::GainTwo",
    ] {
        assert!(!paths.contains(gone), "`{gone}` is generated");
    }
    // The source names stay findable.
    assert!(output.code.contains("#[doc(alias = \"Statusword\")]"));
    assert!(
        output
            .code
            .contains("#[doc(alias = \"ready to switch on\")]")
    );
}

#[test]
fn the_eds_export_ignores_pins() {
    let loaded = read_file(Path::new(FIXTURE), &Options::default());
    let device = loaded.device.expect("a device");
    let eds = eds2rust::r#gen::eds::to_eds(&device);
    for pin in [
        "DriveStatus",
        "MotorTemp",
        "PositionActual",
        "op_mode",
        "Parked",
    ] {
        assert!(!eds.contains(pin), "the export says `{pin}`:\n{eds}");
    }
    assert!(eds.contains("ParameterName=Statusword"));
}

/// One fixture per item kind: the error is at the `rust_name` line, says the
/// case and suggests the converted name.
#[test]
fn a_pin_of_the_wrong_case_is_an_error_with_the_converted_form() {
    let text = "\
format: 1
device: { vendor_name: V, product_name: P }
objects:
  - index: 0x2000
    name: Position
    rust_name: position_actual
    type: UNSIGNED16
    access: ro
  - index: 0x2001
    name: Block
    kind: record
    rust_name: Feedback
    subs:
      - { sub: 1, name: A, type: UNSIGNED8, access: ro, rust_name: \"first value\" }
  - index: 0x2002
    name: Bits
    type: UNSIGNED8
    access: ro
    bits:
      - { bit: 0, name: ready, rust_name: ReadyBit }
    values:
      named:
        - { value: 1, name: one, rust_name: self }
      other: reserved
semantics:
  - { index: 0x2001, sub: 1, rust_name: Self }
";
    let (_, diags) = read("pins.yaml", text);
    let found = errors(&diags, "table::rust-name");
    let summary: Vec<(Option<u32>, &str)> = found
        .iter()
        .map(|d| (d.location.line, d.message.as_str()))
        .collect();
    let expect = [
        (6, "UpperCamelCase", "`PositionActual`"),
        (12, "snake_case", "`feedback`"),
        (14, "UpperCamelCase", "`FirstValue`"),
        (20, "snake_case", "`ready_bit`"),
        (23, "UpperCamelCase", "`Self_`"),
        (26, "UpperCamelCase", "`Self_`"),
    ];
    assert_eq!(
        found.len(),
        expect.len(),
        "{summary:#?}\n{}",
        diags.render()
    );
    for (d, (line, case, suggestion)) in found.iter().zip(expect) {
        assert_eq!(d.location.line, Some(line), "{summary:#?}");
        assert_eq!(d.location.key.as_deref(), Some("rust_name"));
        assert!(
            d.message.contains(case) && d.message.contains(suggestion),
            "line {line}: {}",
            d.message
        );
    }
    assert!(diags.render().contains("pins.yaml:6"), "{}", diags.render());
}

fn generate_errors(text: &str) -> Diagnostics {
    let (device, diags) = read("collide.yaml", text);
    assert!(!diags.has_errors(), "{}", diags.render());
    match generate(&device.expect("a device"), &GenOptions::default()) {
        Ok(_) => panic!("a colliding pin generated code"),
        Err(diags) => diags,
    }
}

#[test]
fn a_pin_equal_to_a_canonical_name_is_an_error() {
    let diags = generate_errors(
        "\
format: 1
device: { vendor_name: V, product_name: P }
objects:
  - { index: 0x1000, name: Device type, type: UNSIGNED32, access: ro, default: 0x00020192 }
  - { index: 0x6041, name: Status word, type: UNSIGNED16, access: ro }
  - { index: 0x2000, name: My status, rust_name: Statusword, type: UNSIGNED16, access: ro }
",
    );
    let found = errors(&diags, "gen::rust-name-collision");
    assert_eq!(found.len(), 1, "{}", diags.render());
    let d = found[0];
    assert_eq!(d.location.line, Some(6));
    assert!(
        d.message
            .contains("`rust_name: Statusword` (collide.yaml:6)")
            && d.message
                .contains("the standard name `Statusword` (collide.yaml:5)"),
        "{}",
        d.message
    );
}

#[test]
fn a_pin_equal_to_another_name_of_its_scope_is_an_error() {
    let diags = generate_errors(
        "\
format: 1
device: { vendor_name: V, product_name: P }
objects:
  - { index: 0x2000, name: Motor speed, rust_name: Speed, type: UNSIGNED16, access: ro }
  - { index: 0x2001, name: Speed, type: UNSIGNED16, access: ro }
  - index: 0x2002
    name: Mode
    type: UNSIGNED8
    access: rw
    values:
      named:
        - { value: 0, name: idle, rust_name: Run }
        - { value: 1, name: run }
      other: reserved
  - index: 0x2003
    name: Control
    type: UNSIGNED8
    access: rw
    bits:
      - { bit: 0, name: enable, rust_name: to_raw }
  - index: 0x2004
    name: Block
    kind: record
    rust_name: pinned
    subs:
      - { sub: 1, name: A, rust_name: Same, type: UNSIGNED8, access: ro }
      - { sub: 2, name: B, rust_name: Same, type: UNSIGNED8, access: ro }
  - { index: 0x2005, name: Other block, kind: record, rust_name: pinned, subs: [ { sub: 1, name: C, type: UNSIGNED8, access: ro } ] }
",
    );
    let found = errors(&diags, "gen::rust-name-collision");
    let messages: Vec<&str> = found.iter().map(|d| d.message.as_str()).collect();
    let has = |line: u32, parts: &[&str]| {
        found
            .iter()
            .any(|d| d.location.line == Some(line) && parts.iter().all(|p| d.message.contains(p)))
    };
    // A pin and a source name.
    assert!(
        has(
            4,
            &[
                "`rust_name: Speed` (collide.yaml:4)",
                "`Speed` (collide.yaml:5)",
                "module `od`"
            ]
        ),
        "{messages:#?}"
    );
    // A pinned variant and another named value.
    assert!(
        has(12, &["`rust_name: Run`", "`run` (collide.yaml:13)"]),
        "{messages:#?}"
    );
    // A pinned getter and a method the generator has.
    assert!(
        has(
            20,
            &["`rust_name: to_raw`", "a name the generator uses there"]
        ),
        "{messages:#?}"
    );
    // Two pinned subs, and two pinned modules.
    assert!(
        has(
            26,
            &[
                "`rust_name: Same` (collide.yaml:26)",
                "the pin `rust_name: Same` (collide.yaml:27)"
            ]
        ),
        "{messages:#?}"
    );
    assert!(
        has(
            21,
            &[
                "`rust_name: pinned` (collide.yaml:21)",
                "the pin `rust_name: pinned` (collide.yaml:28)"
            ]
        ),
        "{messages:#?}"
    );
    assert_eq!(found.len(), 5, "{messages:#?}");
}

/// `modify:` pins names of a base EDS's objects and subs; without `sub`, a
/// record's pin is its module's.
#[test]
fn modify_pins_names_of_a_base() {
    let dir = std::env::temp_dir().join(format!("eds2rust-rust-name-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(
        dir.join("base.eds"),
        "\
[2100]
ParameterName=Speed limit
ObjectType=0x7
DataType=0x0006
AccessType=rw
PDOMapping=0

[2101]
ParameterName=Tuning
ObjectType=0x9
SubNumber=2

[2101sub0]
ParameterName=Highest sub-index supported
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=1
PDOMapping=0

[2101sub1]
ParameterName=Gain
ObjectType=0x7
DataType=0x0006
AccessType=rw
PDOMapping=0
",
    )
    .expect("write");
    let overlay = dir.join("overlay.yaml");
    std::fs::write(
        &overlay,
        "\
format: 1
base: base.eds
modify:
  - { index: 0x2100, rust_name: MaxSpeed }
  - { index: 0x2101, rust_name: gains }
  - { index: 0x2101, sub: 1, rust_name: ProportionalGain }
",
    )
    .expect("write");
    let misplaced = dir.join("misplaced.yaml");
    std::fs::write(
        &misplaced,
        "\
format: 1
base: base.eds
delete:
  - { index: 0x2100, rust_name: Gone }
",
    )
    .expect("write");
    // The scratch directory is the project here: a `base:` outside the
    // project is refused.
    let options = Options {
        project_dir: Some(dir.clone()),
        ..Options::default()
    };
    let loaded = read_file(&overlay, &options);
    let bad = read_file(&misplaced, &options);
    let _ = std::fs::remove_dir_all(&dir);
    // `delete:` has no names to pin.
    assert!(
        bad.diagnostics
            .iter()
            .any(|d| d.code == "table::misplaced-key"
                && d.location.line == Some(4)
                && d.location.key.as_deref() == Some("rust_name")),
        "{}",
        bad.diagnostics.render()
    );
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}",
        loaded.diagnostics.render()
    );
    let device = loaded.device.expect("a device");
    let paths = paths(&code_of(&device));
    for expected in ["od::MaxSpeed", "od::gains", "od::gains::ProportionalGain"] {
        assert!(paths.contains(expected), "`{expected}`: {paths:#?}");
    }
    // Sub 0 of the record is not renamed by the module's pin.
    assert!(
        paths.contains("od::gains::HighestSubIndexSupported"),
        "{paths:#?}"
    );
}
