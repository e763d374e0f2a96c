//! NMT network management (CiA 301): the module-control commands (COB-ID
//! 0x000), the NMT states, a master that tracks every node's reported state,
//! and a slave state machine for devices and simulators.
//!
//! Also home of the crate-internal fixed-size queue that the small protocol
//! cores (NMT, heartbeat, guarding, EMCY, SYNC) keep their events in.

use core::fmt;

use crate::error_control::parse_error_control;
use crate::frame::cob;
use crate::od::NodeId;
use crate::{Frame, Instant, Service};

use crate::queue::Ring;

/// An NMT module-control command (byte 0 of a frame on COB-ID 0x000).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum NmtCommand {
    /// Start remote node: enter Operational.
    Start = 0x01,
    /// Stop remote node: enter Stopped.
    Stop = 0x02,
    /// Enter Pre-operational.
    EnterPreOperational = 0x80,
    /// Reset the whole node (application and communication).
    ResetNode = 0x81,
    /// Reset the communication parameters only.
    ResetCommunication = 0x82,
}

impl NmtCommand {
    /// The command with command specifier `byte`; `None` for other values.
    pub const fn from_byte(byte: u8) -> Option<NmtCommand> {
        match byte {
            0x01 => Some(NmtCommand::Start),
            0x02 => Some(NmtCommand::Stop),
            0x80 => Some(NmtCommand::EnterPreOperational),
            0x81 => Some(NmtCommand::ResetNode),
            0x82 => Some(NmtCommand::ResetCommunication),
            _ => None,
        }
    }

    /// The command specifier byte.
    pub const fn to_byte(self) -> u8 {
        self as u8
    }

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

impl fmt::Display for NmtCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            NmtCommand::Start => "start",
            NmtCommand::Stop => "stop",
            NmtCommand::EnterPreOperational => "enter pre-operational",
            NmtCommand::ResetNode => "reset node",
            NmtCommand::ResetCommunication => "reset communication",
        })
    }
}

/// An NMT state as reported in boot-up, heartbeat and node-guarding frames
/// (bits 6..0 of the state byte).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum NmtState {
    /// The boot-up message: the node has just (re)initialised.
    BootUp = 0x00,
    /// Stopped: only NMT and error control are active.
    Stopped = 0x04,
    /// Operational: all services, PDOs included, are active.
    Operational = 0x05,
    /// Pre-operational: all services but PDOs are active.
    PreOperational = 0x7F,
}

impl NmtState {
    /// The state with code `byte` (bit 7, the guarding toggle, must already
    /// be masked off); `None` for other values.
    pub const fn from_byte(byte: u8) -> Option<NmtState> {
        match byte {
            0x00 => Some(NmtState::BootUp),
            0x04 => Some(NmtState::Stopped),
            0x05 => Some(NmtState::Operational),
            0x7F => Some(NmtState::PreOperational),
            _ => None,
        }
    }

    /// The state code.
    pub const fn to_byte(self) -> u8 {
        self as u8
    }
}

impl fmt::Display for NmtState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            NmtState::BootUp => "boot-up",
            NmtState::Stopped => "stopped",
            NmtState::Operational => "operational",
            NmtState::PreOperational => "pre-operational",
        })
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

/// The outbox of [`NmtMaster`] is full; the command was not queued.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QueueFull;

impl fmt::Display for QueueFull {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("the NMT command queue is full; send the queued frames first")
    }
}

impl core::error::Error for QueueFull {}

/// What an [`NmtMaster`] observed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum NmtEvent {
    /// The node sent its boot-up message (it was reset or powered on).
    BootUp(NodeId),
    /// The node reported a state different from the last one it reported
    /// (`from` is `None` the first time).
    StateChanged {
        /// The reporting node.
        node: NodeId,
        /// The state it reported before, if any.
        from: Option<NmtState>,
        /// The state it reports now.
        to: NmtState,
    },
}

