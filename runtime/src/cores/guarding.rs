//! Node guarding and life guarding (CiA 301 error control, the older
//! alternative to heartbeats).
//!
//! The master sends a remote frame on 0x700 + node (DLC 1) every guard time;
//! the node answers with one byte: bit 7 a toggle bit (0 in the first reply
//! after boot-up or reset, alternating with every reply) and bits 6..0 its
//! NMT state. The master reports a node whose valid replies stop for the
//! life time (guard time × life time factor); the node reports a master
//! whose requests stop for its life time (life guarding).

use core::num::NonZeroU8;
use core::time::Duration;

use crate::error_control::{PerNode, parse_state};
use crate::frame::{CanId, cob};
use crate::heartbeat::Liveness;
use crate::nmt::NmtState;
use crate::od::NodeId;
use crate::queue::Ring;
use crate::time::next_period;
use crate::{Frame, Instant, Service};

/// The guarding request for `node`: a remote frame on 0x700 + node, DLC 1.
pub fn guard_request(node: NodeId) -> Frame {
    Frame::remote(CanId::Standard(cob::heartbeat(node)), 1).unwrap_or(Frame::standard(
        cob::heartbeat(node),
        [0; 8],
        0,
    ))
}

/// The life time of node guarding from the values of objects 0x100C
/// (guard time) and 0x100D (life time factor): their product, or `None`
/// when either is zero, which CiA 301 defines as "guarding not used".
pub const fn life_time(guard_time: Duration, life_time_factor: u8) -> Option<Duration> {
    if guard_time.is_zero() || life_time_factor == 0 {
        return None;
    }
    // A guard time in ms times a u8 factor stays far from overflow; a
    // Duration built otherwise saturates.
    match guard_time.checked_mul(life_time_factor as u32) {
        Some(life_time) => Some(life_time),
        None => Some(Duration::MAX),
    }
}

/// The guarding reply of `node`: 0x700 + node, data `[toggle << 7 | state]`.
pub const fn guard_reply(node: NodeId, toggle: bool, state: NmtState) -> Frame {
    let byte = (toggle as u8) << 7 | state.to_byte();
    Frame::standard(cob::heartbeat(node), [byte, 0, 0, 0, 0, 0, 0, 0], 1)
}

/// What a [`NodeGuard`] observed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum GuardEvent {
    /// The node reported a new state (every boot-up message is reported).
    State {
        /// The guarded node.
        node: NodeId,
        /// Its new state.
        state: NmtState,
    },
    /// A reply whose toggle bit did not alternate; it does not count as a
    /// valid reply.
    ToggleError {
        /// The guarded node.
        node: NodeId,
    },
    /// No valid reply within the life time (reported once per loss).
    LifeTimeExpired {
        /// The guarded node.
        node: NodeId,
    },
    /// A valid reply arrived after [`GuardEvent::LifeTimeExpired`].
    Resumed {
        /// The guarded node.
        node: NodeId,
    },
}

/// Number of events a [`NodeGuard`] keeps (enough for every node at once);
/// when full, the oldest is dropped and counted.
pub const GUARD_EVENTS: usize = 128;

#[derive(Debug, Clone, Copy)]
struct Guarded {
    guard_time: Duration,
    next_request: Instant,
    request_pending: bool,
    expected_toggle: bool,
    life: Liveness,
}

/// Node-guarding master: guards any number of nodes, each with its own
/// guard time and life time factor.
///
/// - A request is due every guard time from [`NodeGuard::guard`]; requests
///   are built when polled (at most one pending per node). If the clock
///   jumps over several guard times, one request is sent and the next is
///   scheduled one guard time after `now`.
/// - Any reply counts, whether a request is outstanding or not. The first
///   reply expected has toggle 0; a boot-up message (state byte 0x00) sets the
///   expectation back to 0 and counts as a valid reply. A reply with the
///   wrong toggle gives [`GuardEvent::ToggleError`]; the expectation then
///   follows that reply, so one lost reply gives one error.
/// - Replies with a state byte that is no CiA 301 state are ignored.
#[derive(Debug, Clone)]
pub struct NodeGuard {
    nodes: PerNode<Guarded>,
    cursor: usize,
    events: Ring<GuardEvent, GUARD_EVENTS>,
}

