//! The bodies of the codegen fuzz targets: each takes arbitrary bytes, reads
//! them as a device (EDS/DCF or YAML object table) and, when the reading has
//! no error, runs the rest of what a build script does with the device: the
//! Rust generator (which formats its output with prettyplease), the rendered
//! diagnostics and the `cargo:` lines; or reads them as a bus file
//! ([`bus_reader`]). They panic only when a property is
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
const BUS_NAME: &str = "fuzz_bus.yml";

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

/// The reading options of the bodies: lenient, the project being
/// [`base_dir`] (wherever the fuzzer runs), so that a `base:` may lead only
/// there.
fn options() -> Options {
    Options {
        project_dir: Some(base_dir().to_path_buf()),
        ..Options::lenient()
    }
}

/// The EDS/DCF reader on raw bytes (it decodes UTF-8 and Latin-1 itself),
/// then the same bytes from a file through the bounded reader ([`size_limit`]).
pub fn eds_reader(data: &[u8]) {
    let loaded = eds2rust::eds::read_bytes(EDS_NAME, data, &options());
    check_loaded(&loaded, EDS_NAME);
    build(&loaded);
    size_limit(data);
}

/// The YAML table reader on raw bytes (it rejects what is not UTF-8 with a
/// diagnostic); a `base:` is resolved in [`base_dir`]. Then the bytes as
/// the path of a `base:` ([`hostile_base`]).
pub fn yaml_reader(data: &[u8]) {
    let loaded = eds2rust::table::read_bytes(YAML_NAME, data, base_dir(), &options());
    check_loaded(&loaded, YAML_NAME);
    check_confined(&loaded);
    build(&loaded);
    hostile_base(data);
}

/// The bus file reader on raw bytes, device files resolved in
/// [`base_dir`] (where `base_ok.eds` is): it returns, a bus unless an
/// error says why not, every error of the bus file past its syntax names
/// a line, the model keeps to the ranges the reader promises, and the
/// diagnostics render without terminal hazards or the environment.
pub fn bus_reader(data: &[u8]) {
    let loaded = eds2rust::network::read_bytes(BUS_NAME, data, base_dir(), &options());
    let rendered = loaded.diagnostics.render();
    assert!(
        !rendered.chars().any(is_terminal_hazard),
        "the diagnostics render a control or bidi character: {rendered:?}"
    );
    check_no_environment(&rendered, data);
    for line in error_lines(&loaded.diagnostics) {
        assert!(
            !line.contains('\n'),
            "a cargo line with a line break: {line:?}"
        );
    }
    for d in loaded.diagnostics.iter() {
        if d.file == BUS_NAME && d.code != "net::syntax" {
            assert!(d.location.line.is_some(), "no line: {d}");
        }
    }
    let Some(bus) = &loaded.bus else {
        assert!(loaded.diagnostics.has_errors(), "no bus and no error");
        return;
    };
    assert!(bus.slaves.len() <= 127, "{} slaves", bus.slaves.len());
    let mut names = std::collections::BTreeSet::new();
    for slave in &bus.slaves {
        assert!(names.insert(&slave.name), "slave {} twice", slave.name);
        if let Some(id) = &slave.node_id {
            assert!((1..=127).contains(&id.value), "node id {}", id.value);
        }
        for number in slave.rpdo.keys().chain(slave.tpdo.keys()) {
            assert!((1..=512).contains(number), "PDO {number}");
        }
    }
    // The configuration and the whole-bus check return on any bus, and
    // each check diagnostic names the bus file.
    let (configured, _) = eds2rust::network::configure(bus);
    let limits = eds2rust::network::check::CheckLimits::default();
    let checked = eds2rust::network::check::check(bus, &configured, &limits);
    for d in checked.iter() {
        assert_eq!(d.file, BUS_NAME, "{d}");
    }
    let _ = eds2rust::network::check::bus_load(bus, &configured).to_string();
}

/// Paths an attacker would name in `base:`; each fuzz input is tried as a
/// path on its own and appended to each of these.
const HOSTILE_BASES: &[&str] = &[
    "../../../..",
    "../../../../Cargo.toml",
    "../../../../../../../../../../etc/passwd",
    "/etc/passwd",
    "/dev/zero",
    "/dev/stdin",
    "/proc/self/environ",
    "/sys/kernel/notes",
    "/",
];

