//! The build-script API: `eds2rust::Builder`, the pure `eds2rust::generate`,
//! overlays given to the builder (`table::apply_overlay`) and the files read.
//!
//! These tests assert behaviour (what is written, when, which diagnostics),
//! never generated content beyond its `@generated` first line, so that they
//! hold for any generator.

use std::path::{Path, PathBuf};

use eds2rust::build::{Report, cargo_lines, generate_device_reading};
use eds2rust::diag::Severity;
use eds2rust::r#gen::rust::Options as GenOptions;
use eds2rust::input::{Options, read_device};
use eds2rust::ir::Value;
use eds2rust::{Builder, Error};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path)
}

/// A fresh, empty directory for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("builder-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

fn build(builder: &mut Builder) -> Result<Report, Error> {
    builder.cargo_output(false).build()
}

fn codes(err: &Error) -> Vec<&'static str> {
    codes_of(err.diagnostics())
}

fn codes_of(d: &eds2rust::diag::Diagnostics) -> Vec<&'static str> {
    d.iter().map(|d| d.code).collect()
}

/// An EDS with warnings only (a repeated key at line 6, an object not
/// listed): fine unless strict.
const WARN_EDS: &str = "[1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x10\nDefaultValue=0x10\n";

/// An overlay without `base:` on eds/example.eds.
const OVERLAY: &str = "format: 1\nmodify:\n  - { index: 0x6060, default: 3 }\n  - { index: 0x1018, sub: 1, name: Vendor id from the overlay }\n";

#[test]
fn writes_the_file_and_rewrites_it_only_when_it_changes() {
    let out = scratch("write");
    let mut builder = Builder::new();
    builder
        .device("linak", repo("eds/linak_techline.yaml"))
        .out_dir(&out);
    let report = build(&mut builder).unwrap();
    let file = out.join("linak.rs");
    assert_eq!(report.written, [file.as_path()]);
    assert!(report.unchanged.is_empty());
    let code = std::fs::read_to_string(&file).unwrap();
    assert!(code.starts_with("// @generated"), "{code}");
    assert_eq!(listing(&out), ["linak.rs"], "no temporary file left");

    // Other bytes in the file: replaced by the generated ones.
    std::fs::write(&file, "stale").unwrap();
    let report = build(&mut builder).unwrap();
    assert_eq!(report.written, [file.as_path()]);
    assert_eq!(std::fs::read_to_string(&file).unwrap(), code);

    // The same bytes: not written again, so cargo does not rebuild.
    let before = std::fs::metadata(&file).unwrap().modified().unwrap();
    builder.generate().unwrap();
    let report = build(&mut builder).unwrap();
    assert!(report.written.is_empty());
    assert_eq!(report.unchanged, [file.as_path()]);
    assert_eq!(
        std::fs::metadata(&file).unwrap().modified().unwrap(),
        before
    );
}

#[test]
fn a_missing_input_is_an_error_naming_it_and_nothing_is_written() {
    let out = scratch("missing");
    let missing = out.join("no_such_device.eds");
    let mut builder = Builder::new();
    builder
        .device("good", repo("eds/example.eds"))
        .device("missing", &missing)
        .out_dir(&out);
    let err = build(&mut builder).unwrap_err();
    assert!(format!("{err}").contains("no_such_device.eds"), "{err}");
    assert!(format!("{err:?}").contains("no_such_device.eds"), "{err:?}");
    assert_eq!(codes(&err), ["io"]);
    assert_eq!(err.files_read().last(), Some(&missing));
    assert!(
        listing(&out).is_empty(),
        "nothing written: {:?}",
        listing(&out)
    );
    // As a build script's `main` returns it.
    let boxed: Box<dyn std::error::Error> = Box::new(err);
    assert!(format!("{boxed:?}").contains("no_such_device.eds"));
}

