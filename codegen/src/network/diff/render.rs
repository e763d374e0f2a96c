//! Network changes in the device diff's three formats ([`crate::diff::render`]):
//! text (one line each, the node after the severity, and the summary),
//! a Markdown table with a node column, and one JSON object whose changes
//! carry `node` and `scope` (`wiring` or `device`) besides the device
//! diff's fields.

use std::fmt::Write;

use super::NetChange;
use crate::diff::Summary;
use crate::diff::render::{md, string, summary_of, value};
use crate::text::{code_span, terminal_line};

/// `5 changes: 2 breaking, 1 additive, 2 compatible`.
pub fn summary(changes: &[NetChange]) -> String {
    let s = Summary::of_severities(changes.iter().map(|c| c.severity));
    summary_of(&s, changes.len())
}

/// One line per change (severity, node, where, kind, Rust path, message)
/// and the summary line; the node column is as wide as the longest name.
pub fn text(changes: &[NetChange]) -> String {
    let width = changes
        .iter()
        .map(|c| terminal_line(&c.node).chars().count())
        .max()
        .unwrap_or(0);
    let mut out = String::new();
    for c in changes {
        let path = c
            .rust_path
            .as_deref()
            .map(|p| format!(" {}", code_span(p)))
            .unwrap_or_default();
        let _ = writeln!(
            out,
            "{:<10} {:<width$} {:<14} {}{path}: {}",
            c.severity.as_str(),
            terminal_line(&c.node),
            terminal_line(&c.place),
            c.kind.as_str(),
            terminal_line(&c.message)
        );
    }
    let _ = writeln!(out, "{}", summary(changes));
    out
}

/// A Markdown table (severity, node, where, kind, Rust path, change) and
/// the summary, for a review comment.
pub fn markdown(old: &str, new: &str, changes: &[NetChange]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "### Network changes: {} → {}\n",
        md(&code_span(old)),
        md(&code_span(new))
    );
    if !changes.is_empty() {
        out.push_str(
            "| severity | node | where | kind | Rust path | change |\n|---|---|---|---|---|---|\n",
        );
        for c in changes {
            let severity = match c.severity {
                crate::diff::Severity::Breaking => "**breaking**",
                crate::diff::Severity::Additive => "additive",
                crate::diff::Severity::Compatible => "compatible",
            };
            let path = c
                .rust_path
                .as_deref()
                .map(|p| md(&code_span(p)))
                .unwrap_or_default();
            let _ = writeln!(
                out,
                "| {severity} | {} | {} | `{}` | {path} | {} |",
                md(&code_span(&c.node)),
                md(&c.place),
                c.kind.as_str(),
                md(&c.message)
            );
        }
        out.push('\n');
    }
    let _ = writeln!(out, "{}", summary(changes));
    out
}

/// One JSON object: `{"old", "new", "changes": [...]}`, two-space
/// indentation, keys in a fixed order.
pub fn json(old: &str, new: &str, changes: &[NetChange]) -> String {
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
        let _ = writeln!(out, "      \"node\": {},", string(&c.node));
        let _ = writeln!(out, "      \"scope\": {},", string(c.kind.scope()));
        let _ = writeln!(out, "      \"index\": {},", c.index);
        let _ = writeln!(
            out,
            "      \"subindex\": {},",
            c.subindex.map_or("null".to_string(), |s| s.to_string())
        );
        let _ = writeln!(out, "      \"where\": {},", string(&c.place));
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
