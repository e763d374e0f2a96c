//! The build-script API, in the shape of prost-build.
//!
//! ```no_run
//! // build.rs
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     eds2rust::Builder::new()
//!         .device("drive", "od/drive.eds")
//!         .overlay("od/drive_fixes.yaml")
//!         .generate()?;
//!     Ok(())
//! }
//! // src/lib.rs: pub mod drive { include!(concat!(env!("OUT_DIR"), "/drive.rs")); }
//! ```
//!
//! Layers, each usable on its own:
//! - [`generate_device`]: one input, its overlays, the generator — pure but
//!   for reading the files; returns the code (or every error) and the files
//!   read. [`generate`] is the same, returning only the code.
//! - [`Builder::build`]: every device through [`generate_device`], then the
//!   output files written (only those whose bytes changed); returns a
//!   [`Report`] or an [`Error`] with every diagnostic of every device. It
//!   prints nothing.
//! - [`Builder::generate`]: [`Builder::build`], then the `cargo:` lines of
//!   the result ([`Report::cargo_lines`], [`Error::cargo_lines`]) on stdout
//!   when running inside a build script.
//!
//! Nothing here panics on any input.

use std::collections::HashSet;
use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::r#gen::rust::{self, Options, Output};
use crate::input::{InputKind, Options as ReadOptions, read_device};
use crate::ir::Device;

/// What generating one device produced.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The code, with every warning of reading and generating in
    /// [`Output::warnings`]; or every diagnostic, at least one an error.
    pub result: Result<Output, Diagnostics>,
    /// Every file read (or tried), in reading order, each once: the input,
    /// a YAML input's `base:` EDS, the overlays.
    pub files: Vec<PathBuf>,
}

/// Reads `input` (EDS/DCF or YAML table), applies the YAML `overlays` in
/// order ([`crate::table::apply_overlay`]) and generates its Rust source.
///
/// The `Err` holds every diagnostic found; with `options.strict` warnings are
/// errors. Use [`generate_device`] to get the warnings of a success and the
/// files read as well.
pub fn generate(
    input: &Path,
    overlays: &[PathBuf],
    options: &Options,
) -> Result<String, Diagnostics> {
    generate_device(input, overlays, options)
        .result
        .map(|output| output.code)
}

/// [`generate`], keeping the warnings and the list of files read.
///
/// The stages stop at the first one with an error: overlays are not read when
/// the input has errors, nor a later overlay when an earlier one has (each
/// would mostly repeat the earlier problem), and nothing is generated.
pub fn generate_device(input: &Path, overlays: &[PathBuf], options: &Options) -> Generated {
    let read = ReadOptions {
        strict: options.strict,
    };
    let (device, mut diagnostics, files) = load(input, overlays, read);
    let result = match device {
        Some(device) if !diagnostics.has_errors() => match rust::generate(&device, options) {
            Ok(mut output) => {
                diagnostics.extend(output.warnings);
                if options.strict && !diagnostics.is_empty() {
                    diagnostics.make_strict();
                    Err(diagnostics)
                } else {
                    output.warnings = diagnostics;
                    Ok(output)
                }
            }
            Err(errors) => {
                diagnostics.extend(errors);
                Err(failed(diagnostics, input))
            }
        },
        _ => Err(failed(diagnostics, input)),
    };
    Generated { result, files }
}

/// Reads the input and applies the overlays, until the first error.
fn load(
    input: &Path,
    overlays: &[PathBuf],
    read: ReadOptions,
) -> (Option<Device>, Diagnostics, Vec<PathBuf>) {
    let loaded = read_device(input, read);
    let mut files = Vec::new();
    push_unique(&mut files, loaded.files);
    let mut diagnostics = loaded.diagnostics;
    let mut device = loaded.device;
    for overlay in overlays {
        if diagnostics.has_errors() {
            break;
        }
        let Some(base) = device.take() else { break };
        if InputKind::of(overlay) != InputKind::Table {
            diagnostics.push(error(
                "build::overlay-not-yaml",
                overlay,
                "an overlay is a YAML object table (.yaml, .yml) without `base:`".into(),
            ));
            break;
        }
        let loaded = crate::table::apply_overlay(base, overlay, read);
        push_unique(&mut files, loaded.files);
        diagnostics.extend(loaded.diagnostics);
        device = loaded.device;
    }
    (device, diagnostics, files)
}

/// `diagnostics` as a failure: with at least one error, whatever the stages
/// reported.
fn failed(mut diagnostics: Diagnostics, input: &Path) -> Diagnostics {
    if !diagnostics.has_errors() {
        diagnostics.push(error(
            "build::no-device",
            input,
            "no device could be generated from this input".into(),
        ));
    }
    diagnostics
}

