//! One way to refuse an input: its diagnostics, then
//! `FILE: not WHAT: N errors` on stderr (`check`, `diff`, `api`,
//! `generate`, `decode`, `net dcf` and the bus-file readers all print it).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use eds2rust::diag::Diagnostics;
use eds2rust::input::Options;
use eds2rust::ir::Device;

/// Writes `diagnostics` in the order they stand, then
/// `PATH: not WHAT: N errors` (at least one error: a file refused without
/// a diagnostic still counts as one).
pub(crate) fn write_refusal(
    err: &mut dyn Write,
    path: &Path,
    diagnostics: &Diagnostics,
    what: &str,
) {
    let _ = write!(err, "{}", diagnostics.render());
    let _ = writeln!(
        err,
        "{}: not {what}: {} errors",
        path.display(),
        diagnostics.error_count().max(1)
    );
}

/// [`write_refusal`] to stderr with the errors first.
pub(crate) fn refuse(path: &Path, mut diagnostics: Diagnostics, what: &str) {
    diagnostics.errors_first();
    write_refusal(&mut std::io::stderr().lock(), path, &diagnostics, what);
}

/// [`refuse`]; exit status 1.
pub(crate) fn failed(path: &Path, diagnostics: Diagnostics, what: &str) -> ExitCode {
    refuse(path, diagnostics, what);
    ExitCode::from(1)
}

/// The device at `path` with `overlays` applied
/// (`eds2rust::build::load_device`), or `None` with its refusal (in the
/// readers' order) written to `err`.
pub(crate) fn device_or_refuse(
    path: &Path,
    overlays: &[PathBuf],
    options: &Options,
    what: &str,
    err: &mut dyn Write,
) -> Option<Device> {
    let loaded = eds2rust::build::load_device(path, overlays, options);
    match loaded.device {
        Some(device) if !loaded.diagnostics.has_errors() => Some(device),
        _ => {
            write_refusal(err, path, &loaded.diagnostics, what);
            None
        }
    }
}
