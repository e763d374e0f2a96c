//! Diagnostics: every problem found in an input, with file, line, section and
//! key, rendered with the source line by codespan-reporting; the rules they
//! belong to ([`rules`]) and the levels a user sets for them ([`Levels`]).

mod cap;
mod levels;
pub mod rules;

pub use cap::CAP;

pub use levels::{Level, Levels};

use std::fmt;
use std::ops::Range;

use codespan_reporting::diagnostic::{Diagnostic as CsDiagnostic, Label};
use codespan_reporting::files::SimpleFiles;
use codespan_reporting::term;

/// How bad a diagnostic is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    Warning,
    Error,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

/// Where in a source file a diagnostic points.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Location {
    /// 1-based line number.
    pub line: Option<u32>,
    /// Byte range in the decoded source text, used to underline the culprit.
    pub span: Option<Range<usize>>,
    /// Section name as written in the source (without brackets).
    pub section: Option<String>,
    /// Key name as written in the source.
    pub key: Option<String>,
}

/// One problem in one input file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    pub severity: Severity,
    /// A stable rule name such as `eds::unknown-data-type`, for tests and filtering.
    pub code: &'static str,
    pub file: String,
    pub location: Location,
    pub message: String,
    /// Extra explanation lines (what was done about it, what to write instead).
    pub notes: Vec<String>,
}

impl Diagnostic {
    /// The message prefixed with `[section] key: ` where those are known.
    pub fn headline(&self) -> String {
        let mut s = String::new();
        if let Some(section) = &self.location.section {
            s.push('[');
            s.push_str(section);
            s.push_str("] ");
        }
        if let Some(key) = &self.location.key {
            s.push_str(key);
            s.push_str(": ");
        }
        s.push_str(&self.message);
        s
    }
}

impl fmt::Display for Diagnostic {
    /// One line: `file:line: severity: [section] key: message`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(line) = self.location.line {
            write!(f, ":{line}")?;
        }
        write!(f, ": {}: {}", self.severity.as_str(), self.headline())
    }
}

/// All diagnostics of one run, with the source texts they point into.
#[derive(Debug, Clone, Default)]
pub struct Diagnostics {
    items: Vec<Diagnostic>,
    sources: Vec<(String, String)>,
    /// Warnings dropped because their rule is allowed.
    allowed: usize,
    /// Diagnostics kept and left out per rule and file ([`CAP`]); boxed to
    /// keep `Diagnostics` (in every error type) small.
    caps: Box<cap::Caps>,
}

impl Diagnostics {
    pub fn new() -> Self {
        Self::default()
    }

    /// Registers the decoded text of a file so rendering can show its lines
    /// (an owned `String` is kept as it is, without a copy).
    pub fn add_source(&mut self, file: &str, text: impl Into<String>) {
        if !self.sources.iter().any(|(name, _)| name == file) {
            self.sources.push((file.to_string(), text.into()));
        }
    }

    /// Adds a diagnostic, unless [`CAP`] diagnostics of its rule in its
    /// file are kept already: then it is only counted, and a summary saying
    /// how many were left out is added by [`Diagnostics::flush_caps`] (which
    /// the sorting, merging and level methods call, so every reader's
    /// output has its summaries).
    pub fn push(&mut self, diagnostic: Diagnostic) {
        if self.caps.admit(&diagnostic) {
            self.items.push(diagnostic);
        }
    }

    /// Adds one summary diagnostic per rule and file for the diagnostics
    /// [`push`](Self::push) left out since the last call.
    pub fn flush_caps(&mut self) {
        self.items.extend(self.caps.take_summaries());
    }

    /// Keeps only the diagnostics for which `keep` is true.
    pub fn retain(&mut self, keep: impl FnMut(&Diagnostic) -> bool) {
        self.items.retain(keep);
    }

    /// Adds a note to the diagnostic pushed last (none when empty).
    pub fn add_note_to_last(&mut self, note: String) {
        if let Some(last) = self.items.last_mut() {
            last.notes.push(note);
        }
    }

    /// Merges the diagnostics of another run (already capped there) into this one.
    pub fn extend(&mut self, mut other: Diagnostics) {
        self.flush_caps();
        other.flush_caps();
        for (file, text) in &other.sources {
            self.add_source(file, text);
        }
        self.items.extend(other.items);
        self.allowed += other.allowed;
        self.caps.absorb(*other.caps);
    }