/// Number of command frames [`NmtMaster::send`] can queue.
pub const MASTER_OUTBOX: usize = 16;
/// Number of events [`NmtMaster`] keeps; when full the oldest is dropped
/// (see [`NmtMaster::dropped_events`]).
pub const MASTER_EVENTS: usize = 32;

/// NMT master: sends module-control commands and tracks the state every
/// node reports in its boot-up, heartbeat and node-guarding frames
/// (0x700 + node; bit 7, the guarding toggle, is ignored). State bytes that
/// are no CiA 301 state are ignored.
#[derive(Debug, Clone)]
pub struct NmtMaster {
    reported: [Option<NmtState>; 128],
    expected: [Option<NmtState>; 128],
    outbox: Ring<Frame, MASTER_OUTBOX>,
    events: Ring<NmtEvent, MASTER_EVENTS>,
}

impl Default for NmtMaster {
    fn default() -> Self {
        NmtMaster::new()
    }
}

impl NmtMaster {
    /// A master that knows nothing about any node yet.
    pub const fn new() -> NmtMaster {
        NmtMaster {
            reported: [None; 128],
            expected: [None; 128],
            outbox: Ring::new(),
            events: Ring::new(),
        }
    }

    /// Queues `cmd` for `target` and records the state the command should
    /// bring the node(s) to (see [`NmtMaster::expected`]). The reported
    /// state ([`NmtMaster::state`]) only changes when a node reports. Fails
    /// when [`MASTER_OUTBOX`] frames are already queued.
    pub fn send(&mut self, cmd: NmtCommand, target: NmtTarget) -> Result<(), QueueFull> {
        self.outbox
            .try_push(command_frame(cmd, target))
            .map_err(|_| QueueFull)?;
        let to = Some(cmd.target_state());
        match target {
            NmtTarget::Node(node) => {
                if let Some(slot) = self.expected.get_mut(usize::from(node.get())) {
                    *slot = to;
                }
            }
            NmtTarget::All => {
                for slot in self.expected.iter_mut().skip(1) {
                    *slot = to;
                }
            }
        }
        Ok(())
    }

    /// The state `node` last reported; `None` until it reports one.
    pub fn state(&self, node: NodeId) -> Option<NmtState> {
        self.reported
            .get(usize::from(node.get()))
            .copied()
            .flatten()
    }

    /// The state the last command sent to `node` should bring it to; `None`
    /// if no command was sent. Compare with [`NmtMaster::state`] to see
    /// whether the node followed.
    pub fn expected(&self, node: NodeId) -> Option<NmtState> {
        self.expected
            .get(usize::from(node.get()))
            .copied()
            .flatten()
    }

    /// Forgets what `node` reported and what was expected of it.
    pub fn forget(&mut self, node: NodeId) {
        let i = usize::from(node.get());
        if let Some(slot) = self.reported.get_mut(i) {
            *slot = None;
        }
        if let Some(slot) = self.expected.get_mut(i) {
            *slot = None;
        }
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }
}

impl Service for NmtMaster {
    type Event = NmtEvent;

    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        let Some((node, byte)) = parse_error_control(frame) else {
            return;
        };
        let Some(to) = NmtState::from_byte(byte & 0x7F) else {
            return;
        };
        let Some(slot) = self.reported.get_mut(usize::from(node.get())) else {
            return;
        };
        // After its boot-up message a node is Pre-operational by itself
        // (CiA 301): that is the master's view of it from then on.
        let booted_up = to == NmtState::BootUp;
        let to = if booted_up {
            NmtState::PreOperational
        } else {
            to
        };
        let from = slot.replace(to);
        if booted_up {
            self.events.push(NmtEvent::BootUp(node));
        }
        if from != Some(to) {
            self.events.push(NmtEvent::StateChanged { node, from, to });
        }
    }

    fn handle_timeout(&mut self, _now: Instant) {}

    fn poll_transmit(&mut self) -> Option<Frame> {
        self.outbox.pop()
    }

    fn poll_event(&mut self) -> Option<NmtEvent> {
        self.events.pop()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        None
    }
}

