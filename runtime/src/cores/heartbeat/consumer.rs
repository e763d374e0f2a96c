//! The heartbeat consumer (object 0x1016): supervises other nodes'
//! heartbeats.

use core::time::Duration;

use super::{Liveness, parse_heartbeat};
use crate::error_control::PerNode;
use crate::nmt::NmtState;
use crate::od::NodeId;
use crate::queue::Ring;
use crate::{Frame, Instant, Service};

/// What a [`HeartbeatConsumer`] observed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum HeartbeatEvent {
    /// No heartbeat within the consumer time (reported once per loss).
    Timeout {
        /// The monitored node.
        node: NodeId,
    },
    /// A heartbeat arrived after a [`HeartbeatEvent::Timeout`].
    Resumed {
        /// The monitored node.
        node: NodeId,
        /// The state its heartbeat reports.
        state: NmtState,
    },
    /// The node reported a new state; every boot-up message is reported.
    State {
        /// The monitored node.
        node: NodeId,
        /// Its new state.
        state: NmtState,
    },
}

/// Number of events a [`HeartbeatConsumer`] keeps (enough for a timeout of
/// every node at once); when full, the oldest is dropped and counted.
pub const CONSUMER_EVENTS: usize = 128;

/// Decodes one entry of object 0x1016 (bits 23..16 node id, bits 15..0
/// consumer time in ms); `None` when the entry is unused (node 0 or above
/// 127, or time 0).
pub fn parse_consumer_entry(value: u32) -> Option<(NodeId, Duration)> {
    let node = NodeId::new(u8::try_from((value >> 16) & 0xFF).ok()?)?;
    let millis = u64::from(value & 0xFFFF);
    (millis != 0).then(|| (node, Duration::from_millis(millis)))
}

/// Encodes an entry of object 0x1016; times above 65535 ms are clamped.
pub fn consumer_entry(node: NodeId, time: Duration) -> u32 {
    let millis = u32::try_from(time.as_millis())
        .unwrap_or(u32::MAX)
        .min(0xFFFF);
    u32::from(node.get()) << 16 | millis
}

/// Heartbeat consumer: supervises the heartbeats of configured nodes
/// (object 0x1016). Supervision of a node starts at its first heartbeat or
/// boot-up message; from then on, each heartbeat must arrive within the
/// consumer time after the previous one, or [`HeartbeatEvent::Timeout`] is
/// reported (once; supervision pauses until the next heartbeat). Frames with
/// a state byte that is no CiA 301 state are ignored.
#[derive(Debug, Clone)]
pub struct HeartbeatConsumer {
    nodes: PerNode<Liveness>,
    events: Ring<HeartbeatEvent, CONSUMER_EVENTS>,
}

default_is_new!(HeartbeatConsumer);

impl HeartbeatConsumer {
    /// A consumer monitoring no node.
    pub const fn new() -> HeartbeatConsumer {
        HeartbeatConsumer {
            nodes: PerNode::new(),
            events: Ring::new(),
        }
    }

    /// Monitors `node` with consumer time `time`, starting afresh (waiting
    /// for its first heartbeat); `None` stops monitoring it (as
    /// [`HeartbeatConsumer::forget`]). A time shorter than the object's
    /// unit, 1 ms, counts as 1 ms.
    pub fn monitor(&mut self, node: NodeId, time: Option<Duration>) {
        let entry = time.map(|time| Liveness::new(time.max(Duration::from_millis(1)), None));
        self.nodes.set(node, entry);
    }

    /// Stops monitoring `node`.
    pub fn forget(&mut self, node: NodeId) {
        self.nodes.set(node, None);
    }

    /// Replaces the configuration with the entries of object 0x1016 (see
    /// [`parse_consumer_entry`]; unused entries are skipped).
    pub fn configure(&mut self, entries: &[u32]) {
        self.nodes = PerNode::new();
        for (node, time) in entries.iter().filter_map(|e| parse_consumer_entry(*e)) {
            // A zero consumer time in the object is CiA 301's "not used".
            self.monitor(node, (!time.is_zero()).then_some(time));
        }
    }

    /// Whether `node` is monitored.
    pub fn is_monitored(&self, node: NodeId) -> bool {
        self.nodes.get(node).is_some()
    }

    /// The state `node` last reported; `None` when not monitored or not heard
    /// from yet.
    pub fn state(&self, node: NodeId) -> Option<NmtState> {
        self.nodes.get(node).and_then(Liveness::state)
    }

    /// Whether `node`'s heartbeat is currently missing (timed out).
    pub fn is_timed_out(&self, node: NodeId) -> bool {
        self.nodes.get(node).is_some_and(Liveness::is_lost)
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }
}

impl Service for HeartbeatConsumer {
    type Event = HeartbeatEvent;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        let Some((node, state)) = parse_heartbeat(frame) else {
            return;
        };
        let Some(m) = self.nodes.get_mut(node) else {
            return;
        };
        if m.alive(now) {
            self.events.push(HeartbeatEvent::Resumed { node, state });
        }
        if m.report(state) {
            self.events.push(HeartbeatEvent::State { node, state });
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        for (node, m) in self.nodes.iter_mut() {
            if m.expired(now) {
                self.events.push(HeartbeatEvent::Timeout { node });
            }
        }
    }

    fn poll_event(&mut self) -> Option<HeartbeatEvent> {
        self.events.pop()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.nodes.iter().filter_map(Liveness::deadline).min()
    }
}
