//! The cap on repeated diagnostics: of one rule in one file only the first
//! [`CAP`] are kept; the rest are counted, and one summary diagnostic of the
//! same rule says how many were left out (docs/diagnostics.md, "Repeated
//! diagnostics"). A hostile or broken file with a million bad lines then
//! costs a million counter increments, not a million messages in memory and
//! on the terminal.

use std::collections::HashMap;

use super::{Diagnostic, Location, Severity};

/// How many diagnostics of one rule in one file are kept.
pub const CAP: usize = 100;

/// The counts of one rule in one file.
#[derive(Debug, Clone, Copy, Default)]
struct Count {
    kept: usize,
    /// Left out since the last summary.
    omitted: usize,
    /// The worst severity among those left out since the last summary.
    worst: Option<Severity>,
    /// The line of the first one left out since the last summary.
    first_line: Option<u32>,
}

/// Counts per rule, then per file.
#[derive(Debug, Clone, Default)]
pub(super) struct Caps {
    counts: HashMap<&'static str, HashMap<String, Count>>,
}

impl Caps {
    /// Whether `d` is kept; a diagnostic that is not kept is counted.
    pub(super) fn admit(&mut self, d: &Diagnostic) -> bool {
        let by_file = self.counts.entry(d.code).or_default();
        let count = match by_file.get_mut(d.file.as_str()) {
            Some(count) => count,
            None => by_file.entry(d.file.clone()).or_default(),
        };
        if count.kept < CAP {
            count.kept += 1;
            return true;
        }
        if count.omitted == 0 {
            count.first_line = d.location.line;
        }
        count.omitted += 1;
        count.worst = count.worst.max(Some(d.severity));
        false
    }

    /// The summaries of everything left out since the last call, sorted by
    /// file and rule; the counts start again from zero.
    pub(super) fn take_summaries(&mut self) -> Vec<Diagnostic> {
        let mut out = Vec::new();
        for (&code, by_file) in &mut self.counts {
            for (file, count) in by_file.iter_mut() {
                let Some(severity) = count.worst.take() else {
                    continue;
                };
                let omitted = std::mem::take(&mut count.omitted);
                out.push(summary(code, file, count.first_line, severity, omitted));
            }
        }
        out.sort_by(|a, b| (&a.file, a.code).cmp(&(&b.file, b.code)));
        out
    }

    /// Adds the counts of `other` (diagnostics of another run merged into this one).
    pub(super) fn absorb(&mut self, other: Caps) {
        for (code, by_file) in other.counts {
            let mine = self.counts.entry(code).or_default();
            for (file, count) in by_file {
                let m = mine.entry(file).or_default();
                m.kept += count.kept;
                m.omitted += count.omitted;
                if m.omitted == count.omitted {
                    m.first_line = count.first_line;
                }
                m.worst = m.worst.max(count.worst);
            }
        }
    }
}

const SUMMARY_TAIL: &str = "were left out: only the first";

/// The diagnostic that stands for `omitted` left-out diagnostics of `code`
/// in `file`, the first of them on `line`.
fn summary(
    code: &'static str,
    file: &str,
    line: Option<u32>,
    severity: Severity,
    omitted: usize,
) -> Diagnostic {
    let what = if omitted == 1 {
        "diagnostic"
    } else {
        "diagnostics"
    };
    Diagnostic {
        severity,
        code,
        file: file.to_string(),
        location: Location {
            line,
            ..Location::default()
        },
        message: format!(
            "{omitted} more `{code}` {what} of this file, from this line on, {SUMMARY_TAIL} {CAP} of each rule are shown"
        ),
        notes: vec![format!(
            "fix the ones shown and read the file again to see the rest, or drop the rule with `allow` if it is expected"
        )],
    }
}

/// How many diagnostics the summary `d` stands for (`None`: not a summary).
pub(super) fn summarised(d: &Diagnostic) -> Option<usize> {
    let l = &d.location;
    if l.span.is_some() || l.section.is_some() || l.key.is_some() || !d.message.contains(SUMMARY_TAIL) {
        return None;
    }
    d.message.split(' ').next()?.parse().ok()
}
