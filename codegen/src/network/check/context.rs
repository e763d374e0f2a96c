//! What every topic of the check shares: the limits, the bus with its
//! configuration and their lookups ([`Net`]), the collected diagnostics
//! ([`Report`]).

use crate::diag::{Diagnostics, Severity};
use crate::network::config::{Configured, Node};
use crate::network::model::{Bus, SlaveSection, Spot};

/// The limits the check holds the bus to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckLimits {
    /// The highest bus load (percent of the bit rate) that is not a
    /// warning (`net::bus-load`).
    pub max_bus_load_percent: f64,
}

/// The default bus load limit: 70 % leaves room for SDO traffic, EMCY
/// bursts and retransmissions.
pub const DEFAULT_MAX_BUS_LOAD_PERCENT: f64 = 70.0;

impl Default for CheckLimits {
    fn default() -> Self {
        CheckLimits {
            max_bus_load_percent: DEFAULT_MAX_BUS_LOAD_PERCENT,
        }
    }
}

/// The bus and its configuration, with the lookups every topic needs.
pub(super) struct Net<'a> {
    pub(super) bus: &'a Bus,
    pub(super) configured: &'a Configured,
}

impl<'a> Net<'a> {
    /// The configured node of slave section `slave`, if dcfgen keeps it.
    pub(super) fn node_of(&self, slave: usize) -> Option<&'a Node> {
        self.configured.nodes.iter().find(|n| n.slave == slave)
    }

    /// Every configured node with its section.
    pub(super) fn nodes(&self) -> impl Iterator<Item = (&'a Node, &'a SlaveSection)> + 'a {
        let slaves = &self.bus.slaves;
        self.configured
            .nodes
            .iter()
            .filter_map(move |n| Some((n, slaves.get(n.slave)?)))
    }

    /// The master's node id when it is a usable one (1..=127).
    pub(super) fn master_id(&self) -> Option<u8> {
        let id = self.bus.master.node_id;
        crate::ir::NODE_IDS.contains(&id).then_some(id)
    }

    /// Where the master's key `key` is written, else the `master:` section.
    pub(super) fn master_spot(&self, key: &str) -> Spot {
        let master = &self.bus.master;
        master
            .spots
            .get(key)
            .cloned()
            .unwrap_or_else(|| master.spot.clone())
    }

    /// Where a slave's node id is written, else its section.
    pub(super) fn node_id_spot(slave: &SlaveSection) -> Spot {
        slave
            .node_id
            .as_ref()
            .map_or_else(|| slave.spot.clone(), |n| n.spot.clone())
    }
}

/// The device file's value of `index`/`sub` (its DCF value, else its
/// default) for node `node_id`, when it is a plain integer.
pub(super) fn device_int(
    device: &crate::ir::Device,
    index: u16,
    sub: u8,
    node_id: u8,
) -> Option<i128> {
    let entry = device.objects.get(&index)?.entries.get(&sub)?;
    let literal = entry.parameter_value.as_ref().or(entry.default.as_ref())?;
    match literal.resolve_checked(node_id, entry.data_type).ok()? {
        crate::ir::Value::Integer(v) => Some(v),
        _ => None,
    }
}

/// Collects the diagnostics of the check, all in the bus file.
pub(super) struct Report<'a> {
    file: &'a std::path::Path,
    pub(super) diagnostics: Diagnostics,
}

impl<'a> Report<'a> {
    pub(super) fn new(bus: &'a Bus) -> Self {
        Report {
            file: &bus.file,
            diagnostics: Diagnostics::new(),
        }
    }

    /// Reports `message` at `spot`, with `notes` (what to do).
    fn push(
        &mut self,
        severity: Severity,
        code: &'static str,
        spot: &Spot,
        message: String,
        notes: Vec<String>,
    ) {
        let mut diagnostic = spot.diagnostic(self.file, severity, code, message);
        diagnostic.notes = notes;
        self.diagnostics.push(diagnostic);
    }

    pub(super) fn error(
        &mut self,
        code: &'static str,
        spot: &Spot,
        message: String,
        notes: Vec<String>,
    ) {
        self.push(Severity::Error, code, spot, message, notes);
    }

    pub(super) fn warning(
        &mut self,
        code: &'static str,
        spot: &Spot,
        message: String,
        notes: Vec<String>,
    ) {
        self.push(Severity::Warning, code, spot, message, notes);
    }
}