default_is_new!(NodeGuard);

impl NodeGuard {
    /// A master guarding no node.
    pub const fn new() -> NodeGuard {
        NodeGuard {
            nodes: PerNode::new(),
            cursor: 0,
            events: Ring::new(),
        }
    }

    /// Starts guarding `node` (afresh if it was guarded): a request every
    /// `guard_time` (at least 1 ms, the unit of object 0x100C), the first
    /// due at `now`; the node is lost when no answer comes for
    /// `guard_time × life_time_factor` from `now`. [`NodeGuard::forget`]
    /// stops guarding it; for the object values, where a zero means
    /// "guarding not used", see [`life_time`].
    pub fn guard(
        &mut self,
        now: Instant,
        node: NodeId,
        guard_time: Duration,
        life_time_factor: NonZeroU8,
    ) {
        let guard_time = guard_time.max(Duration::from_millis(1));
        let life_time = guard_time.saturating_mul(u32::from(life_time_factor.get()));
        let entry = Some(Guarded {
            guard_time,
            next_request: now,
            request_pending: false,
            expected_toggle: false,
            life: Liveness::new(life_time, Some(now + life_time)),
        });
        self.nodes.set(node, entry);
    }

    /// Stops guarding `node`.
    pub fn forget(&mut self, node: NodeId) {
        self.nodes.set(node, None);
    }

    /// Whether `node` is guarded.
    pub fn is_guarded(&self, node: NodeId) -> bool {
        self.nodes.get(node).is_some()
    }

    /// The state `node` last reported; `None` if not guarded or not heard
    /// from yet.
    pub fn state(&self, node: NodeId) -> Option<NmtState> {
        self.nodes.get(node).and_then(|g| g.life.state())
    }

    /// Whether `node`'s life time has expired (and no valid reply came since).
    pub fn is_expired(&self, node: NodeId) -> bool {
        self.nodes.get(node).is_some_and(|g| g.life.is_lost())
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }
}

impl Service for NodeGuard {
    type Event = GuardEvent;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        let Some((node, state, toggle)) = parse_state(frame) else {
            return;
        };
        let Some(g) = self.nodes.get_mut(node) else {
            return;
        };
        if state == NmtState::BootUp {
            g.expected_toggle = false;
        } else if toggle != g.expected_toggle {
            g.expected_toggle = !toggle;
            self.events.push(GuardEvent::ToggleError { node });
            return;
        } else {
            g.expected_toggle = !toggle;
        }
        if g.life.alive(now) {
            self.events.push(GuardEvent::Resumed { node });
        }
        if g.life.report(state) {
            self.events.push(GuardEvent::State { node, state });
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        for (node, g) in self.nodes.iter_mut() {
            if g.life.expired(now) {
                self.events.push(GuardEvent::LifeTimeExpired { node });
            }
            if g.next_request <= now {
                g.request_pending = true;
                g.next_request = next_period(g.next_request, now, g.guard_time);
            }
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        let node = self
            .nodes
            .next_from(self.cursor, |g| core::mem::take(&mut g.request_pending))?;
        self.cursor = (usize::from(node.get()) + 1) % 128;
        Some(guard_request(node))
    }

    fn poll_event(&mut self) -> Option<GuardEvent> {
        self.events.pop()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.nodes
            .iter()
            .flat_map(|g| [Some(g.next_request), g.life.deadline()])
            .flatten()
            .min()
    }
}

mod responder;

pub use responder::{GuardResponder, GuardResponderEvent};

#[cfg(test)]
mod tests;
