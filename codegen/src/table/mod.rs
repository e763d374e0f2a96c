//! The YAML object table reader: YAML text → [`schema::Table`] → [`ir::Device`](crate::ir::Device).
//!
//! A table describes a whole device, overlays an EDS file (`base:`), or
//! overlays a device the caller already read ([`apply_overlay`]); the
//! format is documented in `docs/yaml-tables.md`. Shape errors (YAML syntax,
//! unknown keys, wrong scalar types) stop at the first, as serde does; every
//! semantic error is collected. Nothing here panics on any input.

mod entry;
mod extra;
mod item;
mod levels;
mod lower;
mod meaning;
mod pdo;
pub mod schema;
pub(crate) mod yaml_error;

use std::path::Path;

use serde_saphyr::Spanned;

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::Device;
use crate::read::{Loaded, Options};

/// Reads a YAML object table from disk. A `base:` EDS is read relative to
/// the table's directory.
pub fn read_file(path: &Path, options: &Options) -> Loaded {
    read_file_unfinished(path, options).finish(options)
}

/// [`read_file`] before levels and strictness are applied (but with the
/// size limit and the `base:` directories of `options`).
pub(crate) fn read_file_unfinished(path: &Path, options: &Options) -> Loaded {
    let name = path.display().to_string();
    match Loaded::read_bounded(path, options) {
        Ok(bytes) => {
            let dir = path.parent().unwrap_or(Path::new(""));
            read_table(&name, &bytes, Base::Key(dir, options))
        }
        Err(refused) => *refused,
    }
    .read_first(path)
}

/// Reads YAML table content; `file` names it in diagnostics and origins,
/// `base_dir` is where a `base:` path is resolved (it must lead inside
/// `options.project_dir` or `options.allow_base_dirs`).
pub fn read_bytes(file: &str, bytes: &[u8], base_dir: &Path, options: &Options) -> Loaded {
    read_table(file, bytes, Base::Key(base_dir, options)).finish(options)
}

/// Reads the YAML overlay table at `path` and applies it on `base`, a device
/// already read (from an EDS, a table, or earlier overlays), in the same
/// stage order as an overlay with `base:` (delete → modify → add → semantics
/// → PDO defaults → error tables, variants and checks).
///
/// The table must not name a `base:` of its own: that is an error
/// (`table::overlay-base`) at the `base` key, and that file is not read.
/// The result's device is absent only when the overlay could not be read or
/// parsed at all; [`Loaded::files`] lists the overlay.
///
/// The diagnostics are the overlay's own: those about the base device were
/// reported when it was read, and the overlay leaves their severity alone
/// (but for its own `diagnostics:` section, in [`Loaded::levels`], which the
/// caller applies to the whole device).
pub fn apply_overlay(base: Device, path: &Path, options: &Options) -> Loaded {
    apply_overlay_unfinished(base, path, options).finish(options)
}

/// [`apply_overlay`] before levels and strictness are applied (but with the
/// size limit of `options`).
pub(crate) fn apply_overlay_unfinished(base: Device, path: &Path, options: &Options) -> Loaded {
    let name = path.display().to_string();
    match Loaded::read_bounded(path, options) {
        Ok(bytes) => read_table(&name, &bytes, Base::Given(Box::new(base))),
        Err(refused) => *refused,
    }
    .read_first(path)
}

/// Where the device a table starts from comes from.
pub(crate) enum Base<'a> {
    /// The table's own `base:` key, resolved in this directory and read
    /// with these options; without the key, the table is a whole device.
    Key(&'a Path, &'a Options),
    /// Given by the caller: the table is an overlay on it.
    Given(Box<Device>),
}

fn read_table(file: &str, bytes: &[u8], base: Base) -> Loaded {
    let mut files = Vec::new();
    let mut levels = crate::diag::Levels::new();
    let mut diagnostics = Diagnostics::new();
    let text = match crate::text::decode_utf8(bytes) {
        Ok(text) => text,
        Err(bad) => {
            diagnostics.push(Diagnostic {
                severity: Severity::Error,
                code: "table::not-utf8",
                file: file.to_string(),
                location: Location {
                    line: Some(bad.line),
                    ..Location::default()
                },
                message: format!("a YAML table must be UTF-8; byte {} is not", bad.byte),
                notes: Vec::new(),
            });
            return Loaded {
                device: None,
                diagnostics,
                files,
                levels,
            };
        }
    };
    diagnostics.add_source(file, text);
    let mut yaml_options = serde_saphyr::options! { strict_booleans: true };
    yaml_options.duplicate_keys = serde_saphyr::options::DuplicateKeyPolicy::Error;
    let device = match serde_saphyr::from_str_with_options::<schema::Table>(text, yaml_options) {
        Ok(table) => {
            let mut ctx = Ctx {
                file,
                text,
                diags: &mut diagnostics,
            };
            levels = levels::read(&mut ctx, table.diagnostics.as_ref());
            Some(lower::lower(&mut ctx, &table, base, &mut files))
        }
        Err(err) => {
            let at = err.location().map(|l| At::from_location(&l));
            let message = yaml_error::message(&err, &yaml_error::TABLE)
                .unwrap_or_else(|| first_line(&err.to_string()));
            let mut notes = Vec::new();
            if let Some(suggestion) = levels::did_you_mean(&message) {
                notes.push(suggestion);
            }
            notes.push("the table is read no further; see docs/yaml-tables.md".into());
            diagnostics.push(Diagnostic {
                severity: Severity::Error,
                code: "table::syntax",
                file: file.to_string(),
                location: Location {
                    line: at.map(|a| a.line),
                    span: at.map(|a| a.span(text)),
                    section: None,
                    key: None,
                },
                message,
                notes,
            });
            None
        }
    };
    Loaded {
        device,
        diagnostics,
        files,
        levels,
    }
}