#[test]
fn a_malformed_input_is_an_error_with_file_and_line() {
    let out = scratch("malformed");
    let bad = write(
        &out,
        "bad.yaml",
        "format: 1\ndevice: { vendor_name: V, product_name: P }\nobjects:\n  - { index: 0x2000, name: A, type: UINT16, access: rw }\n",
    );
    let fixture = repo("codegen/tests/fixtures/malformed/bad_access_type.eds");
    let mut builder = Builder::new();
    builder
        .device("bad", &bad)
        .device("bad_access", &fixture)
        .out_dir(out.join("gen"));
    let err = build(&mut builder).unwrap_err();
    let (display, debug) = (err.to_string(), format!("{err:?}"));
    for text in [&display, &debug] {
        assert!(text.contains("bad.yaml:4:"), "{text}");
        assert!(text.contains("table::bad-type"), "{text}");
        // Both devices are reported, not only the first.
        assert!(text.contains("bad_access_type.eds:"), "{text}");
    }
    assert!(!out.join("gen").exists(), "nothing written");
}

#[test]
fn strict_turns_a_warning_into_an_error() {
    let out = scratch("strict");
    let input = write(&out, "warn.eds", WARN_EDS);
    let mut builder = Builder::new();
    builder.device("warn", &input).out_dir(out.join("gen"));
    let report = build(&mut builder).unwrap();
    assert!(report.warnings.warning_count() >= 1 && !report.warnings.has_errors());
    let lines = report.cargo_lines();
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("cargo:warning=") && l.contains("warn.eds:6:")),
        "{lines:?}"
    );

    let err = build(builder.strict(true)).unwrap_err();
    assert!(err.diagnostics().has_errors());
    assert!(err.to_string().contains("warn.eds:6:"), "{err}");

    // The pure function agrees.
    let strict = GenOptions {
        strict: true,
        ..GenOptions::default()
    };
    assert!(eds2rust::generate(&input, &[], &GenOptions::default()).is_ok());
    assert!(eds2rust::generate(&input, &[], &strict).is_err());
}

#[test]
fn builder_usage_errors_are_diagnostics() {
    let out = scratch("usage");
    let example = repo("eds/example.eds");
    for name in ["Drive", "my-drive", "", "type", "2nd"] {
        let mut builder = Builder::new();
        builder.device(name, &example).out_dir(&out);
        let err = build(&mut builder).unwrap_err();
        assert_eq!(codes(&err), ["build::device-name"], "{name}: {err}");
    }
    let mut builder = Builder::new();
    builder
        .device("twice", &example)
        .device("twice", &example)
        .out_dir(&out);
    assert_eq!(
        codes(&build(&mut builder).unwrap_err()),
        ["build::device-name"]
    );

    let overlay = write(&out, "overlay.yaml", OVERLAY);
    let mut builder = Builder::new();
    builder
        .overlay(&overlay)
        .device("drive", &example)
        .out_dir(&out);
    let err = build(&mut builder).unwrap_err();
    assert_eq!(codes(&err), ["build::overlay-without-device"]);
    assert!(err.to_string().contains("overlay.yaml"), "{err}");

    if std::env::var_os("OUT_DIR").is_none() {
        let mut builder = Builder::new();
        builder.device("drive", &example);
        let err = build(&mut builder).unwrap_err();
        assert_eq!(codes(&err), ["build::out-dir"]);
    }
    assert_eq!(listing(&out), ["overlay.yaml"], "nothing written");
}

#[test]
fn an_overlay_without_base_applies_on_the_device() {
    let dir = scratch("overlay");
    let overlay = write(&dir, "overlay.yaml", OVERLAY);
    let loaded = read_device(&repo("eds/example.eds"), &Options::default());
    let base = loaded.device.unwrap();
    let applied = eds2rust::table::apply_overlay(base, &overlay, &Options::default());
    assert!(applied.diagnostics.is_empty(), "{}", applied.diagnostics);
    assert_eq!(applied.files, [overlay.as_path()]);
    let device = applied.device.unwrap();
    let entry = |index: u16, sub: u8| &device.objects[&index].entries[&sub];
    let default = entry(0x6060, 0).default.as_ref().unwrap();
    assert_eq!(default.value, Value::Integer(3));
    assert_eq!(entry(0x1018, 1).name, "Vendor id from the overlay");
    assert_eq!(
        entry(0x1018, 1).default.as_ref().unwrap().value,
        Value::Integer(0xE2D),
        "what the overlay does not name stays"
    );

    // Through the pure function and the builder.
    let example = repo("eds/example.eds");
    let code = eds2rust::generate(
        &example,
        std::slice::from_ref(&overlay),
        &GenOptions::default(),
    )
    .unwrap();
    assert!(code.starts_with("// @generated"), "{code}");
    let mut builder = Builder::new();
    builder
        .device("drive", &example)
        .overlay(&overlay)
        .out_dir(dir.join("gen"));
    assert!(build(&mut builder).is_ok());

    // An overlay's errors are the builder's errors, with file and line.
    let bad = write(
        &dir,
        "bad_overlay.yaml",
        "format: 1\nmodify:\n  - { index: 0x7777, default: 3 }\n",
    );
    let err = eds2rust::generate(&example, &[overlay, bad], &GenOptions::default()).unwrap_err();
    assert!(err.has_errors());
    assert!(err.to_string().contains("bad_overlay.yaml:3:"), "{err}");
}