    pub fn iter(&self) -> impl Iterator<Item = &Diagnostic> {
        self.items.iter()
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    pub fn has_errors(&self) -> bool {
        self.items.iter().any(|d| d.severity == Severity::Error)
    }

    pub fn error_count(&self) -> usize {
        self.items
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .count()
    }

    pub fn warning_count(&self) -> usize {
        self.items.len() - self.error_count()
    }

    /// How many warnings were dropped because their rule is allowed
    /// ([`Diagnostics::apply_levels`]).
    pub fn allowed_count(&self) -> usize {
        self.allowed
    }

    /// Turns every warning into an error (`--strict`).
    pub fn make_strict(&mut self) {
        self.flush_caps();
        for d in &mut self.items {
            d.severity = Severity::Error;
        }
    }

    /// The errors first, then the warnings, each in their order before.
    pub fn errors_first(&mut self) {
        self.flush_caps();
        self.items.sort_by_key(|d| d.severity != Severity::Error);
    }

    /// Sorts by file, then line, keeping the order of diagnostics on one line.
    pub fn sort(&mut self) {
        self.flush_caps();
        self.items
            .sort_by(|a, b| (&a.file, a.location.line).cmp(&(&b.file, b.location.line)));
    }

    /// Gives every diagnostic that has a line but no span the span of its
    /// whole line, where its file's text is registered
    /// ([`add_source`](Self::add_source)), so that rendering shows the line.
    pub fn span_lines(&mut self) {
        self.flush_caps();
        for d in &mut self.items {
            if d.location.span.is_some() {
                continue;
            }
            let (Some(line), Some((_, text))) = (
                d.location.line,
                self.sources.iter().find(|(name, _)| *name == d.file),
            ) else {
                continue;
            };
            d.location.span = Some(line_span(text, line));
        }
    }

    /// Renders every diagnostic with its source line, without colours.
    pub fn render(&self) -> String {
        self.render_where(|_| true)
    }

    /// Renders the diagnostics of one severity, like [`render`](Self::render).
    pub fn render_severity(&self, severity: Severity) -> String {
        self.render_where(|d| d.severity == severity)
    }

    fn render_where(&self, keep: impl Fn(&Diagnostic) -> bool) -> String {
        let mut files = SimpleFiles::new();
        let ids: Vec<(String, usize)> = self
            .sources
            .iter()
            .map(|(name, text)| (name.clone(), files.add(printable(name), printable(text))))
            .collect();
        let config = term::Config::default();
        let mut out = String::new();
        for d in self.items.iter().filter(|d| keep(d)) {
            let id = ids
                .iter()
                .find(|(name, _)| *name == d.file)
                .map(|(_, id)| *id);
            let cs = match (id, &d.location.span) {
                (Some(id), Some(span)) => {
                    let severity = match d.severity {
                        Severity::Error => codespan_reporting::diagnostic::Severity::Error,
                        Severity::Warning => codespan_reporting::diagnostic::Severity::Warning,
                    };
                    CsDiagnostic::new(severity)
                        .with_code(d.code)
                        .with_message(printable(&d.headline()))
                        .with_labels(vec![Label::primary(id, span.clone())])
                        .with_notes(d.notes.iter().map(|n| printable(n)).collect())
                }
                _ => {
                    // No source text to show: a one-line rendering that still names the
                    // file and, when known, the line.
                    out.push_str(&format!(
                        "{}[{}]: {}\n",
                        d.severity.as_str(),
                        d.code,
                        printable(&d.headline())
                    ));
                    let file = printable(&d.file);
                    match d.location.line {
                        Some(line) => out.push_str(&format!("  = in {file}:{line}\n")),
                        None => out.push_str(&format!("  = in {file}\n")),
                    }
                    for note in &d.notes {
                        out.push_str(&format!("  = {}\n", printable(note)));
                    }
                    out.push('\n');
                    continue;
                }
            };
            let mut buf = String::new();
            if term::emit_to_string(&mut buf, &config, &files, &cs).is_err() {
                buf = format!("{}\n", printable(&d.to_string()));
            }
            out.push_str(&buf);
        }
        out
    }
}

/// The byte range of 1-based line `line` of `text` (without its line
/// end), to underline a whole line; an empty range at the end past the
/// last line.
pub fn line_span(text: &str, line: u32) -> Range<usize> {
    // Line n starts after the (n-1)th newline.
    let newlines = usize::try_from(line)
        .unwrap_or(usize::MAX)
        .saturating_sub(1);
    let start = match newlines.checked_sub(1) {
        None => 0,
        Some(k) => text
            .match_indices('\n')
            .nth(k)
            .map_or(text.len(), |(i, _)| i + 1),
    };
    let end = text[start..].find('\n').map_or(text.len(), |n| start + n);
    start..end
}

/// Terminal-safe text: [`crate::text::terminal`] (escape sequences and
/// bidi controls as `?`, byte offsets kept).
fn printable(text: &str) -> String {
    crate::text::terminal(text).into_owned()
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.render())
    }
}

impl std::error::Error for Diagnostics {}

impl IntoIterator for Diagnostics {
    type Item = Diagnostic;
    type IntoIter = std::vec::IntoIter<Diagnostic>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.into_iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rendering_neutralises_control_characters() {
        let text = "[1000]\nParameterName=a\u{1b}[2Jb\u{85}c\n";
        let mut d = Diagnostics::new();
        d.add_source("t.eds", text);
        let start = text.find("ParameterName").unwrap();
        d.push(Diagnostic {
            severity: Severity::Warning,
            code: "test",
            file: "t.eds".into(),
            location: Location {
                line: Some(2),
                span: Some(start..text.len() - 1),
                section: None,
                key: None,
            },
            message: "bad \u{7} bell".into(),
            notes: vec![],
        });
        let out = d.render();
        assert!(
            !out.contains('\u{1b}') && !out.contains('\u{85}') && !out.contains('\u{7}'),
            "{out}"
        );
        assert!(out.contains("a?[2Jb??c"), "{out}");
    }
}
