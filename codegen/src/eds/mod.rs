//! The EDS/DCF reader (CiA 306): bytes → [`ini::Document`] → [`ir::Device`](crate::ir::Device).
//!
//! [`read_file`] and [`read_bytes`] never panic on any input; every problem is
//! a [`Diagnostic`] naming file, line, section and key.

mod check;
mod entry;
pub mod ini;
mod lower;
pub mod number;
mod object;
mod sections;

use std::path::Path;

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};

pub use crate::read::{Loaded, Options};

/// Reads an EDS or DCF file from disk.
pub fn read_file(path: &Path, options: &Options) -> Loaded {
    read_file_unfinished(path).finish(options)
}

/// Reads EDS/DCF content; `file` names it in diagnostics and origins.
pub fn read_bytes(file: &str, bytes: &[u8], options: &Options) -> Loaded {
    read_bytes_unfinished(file, bytes).finish(options)
}

/// [`read_file`] before levels and strictness are applied.
pub(crate) fn read_file_unfinished(path: &Path) -> Loaded {
    let name = path.display().to_string();
    match std::fs::read(path) {
        Ok(bytes) => read_bytes_unfinished(&name, &bytes),
        Err(err) => Loaded::unreadable(name, &err),
    }
    .read_first(path)
}

fn read_bytes_unfinished(file: &str, bytes: &[u8]) -> Loaded {
    let mut diagnostics = Diagnostics::new();
    let text = ini::decode(file, bytes, &mut diagnostics);
    diagnostics.add_source(file, &text);
    let doc = ini::parse(file, &text, &mut diagnostics);
    let device = lower::Lowering {
        doc: &doc,
        diags: &mut diagnostics,
    }
    .lower();
    check::check_device(&doc, &device, &mut diagnostics);
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