fn error(code: &'static str, file: &Path, message: String) -> Diagnostic {
    Diagnostic {
        severity: Severity::Error,
        code,
        file: file.display().to_string(),
        location: Location::default(),
        message,
        notes: Vec::new(),
    }
}

fn push_unique(files: &mut Vec<PathBuf>, new: Vec<PathBuf>) {
    for file in new {
        if !files.contains(&file) {
            files.push(file);
        }
    }
}

/// Generates the Rust of CANopen devices from a build script: one
/// `<OUT_DIR>/<name>.rs` per [`device`](Builder::device), for `include!`.
///
/// Every problem is reported when [`generate`](Builder::generate) (or
/// [`build`](Builder::build)) runs, never by a panic: all diagnostics of all
/// devices come back together in one [`Error`].
#[derive(Debug, Clone, Default)]
pub struct Builder {
    devices: Vec<DeviceInput>,
    /// Overlays given before any device.
    orphan_overlays: Vec<PathBuf>,
    runtime_path: Option<String>,
    out_dir: Option<PathBuf>,
    strict: bool,
    cargo_output: Option<bool>,
}

#[derive(Debug, Clone)]
struct DeviceInput {
    name: String,
    input: PathBuf,
    overlays: Vec<PathBuf>,
}

/// What a successful [`Builder::build`] did.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Every file read (or tried), each once, in reading order: by device,
    /// its input, a YAML input's `base:` EDS, then its overlays.
    pub files_read: Vec<PathBuf>,
    /// Output files written because their content changed (or was missing).
    pub written: Vec<PathBuf>,
    /// Output files that already had exactly the generated bytes (untouched).
    pub unchanged: Vec<PathBuf>,
    /// The warnings of every device.
    pub warnings: Diagnostics,
}

impl Report {
    /// The lines a build script prints for cargo: one
    /// `cargo:rerun-if-changed=<path>` per file read, then one
    /// `cargo:warning=<diagnostic>` per warning (see [`cargo_lines`]).
    pub fn cargo_lines(&self) -> Vec<String> {
        cargo_lines(&self.files_read, &self.warnings)
    }
}

/// The `cargo:` lines for `files` read and `warnings`: a
/// `cargo:rerun-if-changed=` line per file, in the order given, then a
/// `cargo:warning=` line per diagnostic, its one-line `Display`. Line breaks
/// and other control characters in either become spaces, so that each is
/// exactly one line.
pub fn cargo_lines(files: &[PathBuf], warnings: &Diagnostics) -> Vec<String> {
    let files = files.iter().map(|f| {
        format!(
            "cargo:rerun-if-changed={}",
            one_line(&f.display().to_string())
        )
    });
    let warnings = warnings
        .iter()
        .map(|w| format!("cargo:warning={}", one_line(&w.to_string())));
    files.chain(warnings).collect()
}

fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// `true` when this process runs as a cargo build script: `CARGO` and
/// `OUT_DIR` are both set.
pub fn in_build_script() -> bool {
    std::env::var_os("CARGO").is_some() && std::env::var_os("OUT_DIR").is_some()
}

impl Builder {
    /// A builder with no device, the default runtime path, not strict,
    /// writing to `OUT_DIR`.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a device read from `input` (EDS/DCF, or YAML table by its
    /// extension), generated into `<out_dir>/<name>.rs`. `name` must be a
    /// snake_case Rust identifier (`[a-z_][a-z0-9_]*`, not a keyword) and
    /// unique; otherwise `generate` reports an error.
    pub fn device(&mut self, name: &str, input: impl AsRef<Path>) -> &mut Self {
        self.devices.push(DeviceInput {
            name: name.to_string(),
            input: input.as_ref().to_path_buf(),
            overlays: Vec::new(),
        });
        self
    }

    /// Adds a YAML overlay table (without `base:`) to the device added last;
    /// overlays apply in the order given, each on the result of the one
    /// before. An overlay before any device is an error at `generate`.
    pub fn overlay(&mut self, path: impl AsRef<Path>) -> &mut Self {
        let path = path.as_ref().to_path_buf();
        match self.devices.last_mut() {
            Some(device) => device.overlays.push(path),
            None => self.orphan_overlays.push(path),
        }
        self
    }

    /// The path of the runtime crate in generated code (default
    /// `::eds2rust_runtime`), for a crate that re-exports the runtime.
    pub fn runtime_path(&mut self, path: &str) -> &mut Self {
        self.runtime_path = Some(path.to_string());
        self
    }

    /// Where to write the `.rs` files (default: the `OUT_DIR` environment
    /// variable; neither is an error). Created when missing.
    pub fn out_dir(&mut self, dir: impl AsRef<Path>) -> &mut Self {
        self.out_dir = Some(dir.as_ref().to_path_buf());
        self
    }

