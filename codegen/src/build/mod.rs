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
//! Diagnostics a user controls: [`Builder::allow`] and [`Builder::deny`]
//! set a rule's level for every device, over what a YAML table's
//! `diagnostics:` section says for its own device.
//!
//! Nothing here panics on any input.

mod builder;
mod cargo;
mod error;
mod files;
#[cfg(feature = "network")]
mod network;

use std::path::{Path, PathBuf};

use crate::diag::{Diagnostic, Diagnostics, Levels, Location, Severity};
use crate::r#gen::rust::{self, Options, Output};
use crate::input::{InputKind, read_unfinished};
use crate::ir::Device;
use crate::read::Loaded;

pub use builder::{Builder, Report, WARNINGS_FILE};
pub use cargo::{cargo_lines, error_lines, in_build_script, project_dir};
pub use error::Error;
pub use files::write_whole;
#[cfg(feature = "network")]
pub use network::{GeneratedNetwork, generate_bus, generate_network};

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
/// order (`table::apply_overlay`) and generates its Rust source.
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
    generate_device_with(input, overlays, options, &Levels::new())
}

/// [`generate_device`] with the caller's rule levels (`--allow`/`--deny`,
/// [`Builder::allow`]/[`Builder::deny`]). The levels the input's and the
/// overlays' `diagnostics:` sections set apply to the whole device, a later
/// file's over an earlier one's, and `levels` over all of them; then
/// `options.strict` makes every remaining warning an error. A code in
/// `levels` that names no rule matches nothing ([`Levels::unknown`] finds
/// those).
pub fn generate_device_with(
    input: &Path,
    overlays: &[PathBuf],
    options: &Options,
    levels: &Levels,
) -> Generated {
    let read = crate::read::Options {
        levels: levels.clone(),
        ..crate::read::Options::default()
    };
    generate_device_reading(input, overlays, options, &read)
}

/// [`generate_device_with`] with every reading option: the rule levels
/// `read.levels`, the size limit of an input file and where a YAML table's
/// `base:` may lead. Warnings are errors when `options.strict` or
/// `read.strict` is set.
pub fn generate_device_reading(
    input: &Path,
    overlays: &[PathBuf],
    options: &Options,
    read: &crate::read::Options,
) -> Generated {
    let levels = &read.levels;
    let strict = options.strict || read.strict;
    let loaded = load(input, overlays, read);
    let mut diagnostics = loaded.diagnostics;
    let mut code = None;
    if let Some(device) = &loaded.device
        && !diagnostics.has_errors()
    {
        let lenient = Options {
            strict: false,
            ..options.clone()
        };
        match rust::generate(device, &lenient) {
            Ok(output) => {
                diagnostics.extend(output.warnings);
                code = Some(output.code);
            }
            Err(errors) => diagnostics.extend(errors),
        }
    }
    diagnostics.apply_levels(&loaded.levels.merged(levels), strict);
    diagnostics.sort();
    let result = match code {
        Some(code) if !diagnostics.has_errors() => Ok(Output {
            code,
            warnings: diagnostics,
        }),
        _ => Err(failed(diagnostics, input)),
    };
    Generated {
        result,
        files: loaded.files,
    }
}

/// Reads `input` and applies the YAML `overlays` in order, exactly as
/// [`generate_device_with`] does, but generates nothing: the device after
/// every overlay (absent when a stage failed to give one), every diagnostic
/// with the files' `diagnostics:` levels, `options.levels` over them and
/// `options.strict` applied, the files read and the merged file levels. For
/// tools that work on the loaded IR (`eds2rust diff`).
pub fn load_device(input: &Path, overlays: &[PathBuf], options: &crate::read::Options) -> Loaded {
    let loaded = load(input, overlays, options);
    let mut diagnostics = loaded.diagnostics;
    diagnostics.apply_levels(&loaded.levels.merged(&options.levels), options.strict);
    diagnostics.sort();
    Loaded {
        device: loaded.device,
        diagnostics,
        files: loaded.files,
        levels: loaded.levels,
    }
}

