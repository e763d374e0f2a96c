//! Heartbeat (CiA 301 error control): the producer a node runs (boot-up
//! message, then its NMT state every producer time) and the consumer that
//! supervises other nodes like object 0x1016 describes.
//!
//! Frames: COB-ID 0x700 + node, one data byte: the NMT state (0x00 in the
//! boot-up message). Bit 7 is the node-guarding toggle and is masked off here.

use core::time::Duration;

use crate::frame::cob;
use crate::nmt::NmtState;
use crate::od::NodeId;
use crate::queue::Ring;
use crate::{Frame, Instant, Service};

/// The heartbeat frame of `node` in `state`: 0x700 + node, data `[state]`.
pub const fn heartbeat_frame(node: NodeId, state: NmtState) -> Frame {
    Frame::standard(
        cob::heartbeat(node),
        [state.to_byte(), 0, 0, 0, 0, 0, 0, 0],
        1,
    )
}

/// The boot-up message of `node`: 0x700 + node, data `[0x00]`.
pub const fn boot_up_frame(node: NodeId) -> Frame {
    heartbeat_frame(node, NmtState::BootUp)
}

pub use crate::error_control::parse_error_control;

/// Decodes a heartbeat or boot-up frame into the node and its state; `None`
/// for other frames and for state bytes that are no CiA 301 state.
pub fn parse_heartbeat(frame: &Frame) -> Option<(NodeId, NmtState)> {
    let (node, byte) = parse_error_control(frame)?;
    NmtState::from_byte(byte & 0x7F).map(|state| (node, state))
}

/// The next deadline of a periodic task due at `due`, handled at `now`:
/// one period after `due`, or one period after `now` if that is already
/// past (the clock jumped; missed periods are skipped, not caught up).
pub(crate) fn next_period(due: Instant, now: Instant, period: Duration) -> Instant {
    let next = due + period;
    if next > now { next } else { now + period }
}

/// Heartbeat producer of one node (object 0x1017). After
/// [`HeartbeatProducer::start`] it sends the boot-up message, then a
/// heartbeat with the current state every period (the first one period after
/// the start). Without a period (`None`) no heartbeats are sent (the
/// boot-up message still is). A period below 1 ms, the unit of object
/// 0x1017, counts as 1 ms.
///
/// Frames are built when polled: at most one boot-up and one heartbeat are
/// pending; a heartbeat due while the previous one was not yet polled is
/// merged with it. If the clock jumps over several periods, one heartbeat is
/// sent and the next is scheduled one period after `now`.
#[derive(Debug, Clone)]
pub struct HeartbeatProducer {
    node: NodeId,
    period: Option<Duration>,
    state: NmtState,
    running: bool,
    next: Option<Instant>,
    boot_up_pending: bool,
    heartbeat_pending: bool,
}

impl HeartbeatProducer {
    /// A stopped producer for `node` reporting [`NmtState::PreOperational`]
    /// (the state a node enters after boot-up).
    pub const fn new(node: NodeId, period: Option<Duration>) -> HeartbeatProducer {
        HeartbeatProducer {
            node,
            period: at_least(period, MIN_PERIOD),
            state: NmtState::PreOperational,
            running: false,
            next: None,
            boot_up_pending: false,
            heartbeat_pending: false,
        }
    }

    /// The node whose heartbeat this is.
    pub const fn node(&self) -> NodeId {
        self.node
    }

    /// The producer time (`None`: no heartbeats).
    pub const fn period(&self) -> Option<Duration> {
        self.period
    }

    /// The state the heartbeats report.
    pub const fn state(&self) -> NmtState {
        self.state
    }

    /// Whether the producer has been started (and not stopped).
    pub const fn is_running(&self) -> bool {
        self.running
    }