mod slave;

pub use slave::{NmtSlave, NmtSlaveEvent};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CanId;

    fn node(n: u8) -> NodeId {
        NodeId::new(n).unwrap()
    }

    fn data(id: u16, bytes: &[u8]) -> Frame {
        Frame::new(CanId::Standard(id), bytes).unwrap()
    }

    fn events<S: Service>(s: &mut S) -> Vec<S::Event> {
        core::iter::from_fn(|| s.poll_event()).collect()
    }

    #[test]
    fn command_frames_match_cia301_layout() {
        // Start node 32: 000#0120.
        assert_eq!(
            command_frame(NmtCommand::Start, NmtTarget::Node(node(32))),
            data(0x000, &[0x01, 0x20])
        );
        // Reset communication of all nodes: 000#8200.
        assert_eq!(
            command_frame(NmtCommand::ResetCommunication, NmtTarget::All),
            data(0x000, &[0x82, 0x00])
        );
        assert_eq!(
            command_frame(NmtCommand::EnterPreOperational, NmtTarget::Node(node(127))),
            data(0x000, &[0x80, 0x7F])
        );
    }

    #[test]
    fn parse_command_accepts_only_valid_frames() {
        assert_eq!(
            parse_command(&data(0x000, &[0x02, 0x05])),
            Some((NmtCommand::Stop, NmtTarget::Node(node(5))))
        );
        assert_eq!(
            parse_command(&data(0x000, &[0x81, 0x00])),
            Some((NmtCommand::ResetNode, NmtTarget::All))
        );
        assert_eq!(parse_command(&data(0x000, &[0x03, 0x05])), None);
        assert_eq!(parse_command(&data(0x000, &[0x01, 0x80])), None);
        assert_eq!(parse_command(&data(0x000, &[0x01])), None);
        assert_eq!(parse_command(&data(0x000, &[0x01, 0x05, 0x00])), None);
        assert_eq!(parse_command(&data(0x001, &[0x01, 0x05])), None);
        assert_eq!(
            parse_command(&Frame::remote(CanId::Standard(0), 2).unwrap()),
            None
        );
        assert_eq!(
            parse_command(&Frame::new(CanId::Extended(0), &[1, 5]).unwrap()),
            None
        );
    }

    #[test]
    fn only_all_addresses_node_zero() {
        for b in 0..=255u8 {
            let built = [
                NmtTarget::try_from(b).ok(),
                NodeId::new(b).map(NmtTarget::from),
                NodeId::new(b).map(NmtTarget::Node),
            ];
            for target in built.into_iter().flatten() {
                let frame = command_frame(NmtCommand::ResetNode, target);
                assert_eq!(frame.data(), [0x81, b]);
                assert_ne!(target.to_byte(), 0);
            }
            assert_eq!(NmtTarget::try_from(b).is_ok(), (1..=127).contains(&b));
            let parsed = NmtTarget::from_byte(b);
            assert_eq!(parsed.map(NmtTarget::to_byte), parsed.map(|_| b));
        }
        assert_eq!(NmtTarget::try_from(0), Err(InvalidNodeId(0)));
        assert_eq!(
            command_frame(NmtCommand::ResetNode, NmtTarget::All).data(),
            [0x81, 0]
        );
    }

    #[test]
    fn byte_conversions() {
        for b in 0..=255u8 {
            if let Some(c) = NmtCommand::from_byte(b) {
                assert_eq!(c.to_byte(), b);
            }
            if let Some(s) = NmtState::from_byte(b) {
                assert_eq!(s.to_byte(), b);
            }
        }
        assert_eq!(NmtState::from_byte(0x7F), Some(NmtState::PreOperational));
        assert_eq!(NmtState::from_byte(0x01), None);
    }

    #[test]
    fn master_queues_commands_without_claiming_state() {
        let mut m = NmtMaster::new();
        m.send(NmtCommand::Start, NmtTarget::Node(node(32)))
            .unwrap();
        assert_eq!(m.poll_transmit(), Some(data(0x000, &[0x01, 0x20])));
        assert_eq!(m.poll_transmit(), None);
        assert_eq!(m.state(node(32)), None);
        assert_eq!(m.expected(node(32)), Some(NmtState::Operational));
        m.send(NmtCommand::Stop, NmtTarget::All).unwrap();
        assert_eq!(m.expected(node(1)), Some(NmtState::Stopped));
        assert_eq!(m.expected(node(127)), Some(NmtState::Stopped));
        assert!(events(&mut m).is_empty());
    }

    #[test]
    fn master_outbox_is_bounded() {
        let mut m = NmtMaster::new();
        for _ in 0..MASTER_OUTBOX {
            m.send(NmtCommand::Start, NmtTarget::All).unwrap();
        }
        assert_eq!(m.send(NmtCommand::Stop, NmtTarget::All), Err(QueueFull));
        assert_eq!(core::iter::from_fn(|| m.poll_transmit()).count(), 16);
    }

    #[test]
    fn master_tracks_boot_up_and_heartbeats() {
        let mut m = NmtMaster::new();
        let t = Instant::ZERO;
        m.handle_frame(t, &data(0x720, &[0x00]));
        assert_eq!(
            events(&mut m),
            [
                NmtEvent::BootUp(node(32)),
                NmtEvent::StateChanged {
                    node: node(32),
                    from: None,
                    to: NmtState::PreOperational
                }
            ]
        );
        // Pre-operational after the boot-up message, as CiA 301 has it:
        // its first heartbeat changes nothing.
        assert_eq!(m.state(node(32)), Some(NmtState::PreOperational));
        m.handle_frame(t, &data(0x720, &[0x7F]));
        assert!(events(&mut m).is_empty());
        // A boot-up from a node seen pre-operational is still reported.
        m.handle_frame(t, &data(0x720, &[0x00]));
        assert_eq!(events(&mut m), [NmtEvent::BootUp(node(32))]);
        // A guarding reply with the toggle bit set: 0x85 = operational.
        m.handle_frame(t, &data(0x720, &[0x85]));
        assert_eq!(m.state(node(32)), Some(NmtState::Operational));
        assert_eq!(events(&mut m).len(), 1);
        // Unknown state, wrong length, remote frames, other ids: ignored.
        m.handle_frame(t, &data(0x720, &[0x03]));
        m.handle_frame(t, &data(0x720, &[0x05, 0x00]));
        m.handle_frame(t, &Frame::remote(CanId::Standard(0x720), 1).unwrap());
        m.handle_frame(t, &data(0x700, &[0x00]));
        m.handle_frame(t, &data(0x620, &[0x00]));
        assert!(events(&mut m).is_empty());
        assert_eq!(m.state(node(32)), Some(NmtState::Operational));
        // A second boot-up is reported even after another boot-up.
        m.handle_frame(t, &data(0x720, &[0x00]));
        m.handle_frame(t, &data(0x720, &[0x00]));
        assert_eq!(
            events(&mut m),
            [
                NmtEvent::BootUp(node(32)),
                NmtEvent::StateChanged {
                    node: node(32),
                    from: Some(NmtState::Operational),
                    to: NmtState::PreOperational
                },
                NmtEvent::BootUp(node(32)),
            ]
        );
    }

    #[test]
    fn master_event_queue_drops_oldest() {
        let mut m = NmtMaster::new();
        for n in 1..=40u8 {
            m.handle_frame(Instant::ZERO, &data(0x700 + u16::from(n), &[0x05]));
        }
        let got = events(&mut m);
        assert_eq!(got.len(), MASTER_EVENTS);
        assert_eq!(m.dropped_events(), 8);
        assert_eq!(
            got[0],
            NmtEvent::StateChanged {
                node: node(9),
                from: None,
                to: NmtState::Operational
            }
        );
    }
}
