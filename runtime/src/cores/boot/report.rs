//! What the network's boot reports: its events ([`NetworkEvent`]), each
//! slave's state and last boot ([`SlaveStatus`]), and the outcome with
//! every slave ([`NetworkReport`]).

use alloc::borrow::Cow;
use alloc::vec::Vec;

use super::{BootError, BootEvent, BootStatus};
use crate::Instant;
use crate::od::NodeId;

/// What happened in the network.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum NetworkEvent {
    /// One step of a slave's boot.
    Step { node: NodeId, step: BootEvent },
    /// A slave's boot failed (CiA 302-2 status A–O, with the object and
    /// the expected and found values).
    Failed(BootError),
    /// The master sent the slave NMT Start.
    Started(NodeId),
    /// Supervision lost the slave (status E: heartbeat, F: guarding).
    Lost { node: NodeId, status: BootStatus },
    /// A slave booted again by itself, or answered again after it was
    /// lost: its boot starts over.
    Rebooting(NodeId),
    /// The network's boot is over and every mandatory slave is booted;
    /// `failed` lists the optional slaves whose boot failed.
    Booted { failed: Vec<NodeId> },
    /// The network's boot is over and a mandatory slave failed.
    BootFailed { failed: Vec<BootError> },
}

/// Where a slave stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlaveState {
    /// Its boot has not started (the network boot was not started).
    Waiting,
    /// Its boot is running.
    Booting,
    /// Booted, not started (yet).
    Booted,
    /// Booted and started.
    Operational,
    /// Its last boot failed; it is booted again when it sends a boot-up
    /// message.
    Failed,
    /// Supervision lost it; it is booted again when it answers.
    Lost,
}

/// What the last boot did with the configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Configuration {
    /// 0x1020 matched: nothing written.
    Current,
    /// This many entries were written.
    Written(usize),
    /// The slave is not booted by the master (0x1F81 bit 2 clear).
    NotManaged,
}

/// One slave's report.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlaveStatus {
    pub node: NodeId,
    pub name: Cow<'static, str>,
    pub mandatory: bool,
    pub state: SlaveState,
    /// The identity matched in the last boot.
    pub identity_checked: bool,
    pub configuration: Option<Configuration>,
    /// When its last boot started and when it ended (booted or failed).
    pub boot_started: Option<Instant>,
    pub boot_ended: Option<Instant>,
    /// Why the last boot failed.
    pub error: Option<BootError>,
    /// How many boots were started.
    pub boots: u32,
}

/// How the network's boot ended, with every slave's report.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NetworkReport {
    /// Every mandatory slave is booted (the network runs).
    pub booted: bool,
    pub slaves: Vec<SlaveStatus>,
}

impl NetworkReport {
    /// The failed boots (mandatory and optional), in node order.
    pub fn errors(&self) -> impl Iterator<Item = &BootError> {
        self.slaves.iter().filter_map(|s| s.error.as_ref())
    }
}

/// Whether `event` ends the network's first boot ([`NetworkEvent::Booted`]
/// or [`NetworkEvent::BootFailed`]); what the masters wait for.
pub fn ends_boot(event: &NetworkEvent) -> bool {
    matches!(
        event,
        NetworkEvent::Booted { .. } | NetworkEvent::BootFailed { .. }
    )
}
