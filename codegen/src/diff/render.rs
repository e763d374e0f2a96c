//! Changes as text (one line each and a summary), a Markdown table for a
//! review comment, or one JSON object. The JSON is written here by hand so
//! that the library's default build needs no JSON crate.

use std::fmt::Write;

use super::{Change, Summary, Val};
use crate::text::{code_span, terminal_line};

/// Where a change is: `0x6041 sub 0`, `0x1A00`, or `device` for index 0.
pub(crate) fn place(c: &Change) -> String {
    match (c.index, c.subindex) {
        (0, None) => "device".into(),
        (i, None) => format!("0x{i:04X}"),
        (i, Some(s)) => format!("0x{i:04X} sub {s}"),
    }
}

/// `3 changes: 1 breaking, 1 additive, 1 compatible`.
pub fn summary(changes: &[Change]) -> String {
    summary_of(&Summary::of(changes), changes.len())
}

/// The summary line of `total` changes counted in `s`.
pub(crate) fn summary_of(s: &Summary, total: usize) -> String {
    format!(
        "{total} change{}: {} breaking, {} additive, {} compatible",
        if total == 1 { "" } else { "s" },
        s.breaking,
        s.additive,
        s.compatible
    )
}

/// One line per change, severity first, then the summary line. Text from the
/// inputs is terminal-safe ([`crate::text::terminal_line`]).
pub fn text(changes: &[Change]) -> String {
    let mut out = String::new();
    for c in changes {
        let path = c
            .rust_path
            .as_deref()
            .map(|p| format!(" {}", code_span(p)))
            .unwrap_or_default();
        let _ = writeln!(
            out,
            "{:<10} {:<14} {}{path}: {}",
            c.severity.as_str(),
            place(c),
            c.kind.as_str(),
            terminal_line(&c.message)
        );
    }
    let _ = writeln!(out, "{}", summary(changes));
    out
}

/// A Markdown table (severity, where, kind, Rust path, change) and the
/// summary, for a review comment.
pub fn markdown(old: &str, new: &str, changes: &[Change]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "### Object dictionary changes: {} → {}\n",
        md(&code_span(old)),
        md(&code_span(new))
    );
    if !changes.is_empty() {
        out.push_str("| severity | where | kind | Rust path | change |\n|---|---|---|---|---|\n");
        for c in changes {
            let severity = match c.severity {
                super::Severity::Breaking => "**breaking**",
                super::Severity::Additive => "additive",
                super::Severity::Compatible => "compatible",
            };
            let path = c
                .rust_path
                .as_deref()
                .map(|p| md(&code_span(p)))
                .unwrap_or_default();
            let _ = writeln!(
                out,
                "| {severity} | {} | `{}` | {path} | {} |",
                place(c),
                c.kind.as_str(),
                md(&c.message)
            );
        }
        out.push('\n');
    }
    let _ = writeln!(out, "{}", summary(changes));
    out
}

/// Text that is safe inside a Markdown table cell (names in it are code
/// spans already, [`code_span`]): pipes escaped, one line, terminal-safe.
pub(crate) fn md(text: &str) -> String {
    terminal_line(&text.replace(['\n', '\r'], " ")).replace('|', "\\|")
}

/// One JSON object: `{"old", "new", "changes": [...]}`, pretty-printed with
/// two-space indentation, keys in a fixed order.
pub fn json(old: &str, new: &str, changes: &[Change]) -> String {
    let mut out = String::new();
    out.push_str("{\n");
    let _ = writeln!(out, "  \"old\": {},", string(old));
    let _ = writeln!(out, "  \"new\": {},", string(new));
    if changes.is_empty() {
        out.push_str("  \"changes\": []\n}\n");
        return out;
    }
    out.push_str("  \"changes\": [\n");
    for (i, c) in changes.iter().enumerate() {
        out.push_str("    {\n");
        let _ = writeln!(out, "      \"index\": {},", c.index);
        let _ = writeln!(
            out,
            "      \"subindex\": {},",
            c.subindex.map_or("null".to_string(), |s| s.to_string())
        );
        let _ = writeln!(out, "      \"kind\": {},", string(c.kind.as_str()));
        let _ = writeln!(out, "      \"severity\": {},", string(c.severity.as_str()));
        let _ = writeln!(
            out,
            "      \"rust_path\": {},",
            c.rust_path.as_deref().map_or("null".to_string(), string)
        );
        let _ = writeln!(out, "      \"old\": {},", value(c.old.as_ref()));
        let _ = writeln!(out, "      \"new\": {},", value(c.new.as_ref()));
        let _ = writeln!(out, "      \"message\": {}", string(&c.message));
        out.push_str(if i + 1 == changes.len() {
            "    }\n"
        } else {
            "    },\n"
        });
    }
    out.push_str("  ]\n}\n");
    out
}

pub(crate) fn value(v: Option<&Val>) -> String {
    match v {
        None => "null".into(),
        Some(Val::Bool(b)) => b.to_string(),
        Some(Val::Int(i)) => i.to_string(),
        // JSON has no NaN or infinity: those are written as strings.
        Some(Val::Real(r)) if r.is_finite() => {
            let text = format!("{r:?}");
            text
        }
        Some(Val::Real(r)) => string(&r.to_string()),
        Some(Val::Text(t)) => string(t),
        Some(Val::List(items)) => {
            let items: Vec<String> = items.iter().map(|s| string(s)).collect();
            format!("[{}]", items.join(", "))
        }
    }
}

/// A JSON string literal.
pub(crate) fn string(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_strings_are_escaped() {
        assert_eq!(string("a\"b\\c\nd\u{1}"), r#""a\"b\\c\nd\u0001""#);
        assert_eq!(value(Some(&Val::Real(0.1))), "0.1");
        assert_eq!(value(Some(&Val::Real(2.0))), "2.0");
        assert_eq!(value(Some(&Val::Real(f64::NAN))), "\"NaN\"");
        assert_eq!(value(None), "null");
    }
}