    /// Turns every warning into an error (default `false`).
    pub fn strict(&mut self, strict: bool) -> &mut Self {
        self.strict = strict;
        self
    }

    /// Whether [`generate`](Builder::generate) prints the `cargo:` lines;
    /// by default it does exactly when [`in_build_script`].
    pub fn cargo_output(&mut self, print: bool) -> &mut Self {
        self.cargo_output = Some(print);
        self
    }

    /// [`build`](Builder::build), then the `cargo:` lines of the result on
    /// stdout (see [`cargo_output`](Builder::cargo_output)): the
    /// `rerun-if-changed` lines also on failure, the warnings on success.
    pub fn generate(&self) -> Result<(), Error> {
        let result = self.build();
        if self.cargo_output.unwrap_or_else(in_build_script) {
            let lines = match &result {
                Ok(report) => report.cargo_lines(),
                Err(error) => error.cargo_lines(),
            };
            let mut out = std::io::stdout().lock();
            for line in lines {
                let _ = writeln!(out, "{line}");
            }
        }
        result.map(drop)
    }

    /// Generates every device and writes the output files, printing nothing.
    ///
    /// Every device is read and generated, and every diagnostic collected,
    /// before anything is written; when any has an error, nothing is written
    /// and the [`Error`] holds all diagnostics (warnings included). An output
    /// file is replaced only when its bytes differ, through a temporary file
    /// in the same directory renamed over it, so that a reader never sees
    /// half a file and cargo does not rebuild for nothing.
    pub fn build(&self) -> Result<Report, Error> {
        let mut all = Diagnostics::new();
        let mut report = Report::default();
        for overlay in &self.orphan_overlays {
            all.push(error(
                "build::overlay-without-device",
                overlay,
                "an overlay applies to the device added before it; call `.device(…)` first".into(),
            ));
        }
        let out_dir = self
            .out_dir
            .clone()
            .or_else(|| std::env::var_os("OUT_DIR").map(PathBuf::from));
        if out_dir.is_none() {
            all.push(error(
                "build::out-dir",
                Path::new("eds2rust::Builder"),
                "no output directory: OUT_DIR is not set (not in a build script?) \
                 and no `.out_dir(…)` was given"
                    .into(),
            ));
        }
        let options = Options {
            runtime_path: self
                .runtime_path
                .clone()
                .unwrap_or_else(|| Options::default().runtime_path),
            strict: self.strict,
        };
        let mut names = HashSet::new();
        let mut outputs = Vec::new();
        for device in &self.devices {
            if let Err(message) = check_name(&device.name) {
                all.push(error("build::device-name", &device.input, message));
            } else if !names.insert(device.name.as_str()) {
                all.push(error(
                    "build::device-name",
                    &device.input,
                    format!("device name `{}` is given twice", device.name),
                ));
            }
            let generated = generate_device(&device.input, &device.overlays, &options);
            push_unique(&mut report.files_read, generated.files);
            match generated.result {
                Ok(output) => {
                    report.warnings.extend(output.warnings.clone());
                    all.extend(output.warnings);
                    outputs.push((device.name.as_str(), output.code));
                }
                Err(diagnostics) => all.extend(diagnostics),
            }
        }
        let out_dir = match out_dir {
            Some(dir) if !all.has_errors() => dir,
            _ => return Err(Error::new(all, report.files_read)),
        };
        for (name, code) in outputs {
            let path = out_dir.join(format!("{name}.rs"));
            match write_if_changed(&path, code.as_bytes()) {
                Ok(true) => report.written.push(path),
                Ok(false) => report.unchanged.push(path),
                Err(err) => all.push(error(
                    "build::write",
                    &path,
                    format!("cannot write the generated file: {err}"),
                )),
            }
        }
        if all.has_errors() {
            return Err(Error::new(all, report.files_read));
        }
        Ok(report)
    }
}

/// Rust 2024 keywords (strict, reserved and weak ones that cannot name a
/// module), which are not identifiers.
const KEYWORDS: &[&str] = &[
    "abstract", "as", "async", "await", "become", "box", "break", "const", "continue", "crate",
    "do", "dyn", "else", "enum", "extern", "false", "final", "fn", "for", "gen", "if", "impl",
    "in", "let", "loop", "macro", "match", "mod", "move", "mut", "override", "priv", "pub", "ref",
    "return", "self", "static", "struct", "super", "trait", "true", "try", "type", "typeof",
    "union", "unsafe", "unsized", "use", "virtual", "where", "while", "yield",
];

