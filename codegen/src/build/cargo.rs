//! The lines a build script prints for cargo: `rerun-if-changed` per file
//! read, warnings (repeated ones of a rule folded into one line), and on
//! failure one `cargo::error` line per file with errors.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::diag::{Diagnostic, Diagnostics, Severity, rules};

/// How many locations a folded warning line names.
const FIRST_LOCATIONS: usize = 3;

/// `true` when this process runs as a cargo build script: `CARGO` and
/// `OUT_DIR` are both set.
pub fn in_build_script() -> bool {
    std::env::var_os("CARGO").is_some() && std::env::var_os("OUT_DIR").is_some()
}

/// The project a build script builds, where a YAML table's `base:` may
/// lead: the workspace around the package of `CARGO_MANIFEST_DIR` (the
/// nearest directory at or above it whose `Cargo.toml` has a `[workspace]`
/// table), else the package's directory; `None` outside cargo.
pub fn project_dir() -> Option<PathBuf> {
    let package = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR")?);
    let workspace = package.ancestors().find(|dir| {
        crate::bounded::read_input(&dir.join("Cargo.toml"), 1 << 20).is_ok_and(|bytes| {
            String::from_utf8_lossy(&bytes)
                .lines()
                .any(|line| line.trim() == "[workspace]")
        })
    });
    Some(workspace.map_or(package.clone(), Path::to_path_buf))
}

/// The `cargo:` lines for `files` read and `warnings`: a
/// `cargo:rerun-if-changed=` line per file, in the order given, then the
/// warnings. A rule with one warning gets a line of its own
/// (`file:line: warning[code]: message`); a rule with several gets one line
/// with their count, the first, and the first locations, naming
/// `full_list` (the file with every warning) when given. Line breaks and
/// other control characters become spaces, so that each is one line.
pub fn cargo_lines(
    files: &[PathBuf],
    warnings: &Diagnostics,
    full_list: Option<&Path>,
) -> Vec<String> {
    let mut lines: Vec<String> = files
        .iter()
        .map(|f| {
            format!(
                "cargo:rerun-if-changed={}",
                one_line(&f.display().to_string())
            )
        })
        .collect();
    let mut by_rule: BTreeMap<&str, Vec<&Diagnostic>> = BTreeMap::new();
    for w in warnings.iter().filter(|d| d.severity == Severity::Warning) {
        by_rule.entry(w.code).or_default().push(w);
    }
    for (code, items) in by_rule {
        let line = match items.as_slice() {
            [one] => single(one),
            many => folded(code, many, full_list),
        };
        lines.push(format!("cargo:warning={}", one_line(&line)));
    }
    lines
}

/// The `cargo::error=` lines of a failed run: one per file with errors,
/// `N errors in FILE: <the first>` (cargo prints them as `error:` lines and
/// fails the build).
pub fn error_lines(diagnostics: &Diagnostics) -> Vec<String> {
    error_summaries(diagnostics)
        .into_iter()
        .map(|s| format!("cargo::error={}", one_line(&s)))
        .collect()
}

/// Per file with errors, in the order the files first have one:
/// `1 error in od/drive.dcf: <headline of the first>` (and `; N more` when
/// there are more).
pub(crate) fn error_summaries(diagnostics: &Diagnostics) -> Vec<String> {
    let mut files: Vec<(&str, Vec<&Diagnostic>)> = Vec::new();
    for d in diagnostics.iter().filter(|d| d.severity == Severity::Error) {
        match files.iter_mut().find(|(f, _)| *f == d.file) {
            Some((_, list)) => list.push(d),
            None => files.push((&d.file, vec![d])),
        }
    }
    files
        .into_iter()
        .map(|(file, errors)| {
            let first = errors[0];
            let at = first
                .location
                .line
                .map_or(String::new(), |l| format!(" (line {l})"));
            let count = match errors.len() {
                1 => "1 error".to_string(),
                n => format!("{n} errors"),
            };
            format!(
                "{count} in {file}: {}{at} [{}]",
                first.headline(),
                first.code
            )
        })
        .collect()
}

