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

use crate::error_control::parse_error_control;
use crate::frame::{CanId, cob};
use crate::heartbeat::next_period;
use crate::nmt::NmtState;
use crate::od::NodeId;
use crate::queue::Ring;
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
    life_time: Duration,
    next_request: Instant,
    request_pending: bool,
    life_deadline: Option<Instant>,
    expected_toggle: bool,
    state: Option<NmtState>,
    expired: bool,
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
    nodes: [Option<Guarded>; 128],
    cursor: usize,
    events: Ring<GuardEvent, GUARD_EVENTS>,
}

impl Default for NodeGuard {
    fn default() -> Self {
        NodeGuard::new()
    }
}

impl NodeGuard {
    /// A master guarding no node.
    pub const fn new() -> NodeGuard {
        NodeGuard {
            nodes: [None; 128],
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
            life_time,
            next_request: now,
            request_pending: false,
            life_deadline: Some(now + life_time),
            expected_toggle: false,
            state: None,
            expired: false,
        });
        if let Some(slot) = self.nodes.get_mut(usize::from(node.get())) {
            *slot = entry;
        }
    }

    /// Stops guarding `node`.
    pub fn forget(&mut self, node: NodeId) {
        if let Some(slot) = self.nodes.get_mut(usize::from(node.get())) {
            *slot = None;
        }
    }

    /// Whether `node` is guarded.
    pub fn is_guarded(&self, node: NodeId) -> bool {
        self.get(node).is_some()
    }

    /// The state `node` last reported; `None` if not guarded or not heard
    /// from yet.
    pub fn state(&self, node: NodeId) -> Option<NmtState> {
        self.get(node).and_then(|g| g.state)
    }

    /// Whether `node`'s life time has expired (and no valid reply came since).
    pub fn is_expired(&self, node: NodeId) -> bool {
        self.get(node).is_some_and(|g| g.expired)
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }

    fn get(&self, node: NodeId) -> Option<&Guarded> {
        self.nodes.get(usize::from(node.get()))?.as_ref()
    }
}

impl Service for NodeGuard {
    type Event = GuardEvent;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        let Some((node, byte)) = parse_error_control(frame) else {
            return;
        };
        let Some(state) = NmtState::from_byte(byte & 0x7F) else {
            return;
        };
        let Some(Some(g)) = self.nodes.get_mut(usize::from(node.get())) else {
            return;
        };
        let toggle = byte & 0x80 != 0;
        if state == NmtState::BootUp {
            g.expected_toggle = false;
        } else if toggle != g.expected_toggle {
            g.expected_toggle = !toggle;
            self.events.push(GuardEvent::ToggleError { node });
            return;
        } else {
            g.expected_toggle = !toggle;
        }
        g.life_deadline = Some(now + g.life_time);
        if g.expired {
            g.expired = false;
            self.events.push(GuardEvent::Resumed { node });
        }
        if g.state.replace(state) != Some(state) || state == NmtState::BootUp {
            self.events.push(GuardEvent::State { node, state });
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        for (i, slot) in self.nodes.iter_mut().enumerate() {
            let Some(g) = slot else { continue };
            if g.life_deadline.is_some_and(|d| d <= now) {
                g.life_deadline = None;
                g.expired = true;
                if let Some(node) = u8::try_from(i).ok().and_then(NodeId::new) {
                    self.events.push(GuardEvent::LifeTimeExpired { node });
                }
            }
            if g.next_request <= now {
                g.request_pending = true;
                g.next_request = next_period(g.next_request, now, g.guard_time);
            }
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        let len = self.nodes.len();
        for step in 0..len {
            let i = (self.cursor + step) % len;
            if let Some(Some(g)) = self.nodes.get_mut(i)
                && g.request_pending
            {
                g.request_pending = false;
                self.cursor = (i + 1) % len;
                let node = u8::try_from(i).ok().and_then(NodeId::new)?;
                return Some(guard_request(node));
            }
        }
        None
    }

    fn poll_event(&mut self) -> Option<GuardEvent> {
        self.events.pop()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.nodes
            .iter()
            .flatten()
            .flat_map(|g| [Some(g.next_request), g.life_deadline])
            .flatten()
            .min()
    }
}

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
    life_time: Option<Duration>,
    life_deadline: Option<Instant>,
    lost: bool,
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
            life_time: None,
            life_deadline: None,
            lost: false,
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
    /// factor, see [`life_time`]); `None` switches life guarding off.
    /// Supervision (re)starts with the next request.
    pub fn set_life_time(&mut self, life_time: Option<Duration>) {
        self.life_time = life_time;
        self.life_deadline = None;
        self.lost = false;
    }

