//! What every reader shares: how strictly to read ([`Options`]) and what
//! reading one file gives ([`Loaded`]). The EDS reader, the YAML table
//! reader and the input dispatch all depend on this module, and it on
//! none of them.

use std::path::{Path, PathBuf};

pub use crate::bounded::DEFAULT_MAX_INPUT_SIZE;
use crate::diag::{Diagnostic, Diagnostics, Levels, Location, Severity};
use crate::ir::Device;

/// How strictly to read, and how much and where.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Options {
    /// Turn every warning into an error, but those of allowed rules.
    pub strict: bool,
    /// The caller's rule levels (`--allow`, `--deny`, `Builder::allow`):
    /// they win over a YAML table's `diagnostics:` section.
    pub levels: Levels,
    /// The largest input file read, in bytes (default
    /// [`DEFAULT_MAX_INPUT_SIZE`], 64 MiB); a larger one is an error
    /// (`input::too-large`).
    pub max_input_size: u64,
    /// The project a YAML table's `base:` must lie in (`None`: the current
    /// directory, where cargo runs build scripts and tests).
    pub project_dir: Option<PathBuf>,
    /// More directories a `base:` may lie in (`--allow-base-dir`,
    /// `Builder::allow_base_dir`).
    pub allow_base_dirs: Vec<PathBuf>,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            strict: false,
            levels: Levels::default(),
            max_input_size: DEFAULT_MAX_INPUT_SIZE,
            project_dir: None,
            allow_base_dirs: Vec::new(),
        }
    }
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

    /// Reads the input file at `path` through [`crate::bounded::read_input`]
    /// with the limit of `options`; `Err` is the refusal as a [`Loaded`]
    /// without a device.
    pub(crate) fn read_bounded(path: &Path, options: &Options) -> Result<Vec<u8>, Box<Loaded>> {
        crate::bounded::read_input(path, options.max_input_size).map_err(|refused| {
            let mut diagnostics = Diagnostics::new();
            diagnostics.push(refused.diagnostic(&path.display().to_string()));
            Box::new(Loaded {
                device: None,
                diagnostics,
                files: Vec::new(),
                levels: Levels::new(),
            })
        })
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
