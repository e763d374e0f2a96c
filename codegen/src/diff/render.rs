//! Changes as text (one line each and a summary), a Markdown table for a
//! review comment, or one JSON object. The JSON is written here by hand so
//! that the library's default build needs no JSON crate.

use std::borrow::Cow;
use std::fmt::Write;

use super::{Change, Severity, Summary, Val};
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

/// One change as the renderers show it: a device diff's [`Change`], or a
/// network diff's change, which adds the node it is on.
pub(crate) struct Row<'a> {
    /// The node and the scope (`wiring` or `device`) of a network change.
    pub(crate) node: Option<(&'a str, &'a str)>,
    pub(crate) index: u16,
    pub(crate) subindex: Option<u8>,
    pub(crate) place: Cow<'a, str>,
    pub(crate) kind: &'static str,
    pub(crate) severity: Severity,
    pub(crate) rust_path: Option<&'a str>,
    pub(crate) old: Option<&'a Val>,
    pub(crate) new: Option<&'a Val>,
    pub(crate) message: &'a str,
}

/// The [`Row`] of a change `$c` (a device diff's or a network diff's: the
/// fields of the same names), at `$node` and `$place`.
macro_rules! row {
    ($c:expr, $node:expr, $place:expr) => {
        $crate::diff::render::Row {
            node: $node,
            index: $c.index,
            subindex: $c.subindex,
            place: $place,
            kind: $c.kind.as_str(),
            severity: $c.severity,
            rust_path: $c.rust_path.as_deref(),
            old: $c.old.as_ref(),
            new: $c.new.as_ref(),
            message: &$c.message,
        }
    };
}
pub(crate) use row;

impl<'a> Row<'a> {
    fn of(c: &'a Change) -> Row<'a> {
        row!(c, None, Cow::Owned(place(c)))
    }
}

/// One line per change, severity first, then the summary line. Text from the
/// inputs is terminal-safe ([`crate::text::terminal_line`]).
pub fn text(changes: &[Change]) -> String {
    let rows: Vec<Row> = changes.iter().map(Row::of).collect();
    text_of(&rows, &summary(changes))
}

/// One line per row (severity, the node in a column as wide as the longest
/// name, where, kind, Rust path, message) and the `summary` line.
pub(crate) fn text_of(rows: &[Row], summary: &str) -> String {
    let width = rows
        .iter()
        .filter_map(|r| r.node)
        .map(|(node, _)| terminal_line(node).chars().count())
        .max()
        .unwrap_or(0);
    let mut out = String::new();
    for r in rows {
        let path = r
            .rust_path
            .map(|p| format!(" {}", code_span(p)))
            .unwrap_or_default();
        let node = r
            .node
            .map(|(node, _)| format!("{:<width$} ", terminal_line(node)))
            .unwrap_or_default();
        let _ = writeln!(
            out,
            "{:<10} {node}{:<14} {}{path}: {}",
            r.severity.as_str(),
            terminal_line(&r.place),
            r.kind,
            terminal_line(r.message)
        );
    }
    let _ = writeln!(out, "{summary}");
    out
}

/// A Markdown table (severity, where, kind, Rust path, change) and the
/// summary, for a review comment.
pub fn markdown(old: &str, new: &str, changes: &[Change]) -> String {
    let rows: Vec<Row> = changes.iter().map(Row::of).collect();
    let title = "Object dictionary changes";
    markdown_of(title, old, new, &rows, &summary(changes))
}

/// The Markdown of `rows` under `### {title}: old → new` (a node column
/// when the rows have nodes), and the `summary` line.
pub(crate) fn markdown_of(
    title: &str,
    old: &str,
    new: &str,
    rows: &[Row],
    summary: &str,
) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "### {title}: {} → {}\n",
        md(&code_span(old)),
        md(&code_span(new))
    );
    if let Some(first) = rows.first() {
        if first.node.is_some() {
            out.push_str(
                "| severity | node | where | kind | Rust path | change |\n|---|---|---|---|---|---|\n",
            );
        } else {
            out.push_str(
                "| severity | where | kind | Rust path | change |\n|---|---|---|---|---|\n",
            );
        }
        for r in rows {
            let severity = match r.severity {
                Severity::Breaking => "**breaking**",
                Severity::Additive => "additive",
                Severity::Compatible => "compatible",
            };
            let path = r.rust_path.map(|p| md(&code_span(p))).unwrap_or_default();
            let node = r
                .node
                .map(|(node, _)| format!(" {} |", md(&code_span(node))))
                .unwrap_or_default();
            let _ = writeln!(
                out,
                "| {severity} |{node} {} | `{}` | {path} | {} |",
                md(&r.place),
                r.kind,
                md(r.message)
            );
        }
        out.push('\n');
    }
    let _ = writeln!(out, "{summary}");
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
    let rows: Vec<Row> = changes.iter().map(Row::of).collect();
    json_of(old, new, &rows)
}

/// The JSON object of `rows`: a network change has `node` and `scope`
/// first and `where` after the sub-index.
pub(crate) fn json_of(old: &str, new: &str, rows: &[Row]) -> String {
    let mut out = String::new();
    out.push_str("{\n");
    let _ = writeln!(out, "  \"old\": {},", string(old));
    let _ = writeln!(out, "  \"new\": {},", string(new));
    if rows.is_empty() {
        out.push_str("  \"changes\": []\n}\n");
        return out;
    }
    out.push_str("  \"changes\": [\n");
    for (i, r) in rows.iter().enumerate() {
        out.push_str("    {\n");
        if let Some((node, scope)) = r.node {
            let _ = writeln!(out, "      \"node\": {},", string(node));
            let _ = writeln!(out, "      \"scope\": {},", string(scope));
        }
        let _ = writeln!(out, "      \"index\": {},", r.index);
        let _ = writeln!(
            out,
            "      \"subindex\": {},",
            r.subindex.map_or("null".to_string(), |s| s.to_string())
        );
        if r.node.is_some() {
            let _ = writeln!(out, "      \"where\": {},", string(&r.place));
        }
        let _ = writeln!(out, "      \"kind\": {},", string(r.kind));
        let _ = writeln!(out, "      \"severity\": {},", string(r.severity.as_str()));
        let _ = writeln!(
            out,
            "      \"rust_path\": {},",
            r.rust_path.map_or("null".to_string(), string)
        );
        let _ = writeln!(out, "      \"old\": {},", value(r.old));
        let _ = writeln!(out, "      \"new\": {},", value(r.new));
        let _ = writeln!(out, "      \"message\": {}", string(r.message));
        out.push_str(if i + 1 == rows.len() {
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