    /// Whether life guarding detected a lost master (and no request came since).
    pub const fn is_lost(&self) -> bool {
        self.lost
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
        if let Some(life_time) = self.life_time {
            self.life_deadline = Some(now + life_time);
            if self.lost {
                self.lost = false;
                self.events.push(GuardResponderEvent::LifeGuardingResumed);
            }
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        if self.life_deadline.is_some_and(|d| d <= now) {
            self.life_deadline = None;
            self.lost = true;
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
        self.life_deadline
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(n: u8) -> NodeId {
        NodeId::new(n).unwrap()
    }

    fn factor(n: u8) -> NonZeroU8 {
        NonZeroU8::new(n).unwrap()
    }

    fn data(id: u16, bytes: &[u8]) -> Frame {
        Frame::new(CanId::Standard(id), bytes).unwrap()
    }

    fn rtr(id: u16) -> Frame {
        Frame::remote(CanId::Standard(id), 1).unwrap()
    }

    fn ms(n: u64) -> Instant {
        Instant::from_millis(n)
    }

    fn frames<S: Service>(s: &mut S) -> Vec<Frame> {
        core::iter::from_fn(|| s.poll_transmit()).collect()
    }

    fn events<S: Service>(s: &mut S) -> Vec<S::Event> {
        core::iter::from_fn(|| s.poll_event()).collect()
    }

    #[test]
    fn frame_layouts() {
        assert_eq!(guard_request(node(32)).to_string(), "720#R1");
        assert_eq!(
            guard_reply(node(32), true, NmtState::Operational),
            data(0x720, &[0x85])
        );
        assert_eq!(
            guard_reply(node(32), false, NmtState::PreOperational),
            data(0x720, &[0x7F])
        );
    }

    #[test]
    fn master_requests_every_guard_time() {
        let mut g = NodeGuard::new();
        g.guard(ms(0), node(32), Duration::from_millis(100), factor(3));
        g.guard(ms(0), node(5), Duration::from_millis(100), factor(3));
        assert_eq!(g.poll_timeout(), Some(ms(0)));
        g.handle_timeout(ms(0));
        assert_eq!(frames(&mut g), [rtr(0x705), rtr(0x720)]);
        assert_eq!(g.poll_timeout(), Some(ms(100)));
        g.handle_timeout(ms(99));
        assert!(frames(&mut g).is_empty());
        g.handle_timeout(ms(100));
        assert_eq!(frames(&mut g).len(), 2);
        // A big jump: one request each, rescheduled from now.
        g.handle_timeout(ms(50_000));
        assert_eq!(frames(&mut g), [rtr(0x705), rtr(0x720)]);
        assert_eq!(g.poll_timeout(), Some(ms(50_100)));
    }

    #[test]
    fn master_checks_toggle_and_tracks_state() {
        let mut g = NodeGuard::new();
        g.guard(ms(0), node(32), Duration::from_millis(100), factor(3));
        g.handle_frame(ms(1), &data(0x720, &[0x7F]));
        assert_eq!(
            events(&mut g),
            [GuardEvent::State {
                node: node(32),
                state: NmtState::PreOperational
            }]
        );
        g.handle_frame(ms(101), &data(0x720, &[0xFF]));
        g.handle_frame(ms(201), &data(0x720, &[0x05]));
        assert_eq!(
            events(&mut g),
            [GuardEvent::State {
                node: node(32),
                state: NmtState::Operational
            }]
        );
        // Toggle 0 again instead of 1: error, not a valid reply.
        g.handle_frame(ms(301), &data(0x720, &[0x05]));
        assert_eq!(events(&mut g), [GuardEvent::ToggleError { node: node(32) }]);
        // The life time still runs from the valid reply at 201 ms.
        g.handle_timeout(ms(500));
        assert!(events(&mut g).is_empty());
        g.handle_timeout(ms(501));
        assert_eq!(
            events(&mut g),
            [GuardEvent::LifeTimeExpired { node: node(32) }]
        );
        // Expectation follows the erroneous reply: next toggle is 1.
        g.handle_frame(ms(510), &data(0x720, &[0x85]));
        assert_eq!(events(&mut g), [GuardEvent::Resumed { node: node(32) }]);
        // Boot-up resets the toggle expectation to 0.
        g.handle_frame(ms(550), &data(0x720, &[0x00]));
        g.handle_frame(ms(560), &data(0x720, &[0x7F]));
        assert_eq!(
            events(&mut g),
            [
                GuardEvent::State {
                    node: node(32),
                    state: NmtState::BootUp
                },
                GuardEvent::State {
                    node: node(32),
                    state: NmtState::PreOperational
                }
            ]
        );
    }

    #[test]
    fn master_life_time_expires_once() {
        let mut g = NodeGuard::new();
        g.guard(ms(0), node(7), Duration::from_millis(100), factor(3));
        for t in (0..=1000).step_by(50) {
            g.handle_timeout(ms(t));
            frames(&mut g);
            if t == 250 {
                assert!(events(&mut g).is_empty());
            }
        }
        assert_eq!(
            events(&mut g),
            [GuardEvent::LifeTimeExpired { node: node(7) }]
        );
        assert!(g.is_expired(node(7)));
        // A reply without an outstanding request counts too.
        g.handle_frame(ms(1010), &data(0x707, &[0x04]));
        assert_eq!(
            events(&mut g),
            [
                GuardEvent::Resumed { node: node(7) },
                GuardEvent::State {
                    node: node(7),
                    state: NmtState::Stopped
                }
            ]
        );
        g.handle_timeout(ms(1309));
        assert!(events(&mut g).is_empty());
        g.handle_timeout(ms(1310));
        assert_eq!(events(&mut g).len(), 1);
        // Forgotten: guarding off.
        g.forget(node(7));
        assert!(!g.is_guarded(node(7)));
        assert_eq!(g.poll_timeout(), None);
        // The objects' zeros mean "not used".
        assert_eq!(life_time(Duration::from_millis(100), 0), None);
        assert_eq!(life_time(Duration::ZERO, 3), None);
        assert_eq!(
            life_time(Duration::from_millis(100), 3),
            Some(Duration::from_millis(300))
        );
    }

    #[test]
    fn master_and_responder_talk() {
        let mut g = NodeGuard::new();
        let mut r = GuardResponder::new(node(9));
        r.set_life_time(life_time(Duration::from_millis(50), 4));
        g.guard(ms(0), node(9), Duration::from_millis(50), factor(3));
        fn exchange(g: &mut NodeGuard, r: &mut GuardResponder, t: u64) {
            g.handle_timeout(ms(t));
            r.handle_timeout(ms(t));
            for f in frames(g) {
                r.handle_frame(ms(t), &f);
            }
            for f in frames(r) {
                g.handle_frame(ms(t), &f);
            }
        }
        let mut t = 0;
        // Nine replies: toggles 0, 1, ..., 0; the next one expected is 1.
        for _ in 0..9 {
            exchange(&mut g, &mut r, t);
            t += 50;
        }
        assert_eq!(
            events(&mut g),
            [GuardEvent::State {
                node: node(9),
                state: NmtState::PreOperational
            }]
        );
        // The node resets its toggle without a boot-up message: one error,
        // then the master follows.
        r.reset_toggle();
        for _ in 0..3 {
            exchange(&mut g, &mut r, t);
            t += 50;
        }
        assert_eq!(events(&mut g), [GuardEvent::ToggleError { node: node(9) }]);
        assert!(events(&mut r).is_empty());
        // The master stops guarding: the node detects it.
        g.forget(node(9));
        for _ in 0..5 {
            exchange(&mut g, &mut r, t);
            t += 50;
        }
        assert_eq!(events(&mut r), [GuardResponderEvent::LifeGuardingLost]);
    }

    #[test]
    fn responder_answers_with_alternating_toggle() {
        let mut r = GuardResponder::new(node(32));
        r.handle_frame(ms(0), &data(0x720, &[0x00]));
        r.handle_frame(ms(0), &rtr(0x721));
        assert!(frames(&mut r).is_empty());
        r.handle_frame(ms(0), &rtr(0x720));
        assert_eq!(frames(&mut r), [data(0x720, &[0x7F])]);
        r.set_state(NmtState::Operational);
        r.handle_frame(ms(0), &rtr(0x720));
        assert_eq!(frames(&mut r), [data(0x720, &[0x85])]);
        r.handle_frame(ms(0), &rtr(0x720));
        assert_eq!(frames(&mut r), [data(0x720, &[0x05])]);
        r.handle_frame(ms(0), &rtr(0x720));
        r.reset_toggle();
        r.set_state(NmtState::Stopped);
        assert_eq!(frames(&mut r), [data(0x720, &[0x04])]);
        assert_eq!(r.poll_timeout(), None);
    }

    #[test]
    fn responder_detects_life_guarding_loss() {
        let mut r = GuardResponder::new(node(3));
        r.set_life_time(life_time(Duration::from_millis(100), 2));
        // Not before the first request.
        assert_eq!(r.poll_timeout(), None);
        r.handle_frame(ms(1000), &rtr(0x703));
        assert_eq!(r.poll_timeout(), Some(ms(1200)));
        r.handle_timeout(ms(1199));
        assert!(events(&mut r).is_empty());
        r.handle_timeout(ms(1200));
        assert_eq!(events(&mut r), [GuardResponderEvent::LifeGuardingLost]);
        assert!(r.is_lost());
        r.handle_timeout(ms(5000));
        assert!(events(&mut r).is_empty());
        r.handle_frame(ms(5000), &rtr(0x703));
        assert_eq!(events(&mut r), [GuardResponderEvent::LifeGuardingResumed]);
        // Both requests were answered by one reply (not polled in between).
        assert_eq!(frames(&mut r), [data(0x703, &[0x7F])]);
    }
}
