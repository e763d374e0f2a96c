//! The NMT master: sends module-control commands and tracks what every
//! node reports.

use core::fmt;

use super::{NmtCommand, NmtState, NmtTarget, command_frame};
use crate::error_control::{PerNode, parse_state};
use crate::od::NodeId;
use crate::queue::Ring;
use crate::{Frame, Instant, Service};

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
    reported: PerNode<NmtState>,
    expected: PerNode<NmtState>,
    outbox: Ring<Frame, MASTER_OUTBOX>,
    events: Ring<NmtEvent, MASTER_EVENTS>,
}

default_is_new!(NmtMaster);

impl NmtMaster {
    /// A master that knows nothing about any node yet.
    pub const fn new() -> NmtMaster {
        NmtMaster {
            reported: PerNode::new(),
            expected: PerNode::new(),
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
                self.expected.set(node, to);
            }
            NmtTarget::All => self.expected.set_all(to),
        }
        Ok(())
    }

    /// The state `node` last reported; `None` until it reports one.
    pub fn state(&self, node: NodeId) -> Option<NmtState> {
        self.reported.get(node).copied()
    }

    /// The state the last command sent to `node` should bring it to; `None`
    /// if no command was sent. Compare with [`NmtMaster::state`] to see
    /// whether the node followed.
    pub fn expected(&self, node: NodeId) -> Option<NmtState> {
        self.expected.get(node).copied()
    }

    /// Forgets what `node` reported and what was expected of it.
    pub fn forget(&mut self, node: NodeId) {
        self.reported.set(node, None);
        self.expected.set(node, None);
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }
}

impl Service for NmtMaster {
    type Event = NmtEvent;

    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        let Some((node, to, _)) = parse_state(frame) else {
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
        let from = self.reported.set(node, Some(to));
        if booted_up {
            self.events.push(NmtEvent::BootUp(node));
        }
        if from != Some(to) {
            self.events.push(NmtEvent::StateChanged { node, from, to });
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        self.outbox.pop()
    }

    fn poll_event(&mut self) -> Option<NmtEvent> {
        self.events.pop()
    }
}