    /// Starts (or restarts, after a reset): queues the boot-up message and
    /// schedules the first heartbeat one period after `now`.
    pub fn start(&mut self, now: Instant) {
        self.running = true;
        self.boot_up_pending = true;
        self.heartbeat_pending = false;
        self.next = self.schedule(now);
    }

    /// Stops sending (pending frames are discarded).
    pub fn stop(&mut self) {
        self.running = false;
        self.next = None;
        self.boot_up_pending = false;
        self.heartbeat_pending = false;
    }

    /// Sets the state reported by the following heartbeats.
    pub fn set_state(&mut self, state: NmtState) {
        self.state = state;
    }

    /// Changes the producer time (object 0x1017 written); when running, the
    /// next heartbeat is due one new period after `now` (`None` stops the
    /// heartbeats, a later period starts them again).
    pub fn set_period(&mut self, now: Instant, period: Option<Duration>) {
        self.period = at_least(period, MIN_PERIOD);
        if self.is_running() {
            self.next = self.schedule(now);
        }
    }

    fn schedule(&self, now: Instant) -> Option<Instant> {
        self.period.map(|period| now + period)
    }
}

/// The shortest heartbeat period: 1 ms, the unit of object 0x1017.
const MIN_PERIOD: Duration = Duration::from_millis(1);

/// A producer's period raised to `min` (a zero one would be due again at
/// once, for ever): what the producers do with a `Some` period shorter than
/// the unit of their object.
pub(crate) const fn at_least(period: Option<Duration>, min: Duration) -> Option<Duration> {
    match period {
        Some(p) if p.as_nanos() < min.as_nanos() => Some(min),
        other => other,
    }
}

impl Service for HeartbeatProducer {
    type Event = core::convert::Infallible;

    /// The producer does not react to frames.
    fn handle_frame(&mut self, _now: Instant, _frame: &Frame) {}

    fn handle_timeout(&mut self, now: Instant) {
        if let Some(due) = self.next
            && due <= now
        {
            self.heartbeat_pending = true;
            self.next = self.period.map(|period| next_period(due, now, period));
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        if self.boot_up_pending {
            self.boot_up_pending = false;
            Some(boot_up_frame(self.node))
        } else if self.heartbeat_pending {
            self.heartbeat_pending = false;
            Some(heartbeat_frame(self.node, self.state))
        } else {
            None
        }
    }

    fn poll_event(&mut self) -> Option<Self::Event> {
        None
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.next
    }
}

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

#[derive(Debug, Clone, Copy)]
struct Monitor {
    time: Duration,
    deadline: Option<Instant>,
    state: Option<NmtState>,
    timed_out: bool,
}

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
    nodes: [Option<Monitor>; 128],
    events: Ring<HeartbeatEvent, CONSUMER_EVENTS>,
}

impl Default for HeartbeatConsumer {
    fn default() -> Self {
        HeartbeatConsumer::new()
    }
}

impl HeartbeatConsumer {
    /// A consumer monitoring no node.
    pub const fn new() -> HeartbeatConsumer {
        HeartbeatConsumer {
            nodes: [None; 128],
            events: Ring::new(),
        }
    }

    /// Monitors `node` with consumer time `time`, starting afresh (waiting
    /// for its first heartbeat); `None` stops monitoring it (as
    /// [`HeartbeatConsumer::forget`]). A time shorter than the object's
    /// unit, 1 ms, counts as 1 ms.
    pub fn monitor(&mut self, node: NodeId, time: Option<Duration>) {
        let entry = time.map(|time| Monitor {
            time: time.max(Duration::from_millis(1)),
            deadline: None,
            state: None,
            timed_out: false,
        });
        if let Some(slot) = self.nodes.get_mut(usize::from(node.get())) {
            *slot = entry;
        }
    }

    /// Stops monitoring `node`.
    pub fn forget(&mut self, node: NodeId) {
        if let Some(slot) = self.nodes.get_mut(usize::from(node.get())) {
            *slot = None;
        }
    }

