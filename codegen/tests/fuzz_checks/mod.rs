//! The bodies of the codegen fuzz targets: each takes arbitrary bytes, reads
//! them as a device (EDS/DCF or YAML object table) and, when the reading has
//! no error, runs the rest of what a build script does with the device: the
//! Rust generator (which formats its output with prettyplease), the rendered
//! diagnostics and the `cargo:` lines. They panic only when a property is
//! broken. The cargo-fuzz targets in codegen/fuzz run them coverage-guided;
//! tests/fuzz_replay.rs replays the committed corpora through them in CI.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use eds2rust::build::{cargo_lines, error_lines};
use eds2rust::r#gen::rust::{self, HEADER};
use eds2rust::read::{Loaded, Options};

/// The name the input has in diagnostics.
const EDS_NAME: &str = "fuzz.eds";
const YAML_NAME: &str = "fuzz.yaml";

/// Where a table's `base:` is resolved: the malformed-YAML fixtures, which
/// hold a small valid EDS (`base_ok.eds`) for overlays to apply on. The
/// bodies run from two packages (codegen's tests and codegen/fuzz), so the
/// directory is found from either manifest directory.
pub fn base_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
        let rel = Path::new("tests/fixtures/malformed_yaml");
        [manifest.join(rel), manifest.join("..").join(rel)]
            .into_iter()
            .find(|p| p.join("base_ok.eds").is_file())
            .expect("codegen/tests/fixtures/malformed_yaml/base_ok.eds")
    })
}

/// The EDS/DCF reader on raw bytes (it decodes UTF-8 and Latin-1 itself).
pub fn eds_reader(data: &[u8]) {
    let loaded = eds2rust::eds::read_bytes(EDS_NAME, data, &Options::lenient());
    check_loaded(&loaded, EDS_NAME);
    build(&loaded);
}

/// The YAML table reader on raw bytes (it rejects what is not UTF-8 with a
/// diagnostic); a `base:` is resolved in [`base_dir`].
pub fn yaml_reader(data: &[u8]) {
    let loaded = eds2rust::table::read_bytes(YAML_NAME, data, base_dir(), &Options::lenient());
    check_loaded(&loaded, YAML_NAME);
    build(&loaded);
}

/// What holds for every result of reading: a device unless nothing could be
/// read, every diagnostic renders, and an error is said.
fn check_loaded(loaded: &Loaded, name: &str) {
    let rendered = loaded.diagnostics.render();
    assert!(
        loaded.diagnostics.is_empty() || !rendered.is_empty(),
        "diagnostics render to nothing"
    );
    if loaded.device.is_none() {
        assert!(
            loaded.diagnostics.has_errors(),
            "no device and no error for {name}"
        );
    }
    for line in error_lines(&loaded.diagnostics) {
        assert!(
            !line.contains('\n'),
            "a cargo line with a line break: {line:?}"
        );
    }
}

/// The build script's pipeline after reading: a device read without error
/// is generated and formatted; the generated file must parse as Rust again,
/// and its warnings render and fold into single `cargo:` lines.
fn build(loaded: &Loaded) {
    let Some(device) = &loaded.device else { return };
    if loaded.diagnostics.has_errors() {
        return;
    }
    match rust::generate(device, &rust::Options::default()) {
        Ok(output) => {
            assert!(output.code.starts_with(HEADER), "no header line");
            if let Err(err) = syn::parse_file(&output.code) {
                panic!("the generated code does not parse: {err}");
            }
            let _ = output.warnings.render();
            for line in cargo_lines(&loaded.files, &output.warnings, None) {
                assert!(
                    !line.contains('\n'),
                    "a cargo line with a line break: {line:?}"
                );
            }
        }
        Err(errors) => {
            assert!(errors.has_errors(), "generation failed without an error");
            let _ = errors.render();
            let _ = error_lines(&errors);
        }
    }
}
