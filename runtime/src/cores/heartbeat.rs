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
use crate::time::Periodic;
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
use crate::error_control::parse_state;

/// Decodes a heartbeat or boot-up frame into the node and its state; `None`
/// for other frames and for state bytes that are no CiA 301 state.
pub fn parse_heartbeat(frame: &Frame) -> Option<(NodeId, NmtState)> {
    parse_state(frame).map(|(node, state, _)| (node, state))
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
    state: NmtState,
    schedule: Periodic,
    boot_up_pending: bool,
    heartbeat_pending: bool,
}

impl HeartbeatProducer {
    /// A stopped producer for `node` reporting [`NmtState::PreOperational`]
    /// (the state a node enters after boot-up).
    pub const fn new(node: NodeId, period: Option<Duration>) -> HeartbeatProducer {
        HeartbeatProducer {
            node,
            state: NmtState::PreOperational,
            schedule: Periodic::new(period, MIN_PERIOD),
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
        self.schedule.period()
    }

    /// The state the heartbeats report.
    pub const fn state(&self) -> NmtState {
        self.state
    }

    /// Whether the producer has been started (and not stopped).
    pub const fn is_running(&self) -> bool {
        self.schedule.is_running()
    }

    /// Starts (or restarts, after a reset): queues the boot-up message and
    /// schedules the first heartbeat one period after `now`.
    pub fn start(&mut self, now: Instant) {
        self.schedule.start(now);
        self.boot_up_pending = true;
        self.heartbeat_pending = false;
    }

    /// Stops sending (pending frames are discarded).
    pub fn stop(&mut self) {
        self.schedule.stop();
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
        self.schedule.set_period(now, period);
    }
}

/// The shortest heartbeat period: 1 ms, the unit of object 0x1017.
const MIN_PERIOD: Duration = Duration::from_millis(1);

impl Service for HeartbeatProducer {
    type Event = core::convert::Infallible;

    /// The producer does not react to frames.
    fn handle_frame(&mut self, _now: Instant, _frame: &Frame) {}

    fn handle_timeout(&mut self, now: Instant) {
        if self.schedule.fire(now) {
            self.heartbeat_pending = true;
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

    fn poll_timeout(&self) -> Option<Instant> {
        self.schedule.next()
    }
}

/// A supervised node's liveness, as the heartbeat consumer and node
/// guarding see it: a valid message must come within `time` of the
/// previous one; when none does, the node is lost (reported once) until the
/// next one.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Liveness {
    time: Duration,
    deadline: Option<Instant>,
    state: Option<NmtState>,
    lost: bool,
}

impl Liveness {
    /// Supervision with `time` between messages, first due at `deadline`
    /// (`None`: from the first message on).
    pub(crate) const fn new(time: Duration, deadline: Option<Instant>) -> Liveness {
        Liveness {
            time,
            deadline,
            state: None,
            lost: false,
        }
    }

    /// The state last reported, `None` before the first message.
    pub(crate) const fn state(&self) -> Option<NmtState> {
        self.state
    }

    /// Whether the node is lost (and no message came since).
    pub(crate) const fn is_lost(&self) -> bool {
        self.lost
    }

    /// When the next message is due, `None` while lost or not yet started.
    pub(crate) const fn deadline(&self) -> Option<Instant> {
        self.deadline
    }

    /// A valid message arrived at `now`: the deadline moves on. Returns
    /// whether the node came back after a loss.
    pub(crate) fn alive(&mut self, now: Instant) -> bool {
        self.deadline = Some(now + self.time);
        core::mem::replace(&mut self.lost, false)
    }

    /// The message reported `state`: returns whether that is worth
    /// reporting (it changed, or is a boot-up).
    pub(crate) fn report(&mut self, state: NmtState) -> bool {
        self.state.replace(state) != Some(state) || state == NmtState::BootUp
    }

    /// Whether the deadline passed at `now` (true once per loss).
    pub(crate) fn expired(&mut self, now: Instant) -> bool {
        if self.deadline.is_some_and(|d| d <= now) {
            self.deadline = None;
            self.lost = true;
            true
        } else {
            false
        }
    }
}

mod consumer;

pub use consumer::{
    CONSUMER_EVENTS, HeartbeatConsumer, HeartbeatEvent, consumer_entry, parse_consumer_entry,
};

#[cfg(test)]
mod tests;
