//! The top level of a bus file: `options:`, `master:`, the flat slave
//! sections, and ros2_canopen's `defaults:` + `nodes:`, expanded as
//! ros2_canopen expands them before it calls dcfgen (its `cogen` step):
//! each entry of `nodes:` becomes a slave with the keys of `defaults:` put
//! over its own (the defaults win; a nested map such as `tpdo` is replaced
//! whole), the expanded file keeps only `options:`, `master:` and the nodes
//! (a flat slave section beside `nodes:` is dropped, with a warning), and
//! its keys are sorted, so the slaves are ordered by name (dcfgen numbers
//! the master's PDOs in that order). A file without `nodes:` is dcfgen's
//! own input: its slaves stay in file order. Keys starting with `.` are
//! ignored, as dcfgen ignores them.

use std::collections::HashMap;

use super::values::{Ctx, Entry, join};
use super::yaml::{Node, Value};

/// The most slaves a bus holds: one per node id 1..=127.
pub(crate) const MAX_SLAVES: usize = 127;

/// The most values (keys, scalars, lists) the expansion of `defaults:`
/// into the nodes may give, beyond the file's own.
pub(crate) const MAX_EXPANDED: usize = 1_000_000;

/// The sections of a bus file.
#[derive(Debug, Default)]
pub(crate) struct Layout<'n> {
    pub options: Option<Entry<'n>>,
    pub master: Option<Entry<'n>>,
    pub slaves: Vec<SlaveSource<'n>>,
}

/// One slave's section before it is read: its name and its keys (for a
/// node of `nodes:`, with the defaults merged in), each with its path
/// under the slave's name.
#[derive(Debug)]
pub(crate) struct SlaveSource<'n> {
    pub name: String,
    /// The slave's key (in the file's top level or in `nodes:`).
    pub key_node: &'n Node,
    pub entries: Vec<Entry<'n>>,
}

/// Splits the top level into its sections and expands `nodes:`; `None`
/// (with an error) when the top level is not a map.
pub(crate) fn layout<'n>(ctx: &mut Ctx, root: &'n Node) -> Option<Layout<'n>> {
    let mut layout = Layout::default();
    let pairs = match &root.value {
        Value::Map(pairs) => pairs,
        Value::Null => return Some(layout),
        other => {
            ctx.error(
                "net::syntax",
                root.at,
                "",
                format!(
                    "a bus file is a map of sections (master:, options:, one per slave), not {}",
                    other.kind()
                ),
            );
            return None;
        }
    };
    let mut defaults: Option<Entry<'n>> = None;
    let mut nodes: Option<Entry<'n>> = None;
    let mut flat = Slaves::default();
    for (key_node, value) in pairs {
        let Value::Str(key) = &key_node.value else {
            ctx.error(
                "net::bad-value",
                key_node.at,
                &key_node.key_text().unwrap_or_default(),
                format!(
                    "a section name must be text, not {}; quote it to name a slave",
                    key_node.value.kind()
                ),
            );
            continue;
        };
        if key.starts_with('.') {
            continue;
        }
        let entry = Entry {
            key: key.clone(),
            key_node,
            value,
            path: key.clone(),
        };
        let slot = match key.as_str() {
            "options" => &mut layout.options,
            "master" => &mut layout.master,
            "defaults" => &mut defaults,
            "nodes" => &mut nodes,
            _ => {
                add_slave(ctx, &mut flat, entry);
                continue;
            }
        };
        if let Some(first) = slot.replace(entry) {
            ctx.warn(
                "net::duplicate-key",
                key_node.at,
                key,
                format!(
                    "section given again (first at line {}); this later one wins, as in dcfgen",
                    first.key_node.at.line
                ),
            );
        }
    }
    match &nodes {
        Some(nodes) => {
            for entry in flat.list {
                ctx.warn(
                    "net::dropped-section",
                    entry.key_node.at,
                    &entry.path,
                    format!(
                        "a file with `nodes:` (line {}) is expanded by ros2_canopen, which keeps \
                         only options:, master: and the nodes: this section is not on the bus",
                        nodes.key_node.at.line
                    ),
                );
                ctx.note(format!(
                    "move it into `nodes:` to put {} on the bus",
                    entry.key
                ));
            }
        }
        None => {
            for entry in flat.list {
                if let Some(slave) = flat_slave(ctx, entry) {
                    layout.slaves.push(slave);
                }
            }
        }
    }
    let sorted = nodes.is_some();
    match (nodes, defaults) {
        (Some(nodes), defaults) => expand(ctx, &mut layout.slaves, &nodes, defaults.as_ref()),
        (None, Some(defaults)) => ctx.warn(
            "net::unused-defaults",
            defaults.key_node.at,
            "defaults",
            "`defaults:` without `nodes:` applies to no slave".into(),
        ),
        (None, None) => {}
    }
    if sorted {
        layout.slaves.sort_by(|a, b| a.name.cmp(&b.name));
    }
    if layout.slaves.len() > MAX_SLAVES {
        let first_dropped = &layout.slaves[MAX_SLAVES];
        ctx.error(
            "net::too-large",
            first_dropped.key_node.at,
            &first_dropped.name,
            format!(
                "the bus has {} slaves; a CANopen bus holds at most {MAX_SLAVES} (node ids \
                 1..=127): this slave and those after it are not read",
                layout.slaves.len()
            ),
        );
        layout.slaves.truncate(MAX_SLAVES);
    }
    Some(layout)
}

