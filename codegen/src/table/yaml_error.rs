//! Sentences for the YAML reader's limits and document-level errors.
//!
//! serde-saphyr guards against hostile YAML with budgets (nodes, depth,
//! aliases, documents); its own messages are written for the program that
//! calls it (`budget breached: Nodes { nodes: 250001 }`, `use
//! from_str_multiple`). A table's author gets instead what was too much and
//! why an object table never needs that much. Other errors keep
//! serde-saphyr's message.

use serde_saphyr::Error;
use serde_saphyr::budget::BudgetBreach;

/// What an object table looks like next to a limit it broke.
const WRONG_FILE: &str = "an object table is far smaller: is this the right file?";

/// A sentence for `err` when it is a limit or a document-level error;
/// `None` for the errors whose own message already speaks to the author.
pub(super) fn message(err: &Error) -> Option<String> {
    match err {
        Error::Budget { breach, .. } => Some(budget(breach)),
        Error::MultipleDocuments { .. } => Some(several_documents()),
        Error::AliasReplayLimitExceeded { .. }
        | Error::AliasExpansionLimitExceeded { .. }
        | Error::AliasReplayStackDepthExceeded { .. } => Some(format!(
            "the YAML's aliases (`*name`) expand to more than the reader allows; {WRONG_FILE}"
        )),
        Error::AliasError { error, .. } | Error::WithSnippet { error, .. } => message(error),
        _ => None,
    }
}

fn several_documents() -> String {
    "the file holds several YAML documents (a `---` line starts another); an object table is \
     one document: remove the extra `---` and what follows it, or split the file"
        .into()
}

/// `count` is what the reader had seen when it stopped, one more than the limit.
fn budget(breach: &BudgetBreach) -> String {
    let over = |count: usize| count.saturating_sub(1);
    match breach {
        BudgetBreach::Nodes { nodes } => format!(
            "the YAML has more than {} nodes (keys, values and lists); {WRONG_FILE}",
            over(*nodes)
        ),
        BudgetBreach::Events { events } => format!(
            "the YAML has more than {} parser events; {WRONG_FILE}",
            over(*events)
        ),
        BudgetBreach::Depth { depth } => format!(
            "the YAML nests more than {} levels deep; an object table nests a few levels: \
             is this the right file?",
            over(*depth)
        ),
        BudgetBreach::Documents { .. } => several_documents(),
        BudgetBreach::Aliases { aliases } => format!(
            "the YAML uses more than {} aliases (`*name`); an object table needs few or none: \
             is this the right file?",
            over(*aliases)
        ),
        BudgetBreach::Anchors { anchors } => format!(
            "the YAML defines more than {} anchors (`&name`); an object table needs few or \
             none: is this the right file?",
            over(*anchors)
        ),
        BudgetBreach::AliasAnchorRatio { aliases, anchors } => format!(
            "the YAML uses {aliases} aliases (`*name`) for {anchors} anchors (`&name`), a \
             pattern of alias bombs, not of object tables: is this the right file?"
        ),
        BudgetBreach::MergeKeys { merge_keys } => format!(
            "the YAML uses more than {} merge keys (`<<`); {WRONG_FILE}",
            over(*merge_keys)
        ),
        BudgetBreach::ScalarBytes { total_scalar_bytes } => format!(
            "the YAML's values hold more than {} bytes of text; {WRONG_FILE}",
            over(*total_scalar_bytes)
        ),
        _ => format!("the YAML exceeds a size limit of the reader; {WRONG_FILE}"),
    }
}
