//! A network change reviewed: two bus files compared as the networks dcfgen
//! configures from them ([`super::configure`]). Nodes are matched
//! by their YAML key; each pair's device files are compared by the device
//! diff ([`crate::diff`], unchanged), and the wiring by the rules here: a
//! node added or removed, its node id or device identity changed, a PDO
//! enabled, disabled, remapped, moved to another COB-ID or retimed,
//! heartbeat, guarding and SYNC times, the `sdo:` writes at boot, and every
//! other setting of the bus file.
//!
//! Severities are the device diff's ([`Severity`]): `breaking` when code
//! built on the old network or the other nodes on the bus stop working as
//! they did (a node or PDO gone, a PDO's frame layout or COB-ID changed, a
//! node id or bit rate changed, error control or SYNC switched off);
//! `additive` when something new appears (a node, a PDO, error control or
//! SYNC switched on); `compatible` for times, boot settings and SDO writes
//! that keep every frame's identifier and layout. The table of every kind
//! is in docs/network.md (Reviewing a network change).
//!
//! This module uses [`crate::diff`]; `crate::diff` does not use it.

mod boot;
mod nodes;
mod out;
pub mod render;
mod sections;

use crate::diff::{Kind, Severity, Val};

use super::config::Configured;
use super::model::Bus;

/// One side of the comparison: the bus file as read and the network
/// configured from it.
#[derive(Debug, Clone, Copy)]
pub struct Network<'a> {
    pub bus: &'a Bus,
    pub configured: &'a Configured,
}

/// The wiring kinds; [`Wiring::as_str`] is the stable kebab-case name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Wiring {
    NodeAdded,
    NodeRemoved,
    NodeIdChanged,
    NodeIdentityChanged,
    NodeDeviceFileChanged,
    PdoEnabled,
    PdoDisabled,
    PdoRemapped,
    PdoCobIdMoved,
    PdoTransmissionChanged,
    PdoInhibitTimeChanged,
    PdoEventTimerChanged,
    PdoSyncStartChanged,
    HeartbeatProducerChanged,
    HeartbeatConsumerChanged,
    GuardingChanged,
    SyncPeriodChanged,
    SyncWindowChanged,
    SyncOverflowChanged,
    BaudrateChanged,
    SdoWriteAdded,
    SdoWriteRemoved,
    SdoWriteChanged,
    SdoWritesReordered,
    SettingChanged,
}

impl Wiring {
    /// Every kind, in declaration order.
    pub const ALL: &'static [Wiring] = &[
        Wiring::NodeAdded,
        Wiring::NodeRemoved,
        Wiring::NodeIdChanged,
        Wiring::NodeIdentityChanged,
        Wiring::NodeDeviceFileChanged,
        Wiring::PdoEnabled,
        Wiring::PdoDisabled,
        Wiring::PdoRemapped,
        Wiring::PdoCobIdMoved,
        Wiring::PdoTransmissionChanged,
        Wiring::PdoInhibitTimeChanged,
        Wiring::PdoEventTimerChanged,
        Wiring::PdoSyncStartChanged,
        Wiring::HeartbeatProducerChanged,
        Wiring::HeartbeatConsumerChanged,
        Wiring::GuardingChanged,
        Wiring::SyncPeriodChanged,
        Wiring::SyncWindowChanged,
        Wiring::SyncOverflowChanged,
        Wiring::BaudrateChanged,
        Wiring::SdoWriteAdded,
        Wiring::SdoWriteRemoved,
        Wiring::SdoWriteChanged,
        Wiring::SdoWritesReordered,
        Wiring::SettingChanged,
    ];

    /// The stable kebab-case name (`pdo-remapped`).
    pub fn as_str(self) -> &'static str {
        match self {
            Wiring::NodeAdded => "node-added",
            Wiring::NodeRemoved => "node-removed",
            Wiring::NodeIdChanged => "node-id-changed",
            Wiring::NodeIdentityChanged => "node-identity-changed",
            Wiring::NodeDeviceFileChanged => "node-device-file-changed",
            Wiring::PdoEnabled => "pdo-enabled",
            Wiring::PdoDisabled => "pdo-disabled",
            Wiring::PdoRemapped => "pdo-remapped",
            Wiring::PdoCobIdMoved => "pdo-cob-id-moved",
            Wiring::PdoTransmissionChanged => "pdo-transmission-changed",
            Wiring::PdoInhibitTimeChanged => "pdo-inhibit-time-changed",
            Wiring::PdoEventTimerChanged => "pdo-event-timer-changed",
            Wiring::PdoSyncStartChanged => "pdo-sync-start-changed",
            Wiring::HeartbeatProducerChanged => "heartbeat-producer-changed",
            Wiring::HeartbeatConsumerChanged => "heartbeat-consumer-changed",
            Wiring::GuardingChanged => "guarding-changed",
            Wiring::SyncPeriodChanged => "sync-period-changed",
            Wiring::SyncWindowChanged => "sync-window-changed",
            Wiring::SyncOverflowChanged => "sync-overflow-changed",
            Wiring::BaudrateChanged => "baudrate-changed",
            Wiring::SdoWriteAdded => "sdo-write-added",
            Wiring::SdoWriteRemoved => "sdo-write-removed",
            Wiring::SdoWriteChanged => "sdo-write-changed",
            Wiring::SdoWritesReordered => "sdo-writes-reordered",
            Wiring::SettingChanged => "setting-changed",
        }
    }
}

