//! The per-node table of `eds2rust monitor --table`: what every node said
//! last (NMT state from its boot-up, heartbeat and guarding replies, its
//! last EMCY), how often each of its PDOs comes, and the SDO transfers
//! made with it. Fed with the decoder's records; drawn with comfy-table.

use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

use comfy_table::{CellAlignment, ColumnConstraint, Table, Width, presets};
use eds2rust::ir::PdoDirection;
use eds2rust_decode::{Kind, Record};
use eds2rust_runtime::emcy::Emcy;
use eds2rust_runtime::nmt::NmtState;

/// PDO rates count the frames of this many seconds.
pub const RATE_WINDOW: f64 = 2.0;

/// The column titles.
pub const HEADER: [&str; 6] = [
    "node",
    "NMT state",
    "heartbeat",
    "last EMCY",
    "PDOs",
    "SDO transfers",
];

/// The frames of one PDO.
#[derive(Debug, Clone, Default)]
pub struct PdoStats {
    /// The PDO's name in the node's file (YAML `pdos:` labels).
    pub label: Option<Arc<str>>,
    /// Frames since the monitor started.
    pub frames: usize,
    /// The times of the frames of the last [`RATE_WINDOW`] seconds.
    recent: VecDeque<f64>,
}

impl PdoStats {
    fn seen(&mut self, t: f64) {
        self.frames += 1;
        self.recent.push_back(t);
        self.prune(t);
    }

    fn prune(&mut self, t: f64) {
        while self.recent.front().is_some_and(|&f| f <= t - RATE_WINDOW) {
            self.recent.pop_front();
        }
    }

    /// Frames per second at `t` (seconds since the monitor started): the
    /// frames of the last [`RATE_WINDOW`] seconds (or of the whole run when
    /// it is shorter, but at least half a second) over that time.
    pub fn rate(&self, t: f64) -> f64 {
        let n = self.recent.iter().filter(|&&f| f > t - RATE_WINDOW).count();
        n as f64 / t.clamp(0.5, RATE_WINDOW)
    }
}

/// The last EMCY of a node.
#[derive(Debug, Clone)]
pub struct LastEmcy {
    pub time: f64,
    pub emcy: Emcy,
    /// The device's text for the code (its file's error tables).
    pub text: Option<String>,
}

/// What is known of one node.
#[derive(Debug, Clone, Default)]
pub struct NodeRow {
    /// The state byte of its last boot-up, heartbeat or guarding reply.
    pub state: Option<u8>,
    /// When that came.
    pub heartbeat: Option<f64>,
    pub emcy: Option<LastEmcy>,
    /// By direction (TPDOs first) and number.
    pub pdos: BTreeMap<(bool, u16), PdoStats>,
    /// SDO transfers that ended (done or aborted), and the aborted ones.
    pub sdo: usize,
    pub sdo_aborted: usize,
    /// The last transfer: `upload 0x1018.1`.
    pub last_sdo: Option<String>,
}

impl NodeRow {
    /// The NMT state for a person: `operational`; `-` before any word.
    pub fn state_text(&self) -> String {
        match self.state {
            None => "-".into(),
            Some(s) => match NmtState::from_byte(s) {
                Some(state) => state.to_string(),
                None => format!("state {s:#04X}"),
            },
        }
    }

    fn heartbeat_text(&self, t: f64) -> String {
        match self.heartbeat {
            None => "-".into(),
            Some(h) => format!("{:.1} s ago", (t - h).max(0.0)),
        }
    }

    fn emcy_text(&self, t: f64) -> String {
        let Some(e) = &self.emcy else {
            return "-".into();
        };
        let what = if e.emcy.is_reset() {
            "error reset".to_string()
        } else {
            let text = e.text.as_deref().unwrap_or(e.emcy.class());
            format!("{:#06X} {text}", e.emcy.code)
        };
        format!("{what} ({:.1} s ago)", (t - e.time).max(0.0))
    }

    fn pdo_text(&self, t: f64) -> String {
        if self.pdos.is_empty() {
            return "-".into();
        }
        let lines: Vec<String> = self
            .pdos
            .iter()
            .map(|(&(rpdo, number), p)| {
                let name = format!("{}{number}", if rpdo { "RPDO" } else { "TPDO" });
                let label = p
                    .label
                    .as_ref()
                    .map_or_else(String::new, |l| format!(" {l}"));
                format!("{name}{label}: {:.1}/s ({} frames)", p.rate(t), p.frames)
            })
            .collect();
        lines.join("\n")
    }