/// serde-saphyr's message without its `line L column C:` prefix and without
/// the source excerpt it appends (the renderer shows the source itself).
pub(crate) fn first_line(message: &str) -> String {
    let line = message.lines().next().unwrap_or("").trim();
    let line = line.strip_prefix("error: ").unwrap_or(line);
    let line = match line.find(": ") {
        Some(pos) if line.starts_with("line ") => &line[pos + 2..],
        _ => line,
    };
    // serde-saphyr advises its caller, not the table's author.
    line.trim_end_matches(", set DuplicateKeyPolicy in Options if acceptable")
        .to_string()
}

/// A position in the table: 1-based line and byte offset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct At {
    pub line: u32,
    offset: usize,
    len: usize,
}

impl At {
    /// A whole line, for items known only by their origin line.
    pub fn line(line: u32) -> At {
        At {
            line,
            offset: usize::MAX,
            len: 0,
        }
    }

    pub fn of<T>(spanned: &Spanned<T>) -> At {
        At::from_location(&spanned.referenced)
    }

    pub(crate) fn from_location(location: &serde_saphyr::Location) -> At {
        let span = location.span();
        let line = u32::try_from(location.line()).unwrap_or(0);
        match span.byte_offset().and_then(|o| usize::try_from(o).ok()) {
            // Without a byte offset (some syntax errors), the whole line.
            None => At::line(line),
            Some(offset) => At {
                line,
                offset,
                len: span
                    .byte_len()
                    .and_then(|l| usize::try_from(l).ok())
                    .unwrap_or(0),
            },
        }
    }

    /// The byte range to underline: the scalar, or the rest of its line.
    pub(crate) fn span(self, text: &str) -> std::ops::Range<usize> {
        if self.offset == usize::MAX {
            return crate::diag::line_span(text, self.line);
        }
        let start = self.offset.min(text.len());
        if !text.is_char_boundary(start) {
            return start..start;
        }
        let end = if self.len > 0 {
            start.saturating_add(self.len).min(text.len())
        } else {
            text[start..].find('\n').map_or(text.len(), |n| start + n)
        };
        if end > start && text.is_char_boundary(start) && text.is_char_boundary(end) {
            start..end
        } else {
            start..start
        }
    }
}

/// The reporting context of one table.
pub(crate) struct Ctx<'a> {
    pub file: &'a str,
    pub text: &'a str,
    pub diags: &'a mut Diagnostics,
}

impl Ctx<'_> {
    /// Reports a problem at `at`; `place` says which object or table item it
    /// concerns (shown as `[place]`), `key` the YAML key.
    pub fn report(
        &mut self,
        severity: Severity,
        code: &'static str,
        at: At,
        place: &str,
        key: Option<&str>,
        message: String,
    ) {
        self.diags.push(Diagnostic {
            severity,
            code,
            file: self.file.to_string(),
            location: Location {
                line: (at.line > 0).then_some(at.line),
                span: (at.line > 0).then(|| at.span(self.text)),
                section: (!place.is_empty()).then(|| place.to_string()),
                key: key.map(str::to_string),
            },
            message,
            notes: Vec::new(),
        });
    }

    /// Adds a note to the diagnostic reported last.
    pub fn note(&mut self, note: String) {
        self.diags.add_note_to_last(note);
    }

    pub fn error(&mut self, code: &'static str, at: At, place: &str, key: &str, message: String) {
        let key = (!key.is_empty()).then_some(key);
        self.report(Severity::Error, code, at, place, key, message);
    }

    pub fn origin(&self, at: At) -> crate::ir::Origin {
        crate::ir::Origin {
            file: self.file.to_string(),
            line: at.line,
        }
    }
}

/// `0x2000` or `0x2000 sub 1`: how diagnostics name an entry.
pub(crate) fn place(index: u16, sub: Option<u8>) -> String {
    match sub {
        Some(sub) => format!("0x{index:04X} sub {sub}"),
        None => format!("0x{index:04X}"),
    }
}
