//! The node-guarding slave: answers the master's requests and, with a life
//! time, supervises them (life guarding).

use core::time::Duration;

use super::guard_reply;
use crate::frame::cob;
use crate::heartbeat::Liveness;
use crate::nmt::NmtState;
use crate::od::NodeId;
use crate::queue::Ring;
use crate::{Frame, Instant, Service};

/// What a [`GuardResponder`] observed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum GuardResponderEvent {
    /// Life guarding: no request from the master within the life time after
    /// the previous one (reported once per loss).
    LifeGuardingLost,
    /// A request arrived after [`GuardResponderEvent::LifeGuardingLost`].
    LifeGuardingResumed,
}

/// Node-guarding slave of one node: answers every remote frame on its
/// 0x700 + node with toggle | state (the toggle alternates with every reply
/// sent; requests arriving before the reply is polled get one reply), and,
/// when a life time is set, supervises the master's requests from the first
/// one on (life guarding). Its event queue holds 4 events; when full the
/// oldest is dropped.
#[derive(Debug, Clone)]
pub struct GuardResponder {
    node: NodeId,
    state: NmtState,
    toggle: bool,
    reply_pending: bool,
    life: Option<Liveness>,
    events: Ring<GuardResponderEvent, 4>,
}

impl GuardResponder {
    /// A responder for `node` in [`NmtState::PreOperational`], toggle 0,
    /// without life guarding.
    pub const fn new(node: NodeId) -> GuardResponder {
        GuardResponder {
            node,
            state: NmtState::PreOperational,
            toggle: false,
            reply_pending: false,
            life: None,
            events: Ring::new(),
        }
    }

    /// The node this responder answers for.
    pub const fn node(&self) -> NodeId {
        self.node
    }

    /// Sets the state reported in the following replies.
    pub fn set_state(&mut self, state: NmtState) {
        self.state = state;
    }

    /// The state reported in replies.
    pub const fn state(&self) -> NmtState {
        self.state
    }

    /// The toggle bit the next reply carries.
    pub const fn toggle(&self) -> bool {
        self.toggle
    }

    /// Sets the toggle back to 0 (after boot-up or a communication reset).
    pub fn reset_toggle(&mut self) {
        self.toggle = false;
    }

    /// Sets the life time (objects 0x100C guard time × 0x100D life time
    /// factor, see [`life_time`](super::life_time)); `None` switches life guarding off.
    /// Supervision (re)starts with the next request.
    pub fn set_life_time(&mut self, life_time: Option<Duration>) {
        self.life = life_time.map(|time| Liveness::new(time, None));
    }

    /// Whether life guarding detected a lost master (and no request came since).
    pub fn is_lost(&self) -> bool {
        self.life.is_some_and(|life| life.is_lost())
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }
}

impl Service for GuardResponder {
    type Event = GuardResponderEvent;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        if !frame.is_remote() || frame.standard_id() != Some(cob::heartbeat(self.node)) {
            return;
        }
        self.reply_pending = true;
        if let Some(life) = &mut self.life
            && life.alive(now)
        {
            self.events.push(GuardResponderEvent::LifeGuardingResumed);
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        if let Some(life) = &mut self.life
            && life.expired(now)
        {
            self.events.push(GuardResponderEvent::LifeGuardingLost);
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        if !self.reply_pending {
            return None;
        }
        self.reply_pending = false;
        let frame = guard_reply(self.node, self.toggle, self.state);
        self.toggle = !self.toggle;
        Some(frame)
    }

    fn poll_event(&mut self) -> Option<GuardResponderEvent> {
        self.events.pop()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.life.and_then(|life| life.deadline())
    }
}
