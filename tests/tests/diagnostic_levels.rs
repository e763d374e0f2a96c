//! Diagnostics a user controls, on a real vendor DCF of ../shared/eds-corpus
//! (Elmo Gold drive: the base warns that 0x1601 sub 1 maps the UNSIGNED64
//! 0x2012 with 32 bits, and that `[PreDefines]` is not a CiA 306 section):
//! an overlay leaves the base's severities and locations alone; rule levels
//! from the builder, the YAML `diagnostics:` section and the command line;
//! folded build-script warnings with the full list in OUT_DIR; errors
//! before warnings; "did you mean".

use std::path::{Path, PathBuf};

use eds2rust::build::{Builder, generate_device, generate_device_with};
use eds2rust::diag::{Diagnostic, Levels, Severity};
use eds2rust::r#gen::rust::Options;
use eds2rust_tests::{corpus_files, target_dir};

const DCF: &str = "elmo_gold-drive_ros-test-utils.dcf";

fn dcf(what: &str) -> Option<PathBuf> {
    let files = corpus_files(what)?;
    Some(
        files
            .into_iter()
            .find(|f| f.ends_with(DCF))
            .expect("the Elmo DCF is in the corpus"),
    )
}

fn scratch(name: &str) -> PathBuf {
    let dir = target_dir().join("diagnostic-levels").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The DCF built as device `drive` into `out`, with the rule levels
/// `levels` sets, without cargo's output.
fn build_drive(
    dcf: &Path,
    out: PathBuf,
    levels: impl FnOnce(&mut Builder) -> &mut Builder,
) -> Result<eds2rust::build::Report, eds2rust::build::Error> {
    let mut builder = Builder::new();
    levels(builder.device("drive", dcf))
        .out_dir(out)
        .cargo_output(false)
        .build()
}

fn of_code<'a>(diags: impl IntoIterator<Item = &'a Diagnostic>, code: &str) -> Vec<&'a Diagnostic> {
    diags.into_iter().filter(|d| d.code == code).collect()
}

const RENAME: &str = "format: 1\nmodify:\n  - { index: 0x6041, sub: 0, name: Statusword }\n";

#[test]
fn an_overlay_leaves_the_base_warnings_alone() {
    let Some(dcf) = dcf("overlay severity test") else {
        return;
    };
    let dir = scratch("severity");
    let overlay = write(&dir, "rename.yaml", RENAME);
    let plain = generate_device(&dcf, &[], &Options::default())
        .result
        .unwrap();
    let with = generate_device(&dcf, &[overlay], &Options::default())
        .result
        .unwrap_or_else(|e| panic!("the overlay must not fail the build:\n{e}"));
    for output in [&plain, &with] {
        let mapping = of_code(output.warnings.iter(), "eds::pdo-mapping");
        assert_eq!(mapping.len(), 1, "{}", output.warnings.render());
        let w = mapping[0];
        assert_eq!(w.severity, Severity::Warning);
        assert_eq!(w.file, dcf.display().to_string(), "points at the base file");
        assert_eq!(w.location.line, Some(838));
        assert_eq!(w.location.key.as_deref(), Some("DefaultValue"));
        assert!(
            w.notes.iter().any(|n| n.contains("0x20120040")),
            "the fix is named: {:?}",
            w.notes
        );
    }
    assert!(of_code(with.warnings.iter(), "table::pdo-mapping").is_empty());
    assert_eq!(plain.warnings.len(), with.warnings.len());
}

#[test]
fn the_named_fix_removes_the_warning() {
    let Some(dcf) = dcf("overlay fix test") else {
        return;
    };
    let plain = generate_device(&dcf, &[], &Options::default())
        .result
        .unwrap();
    let note = &of_code(plain.warnings.iter(), "eds::pdo-mapping")[0].notes;
    let fix = note
        .iter()
        .find_map(|n| n.split('`').nth(1))
        .expect("a note with the overlay line in backticks");
    let dir = scratch("fix");
    let overlay = write(&dir, "fix.yaml", &format!("format: 1\n{fix}\n"));
    let fixed = generate_device(&dcf, &[overlay], &Options::default())
        .result
        .unwrap_or_else(|e| panic!("{fix}:\n{e}"));
    assert!(of_code(fixed.warnings.iter(), "eds::pdo-mapping").is_empty());
    assert!(of_code(fixed.warnings.iter(), "table::pdo-mapping").is_empty());
    // With the mapping fixed, RPDO2 gets its struct.
    assert!(of_code(fixed.warnings.iter(), "gen::pdo-skipped").is_empty());
}

