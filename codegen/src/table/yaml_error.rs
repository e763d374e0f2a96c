//! Sentences for the YAML readers' limits and document-level errors.
//!
//! serde-saphyr guards against hostile YAML with budgets (nodes, depth,
//! aliases, documents); its own messages are written for the program that
//! calls it (`budget breached: Nodes { nodes: 250001 }`, `use
//! from_str_multiple`). A file's author gets instead what was too much and
//! why a file of its kind (an object table, a bus file) never needs that
//! much. Other errors keep serde-saphyr's message.

use serde_saphyr::Error;
use serde_saphyr::budget::BudgetBreach;

/// The kind of file read, as the sentences name it.
pub(crate) struct Subject {
    /// `an object table`.
    pub one: &'static str,
    /// `object tables`.
    pub many: &'static str,
}

/// The YAML object tables.
pub(crate) const TABLE: Subject = Subject {
    one: "an object table",
    many: "object tables",
};

/// A sentence for `err` when it is a limit or a document-level error;
/// `None` for the errors whose own message already speaks to the author.
pub(crate) fn message(err: &Error, what: &Subject) -> Option<String> {
    match err {
        Error::Budget { breach, .. } => Some(budget(breach, what)),
        Error::MultipleDocuments { .. } => Some(several_documents(what)),
        Error::AliasReplayLimitExceeded { .. }
        | Error::AliasExpansionLimitExceeded { .. }
        | Error::AliasReplayStackDepthExceeded { .. } => Some(format!(
            "the YAML's aliases (`*name`) expand to more than the reader allows; {}",
            wrong_file(what)
        )),
        Error::AliasError { error, .. } | Error::WithSnippet { error, .. } => message(error, what),
        _ => None,
    }
}

/// What a file of this kind looks like next to a limit it broke.
fn wrong_file(what: &Subject) -> String {
    format!("{} is far smaller: is this the right file?", what.one)
}

fn several_documents(what: &Subject) -> String {
    format!(
        "the file holds several YAML documents (a `---` line starts another); {} is one \
         document: remove the extra `---` and what follows it, or split the file",
        what.one
    )
}

/// `count` is what the reader had seen when it stopped, one more than the limit.
fn budget(breach: &BudgetBreach, what: &Subject) -> String {
    let wrong = wrong_file(what);
    let one = what.one;
    let many = what.many;
    let over = |count: usize| count.saturating_sub(1);
    match breach {
        BudgetBreach::Nodes { nodes } => format!(
            "the YAML has more than {} nodes (keys, values and lists); {wrong}",
            over(*nodes)
        ),
        BudgetBreach::Events { events } => format!(
            "the YAML has more than {} parser events; {wrong}",
            over(*events)
        ),
        BudgetBreach::Depth { depth } => format!(
            "the YAML nests more than {} levels deep; {one} nests a few levels: \
             is this the right file?",
            over(*depth)
        ),
        BudgetBreach::Documents { .. } => several_documents(what),
        BudgetBreach::Aliases { aliases } => format!(
            "the YAML uses more than {} aliases (`*name`); {one} needs few or none: \
             is this the right file?",
            over(*aliases)
        ),
        BudgetBreach::Anchors { anchors } => format!(
            "the YAML defines more than {} anchors (`&name`); {one} needs few or none: \
             is this the right file?",
            over(*anchors)
        ),
        BudgetBreach::AliasAnchorRatio { aliases, anchors } => format!(
            "the YAML uses {aliases} aliases (`*name`) for {anchors} anchors (`&name`), a \
             pattern of alias bombs, not of {many}: is this the right file?"
        ),
        BudgetBreach::MergeKeys { merge_keys } => format!(
            "the YAML uses more than {} merge keys (`<<`); {wrong}",
            over(*merge_keys)
        ),
        BudgetBreach::ScalarBytes { total_scalar_bytes } => format!(
            "the YAML's values hold more than {} bytes of text; {wrong}",
            over(*total_scalar_bytes)
        ),
        _ => format!("the YAML exceeds a size limit of the reader; {wrong}"),
    }
}
