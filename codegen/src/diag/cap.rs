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
            "{omitted} more `{code}` {what} of this file{} {SUMMARY_TAIL} {CAP} of each rule are shown",
            if line.is_some() {
                ", from this line on,"
            } else {
                ""
            }
        ),
        notes: vec![format!(
            "fix the ones shown and read the file again to see the rest, or drop the rule with `allow` if it is expected"
        )],
    }
}

/// How many diagnostics the summary `d` stands for (`None`: not a summary).
pub(super) fn summarised(d: &Diagnostic) -> Option<usize> {
    let l = &d.location;
    if l.span.is_some()
        || l.section.is_some()
        || l.key.is_some()
        || !d.message.contains(SUMMARY_TAIL)
    {
        return None;
    }
    d.message.split(' ').next()?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::{Diagnostics, Level, Levels};

    fn diag(code: &'static str, file: &str, line: u32, severity: Severity) -> Diagnostic {
        Diagnostic {
            severity,
            code,
            file: file.into(),
            location: Location {
                line: Some(line),
                ..Location::default()
            },
            message: format!("problem on line {line}"),
            notes: Vec::new(),
        }
    }

    #[test]
    fn the_first_of_each_rule_and_file_are_kept_and_the_rest_counted() {
        let mut d = Diagnostics::new();
        for line in 1..=250 {
            d.push(diag("eds::duplicate-key", "a.eds", line, Severity::Warning));
            if line <= 3 {
                d.push(diag("eds::bad-value", "a.eds", line, Severity::Warning));
            }
            if line <= 120 {
                d.push(diag("eds::duplicate-key", "b.eds", line, Severity::Warning));
            }
        }
        // One error among the left-out warnings makes the summary an error.
        d.push(diag("eds::duplicate-key", "a.eds", 251, Severity::Error));
        d.sort();
        assert_eq!(d.len(), CAP + 1 + 3 + CAP + 1);
        let summaries: Vec<(&str, Option<u32>, Severity, usize)> = d
            .iter()
            .filter_map(|x| Some((x.file.as_str(), x.location.line, x.severity, summarised(x)?)))
            .collect();
        assert_eq!(
            summaries,
            [
                ("a.eds", Some(101), Severity::Error, 151),
                ("b.eds", Some(101), Severity::Warning, 20),
            ]
        );
        // A second flush adds nothing; more left out make a new summary.
        d.flush_caps();
        assert_eq!(d.len(), 2 * CAP + 5);
        d.push(diag("eds::duplicate-key", "b.eds", 500, Severity::Warning));
        d.sort();
        assert_eq!(d.len(), 2 * CAP + 6);
    }

    #[test]
    fn an_allowed_rule_counts_every_left_out_warning() {
        let mut d = Diagnostics::new();
        for line in 1..=130 {
            d.push(diag(
                "eds::unknown-section",
                "a.eds",
                line,
                Severity::Warning,
            ));
        }
        let mut levels = Levels::new();
        levels.set("eds::unknown-section", Level::Allow, "test");
        d.apply_levels(&levels, false);
        assert!(d.is_empty());
        assert_eq!(d.allowed_count(), 130);
    }

    #[test]
    fn merged_runs_keep_their_summaries() {
        let mut a = Diagnostics::new();
        let mut b = Diagnostics::new();
        for line in 1..=110 {
            b.push(diag("eds::limits", "b.eds", line, Severity::Warning));
        }
        a.push(diag("eds::limits", "a.eds", 1, Severity::Warning));
        a.extend(b);
        assert_eq!(a.len(), 1 + CAP + 1);
        assert_eq!(a.iter().filter_map(summarised).collect::<Vec<_>>(), [10]);
    }
}
