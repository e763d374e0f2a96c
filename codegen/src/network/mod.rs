//! Networks: a bus file (lely dcfgen's YAML, as ros2_canopen users write
//! it) read into [`model::Bus`], configured as dcfgen configures it
//! ([`config`]), checked as a whole, and written as master.dcf and concise
//! DCFs.

#[cfg(feature = "api")]
pub mod api;
mod boot;
pub use boot::boot_plan;
#[cfg(feature = "network-check")]
pub mod check;
pub mod config;
mod configure;
pub use configure::configure;
pub mod configured;
#[cfg(feature = "export")]
pub mod dcf;
#[cfg(feature = "diff")]
pub mod diff;
mod expand;
pub mod model;
mod pdo;
mod pdo_config;
mod read;
pub mod sniff;
mod values;
mod view;
mod yaml;

#[cfg(test)]
mod tests;

pub use sniff::is_bus_file;

use std::path::{Path, PathBuf};

use crate::diag::Diagnostics;
use crate::read::Options;

/// The result of reading a bus file.
#[derive(Debug)]
pub struct BusLoaded {
    /// Absent when the file could not be read or parsed at all.
    pub bus: Option<model::Bus>,
    /// The bus file's diagnostics and its device files'.
    pub diagnostics: Diagnostics,
    /// Every file read (the bus file and each device file), for
    /// `cargo:rerun-if-changed`.
    pub files: Vec<PathBuf>,
}

/// Reads a bus file and every device file it names (relative to the bus
/// file's directory). The bus file is read within `options.max_input_size`
/// and serde-saphyr's budgets; every problem is a diagnostic naming file,
/// line and key. Levels and strictness of `options` apply to the bus
/// file's diagnostics and to its device files'.
pub fn read_file(path: &Path, options: &Options) -> BusLoaded {
    match crate::read::Loaded::read_bounded(path, options) {
        Ok(bytes) => {
            let dir = path.parent().unwrap_or(Path::new(""));
            read_in(path, &bytes, dir, options, true)
        }
        Err(refused) => {
            let mut diagnostics = refused.diagnostics;
            diagnostics.sort();
            BusLoaded {
                bus: None,
                diagnostics,
                files: vec![path.to_path_buf()],
            }
        }
    }
}

/// Reads a bus file's content; `file` names it in diagnostics and in
/// [`model::Bus::file`], device files are resolved in `dir`. As
/// [`read_file`] otherwise ([`BusLoaded::files`] lists the device files
/// read).
pub fn read_bytes(file: &str, bytes: &[u8], dir: &Path, options: &Options) -> BusLoaded {
    read_in(Path::new(file), bytes, dir, options, false)
}

/// `from_disk`: the bus file itself was read from `path` (and is listed
/// first in the files).
fn read_in(path: &Path, bytes: &[u8], dir: &Path, options: &Options, from_disk: bool) -> BusLoaded {
    let name = path.display().to_string();
    let mut diagnostics = Diagnostics::new();
    let mut files = Vec::new();
    if from_disk {
        files.push(path.to_path_buf());
    }
    let mut devices = read::Devices::new(dir, options);
    let bus = read_text(&name, bytes, path, &mut diagnostics, &mut devices);
    diagnostics.apply_levels(&options.levels, options.strict);
    diagnostics.extend(devices.diagnostics);
    for file in devices.files {
        if !files.contains(&file) {
            files.push(file);
        }
    }
    diagnostics.sort();
    BusLoaded {
        bus,
        diagnostics,
        files,
    }
}

/// Reads a bus file's bytes; `None` when they are not UTF-8 or not YAML.
fn read_text(
    name: &str,
    bytes: &[u8],
    path: &Path,
    diagnostics: &mut Diagnostics,
    devices: &mut read::Devices,
) -> Option<model::Bus> {
    let text = match crate::text::decode_utf8(bytes) {
        Ok(text) => text,
        Err(bad) => {
            let mut ctx = values::Ctx {
                file: name,
                text: "",
                diags: diagnostics,
            };
            ctx.error(
                "net::syntax",
                crate::table::At::line(bad.line),
                "",
                format!("a bus file must be UTF-8; byte {} is not", bad.byte),
            );
            return None;
        }
    };
    diagnostics.add_source(name, text);
    let mut ctx = values::Ctx {
        file: name,
        text,
        diags: diagnostics,
    };
    match yaml::parse(text) {
        Ok(root) => read::bus(&mut ctx, &root, path, devices),
        Err(err) => {
            let at = err.location().map_or(crate::table::At::line(0), |l| {
                crate::table::At::from_location(&l)
            });
            let message = crate::table::yaml_error::message(&err, &yaml_error_subject())
                .unwrap_or_else(|| crate::table::first_line(&err.to_string()));
            ctx.error("net::syntax", at, "", message);
            ctx.note("the bus file is read no further".into());
            None
        }
    }
}

fn yaml_error_subject() -> crate::table::yaml_error::Subject {
    crate::table::yaml_error::Subject {
        one: "a bus file",
        many: "bus files",
    }
}