/// A table whose `base:` is a hostile path or the data itself (one line,
/// quoted as a YAML string): the reader returns, reads no file outside
/// [`base_dir`] and quotes nothing of the environment.
pub fn hostile_base(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let line: String = text.chars().take(256).filter(|c| !c.is_control()).collect();
    let mut paths = vec![line.clone()];
    for hostile in HOSTILE_BASES {
        paths.push(hostile.to_string());
        paths.push(format!("{hostile}/{line}"));
    }
    for path in paths {
        let quoted = path.replace('\\', "\\\\").replace('"', "\\\"");
        let table = format!("format: 1\nbase: \"{quoted}\"\n");
        let loaded =
            eds2rust::table::read_bytes(YAML_NAME, table.as_bytes(), base_dir(), &options());
        check_loaded(&loaded, YAML_NAME);
        check_confined(&loaded);
    }
}

/// Every file the result lists (read or tried) lies inside [`base_dir`] or
/// does not exist, and no diagnostic quotes a variable of the environment
/// (what `/proc/self/environ` holds).
fn check_confined(loaded: &Loaded) {
    static ROOT: OnceLock<PathBuf> = OnceLock::new();
    let root = ROOT.get_or_init(|| std::fs::canonicalize(base_dir()).expect("base_dir"));
    for file in &loaded.files {
        if let Ok(real) = std::fs::canonicalize(file) {
            assert!(
                real.starts_with(root),
                "a file outside the allowed directory was read: {}",
                real.display()
            );
        }
    }
    check_no_environment(&loaded.diagnostics.render(), b"");
}

/// No rendered diagnostic quotes a variable of the environment (what
/// `/proc/self/environ` holds) that the input itself does not hold (the
/// fuzzer learns the values this check compares with and writes them into
/// its inputs, which diagnostics may quote).
fn check_no_environment(rendered: &str, input: &[u8]) {
    let input = String::from_utf8_lossy(input);
    for (key, value) in std::env::vars() {
        if value.len() >= 8 {
            let pair = format!("{key}={value}");
            assert!(
                !rendered.contains(&pair) || input.contains(&pair),
                "the environment is quoted ({key})"
            );
        }
    }
}

/// The limit of [`size_limit`]: small, so that the fuzzer's inputs cross it.
const TINY_LIMIT: u64 = 64;

/// The data written to a file and read back through the bounded reader
/// with a tiny limit: the bytes come back exactly when they fit, and
/// `input::too-large` is reported exactly when they do not.
pub fn size_limit(data: &[u8]) {
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path =
        std::env::temp_dir().join(format!("eds2rust-fuzz-size-{}-{n}.eds", std::process::id()));
    std::fs::write(&path, data).expect("write the temporary file");
    let len = u64::try_from(data.len()).unwrap_or(u64::MAX);
    let read = eds2rust::bounded::read_input(&path, TINY_LIMIT);
    if len <= TINY_LIMIT {
        assert_eq!(read.expect("a file within the limit is read"), data);
    } else {
        assert!(
            matches!(read, Err(eds2rust::bounded::Refused::TooLarge { .. })),
            "a file above the limit is refused"
        );
    }
    let options = Options {
        max_input_size: TINY_LIMIT,
        ..options()
    };
    let loaded = eds2rust::eds::read_file(&path, &options);
    let _ = std::fs::remove_file(&path);
    let too_large = loaded
        .diagnostics
        .iter()
        .any(|d| d.code == "input::too-large");
    assert_eq!(
        too_large,
        len > TINY_LIMIT,
        "input::too-large iff above the limit"
    );
    check_loaded(&loaded, "size");
}

/// What holds for every result of reading: a device unless nothing could be
/// read, every diagnostic renders, and an error is said.
fn check_loaded(loaded: &Loaded, name: &str) {
    let rendered = loaded.diagnostics.render();
    assert!(
        loaded.diagnostics.is_empty() || !rendered.is_empty(),
        "diagnostics render to nothing"
    );
    assert!(
        !rendered.chars().any(is_terminal_hazard),
        "{name}: the diagnostics render a control or bidi character: {rendered:?}"
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
            // rustc rejects bidirectional-text characters in comments and
            // literals (deny-by-default lints): none may reach the file.
            if let Some(c) = output.code.chars().find(|&c| eds2rust::text::is_bidi(c)) {
                panic!("the generated code holds U+{:04X}", c as u32);
            }
            // Terminal text: every rendered diagnostic is free of control
            // and bidirectional characters (but line breaks).
            let rendered = output.warnings.render();
            assert!(
                !rendered.chars().any(is_terminal_hazard),
                "a warning renders a control or bidi character: {rendered:?}"
            );
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

/// A character no rendered diagnostic may hold: a control character (but
/// line feeds, tabs and the carriage returns of CR LF source lines) or a
/// bidirectional-text control.
fn is_terminal_hazard(c: char) -> bool {
    eds2rust::text::is_hazard(c) && c != '\r'
}
