//! `eds2rust diff OLD NEW` and `eds2rust api FILE` on bus files
//! (docs/network.md, Reviewing a network change): `main` sends a file here
//! when [`eds2rust::network::is_bus_file`] says it is one.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use eds2rust::input::Options;
use eds2rust::network::config::Configured;
use eds2rust::network::diff::{self, Network, render};
use eds2rust::network::model::Bus;

use crate::{DiffFormat, FailOn};

/// A usage error: the message and exit status 2.
fn usage(message: &str) -> ExitCode {
    let _ = writeln!(std::io::stderr().lock(), "error: {message}");
    ExitCode::from(2)
}

/// Reads and configures one side; `None` (its diagnostics printed) when
/// either has errors.
fn side(path: &Path, options: &Options) -> Option<(Bus, Configured)> {
    super::load::read_configured(path, options, "compared").map(|n| (n.bus, n.configured))
}

fn network((bus, configured): &(Bus, Configured)) -> Network<'_> {
    Network { bus, configured }
}

/// `diff` of two bus files: the wiring and each node's device diff, in
/// the device diff's formats and exit codes.
pub(crate) fn diff(
    (old, old_overlays): (&Path, &[PathBuf]),
    (new, new_overlays): (&Path, &[PathBuf]),
    format: DiffFormat,
    fail_on: FailOn,
    diff_options: &eds2rust::diff::Options,
    options: &Options,
) -> ExitCode {
    let is_bus = eds2rust::network::is_bus_file;
    if !is_bus(old) || !is_bus(new) {
        let (bus, device) = if is_bus(old) { (old, new) } else { (new, old) };
        return usage(&format!(
            "{} is a bus file and {} is not: diff compares two devices or two bus files",
            bus.display(),
            device.display()
        ));
    }
    if !old_overlays.is_empty() || !new_overlays.is_empty() {
        return usage("--old-overlay and --new-overlay apply to device files, not to bus files");
    }
    let (old_side, new_side) = (side(old, options), side(new, options));
    let (Some(old_net), Some(new_net)) = (old_side, new_side) else {
        return ExitCode::from(2);
    };
    let changes = diff::diff(network(&old_net), network(&new_net), diff_options);
    let (old_name, new_name) = (old.display().to_string(), new.display().to_string());
    let text = match format {
        DiffFormat::Text => render::text(&changes),
        DiffFormat::Json => render::json(&old_name, &new_name, &changes),
        DiffFormat::Markdown => render::markdown(&old_name, &new_name, &changes),
    };
    if let Err(code) = crate::print(&text) {
        return code;
    }
    let threshold = fail_on.threshold();
    if threshold.is_some_and(|t| changes.iter().any(|c| c.severity >= t)) {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// `api` of a bus file: the wiring and every node's API listing.
pub(crate) fn api(path: &Path, overlays: &[PathBuf], options: &Options) -> ExitCode {
    if !overlays.is_empty() {
        return usage("--overlay applies to device files, not to bus files");
    }
    match eds2rust::network::api::api_listing_file(path, options) {
        Ok(listing) => {
            let _ = write!(std::io::stderr().lock(), "{}", listing.warnings.render());
            match crate::print(&listing.text) {
                Ok(()) => ExitCode::SUCCESS,
                Err(code) => code,
            }
        }
        Err(diagnostics) => crate::refusal::failed(path, diagnostics, "listed"),
    }
}