fn single(d: &Diagnostic) -> String {
    let mut s = d.file.clone();
    if let Some(line) = d.location.line {
        s.push_str(&format!(":{line}"));
    }
    s.push_str(&format!(": warning[{}]: {}", d.code, d.headline()));
    s
}

fn folded(code: &str, items: &[&Diagnostic], full_list: Option<&Path>) -> String {
    let summary = rules::RULES
        .iter()
        .find(|r| r.code == code)
        .map_or(String::new(), |r| format!(" ({})", r.summary));
    let first = items[0];
    let location = |d: &Diagnostic| match d.location.line {
        Some(line) => format!("{}:{line}", d.file),
        None => d.file.clone(),
    };
    // The other first locations: by line in the first's file, else by file too.
    let others: Vec<String> = items[1..]
        .iter()
        .take(FIRST_LOCATIONS - 1)
        .map(|d| match d.location.line {
            Some(line) if d.file == first.file => format!("line {line}"),
            _ => location(d),
        })
        .collect();
    let more = items.len().saturating_sub(FIRST_LOCATIONS);
    let mut s = format!(
        "{} warnings[{code}]{summary}: {}: {}; also at {}",
        items.len(),
        location(first),
        first.headline(),
        others.join(", ")
    );
    if more > 0 {
        s.push_str(&format!(" and {more} more"));
    }
    if let Some(path) = full_list {
        s.push_str(&format!("; all of them in {}", path.display()));
    }
    s.push_str(&format!("; to silence: .allow(\"{code}\")"));
    s
}

fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::Location;

    fn warning(code: &'static str, line: u32, message: &str) -> Diagnostic {
        Diagnostic {
            severity: Severity::Warning,
            code,
            file: "a.eds".into(),
            location: Location {
                line: Some(line),
                ..Location::default()
            },
            message: message.into(),
            notes: vec!["not shown".into()],
        }
    }

    #[test]
    fn single_warnings_are_single_lines() {
        let mut warnings = Diagnostics::new();
        warnings.push(warning("eds::unknown-section", 3, "two\nlines"));
        let files = [PathBuf::from("a.eds"), PathBuf::from("b.yaml")];
        assert_eq!(
            cargo_lines(&files, &warnings, None),
            [
                "cargo:rerun-if-changed=a.eds",
                "cargo:rerun-if-changed=b.yaml",
                "cargo:warning=a.eds:3: warning[eds::unknown-section]: two lines",
            ]
        );
    }

    #[test]
    fn repeated_warnings_of_a_rule_fold_into_one_line() {
        let mut warnings = Diagnostics::new();
        for line in [10, 20, 30, 40, 50] {
            warnings.push(warning("eds::unlisted-object", line, "not listed"));
        }
        warnings.push(warning("eds::unknown-section", 7, "odd"));
        let lines = cargo_lines(
            &[],
            &warnings,
            Some(Path::new("/out/eds2rust-warnings.txt")),
        );
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert_eq!(
            lines[0],
            "cargo:warning=a.eds:7: warning[eds::unknown-section]: odd"
        );
        assert_eq!(
            lines[1],
            "cargo:warning=5 warnings[eds::unlisted-object] (an object section not named in any \
             object list): a.eds:10: not listed; also at line 20, line 30 and 2 more; all of \
             them in /out/eds2rust-warnings.txt; to silence: .allow(\"eds::unlisted-object\")"
        );
    }

    #[test]
    fn errors_are_summed_up_per_file() {
        let mut d = Diagnostics::new();
        let mut e = warning("eds::bad-value", 4, "bad");
        e.severity = Severity::Error;
        d.push(e.clone());
        d.push(warning("eds::unknown-section", 7, "odd"));
        e.location.line = Some(9);
        d.push(e);
        assert_eq!(
            error_lines(&d),
            ["cargo::error=2 errors in a.eds: bad (line 4) [eds::bad-value]"]
        );
    }
}