/// `Ok` when `name` is a snake_case Rust identifier.
fn check_name(name: &str) -> Result<(), String> {
    let shape = name
        .bytes()
        .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_')
        && !name.starts_with(|c: char| c.is_ascii_digit())
        && name.bytes().any(|b| b != b'_');
    if !shape {
        return Err(format!(
            "device name `{}` is not a snake_case Rust identifier \
             (lower-case ASCII letters, digits and `_`, not starting with a digit)",
            name.escape_debug()
        ));
    }
    if KEYWORDS.contains(&name) {
        return Err(format!(
            "device name `{name}` is a Rust keyword; it names a module"
        ));
    }
    Ok(())
}

/// Writes `bytes` to `path` unless it holds them already: `Ok(true)` when
/// written, `Ok(false)` when unchanged.
fn write_if_changed(path: &Path, bytes: &[u8]) -> std::io::Result<bool> {
    if std::fs::read(path).is_ok_and(|old| old == bytes) {
        return Ok(false);
    }
    write_whole(path, bytes)?;
    Ok(true)
}

/// Writes `bytes` to a temporary file beside `path` (creating the directory
/// when missing) and renames it over `path`, so that a reader never sees
/// half a file. Used for every output file the crate writes.
pub fn write_whole(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let dir = path.parent().unwrap_or(Path::new(""));
    if !dir.as_os_str().is_empty() {
        std::fs::create_dir_all(dir)?;
    }
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(path.file_name().unwrap_or_default());
    tmp_name.push(format!(
        ".{}.{}.tmp",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let tmp = dir.join(tmp_name);
    std::fs::write(&tmp, bytes)
        .and_then(|()| std::fs::rename(&tmp, path))
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
}

/// A failed [`Builder`] run: every diagnostic of every device (warnings
/// too), and of writing the output.
///
/// `Display` and `Debug` both render the diagnostics with file, line and
/// source lines ([`Diagnostics::render`]), so that a build script's
/// `fn main() -> Result<(), Box<dyn std::error::Error>>` shows them readably.
pub struct Error {
    diagnostics: Diagnostics,
    files_read: Vec<PathBuf>,
}

impl Error {
    fn new(diagnostics: Diagnostics, files_read: Vec<PathBuf>) -> Self {
        Error {
            diagnostics,
            files_read,
        }
    }

    /// Every diagnostic, in device order.
    pub fn diagnostics(&self) -> &Diagnostics {
        &self.diagnostics
    }

    /// The diagnostics, by value.
    pub fn into_diagnostics(self) -> Diagnostics {
        self.diagnostics
    }

    /// Every file read (or tried) before the failure, each once.
    pub fn files_read(&self) -> &[PathBuf] {
        &self.files_read
    }

    /// The `cargo:rerun-if-changed` lines of the files read, so that cargo
    /// reruns the build script when one of them is fixed.
    pub fn cargo_lines(&self) -> Vec<String> {
        cargo_lines(&self.files_read, &Diagnostics::new())
    }
}

impl From<Diagnostics> for Error {
    fn from(diagnostics: Diagnostics) -> Self {
        Error::new(diagnostics, Vec::new())
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.diagnostics.render())?;
        write!(
            f,
            "eds2rust: generation failed: {} errors, {} warnings",
            self.diagnostics.error_count(),
            self.diagnostics.warning_count()
        )
    }
}

impl fmt::Debug for Error {
    /// The same text as `Display`: what `main` returning `Err` prints.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl std::error::Error for Error {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names() {
        for ok in ["drive", "linak_techline", "_x", "a1", "a__b"] {
            assert_eq!(check_name(ok), Ok(()), "{ok}");
        }
        for bad in [
            "", "_", "__", "Drive", "my-drive", "1x", "type", "gen", "a b", "é",
        ] {
            assert!(check_name(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn cargo_lines_are_single_lines() {
        let mut warnings = Diagnostics::new();
        warnings.push(Diagnostic {
            severity: Severity::Warning,
            code: "test",
            file: "a.eds".into(),
            location: Location {
                line: Some(3),
                ..Location::default()
            },
            message: "two\nlines".into(),
            notes: vec!["not shown".into()],
        });
        let files = [PathBuf::from("a.eds"), PathBuf::from("b.yaml")];
        assert_eq!(
            cargo_lines(&files, &warnings),
            [
                "cargo:rerun-if-changed=a.eds",
                "cargo:rerun-if-changed=b.yaml",
                "cargo:warning=a.eds:3: warning: two lines",
            ]
        );
    }

    #[test]
    fn write_only_when_changed() {
        let dir = std::env::temp_dir().join(format!("eds2rust-build-unit-{}", std::process::id()));
        let path = dir.join("x.rs");
        assert!(write_if_changed(&path, b"one").unwrap());
        assert!(!write_if_changed(&path, b"one").unwrap());
        assert!(write_if_changed(&path, b"two").unwrap());
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        let leftovers = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(leftovers, 1, "no temporary file is left behind");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