    /// Replaces the configuration with the entries of object 0x1016 (see
    /// [`parse_consumer_entry`]; unused entries are skipped).
    pub fn configure(&mut self, entries: &[u32]) {
        self.nodes = [None; 128];
        for (node, time) in entries.iter().filter_map(|e| parse_consumer_entry(*e)) {
            // A zero consumer time in the object is CiA 301's "not used".
            self.monitor(node, (!time.is_zero()).then_some(time));
        }
    }

    /// Whether `node` is monitored.
    pub fn is_monitored(&self, node: NodeId) -> bool {
        self.get(node).is_some()
    }

    /// The state `node` last reported; `None` when not monitored or not heard
    /// from yet.
    pub fn state(&self, node: NodeId) -> Option<NmtState> {
        self.get(node).and_then(|m| m.state)
    }

    /// Whether `node`'s heartbeat is currently missing (timed out).
    pub fn is_timed_out(&self, node: NodeId) -> bool {
        self.get(node).is_some_and(|m| m.timed_out)
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }

    fn get(&self, node: NodeId) -> Option<&Monitor> {
        self.nodes.get(usize::from(node.get()))?.as_ref()
    }
}

impl Service for HeartbeatConsumer {
    type Event = HeartbeatEvent;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        let Some((node, state)) = parse_heartbeat(frame) else {
            return;
        };
        let Some(Some(m)) = self.nodes.get_mut(usize::from(node.get())) else {
            return;
        };
        m.deadline = Some(now + m.time);
        if m.timed_out {
            m.timed_out = false;
            self.events.push(HeartbeatEvent::Resumed { node, state });
        }
        if m.state.replace(state) != Some(state) || state == NmtState::BootUp {
            self.events.push(HeartbeatEvent::State { node, state });
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        for (i, slot) in self.nodes.iter_mut().enumerate() {
            let Some(m) = slot else { continue };
            if m.deadline.is_some_and(|d| d <= now) {
                m.deadline = None;
                m.timed_out = true;
                if let Some(node) = u8::try_from(i).ok().and_then(NodeId::new) {
                    self.events.push(HeartbeatEvent::Timeout { node });
                }
            }
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        None
    }

    fn poll_event(&mut self) -> Option<HeartbeatEvent> {
        self.events.pop()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.nodes.iter().flatten().filter_map(|m| m.deadline).min()
    }
}

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
        assert_eq!(boot_up_frame(node(32)), data(0x720, &[0x00]));
        assert_eq!(
            heartbeat_frame(node(32), NmtState::Operational),
            data(0x720, &[0x05])
        );
        assert_eq!(
            heartbeat_frame(node(1), NmtState::PreOperational),
            data(0x701, &[0x7F])
        );
        assert_eq!(
            parse_heartbeat(&data(0x77F, &[0x04])),
            Some((node(127), NmtState::Stopped))
        );
        assert_eq!(
            parse_heartbeat(&data(0x720, &[0x85])),
            Some((node(32), NmtState::Operational))
        );
        assert_eq!(parse_heartbeat(&data(0x700, &[0x05])), None);
        assert_eq!(parse_heartbeat(&data(0x720, &[])), None);
        assert_eq!(parse_heartbeat(&data(0x720, &[0x05, 0])), None);
        assert_eq!(parse_heartbeat(&data(0x720, &[0x06])), None);
        assert_eq!(parse_heartbeat(&data(0x6A0, &[0x05])), None);
        assert_eq!(
            parse_heartbeat(&Frame::remote(CanId::Standard(0x720), 1).unwrap()),
            None
        );
    }

    #[test]
    fn producer_sends_boot_up_then_periodic_heartbeats() {
        let mut p = HeartbeatProducer::new(node(32), Some(Duration::from_millis(100)));
        assert_eq!(p.poll_timeout(), None);
        assert!(frames(&mut p).is_empty());
        p.start(ms(1000));
        assert_eq!(frames(&mut p), [data(0x720, &[0x00])]);
        assert_eq!(p.poll_timeout(), Some(ms(1100)));
        p.handle_timeout(ms(1099));
        assert!(frames(&mut p).is_empty());
        p.handle_timeout(ms(1100));
        assert_eq!(frames(&mut p), [data(0x720, &[0x7F])]);
        assert_eq!(p.poll_timeout(), Some(ms(1200)));
        p.set_state(NmtState::Operational);
        // Handled a little late: the schedule does not drift.
        p.handle_timeout(ms(1203));
        assert_eq!(frames(&mut p), [data(0x720, &[0x05])]);
        assert_eq!(p.poll_timeout(), Some(ms(1300)));
    }

    #[test]
    fn producer_big_time_jump_sends_one_frame() {
        let mut p = HeartbeatProducer::new(node(5), Some(Duration::from_millis(10)));
        p.start(ms(0));
        frames(&mut p);
        p.handle_timeout(ms(60_000));
        assert_eq!(frames(&mut p), [data(0x705, &[0x7F])]);
        assert_eq!(p.poll_timeout(), Some(ms(60_010)));
    }

    #[test]
    fn producer_zero_period_and_period_changes() {
        let mut p = HeartbeatProducer::new(node(5), None);
        p.start(ms(0));
        assert_eq!(p.poll_timeout(), None);
        assert_eq!(frames(&mut p), [data(0x705, &[0x00])]);
        assert!(p.is_running());
        // Enabled later (0x1017 written while running).
        p.set_period(ms(70), Some(Duration::from_millis(20)));
        assert_eq!(p.poll_timeout(), Some(ms(90)));
        p.handle_timeout(ms(90));
        p.stop();
        assert!(!p.is_running());
        assert_eq!(p.poll_timeout(), None);
        assert!(frames(&mut p).is_empty());
        // Not started: a period change schedules nothing.
        p.set_period(ms(100), Some(Duration::from_millis(20)));
        assert_eq!(p.poll_timeout(), None);
        // A period below 1 ms counts as 1 ms.
        p.set_period(ms(100), Some(Duration::from_micros(10)));
        assert_eq!(p.period(), Some(Duration::from_millis(1)));
        assert_eq!(p.poll_timeout(), None);
    }

    #[test]
    fn consumer_times_out_once_after_exactly_the_consumer_time() {
        let mut c = HeartbeatConsumer::new();
        c.monitor(node(32), Some(Duration::from_millis(150)));
        // Supervision starts with the first heartbeat.
        assert_eq!(c.poll_timeout(), None);
        c.handle_timeout(ms(10_000));
        assert!(events(&mut c).is_empty());
        c.handle_frame(ms(10_000), &data(0x720, &[0x05]));
        assert_eq!(
            events(&mut c),
            [HeartbeatEvent::State {
                node: node(32),
                state: NmtState::Operational
            }]
        );
        assert_eq!(c.poll_timeout(), Some(ms(10_150)));
        c.handle_timeout(Instant::from_micros(10_149_999));
        assert!(events(&mut c).is_empty());
        c.handle_timeout(ms(10_150));
        assert_eq!(events(&mut c), [HeartbeatEvent::Timeout { node: node(32) }]);
        assert!(c.is_timed_out(node(32)));
        // Not repeated.
        assert_eq!(c.poll_timeout(), None);
        c.handle_timeout(ms(20_000));
        assert!(events(&mut c).is_empty());
        // Back, same state: only Resumed.
        c.handle_frame(ms(20_000), &data(0x720, &[0x05]));
        assert_eq!(
            events(&mut c),
            [HeartbeatEvent::Resumed {
                node: node(32),
                state: NmtState::Operational
            }]
        );
        assert_eq!(c.poll_timeout(), Some(ms(20_150)));
        // A heartbeat in time pushes the deadline.
        c.handle_frame(ms(20_100), &data(0x720, &[0x05]));
        c.handle_timeout(ms(20_150));
        assert!(events(&mut c).is_empty());
        assert_eq!(c.poll_timeout(), Some(ms(20_250)));
    }

    #[test]
    fn consumer_reports_state_changes_and_every_boot_up() {
        let mut c = HeartbeatConsumer::new();
        c.monitor(node(32), Some(Duration::from_millis(150)));
        let t = ms(0);
        for b in [0x00, 0x7F, 0x7F, 0x00, 0x00, 0x04] {
            c.handle_frame(t, &data(0x720, &[b]));
        }
        let states: Vec<_> = events(&mut c)
            .into_iter()
            .map(|e| match e {
                HeartbeatEvent::State { state, .. } => state,
                other => panic!("{other:?}"),
            })
            .collect();
        use NmtState::*;
        assert_eq!(states, [BootUp, PreOperational, BootUp, BootUp, Stopped]);
        // Unmonitored nodes and unknown states are ignored.
        c.handle_frame(t, &data(0x721, &[0x05]));
        c.handle_frame(t, &data(0x720, &[0x33]));
        assert!(events(&mut c).is_empty());
        assert_eq!(c.state(node(32)), Some(Stopped));
        c.forget(node(32));
        assert_eq!(c.poll_timeout(), None);
        assert!(!c.is_monitored(node(32)));
    }

    #[test]
    fn producer_feeds_consumer() {
        let mut p = HeartbeatProducer::new(node(32), Some(Duration::from_millis(100)));
        let mut c = HeartbeatConsumer::new();
        c.monitor(node(32), Some(Duration::from_millis(150)));
        p.start(ms(0));
        let mut seen = Vec::new();
        for t in (0..=1000).step_by(10) {
            if t == 500 {
                p.set_state(NmtState::Operational);
            }
            if t == 700 {
                // Stopped before the heartbeat due at 700 ms.
                p.stop();
            }
            p.handle_timeout(ms(t));
            c.handle_timeout(ms(t));
            for f in frames(&mut p) {
                c.handle_frame(ms(t), &f);
            }
            seen.extend(events(&mut c).into_iter().map(|e| (t, e)));
        }
        let n = node(32);
        use HeartbeatEvent::*;
        use NmtState::*;
        assert_eq!(
            seen,
            [
                (
                    0,
                    State {
                        node: n,
                        state: BootUp
                    }
                ),
                (
                    100,
                    State {
                        node: n,
                        state: PreOperational
                    }
                ),
                (
                    500,
                    State {
                        node: n,
                        state: Operational
                    }
                ),
                // Last heartbeat at 600 ms + 150 ms consumer time.
                (750, Timeout { node: n }),
            ]
        );
    }

    #[test]
    fn consumer_entries_and_many_timeouts() {
        assert_eq!(
            parse_consumer_entry(0x0020_01F4),
            Some((node(32), Duration::from_millis(500)))
        );
        assert_eq!(parse_consumer_entry(0x0020_0000), None);
        assert_eq!(parse_consumer_entry(0x0080_0010), None);
        assert_eq!(parse_consumer_entry(0x0000_0010), None);
        assert_eq!(
            consumer_entry(node(32), Duration::from_millis(500)),
            0x0020_01F4
        );
        let entries: Vec<u32> = (1..=127u32).map(|n| n << 16 | 100).collect();
        let mut c = HeartbeatConsumer::new();
        c.configure(&entries);
        for n in 1..=127u16 {
            c.handle_frame(ms(0), &data(0x700 + n, &[0x05]));
        }
        events(&mut c);
        c.handle_timeout(ms(100));
        let got = events(&mut c);
        assert_eq!(got.len(), 127);
        assert_eq!(c.dropped_events(), 0);
        assert_eq!(got[0], HeartbeatEvent::Timeout { node: node(1) });
    }
}