/// Adds a slave section, unless its name is taken (an error: dcfgen would
/// silently read only the later one).
fn add_slave<'n>(ctx: &mut Ctx, slaves: &mut Slaves<'n>, entry: Entry<'n>) {
    if let Some(&pos) = slaves.seen.get(&entry.key) {
        let line = slaves.list[pos].key_node.at.line;
        ctx.error(
            "net::duplicate-node",
            entry.key_node.at,
            &entry.path,
            format!("a slave of this name is given already (line {line}); this one is not read"),
        );
        return;
    }
    slaves.seen.insert(entry.key.clone(), slaves.list.len());
    slaves.list.push(entry);
}

/// Slave sections by name, in file order.
#[derive(Default)]
struct Slaves<'n> {
    list: Vec<Entry<'n>>,
    seen: HashMap<String, usize>,
}

fn flat_slave<'n>(ctx: &mut Ctx, entry: Entry<'n>) -> Option<SlaveSource<'n>> {
    let entries = ctx.entries(entry.value, &entry.path)?;
    Some(SlaveSource {
        name: entry.key,
        key_node: entry.key_node,
        entries,
    })
}

/// Expands every node of `nodes:` with `defaults:` merged in.
fn expand<'n>(
    ctx: &mut Ctx,
    slaves: &mut Vec<SlaveSource<'n>>,
    nodes: &Entry<'n>,
    defaults: Option<&Entry<'n>>,
) {
    let Some(node_entries) = node_list(ctx, nodes) else {
        return;
    };
    let default_entries = match defaults {
        Some(d) => match ctx.entries(d.value, "defaults") {
            Some(entries) => entries,
            None => return,
        },
        None => Vec::new(),
    };
    let size = defaults.map_or(0, |d| d.value.size(MAX_EXPANDED));
    if size.saturating_mul(node_entries.len()) > MAX_EXPANDED {
        ctx.error(
            "net::too-large",
            nodes.key_node.at,
            "nodes",
            format!(
                "`defaults:` ({size} values) expanded into {} nodes gives more than {MAX_EXPANDED} \
                 values; a bus file is far smaller: is this the right file?",
                node_entries.len()
            ),
        );
        return;
    }
    for node in node_entries {
        let Some(mut entries) = ctx.entries(node.value, &node.key) else {
            continue;
        };
        let mut own: HashMap<String, usize> = entries
            .iter()
            .enumerate()
            .map(|(n, e)| (e.key.clone(), n))
            .collect();
        for default in &default_entries {
            let merged = Entry {
                path: join(&node.key, &default.key),
                ..default.clone()
            };
            match own.get(&default.key) {
                Some(&pos) => entries[pos] = merged,
                None => {
                    own.insert(default.key.clone(), entries.len());
                    entries.push(merged);
                }
            }
        }
        slaves.push(SlaveSource {
            name: node.key,
            key_node: node.key_node,
            entries,
        });
    }
}

/// The entries of `nodes:`, each a slave's name; a name given twice is an
/// error (the later one is not read).
fn node_list<'n>(ctx: &mut Ctx, nodes: &Entry<'n>) -> Option<Vec<Entry<'n>>> {
    let pairs = match &nodes.value.value {
        Value::Map(pairs) => pairs,
        Value::Null => return Some(Vec::new()),
        other => {
            ctx.error(
                "net::bad-value",
                nodes.value.at,
                "nodes",
                format!("`nodes:` is a map of slave names, not {}", other.kind()),
            );
            return None;
        }
    };
    let mut out = Slaves::default();
    for (key_node, value) in pairs {
        let Value::Str(key) = &key_node.value else {
            ctx.error(
                "net::bad-value",
                key_node.at,
                "nodes",
                format!(
                    "a node name must be text, not {}; quote it to name a slave",
                    key_node.value.kind()
                ),
            );
            continue;
        };
        if key.starts_with('.') {
            continue;
        }
        add_slave(
            ctx,
            &mut out,
            Entry {
                key: key.clone(),
                key_node,
                value,
                path: key.clone(),
            },
        );
    }
    Some(out.list)
}
