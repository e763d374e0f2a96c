//! Reading a device from any input file: EDS/DCF or YAML object table,
//! chosen by the file name's extension.

use std::path::{Path, PathBuf};

use crate::diag::Diagnostics;
use crate::ir::Device;

/// How strictly to read.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Options {
    /// Turn every warning into an error.
    pub strict: bool,
}

/// The result of reading one file: the device (absent only when the file could
/// not be read at all), every diagnostic, and the files the result depends on.
#[derive(Debug, Clone)]
pub struct Loaded {
    pub device: Option<Device>,
    pub diagnostics: Diagnostics,
    /// Every file read from disk (or tried: a file that could not be read is
    /// listed too), in reading order, each once: the input itself first,
    /// then the `base:` EDS of a YAML overlay table. Empty for the
    /// `read_bytes` readers, which read nothing from disk themselves (but a
    /// table's `base:` is listed). Build scripts print these as
    /// `cargo:rerun-if-changed`.
    pub files: Vec<PathBuf>,
}

impl Loaded {
    /// A file that could not be read at all.
    pub fn unreadable(file: String, err: &std::io::Error) -> Loaded {
        let mut diagnostics = Diagnostics::new();
        diagnostics.push(crate::diag::Diagnostic {
            severity: crate::diag::Severity::Error,
            code: "io",
            file,
            location: crate::diag::Location::default(),
            message: format!("cannot read the file: {err}"),
            notes: Vec::new(),
        });
        Loaded {
            device: None,
            diagnostics,
            files: Vec::new(),
        }
    }

    /// Records that `path` was read (or tried), in front of the files
    /// already listed, unless it is listed already.
    pub(crate) fn read_first(mut self, path: &Path) -> Loaded {
        if !self.files.iter().any(|f| f == path) {
            self.files.insert(0, path.to_path_buf());
        }
        self
    }
}

/// The kinds of input file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// CiA 306 EDS or DCF.
    Eds,
    /// A YAML object table (`.yaml`, `.yml`).
    Table,
}

impl InputKind {
    /// The kind a path's extension says (anything but `.yaml`/`.yml` is EDS).
    pub fn of(path: &Path) -> InputKind {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("yaml" | "yml") => InputKind::Table,
            _ => InputKind::Eds,
        }
    }
}

/// Reads an EDS/DCF file or a YAML object table from disk.
pub fn read_device(path: &Path, options: Options) -> Loaded {
    match InputKind::of(path) {
        InputKind::Eds => crate::eds::read_file(path, options),
        InputKind::Table => crate::table::read_file(path, options),
    }
}