/// Reads `input`, applies the YAML `overlays` in order and lists the API of
/// the device, as [`generate_device_with`] reads and generates it: the
/// files' `diagnostics:` levels, `read.levels` over them and `read.strict`
/// apply to every diagnostic. The `Err` holds every diagnostic when there is
/// an error.
#[cfg(feature = "api")]
pub fn api_listing_files(
    input: &Path,
    overlays: &[PathBuf],
    read: &crate::read::Options,
) -> Result<rust::ApiListing, Diagnostics> {
    let loaded = load_device(input, overlays, read);
    let mut diagnostics = loaded.diagnostics;
    let device = match loaded.device {
        Some(device) if !diagnostics.has_errors() => device,
        _ => return Err(diagnostics),
    };
    match rust::api_listing(&device, &Options::default()) {
        Ok(listing) => {
            let mut warnings = listing.warnings;
            warnings.apply_levels(&loaded.levels.merged(&read.levels), read.strict);
            diagnostics.extend(warnings);
            diagnostics.sort();
            if diagnostics.has_errors() {
                Err(diagnostics)
            } else {
                Ok(rust::ApiListing {
                    text: listing.text,
                    warnings: diagnostics,
                })
            }
        }
        Err(mut errors) => {
            errors.apply_levels(&loaded.levels.merged(&read.levels), read.strict);
            diagnostics.extend(errors);
            diagnostics.sort();
            Err(diagnostics)
        }
    }
}

/// What [`load`] gives: the device after every overlay, every diagnostic
/// (no levels applied yet), the files read, and the levels the files set.
struct LoadedDevice {
    device: Option<Device>,
    diagnostics: Diagnostics,
    files: Vec<PathBuf>,
    levels: Levels,
}

/// Reads the input and applies the overlays, until the first error; the
/// size limit and the `base:` directories of `read` apply (its levels and
/// strictness do not, yet).
fn load(input: &Path, overlays: &[PathBuf], read: &crate::read::Options) -> LoadedDevice {
    let loaded = read_unfinished(input, read);
    let mut files = Vec::new();
    push_unique(&mut files, loaded.files);
    let mut diagnostics = loaded.diagnostics;
    let mut device = loaded.device;
    let mut levels = loaded.levels;
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
        #[cfg(feature = "yaml")]
        let loaded = crate::table::apply_overlay_unfinished(base, overlay, read);
        #[cfg(not(feature = "yaml"))]
        let loaded = {
            drop(base);
            crate::input::yaml_off(overlay, "an overlay")
        };
        push_unique(&mut files, loaded.files);
        diagnostics.extend(loaded.diagnostics);
        levels = levels.merged(&loaded.levels);
        device = loaded.device;
    }
    if !overlays.is_empty()
        && let Some(device) = &device
    {
        diagnostics.retain(|d| !fixed_by_overlay(d, device));
    }
    if let Some(device) = &mut device {
        crate::profiles::apply(device);
    }
    LoadedDevice {
        device,
        diagnostics,
        files,
        levels,
    }
}

/// Is `d` a base file's PDO-mapping warning that the overlays fixed (the
/// mapping entry it names is gone or no longer has that problem)?
fn fixed_by_overlay(d: &Diagnostic, device: &Device) -> bool {
    if d.code != "eds::pdo-mapping" {
        return false;
    }
    let Some((index, sub)) = d.location.section.as_deref().and_then(sub_section) else {
        return false;
    };
    let Some(entry) = device.objects.get(&index).and_then(|o| o.entries.get(&sub)) else {
        return true;
    };
    let Some(raw) = crate::ir::pdo::raw_mapping(entry) else {
        return true;
    };
    !crate::ir::pdo::check_entry(device, raw)
        .iter()
        .any(|problem| d.message.contains(&problem.to_string()))
}

/// `1601sub1` → (0x1601, 1): the entry an EDS sub-section names.
fn sub_section(name: &str) -> Option<(u16, u8)> {
    let lower = name.to_ascii_lowercase();
    let (index, sub) = lower.split_once("sub")?;
    Some((
        u16::from_str_radix(index, 16).ok()?,
        u8::from_str_radix(sub, 16).ok()?,
    ))
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

pub(crate) fn error(code: &'static str, file: &Path, message: String) -> Diagnostic {
    Diagnostic {
        severity: Severity::Error,
        code,
        file: file.display().to_string(),
        location: Location::default(),
        message,
        notes: Vec::new(),
    }
}

pub(crate) fn push_unique(files: &mut Vec<PathBuf>, new: Vec<PathBuf>) {
    for file in new {
        if !files.contains(&file) {
            files.push(file);
        }
    }
}
