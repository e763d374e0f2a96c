//! Reading a device from any input file: EDS/DCF or YAML object table,
//! chosen by the file name's extension.

use std::path::Path;

pub use crate::read::{Loaded, Options};

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
pub fn read_device(path: &Path, options: &Options) -> Loaded {
    read_unfinished(path, options).finish(options)
}

/// [`read_device`] before the levels and strictness are applied: for
/// callers that apply overlays first and then all levels at once. The size
/// limit and the `base:` directories of `options` apply.
pub(crate) fn read_unfinished(path: &Path, options: &Options) -> Loaded {
    match InputKind::of(path) {
        InputKind::Eds => crate::eds::read_file_unfinished(path, options),
        #[cfg(feature = "yaml")]
        InputKind::Table => crate::table::read_file_unfinished(path, options),
        #[cfg(not(feature = "yaml"))]
        InputKind::Table => yaml_off(path, "a YAML object table"),
    }
}

/// The error for a YAML input (`what`: "a YAML object table", "an
/// overlay") when the crate is built without its `yaml` feature.
#[cfg(not(feature = "yaml"))]
pub(crate) fn yaml_off(path: &Path, what: &str) -> Loaded {
    use crate::diag::{Diagnostic, Diagnostics, Levels, Location, Severity};
    let mut diagnostics = Diagnostics::new();
    diagnostics.push(Diagnostic {
        severity: Severity::Error,
        code: "input::feature-off",
        file: path.display().to_string(),
        location: Location::default(),
        message: format!(
            "{what} cannot be read: eds2rust is built without its `yaml` feature \
             (turn it on in Cargo.toml: `eds2rust = {{ version = \"0.1\", features = [\"yaml\"] }}`)"
        ),
        notes: Vec::new(),
    });
    Loaded {
        device: None,
        diagnostics,
        files: vec![path.to_path_buf()],
        levels: Levels::new(),
    }
}
