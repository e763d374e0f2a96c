//! Network changes in the device diff's three formats ([`crate::diff::render`]):
//! text (one line each, the node after the severity, and the summary),
//! a Markdown table with a node column, and one JSON object whose changes
//! carry `node` and `scope` (`wiring` or `device`) besides the device
//! diff's fields. The rendering is the device diff's, on rows that carry
//! the node.

use std::borrow::Cow;

use super::NetChange;
use crate::diff::Summary;
use crate::diff::render::{Row, json_of, markdown_of, row, summary_of, text_of};

/// `5 changes: 2 breaking, 1 additive, 2 compatible`.
pub fn summary(changes: &[NetChange]) -> String {
    let s = Summary::of_severities(changes.iter().map(|c| c.severity));
    summary_of(&s, changes.len())
}

fn rows(changes: &[NetChange]) -> Vec<Row<'_>> {
    changes
        .iter()
        .map(|c| row!(c, Some((&c.node, c.kind.scope())), Cow::Borrowed(&c.place)))
        .collect()
}

/// One line per change (severity, node, where, kind, Rust path, message)
/// and the summary line; the node column is as wide as the longest name.
pub fn text(changes: &[NetChange]) -> String {
    text_of(&rows(changes), &summary(changes))
}

/// A Markdown table (severity, node, where, kind, Rust path, change) and
/// the summary, for a review comment.
pub fn markdown(old: &str, new: &str, changes: &[NetChange]) -> String {
    markdown_of(
        "Network changes",
        old,
        new,
        &rows(changes),
        &summary(changes),
    )
}

/// One JSON object: `{"old", "new", "changes": [...]}`, two-space
/// indentation, keys in a fixed order.
pub fn json(old: &str, new: &str, changes: &[NetChange]) -> String {
    json_of(old, new, &rows(changes))
}