#[test]
fn a_base_mapping_the_overlay_breaks_is_an_error_at_the_overlay_change() {
    let Some(dcf) = dcf("overlay breakage test") else {
        return;
    };
    let dir = scratch("breaks");
    let text = "format: 1\nnotes: [widens the statusword]\nmodify:\n  - { index: 0x6041, sub: 0, type: UNSIGNED32 }\n";
    let overlay = write(&dir, "widen.yaml", text);
    let err = generate_device(&dcf, std::slice::from_ref(&overlay), &Options::default())
        .result
        .unwrap_err();
    let errors = of_code(err.iter(), "table::pdo-mapping");
    assert!(!errors.is_empty(), "{}", err.render());
    for e in errors {
        assert_eq!(e.file, overlay.display().to_string());
        assert_eq!(
            e.location.line,
            Some(4),
            "the modify line, not the end of the file"
        );
        assert!(
            e.message.contains(&format!("{}:", dcf.display())),
            "{}",
            e.message
        );
    }
    // The base's own warning is still a warning.
    let base = of_code(err.iter(), "eds::pdo-mapping");
    assert!(base.iter().all(|d| d.severity == Severity::Warning));
}

#[test]
fn builder_allow_and_deny() {
    let Some(dcf) = dcf("builder allow/deny test") else {
        return;
    };
    let dir = scratch("builder");
    let report = build_drive(&dcf, dir.join("out"), |b| b.allow("eds::unknown-section")).unwrap();
    assert!(of_code(report.warnings.iter(), "eds::unknown-section").is_empty());
    assert_eq!(report.warnings.allowed_count(), 1);
    assert_eq!(of_code(report.warnings.iter(), "eds::pdo-mapping").len(), 1);

    let err = build_drive(&dcf, dir.join("out2"), |b| b.deny("eds::pdo-mapping")).unwrap_err();
    let text = err.to_string();
    let first = text.lines().next().unwrap();
    assert!(
        first.starts_with(&format!(
            "1 error in {}: [1601sub1] DefaultValue:",
            dcf.display()
        )),
        "{text}"
    );
    let error_at = text
        .find("error[eds::pdo-mapping]")
        .expect("rendered error");
    let warning_at = text
        .find("warning[eds::unknown-section]")
        .expect("rendered warning");
    assert!(error_at < warning_at, "errors before warnings:\n{text}");
    assert!(text.contains("is denied by the build script"), "{text}");
    assert!(!dir.join("out2/drive.rs").exists(), "nothing written");
    let cargo = err.cargo_lines();
    assert!(
        cargo
            .iter()
            .any(|l| l.starts_with("cargo::error=1 error in ")),
        "{cargo:?}"
    );

    let err =
        build_drive(&dcf, dir.join("out3"), |b| b.allow("eds::unknown-sections")).unwrap_err();
    let unknown = of_code(err.diagnostics().iter(), "build::unknown-rule");
    assert_eq!(unknown.len(), 1);
    assert!(
        unknown[0]
            .message
            .contains("did you mean `eds::unknown-section`?"),
        "{}",
        unknown[0].message
    );
}

