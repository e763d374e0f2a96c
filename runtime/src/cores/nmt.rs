//! NMT network management (CiA 301): the module-control commands (COB-ID
//! 0x000), the NMT states, a master that tracks every node's reported state,
//! and a slave state machine for devices and simulators.

use core::fmt;

use crate::Frame;
pub use crate::error_control::NmtState;
use crate::frame::cob;
use crate::od::NodeId;

byte_enum! {
    /// An NMT module-control command (byte 0 of a frame on COB-ID 0x000).
    pub enum NmtCommand {
        /// Start remote node: enter Operational.
        Start = 0x01 => "start",
        /// Stop remote node: enter Stopped.
        Stop = 0x02 => "stop",
        /// Enter Pre-operational.
        EnterPreOperational = 0x80 => "enter pre-operational",
        /// Reset the whole node (application and communication).
        ResetNode = 0x81 => "reset node",
        /// Reset the communication parameters only.
        ResetCommunication = 0x82 => "reset communication",
    }
}

impl NmtCommand {
    /// The state a node is in once it has carried the command out (resets
    /// end in Pre-operational, after the boot-up message).
    pub const fn target_state(self) -> NmtState {
        match self {
            NmtCommand::Start => NmtState::Operational,
            NmtCommand::Stop => NmtState::Stopped,
            NmtCommand::EnterPreOperational
            | NmtCommand::ResetNode
            | NmtCommand::ResetCommunication => NmtState::PreOperational,
        }
    }
}

/// The node(s) an NMT command addresses. A broadcast is spelled out
/// ([`NmtTarget::All`]): an invalid node id never turns into one, since
/// [`NodeId`] holds only 1 to 127 and [`NmtTarget::try_from`] a `u8`
/// refuses 0 and 128 to 255.
///
/// ```
/// use eds2rust_runtime::nmt::{NmtTarget, InvalidNodeId};
/// use eds2rust_runtime::od::NodeId;
///
/// assert_eq!(NmtTarget::try_from(0x20).unwrap().to_byte(), 0x20);
/// assert_eq!(NmtTarget::try_from(0), Err(InvalidNodeId(0)));
/// assert_eq!(NodeId::new(0).map(NmtTarget::Node), None);
/// assert_eq!(NmtTarget::All.to_byte(), 0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NmtTarget {
    /// Every node: node id 0 on the bus.
    All,
    /// One node.
    Node(NodeId),
}

impl NmtTarget {
    /// The node byte of the command frame (0 for [`NmtTarget::All`]).
    pub const fn to_byte(self) -> u8 {
        match self {
            NmtTarget::All => 0,
            NmtTarget::Node(node) => node.get(),
        }
    }

    /// The target a received command frame's node byte names: 0 is every
    /// node, 1 to 127 one node, anything else none (the frame is invalid).
    /// Not public: a number never becomes a broadcast outside frame
    /// decoding ([`parse_command`]).
    const fn from_byte(byte: u8) -> Option<NmtTarget> {
        match byte {
            0 => Some(NmtTarget::All),
            n => match NodeId::new(n) {
                Some(node) => Some(NmtTarget::Node(node)),
                None => None,
            },
        }
    }

    /// Whether a node with id `node` carries out a command sent to this
    /// target.
    pub fn includes(self, node: NodeId) -> bool {
        match self {
            NmtTarget::All => true,
            NmtTarget::Node(target) => target == node,
        }
    }
}

impl From<NodeId> for NmtTarget {
    fn from(node: NodeId) -> NmtTarget {
        NmtTarget::Node(node)
    }
}

impl TryFrom<u8> for NmtTarget {
    type Error = InvalidNodeId;

    /// The node `id` (1 to 127). 0 is refused too: a broadcast is
    /// [`NmtTarget::All`], never a number.
    fn try_from(id: u8) -> Result<NmtTarget, InvalidNodeId> {
        NodeId::new(id)
            .map(NmtTarget::Node)
            .ok_or(InvalidNodeId(id))
    }
}

impl fmt::Display for NmtTarget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NmtTarget::All => f.write_str("all nodes"),
            NmtTarget::Node(node) => write!(f, "node {node}"),
        }
    }
}

/// A node id outside 1 to 127 where one node was meant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InvalidNodeId(pub u8);

impl fmt::Display for InvalidNodeId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} is no node id (1 to 127); to address every node use NmtTarget::All",
            self.0
        )
    }
}

impl core::error::Error for InvalidNodeId {}

/// The NMT frame for `cmd`: COB-ID 0x000, data `[command, node]`, node 0
/// for [`NmtTarget::All`].
pub const fn command_frame(cmd: NmtCommand, target: NmtTarget) -> Frame {
    Frame::standard(
        cob::NMT,
        [cmd.to_byte(), target.to_byte(), 0, 0, 0, 0, 0, 0],
        2,
    )
}

/// Decodes an NMT module-control frame: COB-ID 0x000, a data frame of
/// exactly 2 bytes, a known command and a node id of 0 (all nodes) or 1 to
/// 127. Anything else gives `None`.
pub fn parse_command(frame: &Frame) -> Option<(NmtCommand, NmtTarget)> {
    if frame.standard_id() != Some(cob::NMT) || frame.is_remote() {
        return None;
    }
    let [cmd, node] = *frame.data() else {
        return None;
    };
    Some((NmtCommand::from_byte(cmd)?, NmtTarget::from_byte(node)?))
}

mod master;
mod slave;

pub use master::{MASTER_EVENTS, MASTER_OUTBOX, NmtEvent, NmtMaster, QueueFull};
pub use slave::{NmtSlave, NmtSlaveEvent};

#[cfg(test)]
mod tests;
