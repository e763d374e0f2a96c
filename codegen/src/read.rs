//! What every reader shares: how strictly to read ([`Options`]) and what
//! reading one file gives ([`Loaded`]). The EDS reader, the YAML table
//! reader and the input dispatch all depend on this module, and it on
//! none of them.

use std::path::{Path, PathBuf};

use crate::diag::{Diagnostic, Diagnostics, Levels, Location, Severity};
use crate::ir::Device;

/// How strictly to read.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Options {
    /// Turn every warning into an error, but those of allowed rules.
    pub strict: bool,
    /// The caller's rule levels (`--allow`, `--deny`, `Builder::allow`):
    /// they win over a YAML table's `diagnostics:` section.
    pub levels: Levels,
}

impl Options {
    /// Lenient (the default): warnings stay warnings.
    pub fn lenient() -> Options {
        Options::default()
    }

    /// Every warning is an error.
    pub fn strict() -> Options {
        Options {
            strict: true,
            ..Options::default()
        }
    }
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
    /// The rule levels a YAML table's `diagnostics:` section sets (empty for
    /// an EDS). They are already applied to `diagnostics`; a caller that
    /// goes on with the device (more overlays, the generator) applies them
    /// to what comes later too.
    pub levels: Levels,
}

impl Loaded {
    /// A file that could not be read at all.
    pub fn unreadable(file: String, err: &std::io::Error) -> Loaded {
        let mut diagnostics = Diagnostics::new();
        diagnostics.push(Diagnostic {
            severity: Severity::Error,
            code: "io",
            file,
            location: Location::default(),
            message: format!("cannot read the file: {err}"),
            notes: Vec::new(),
        });
        Loaded {
            device: None,
            diagnostics,
            files: Vec::new(),
            levels: Levels::new(),
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

    /// Fills in the built-in meanings of the standard objects
    /// (`profiles::apply`), applies the levels (the file's own, then the
    /// caller's on top) and `strict` to the diagnostics, and sorts them:
    /// the last step of every public reader.
    pub(crate) fn finish(mut self, options: &Options) -> Loaded {
        if let Some(device) = &mut self.device {
            crate::profiles::apply(device);
        }
        let levels = self.levels.merged(&options.levels);
        self.diagnostics.apply_levels(&levels, options.strict);
        self.diagnostics.sort();
        self
    }
}
