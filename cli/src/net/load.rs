//! A bus file read and configured, refused on errors: what the commands
//! that review, boot or watch a network start from (`diff`/`api` of bus
//! files, `net boot`, `monitor --bus`, `decode --bus`).

use std::path::Path;

use eds2rust::diag::Diagnostics;
use eds2rust::input::Options;
use eds2rust::network::config::Configured;
use eds2rust::network::model::Bus;

/// A bus file without errors, as configured, with its warnings.
pub(crate) struct Network {
    pub bus: Bus,
    pub configured: Configured,
    /// Warnings (and notes) of the bus file, its device files and the
    /// configuration; no errors.
    pub warnings: Diagnostics,
}

/// Reads the bus file at `path` and its device files
/// (`eds2rust::network::read_file`) and configures the network
/// (`eds2rust::network::configure`); `options`' levels and strictness
/// apply to every diagnostic. With an error, the diagnostics (errors
/// first) and `PATH: not WHAT: N errors` go to stderr and the result is
/// `None`.
pub(crate) fn read_configured(path: &Path, options: &Options, what: &str) -> Option<Network> {
    let loaded = eds2rust::network::read_file(path, options);
    let mut diagnostics = loaded.diagnostics;
    let configured = match &loaded.bus {
        Some(bus) if !diagnostics.has_errors() => {
            let (configured, more) = eds2rust::network::configure(bus);
            diagnostics.extend(more);
            diagnostics.apply_levels(&options.levels, options.strict);
            Some(configured)
        }
        _ => None,
    };
    match (loaded.bus, configured) {
        (Some(bus), Some(configured)) if !diagnostics.has_errors() => Some(Network {
            bus,
            configured,
            warnings: diagnostics,
        }),
        _ => {
            crate::refusal::refuse(path, diagnostics, what);
            None
        }
    }
}
