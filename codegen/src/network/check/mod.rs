//! The whole-bus check (`eds2rust net check`): what no single device file
//! can show, found in the bus file and the network [`configure`]d from it.
//! Every diagnostic names the bus file, the line and the key it is about,
//! and says what to do where a fix is known. The rules, by topic:
//!
//! - [`ids`]: node ids out of range or colliding, COB-IDs of two producers
//!   colliding, PDO COB-IDs in the ranges CiA 301 restricts;
//! - [`pdo`]: mappings the bus file writes that do not fit the device, SDO
//!   writes that change PDOs behind the `rpdo`/`tpdo` sections, PDOs that
//!   are sent and never used or awaited and never sent;
//! - [`heartbeat`]: heartbeat consumer times that cannot hold, consumers
//!   of a heartbeat no one produces, heartbeat and node guarding both set;
//! - [`load`]: the bus load estimate ([`BusLoad`]) and its limit.
//!
//! [`configure`]: super::config::configure

mod heartbeat;
mod ids;
mod load;
mod pdo;
#[cfg(test)]
mod tests;

use crate::diag::{Diagnostics, Severity};

use super::config::{Configured, Node};
use super::model::{Bus, SlaveSection, Spot};

pub use load::{BusLoad, LoadItem, bus_load, frame_bits};

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

/// Checks the whole bus: every `net::` rule. The diagnostics point into
/// the bus file by line and key; to show the lines, render them together
/// with the reader's diagnostics (which hold the bus file's text) after
/// [`Diagnostics::span_lines`].
pub fn check(bus: &Bus, configured: &Configured, limits: &CheckLimits) -> Diagnostics {
    let mut report = Report::new(bus);
    let net = Net { bus, configured };
    ids::check(&net, &mut report);
    pdo::check(&net, &mut report);
    heartbeat::check(&net, &mut report);
    load::check(&net, limits, &mut report);
    report.diagnostics
}

/// The bus and its configuration, with the lookups every topic needs.
struct Net<'a> {
    bus: &'a Bus,
    configured: &'a Configured,
}

impl<'a> Net<'a> {
    /// The configured node of slave section `slave`, if dcfgen keeps it.
    fn node_of(&self, slave: usize) -> Option<&'a Node> {
        self.configured.nodes.iter().find(|n| n.slave == slave)
    }

    /// Every configured node with its section.
    fn nodes(&self) -> impl Iterator<Item = (&'a Node, &'a SlaveSection)> + 'a {
        let slaves = &self.bus.slaves;
        self.configured
            .nodes
            .iter()
            .filter_map(move |n| Some((n, slaves.get(n.slave)?)))
    }

    /// The master's node id when it is a usable one (1..=127).
    fn master_id(&self) -> Option<u8> {
        let id = self.bus.master.node_id;
        crate::ir::NODE_IDS.contains(&id).then_some(id)
    }

    /// Where the master's key `key` is written, else the `master:` section.
    fn master_spot(&self, key: &str) -> Spot {
        let master = &self.bus.master;
        master
            .spots
            .get(key)
            .cloned()
            .unwrap_or_else(|| master.spot.clone())
    }

    /// Where a slave's node id is written, else its section.
    fn node_id_spot(slave: &SlaveSection) -> Spot {
        slave
            .node_id
            .as_ref()
            .map_or_else(|| slave.spot.clone(), |n| n.spot.clone())
    }
}

/// The device file's value of `index`/`sub` (its DCF value, else its
/// default) for node `node_id`, when it is a plain integer.
fn device_int(device: &crate::ir::Device, index: u16, sub: u8, node_id: u8) -> Option<i128> {
    let entry = device.objects.get(&index)?.entries.get(&sub)?;
    let literal = entry.parameter_value.as_ref().or(entry.default.as_ref())?;
    match literal.resolve_checked(node_id, entry.data_type).ok()? {
        crate::ir::Value::Integer(v) => Some(v),
        _ => None,
    }
}

/// Collects the diagnostics of the check, all in the bus file.
struct Report<'a> {
    file: &'a std::path::Path,
    diagnostics: Diagnostics,
}

impl<'a> Report<'a> {
    fn new(bus: &'a Bus) -> Self {
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

    fn error(&mut self, code: &'static str, spot: &Spot, message: String, notes: Vec<String>) {
        self.push(Severity::Error, code, spot, message, notes);
    }

    fn warning(&mut self, code: &'static str, spot: &Spot, message: String, notes: Vec<String>) {
        self.push(Severity::Warning, code, spot, message, notes);
    }
}