#[test]
fn an_overlay_with_its_own_base_is_an_error_at_the_base_key() {
    let dir = scratch("overlay_base");
    std::fs::copy(repo("eds/example.eds"), dir.join("other.eds")).unwrap();
    let overlay = write(
        &dir,
        "with_base.yaml",
        "format: 1\nbase: other.eds\nmodify:\n  - { index: 0x6060, default: 2 }\n",
    );
    let mut builder = Builder::new();
    builder
        .device("drive", repo("eds/example.eds"))
        .overlay(&overlay)
        .out_dir(dir.join("gen"));
    let err = build(&mut builder).unwrap_err();
    assert_eq!(codes(&err), ["table::overlay-base"]);
    let d = err.diagnostics().iter().next().unwrap();
    assert_eq!(d.severity, Severity::Error);
    assert_eq!(d.location.line, Some(2));
    assert!(err.to_string().contains("with_base.yaml:2:"), "{err}");
    assert!(
        !err.files_read().contains(&dir.join("other.eds")),
        "the second base is not read: {:?}",
        err.files_read()
    );
    assert!(!dir.join("gen").exists());
}

#[test]
fn files_read_include_a_tables_base_each_once_in_order() {
    let dir = scratch("files");
    let base = dir.join("base.eds");
    std::fs::copy(repo("eds/example.eds"), &base).unwrap();
    let table = write(
        &dir,
        "table.yaml",
        "format: 1\nbase: base.eds\nmodify:\n  - { index: 0x6060, default: 2 }\n",
    );
    let overlay = write(&dir, "overlay.yaml", OVERLAY);

    // The scratch directory lies outside the project: its `base:` is
    // refused unless allowed.
    let refused = read_device(&table, &Options::default());
    assert_eq!(codes_of(&refused.diagnostics), ["table::base-outside"]);
    assert_eq!(refused.files, std::slice::from_ref(&table));
    let allowed = Options {
        allow_base_dirs: vec![dir.clone()],
        ..Options::default()
    };
    let loaded = read_device(&table, &allowed);
    assert!(loaded.diagnostics.is_empty(), "{}", loaded.diagnostics);
    assert_eq!(loaded.files, [table.clone(), base.clone()]);
    assert_eq!(
        read_device(&base, &Options::default()).files,
        [base.as_path()]
    );

    let generated = generate_device_reading(
        &table,
        std::slice::from_ref(&overlay),
        &GenOptions::default(),
        &allowed,
    );
    assert!(generated.result.is_ok());
    assert_eq!(
        generated.files,
        [table.clone(), base.clone(), overlay.clone()]
    );

    // Two devices sharing files: each file once, in first-read order.
    let mut builder = Builder::new();
    builder
        .device("first", &table)
        .overlay(&overlay)
        .device("second", &base)
        .overlay(&overlay)
        .allow_base_dir(&dir)
        .out_dir(dir.join("gen"));
    let report = build(&mut builder).unwrap();
    let expected = [table, base, overlay];
    assert_eq!(report.files_read, expected);
    let rerun: Vec<String> = expected
        .iter()
        .map(|f| format!("cargo:rerun-if-changed={}", f.display()))
        .collect();
    // The rerun lines first, then the warnings (if any).
    let lines = report.cargo_lines();
    assert_eq!(lines[..rerun.len()], rerun);
    assert!(
        lines[rerun.len()..]
            .iter()
            .all(|l| l.starts_with("cargo:warning=")),
        "{lines:?}"
    );
    assert_eq!(
        cargo_lines(
            &report.files_read,
            &report.warnings,
            report.warnings_file.as_deref()
        ),
        lines
    );
    assert_eq!(listing(&dir.join("gen")), ["first.rs", "second.rs"]);
}
