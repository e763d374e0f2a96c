//! The EDS/DCF reader (CiA 306): bytes → [`ini::Document`] → [`ir::Device`](crate::ir::Device).
//!
//! [`read_file`] and [`read_bytes`] never panic on any input; every problem is
//! a [`Diagnostic`] naming file, line, section and key.

mod check;
mod entry;
pub mod ini;
mod legacy;
mod lower;
pub mod number;
mod object;
mod sections;

use std::path::Path;

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};

pub use crate::read::{Loaded, Options};

/// Reads an EDS or DCF file from disk.
pub fn read_file(path: &Path, options: &Options) -> Loaded {
    read_file_unfinished(path, options).finish(options)
}

/// Reads EDS/DCF content; `file` names it in diagnostics and origins.
pub fn read_bytes(file: &str, bytes: &[u8], options: &Options) -> Loaded {
    read_bytes_unfinished(file, bytes.to_vec()).finish(options)
}

/// [`read_file`] before levels and strictness are applied (but with the
/// size limit of `options`).
pub(crate) fn read_file_unfinished(path: &Path, options: &Options) -> Loaded {
    let name = path.display().to_string();
    match Loaded::read_bounded(path, options) {
        Ok(bytes) => read_bytes_unfinished(&name, bytes),
        Err(refused) => *refused,
    }
    .read_first(path)
}

fn read_bytes_unfinished(file: &str, bytes: Vec<u8>) -> Loaded {
    let mut diagnostics = Diagnostics::new();
    let text = ini::decode_owned(file, bytes, &mut diagnostics);
    let doc = ini::parse(file, &text, &mut diagnostics);
    let device = lower::Lowering {
        doc: &doc,
        diags: &mut diagnostics,
    }
    .lower();
    check::check_device(&doc, &device, &mut diagnostics);
    if device.objects.is_empty() && !looks_like_eds(&doc) {
        return not_a_device_file(file, device, diagnostics.len());
    }
    drop(doc);
    // The text the diagnostics point into, moved there once nothing borrows it.
    diagnostics.add_source(file, text);
    if device.objects.is_empty() {
        diagnostics.push(Diagnostic {
            severity: Severity::Error,
            code: "eds::no-objects",
            file: file.to_string(),
            location: Location {
                line: None,
                ..Location::default()
            },
            message: "no object sections found: this is not an EDS/DCF file or it is truncated"
                .into(),
            notes: vec!["an object section is a 4-hex-digit index in brackets, e.g. [1000]".into()],
        });
    }
    Loaded {
        device: Some(device),
        diagnostics,
        files: Vec::new(),
        levels: crate::diag::Levels::new(),
    }
}

/// Has `doc` any section CiA 306 defines (an object or FileInfo, DeviceInfo,
/// …)? A file without one is not a device file at all.
fn looks_like_eds(doc: &ini::Document) -> bool {
    doc.sections
        .iter()
        .any(|s| sections::classify(s.name) != sections::SectionKind::Unknown)
}

/// The report on a file that is not an EDS/DCF at all: only `eds::no-objects`,
/// without the file's text and without the `others` diagnostics its lines
/// gave, which would quote it (it may be anything: `/proc/self/environ`,
/// a key file).
fn not_a_device_file(file: &str, device: crate::ir::Device, others: usize) -> Loaded {
    let mut notes = vec![
        "an object section is a 4-hex-digit index in brackets, e.g. [1000]".to_string(),
        "nothing in it looks like an EDS/DCF (no CiA 306 section), so its content is not shown"
            .to_string(),
    ];
    if others > 0 {
        notes.push(format!(
            "{others} other problems with its lines are not reported"
        ));
    }
    let mut diagnostics = Diagnostics::new();
    diagnostics.push(Diagnostic {
        severity: Severity::Error,
        code: "eds::no-objects",
        file: file.to_string(),
        location: Location::default(),
        message: "no object sections found: this is not an EDS/DCF file or it is truncated".into(),
        notes,
    });
    Loaded {
        device: Some(device),
        diagnostics,
        files: Vec::new(),
        levels: crate::diag::Levels::new(),
    }
}