#[test]
fn a_yaml_diagnostics_section_scopes_levels_to_its_device() {
    let Some(dcf) = dcf("YAML diagnostics section test") else {
        return;
    };
    let dir = scratch("yaml");
    let text = format!(
        "{RENAME}diagnostics:\n  allow: [eds::unknown-section]\n  deny: [eds::pdo-mapping]\n"
    );
    let overlay = write(&dir, "levels.yaml", &text);
    let err = generate_device(&dcf, std::slice::from_ref(&overlay), &Options::default())
        .result
        .unwrap_err();
    assert!(of_code(err.iter(), "eds::unknown-section").is_empty());
    let denied = of_code(err.iter(), "eds::pdo-mapping");
    assert_eq!(denied[0].severity, Severity::Error);
    assert_eq!(denied[0].file, dcf.display().to_string());

    // The caller's word wins over the file's.
    let mut levels = Levels::new();
    levels.allow("eds::pdo-mapping", "--allow");
    let output = generate_device_with(&dcf, &[overlay], &Options::default(), &levels)
        .result
        .unwrap();
    assert!(of_code(output.warnings.iter(), "eds::pdo-mapping").is_empty());
    assert!(of_code(output.warnings.iter(), "eds::unknown-section").is_empty());

    // Another device of the same build is not affected.
    let report = Builder::new()
        .device("with_levels", &dcf)
        .overlay(dir.join("levels.yaml"))
        .allow("eds::pdo-mapping")
        .device("without", &dcf)
        .out_dir(dir.join("out"))
        .cargo_output(false)
        .build()
        .unwrap();
    assert_eq!(
        of_code(report.warnings.iter(), "eds::unknown-section").len(),
        1
    );

    // A code that names no rule is an error at its key.
    let bad = write(
        &dir,
        "bad.yaml",
        "format: 1\ndiagnostics:\n  allow: [eds::pdo-maping]\n",
    );
    let err = generate_device(&dcf, &[bad], &Options::default())
        .result
        .unwrap_err();
    let unknown = of_code(err.iter(), "table::unknown-rule");
    assert_eq!(unknown[0].location.line, Some(3));
    assert!(
        unknown[0]
            .message
            .contains("did you mean `eds::pdo-mapping`?")
    );
}

#[test]
fn repeated_warnings_fold_into_one_cargo_line_with_the_full_list_in_out_dir() {
    let Some(files) = corpus_files("folded cargo warnings test") else {
        return;
    };
    let sample = files
        .into_iter()
        .find(|f| f.ends_with("python-canopen_sample.eds"))
        .unwrap();
    let dir = scratch("folded");
    let report = Builder::new()
        .device("sample", &sample)
        .out_dir(dir.join("out"))
        .cargo_output(false)
        .build()
        .unwrap();
    let mapping = of_code(report.warnings.iter(), "eds::pdo-mapping").len();
    assert!(mapping > 3, "the sample has many mapping warnings");
    let lines = report.cargo_lines();
    let folded: Vec<_> = lines
        .iter()
        .filter(|l| l.contains("warnings[eds::pdo-mapping]"))
        .collect();
    assert_eq!(folded.len(), 1, "{lines:#?}");
    let list = report.warnings_file.clone().expect("a warnings file");
    assert_eq!(list, dir.join("out/eds2rust-warnings.txt"));
    assert!(
        folded[0].contains(&list.display().to_string()),
        "{}",
        folded[0]
    );
    assert!(folded[0].starts_with(&format!("cargo:warning={mapping} warnings")));
    let text = std::fs::read_to_string(&list).unwrap();
    assert_eq!(text.matches("warning[eds::pdo-mapping]").count(), mapping);
    let warning_lines = lines
        .iter()
        .filter(|l| l.starts_with("cargo:warning="))
        .count();
    assert!(warning_lines < report.warnings.len());
}

#[test]
fn an_unknown_yaml_key_gets_a_suggestion() {
    let dir = scratch("did-you-mean");
    let table = write(&dir, "typo.yaml", "format: 1\nsemantic: []\n");
    let loaded = eds2rust::input::read_device(&table, &eds2rust::input::Options::default());
    let d = loaded.diagnostics.iter().next().expect("a syntax error");
    assert_eq!(d.code, "table::syntax");
    assert!(
        d.notes.iter().any(|n| n == "did you mean `semantics`?"),
        "{:?}",
        d.notes
    );
}