    fn sdo_text(&self) -> String {
        let mut s = self.sdo.to_string();
        if self.sdo_aborted > 0 {
            s.push_str(&format!(" ({} aborted)", self.sdo_aborted));
        }
        if let Some(last) = &self.last_sdo {
            s.push_str(&format!("\nlast: {last}"));
        }
        s
    }
}

/// Every node heard of, by node id.
#[derive(Debug, Clone, Default)]
pub struct NodeTable {
    pub rows: BTreeMap<u8, NodeRow>,
    /// The nodes' names (a bus file's slaves), shown after their ids.
    pub names: BTreeMap<u8, String>,
}

impl NodeTable {
    /// A table with a row for each of `nodes` (those with a file) from the
    /// start; other nodes get one when they are heard.
    pub fn new(nodes: impl IntoIterator<Item = u8>) -> NodeTable {
        NodeTable {
            rows: nodes.into_iter().map(|n| (n, NodeRow::default())).collect(),
            names: BTreeMap::new(),
        }
    }

    /// Takes one record of time `t` (seconds since the monitor started).
    /// NMT commands name a node but are the master's: they change nothing.
    pub fn record(&mut self, t: f64, record: &Record) {
        match record {
            Record::Frame(f) => {
                let Some(node) = f.node else { return };
                match &f.kind {
                    Kind::Heartbeat { state } | Kind::GuardReply { state, .. } => {
                        let row = self.rows.entry(node).or_default();
                        row.state = Some(*state);
                        row.heartbeat = Some(t);
                    }
                    Kind::Emcy { emcy, text } => {
                        self.rows.entry(node).or_default().emcy = Some(LastEmcy {
                            time: t,
                            emcy: *emcy,
                            text: text.clone(),
                        });
                    }
                    Kind::Pdo {
                        direction,
                        number,
                        layout,
                        ..
                    } => {
                        let rpdo = *direction == PdoDirection::Rpdo;
                        let row = self.rows.entry(node).or_default();
                        let stats = row.pdos.entry((rpdo, *number)).or_default();
                        stats.label = layout.as_ref().and_then(|l| l.label.clone());
                        stats.seen(t);
                    }
                    Kind::Sdo { .. } | Kind::GuardRequest => {
                        self.rows.entry(node).or_default();
                    }
                    _ => {}
                }
            }
            Record::Transfer(tr) => {
                let row = self.rows.entry(tr.node).or_default();
                row.sdo += 1;
                let x = &tr.transfer;
                if x.abort.is_some() {
                    row.sdo_aborted += 1;
                }
                let verb = x.direction.as_str();
                let what = if x.abort.is_some() { " (aborted)" } else { "" };
                row.last_sdo = Some(format!("{verb} {:#06X}.{}{what}", x.index, x.subindex));
            }
            Record::Diagnostic { .. } => {}
        }
    }

    /// The table at `t` (seconds since the monitor started); `ascii`:
    /// drawn with ASCII characters only (for a pipe or a file), else with
    /// box-drawing characters.
    pub fn render(&mut self, t: f64, ascii: bool) -> String {
        let mut table = Table::new();
        table.load_style(if ascii {
            presets::ASCII_FULL_CONDENSED
        } else {
            presets::UTF8_FULL_CONDENSED
        });
        table.set_header(HEADER);
        for (node, row) in &mut self.rows {
            for p in row.pdos.values_mut() {
                p.prune(t);
            }
            table.add_row([
                match self.names.get(node) {
                    Some(name) => format!("{node} {name}"),
                    None => node.to_string(),
                },
                row.state_text(),
                row.heartbeat_text(t),
                row.emcy_text(t),
                row.pdo_text(t),
                row.sdo_text(),
            ]);
        }
        if let Some(c) = table.column_mut(0) {
            c.set_cell_alignment(CellAlignment::Right);
        }
        // Long EMCY texts and PDO labels wrap.
        for (column, width) in [(3, 40), (4, 48)] {
            if let Some(c) = table.column_mut(column) {
                c.set_constraint(ColumnConstraint::UpperBoundary(Width::Fixed(width)));
            }
        }
        if self.rows.is_empty() {
            return format!("{table}\n(no node heard yet)");
        }
        table.to_string()
    }
}
