//! The error of a failed [`Builder`](super::Builder) run.

use std::fmt;
use std::path::PathBuf;

use super::cargo::{cargo_lines, error_lines, error_summaries};
use crate::diag::{Diagnostics, Severity};

/// A failed [`Builder`](super::Builder) run: every diagnostic of every
/// device (warnings too), and of writing the output.
///
/// `Display` and `Debug` both start with one line per file with errors
/// (`1 error in od/drive.dcf: …`), then render the errors, then the
/// warnings, with file, line and source lines, so that a build script's
/// `fn main() -> Result<(), eds2rust::Error>` shows the error first
/// (`Error: 1 error in …`). [`Builder::generate`](super::Builder::generate)
/// also prints the first lines as `cargo::error`, which cargo shows as its
/// first `error:` lines.
pub struct Error {
    diagnostics: Diagnostics,
    files_read: Vec<PathBuf>,
}

impl Error {
    pub(crate) fn new(mut diagnostics: Diagnostics, files_read: Vec<PathBuf>) -> Self {
        diagnostics.errors_first();
        Error {
            diagnostics,
            files_read,
        }
    }

    /// Every diagnostic: the errors first, then the warnings, each in
    /// device order.
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
    /// reruns the build script when one of them is fixed, then one
    /// `cargo::error=` line per file with errors, so that cargo's own
    /// output starts with them.
    pub fn cargo_lines(&self) -> Vec<String> {
        let mut lines = cargo_lines(&self.files_read, &Diagnostics::new(), None);
        lines.extend(error_lines(&self.diagnostics));
        lines
    }
}

impl From<Diagnostics> for Error {
    fn from(diagnostics: Diagnostics) -> Self {
        Error::new(diagnostics, Vec::new())
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for summary in error_summaries(&self.diagnostics) {
            writeln!(f, "{summary}")?;
        }
        writeln!(f)?;
        f.write_str(&self.diagnostics.render_severity(Severity::Error))?;
        f.write_str(&self.diagnostics.render_severity(Severity::Warning))?;
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