/// A change of the wiring, or of one node's device file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum NetKind {
    Wiring(Wiring),
    Device(Kind),
}

impl NetKind {
    /// The kind's kebab-case name: the device diff's for device changes.
    pub fn as_str(self) -> &'static str {
        match self {
            NetKind::Wiring(w) => w.as_str(),
            NetKind::Device(k) => k.as_str(),
        }
    }

    /// `wiring` or `device`.
    pub fn scope(self) -> &'static str {
        match self {
            NetKind::Wiring(_) => "wiring",
            NetKind::Device(_) => "device",
        }
    }
}

/// The section name of the bus file's `master:` in [`NetChange::node`]
/// (dcfgen never reads a slave of that name).
pub const MASTER: &str = "master";
/// The section name of the bus file's `options:` in [`NetChange::node`].
pub const OPTIONS: &str = "options";

/// One change between the old and the new network.
#[derive(Debug, Clone, PartialEq)]
pub struct NetChange {
    /// The slave's name (its YAML key), or [`MASTER`] / [`OPTIONS`] for the
    /// bus file's own sections.
    pub node: String,
    pub kind: NetKind,
    pub severity: Severity,
    /// The object on the node the change is at (`0x1800` for TPDO1's
    /// COB-ID, the index of an `sdo:` write); 0 when there is none. A
    /// device change keeps the device diff's index.
    pub index: u16,
    pub subindex: Option<u8>,
    /// Where, for a reader: `TPDO1`, `0x2000 sub 1`, `node`, `heartbeat`;
    /// a device change's place as the device diff shows it.
    pub place: String,
    /// The Rust path inside the device module (device changes only).
    pub rust_path: Option<String>,
    pub old: Option<Val>,
    pub new: Option<Val>,
    /// One line for a reviewer.
    pub message: String,
}

/// Every change from `old` to `new`: the `options:` and `master:`
/// sections first, then each node in the new network's order (removed
/// nodes after them, in the old order); within a node the wiring first,
/// then its device file's changes in the device diff's order. `options`
/// apply to each node's device diff (`ignore_semantics`).
pub fn diff(old: Network, new: Network, options: &crate::diff::Options) -> Vec<NetChange> {
    let mut out = Vec::new();
    sections::bus(&mut out, old.bus, new.bus);
    for node in &new.configured.nodes {
        match old.configured.nodes.iter().find(|n| n.name == node.name) {
            None => nodes::node_added(&mut out, new.bus, node),
            Some(old_node) => {
                // `configure` keeps `slave` in range; a hand-built network
                // that does not is skipped, never a panic.
                let (Some(old_slave), Some(new_slave)) = (
                    old.bus.slaves.get(old_node.slave),
                    new.bus.slaves.get(node.slave),
                ) else {
                    continue;
                };
                let (old_side, new_side) =
                    ((old.bus, old_node, old_slave), (new.bus, node, new_slave));
                let mut o = out::Out {
                    out: &mut out,
                    node: &node.name,
                };
                nodes::node(&mut o, old_side, new_side);
                boot::sdo_writes(&mut o, old_slave, new_slave);
                boot::settings(&mut o, old_side, new_side);
                device(&mut out, &node.name, old_slave, new_slave, options);
            }
        }
    }
    for node in &old.configured.nodes {
        if !new.configured.nodes.iter().any(|n| n.name == node.name) {
            nodes::node_removed(&mut out, old.bus, node);
        }
    }
    out
}

/// The device diff of one node's device files, each change tagged with
/// the node.
fn device(
    out: &mut Vec<NetChange>,
    node: &str,
    old: &super::model::SlaveSection,
    new: &super::model::SlaveSection,
    options: &crate::diff::Options,
) {
    for c in crate::diff::diff_with(&old.device, &new.device, options) {
        out.push(NetChange {
            node: node.to_string(),
            kind: NetKind::Device(c.kind),
            severity: c.severity,
            index: c.index,
            subindex: c.subindex,
            place: crate::diff::render::place(&c),
            rust_path: c.rust_path,
            old: c.old,
            new: c.new,
            message: c.message,
        });
    }
}

#[cfg(test)]
mod tests;
