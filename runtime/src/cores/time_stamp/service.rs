//! The TIME producer and consumer cores and the COB-ID object 0x1012.

use core::fmt;
use core::time::Duration;

use super::{DEFAULT_COB_ID, TimeError, TimeOfDay};
use crate::queue::Ring;
use crate::time::Periodic;
use crate::{CanId, Frame, Instant, Service};

/// The shortest TIME period: 1 ms, the resolution of TIME_OF_DAY.
const MIN_PERIOD: Duration = Duration::from_millis(1);

/// Object 0x1012 "COB-ID time stamp": whether the node consumes and
/// produces TIME, and the identifier (11-bit or 29-bit).
///
/// Raw layout: bit 31 consume, bit 30 produce, bit 29 frame (1: 29-bit
/// identifier), bits 0 to 28 the identifier (bits 11 to 28 zero for an
/// 11-bit one).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TimeCobId {
    /// Bit 31: the node consumes TIME frames.
    pub consume: bool,
    /// Bit 30: the node produces TIME frames.
    pub produce: bool,
    /// The identifier (bit 29 and bits 0 to 28).
    pub id: CanId,
}

impl TimeCobId {
    /// Neither consumer nor producer, 11-bit identifier 0x100.
    pub const DEFAULT: TimeCobId = TimeCobId {
        consume: false,
        produce: false,
        id: CanId::Standard(DEFAULT_COB_ID),
    };

    /// Parses the value of object 0x1012; an 11-bit identifier with any of
    /// bits 11 to 28 set is refused.
    pub const fn from_raw(raw: u32) -> Result<TimeCobId, TimeConfigError> {
        let id = raw & 0x1FFF_FFFF;
        let id = if raw & 1 << 29 != 0 {
            CanId::Extended(id)
        } else if id <= 0x7FF {
            CanId::Standard(id as u16)
        } else {
            return Err(TimeConfigError::CobId(raw));
        };
        Ok(TimeCobId {
            consume: raw & 1 << 31 != 0,
            produce: raw & 1 << 30 != 0,
            id,
        })
    }

    /// The value of object 0x1012 (the identifier masked to its width).
    pub const fn to_raw(self) -> u32 {
        let id = match self.id {
            CanId::Standard(id) => (id & 0x7FF) as u32,
            CanId::Extended(id) => id & 0x1FFF_FFFF | 1 << 29,
        };
        id | (self.consume as u32) << 31 | (self.produce as u32) << 30
    }
}

impl Default for TimeCobId {
    fn default() -> Self {
        TimeCobId::DEFAULT
    }
}

/// A TIME configuration that cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum TimeConfigError {
    /// A value of object 0x1012 with an 11-bit identifier above 0x7FF.
    CobId(u32),
    /// An identifier out of range for its kind.
    Id(CanId),
}

impl fmt::Display for TimeConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TimeConfigError::CobId(raw) => write!(
                f,
                "COB-ID time stamp {raw:#010x} selects an 11-bit identifier but has bits 11 to 28 set"
            ),
            TimeConfigError::Id(CanId::Standard(id)) => {
                write!(f, "TIME identifier {id:#x} is not an 11-bit identifier")
            }
            TimeConfigError::Id(CanId::Extended(id)) => {
                write!(f, "TIME identifier {id:#x} is not a 29-bit identifier")
            }
        }
    }
}

impl core::error::Error for TimeConfigError {}

/// `id` if it is in range for its kind.
const fn checked_id(id: CanId) -> Result<CanId, TimeConfigError> {
    let ok = match id {
        CanId::Standard(raw) => raw <= 0x7FF,
        CanId::Extended(raw) => raw <= 0x1FFF_FFFF,
    };
    if ok {
        Ok(id)
    } else {
        Err(TimeConfigError::Id(id))
    }
}

/// The TIME frame carrying `time` on `id` (an 11-bit identifier is masked
/// to 11 bits).
pub fn time_frame(id: CanId, time: TimeOfDay) -> Frame {
    let [b0, b1, b2, b3, b4, b5] = time.encode();
    match id {
        CanId::Standard(raw) => Frame::standard(raw, [b0, b1, b2, b3, b4, b5, 0, 0], 6),
        CanId::Extended(_) => match Frame::new(id, &[b0, b1, b2, b3, b4, b5]) {
            Ok(frame) => frame,
            // Frame::new fails only above 8 bytes.
            Err(_) => Frame::standard(0, [0; 8], 0),
        },
    }
}

/// TIME producer (sans-IO): sends given times at once ([`TimeProducer::send`])
/// and, once started with a period, the current time periodically.
///
/// The producer knows the wall-clock time only from the caller:
/// [`TimeProducer::set_time`] says which [`TimeOfDay`] an [`Instant`] of
/// the cores' clock corresponds to, and later times are extrapolated from
/// it. After [`TimeProducer::start`], the first TIME is due at the start
/// (consumers need not wait a whole period), then one every period; a zero
/// period produces nothing by itself. At most one frame is pending: a newer
/// TIME replaces one not yet polled. A periodic TIME that cannot be sent
/// (no reference time yet, or after 2163-06-06) is skipped and counted.
#[derive(Debug, Clone)]
pub struct TimeProducer {
    id: CanId,
    schedule: Periodic,
    reference: Option<(Instant, TimeOfDay)>,
    pending: Option<Frame>,
    skipped: u32,
}

impl Default for TimeProducer {
    fn default() -> Self {
        TimeProducer {
            id: CanId::Standard(DEFAULT_COB_ID),
            schedule: Periodic::new(None, MIN_PERIOD),
            reference: None,
            pending: None,
            skipped: 0,
        }
    }
}

impl TimeProducer {
    /// A stopped producer on 0x100 with period `period` (`None`: only
    /// [`TimeProducer::send`] and [`TimeProducer::send_now`] send; a period
    /// below 1 ms, the resolution of TIME, counts as 1 ms).
    pub fn new(period: Option<Duration>) -> TimeProducer {
        TimeProducer {
            schedule: Periodic::new(period, MIN_PERIOD),
            ..TimeProducer::default()
        }
    }

    /// A stopped producer on `id` (11-bit or 29-bit).
    pub fn with_id(id: CanId, period: Option<Duration>) -> Result<TimeProducer, TimeConfigError> {
        Ok(TimeProducer {
            id: checked_id(id)?,
            schedule: Periodic::new(period, MIN_PERIOD),
            ..TimeProducer::default()
        })
    }

    /// The identifier the TIME frames are sent on.
    pub const fn id(&self) -> CanId {
        self.id
    }

    /// The period of the periodic TIME (`None`: none).
    pub const fn period(&self) -> Option<Duration> {
        self.schedule.period()
    }

    /// Whether the producer has been started (and not stopped).
    pub const fn is_running(&self) -> bool {
        self.schedule.is_running()
    }

    /// Periodic TIME frames skipped: no reference time, or out of range.
    pub const fn skipped(&self) -> u32 {
        self.skipped
    }

    /// The TIME frame this producer sends for `time`.
    pub fn frame(&self, time: TimeOfDay) -> Frame {
        time_frame(self.id, time)
    }

    /// Sends `time` (replacing a frame not yet polled).
    pub fn send(&mut self, time: TimeOfDay) {
        self.pending = Some(self.frame(time));
    }

    /// The wall-clock time at `now` is `time`: later times are extrapolated
    /// from this pair.
    pub fn set_time(&mut self, now: Instant, time: TimeOfDay) {
        self.reference = Some((now, time));
    }

    /// The wall-clock time at `now` extrapolated from the last
    /// [`TimeProducer::set_time`]; `None` without one or after
    /// [`TimeOfDay::MAX`]. An `Instant` before the reference gives the
    /// reference time.
    pub fn time_at(&self, now: Instant) -> Option<TimeOfDay> {
        let (at, time) = self.reference?;
        extrapolate(at, time, now)
    }

    /// Sends the time at `now` (see [`TimeProducer::time_at`]) and returns
    /// it; `None` (and nothing sent) when it is not known.
    pub fn send_now(&mut self, now: Instant) -> Option<TimeOfDay> {
        let time = self.time_at(now)?;
        self.send(time);
        Some(time)
    }

    /// Starts the periodic TIME: the first one is due at `now`.
    pub fn start(&mut self, now: Instant) {
        self.schedule.start_at_once(now);
    }

    /// Stops the periodic TIME (a frame not yet polled is discarded).
    pub fn stop(&mut self) {
        self.schedule.stop();
        self.pending = None;
    }

    /// Changes the period; when running, the next TIME is due one new
    /// period after `now` (`None` pauses the periodic TIME).
    pub fn set_period(&mut self, now: Instant, period: Option<Duration>) {
        self.schedule.set_period(now, period);
    }
}

/// `time` at `at`, moved on to `now` (whole milliseconds).
fn extrapolate(at: Instant, time: TimeOfDay, now: Instant) -> Option<TimeOfDay> {
    let elapsed = u64::try_from(now.saturating_duration_since(at).as_millis()).ok()?;
    TimeOfDay::from_epoch_millis(time.epoch_millis().checked_add(elapsed)?).ok()
}

impl Service for TimeProducer {
    type Event = core::convert::Infallible;

    /// The producer does not react to frames.
    fn handle_frame(&mut self, _now: Instant, _frame: &Frame) {}

    fn handle_timeout(&mut self, now: Instant) {
        if self.schedule.fire(now) && self.send_now(now).is_none() {
            self.skipped = self.skipped.saturating_add(1);
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        self.pending.take()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.schedule.next()
    }
}

/// What a [`TimeConsumer`] received.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum TimeEvent {
    /// A valid TIME frame.
    Time {
        /// The time it carries.
        time: TimeOfDay,
        /// When it was received (the `now` given with the frame).
        received: Instant,
    },
    /// A data frame on the TIME identifier that is not a valid TIME_OF_DAY
    /// (wrong length, reserved bits set, milliseconds of a day exceeded).
    Malformed {
        /// The frame as received.
        frame: Frame,
        /// What is wrong with it.
        error: TimeError,
    },
}

impl fmt::Display for TimeEvent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TimeEvent::Time { time, .. } => write!(f, "TIME {time}"),
            TimeEvent::Malformed { frame, error } => write!(f, "malformed TIME {frame}: {error}"),
        }
    }
}

/// Number of events a [`TimeConsumer`] keeps; when full, the oldest is
/// dropped and counted.
pub const CONSUMER_EVENTS: usize = 8;

/// TIME consumer: decodes each data frame on its identifier into a
/// [`TimeEvent`]. Remote frames and frames on other identifiers (an 11-bit
/// and a 29-bit identifier of the same number are different) are ignored.
#[derive(Debug, Clone)]
pub struct TimeConsumer {
    id: CanId,
    last: Option<(Instant, TimeOfDay)>,
    events: Ring<TimeEvent, CONSUMER_EVENTS>,
}

default_is_new!(TimeConsumer);

impl TimeConsumer {
    /// A consumer on the 11-bit identifier 0x100.
    pub const fn new() -> TimeConsumer {
        TimeConsumer {
            id: CanId::Standard(DEFAULT_COB_ID),
            last: None,
            events: Ring::new(),
        }
    }

    /// A consumer on `id` (11-bit or 29-bit).
    pub const fn with_id(id: CanId) -> Result<TimeConsumer, TimeConfigError> {
        match checked_id(id) {
            Ok(id) => Ok(TimeConsumer {
                id,
                last: None,
                events: Ring::new(),
            }),
            Err(e) => Err(e),
        }
    }

    /// The identifier listened on.
    pub const fn id(&self) -> CanId {
        self.id
    }

    /// The last valid TIME received and when, `None` before the first.
    pub const fn last(&self) -> Option<(Instant, TimeOfDay)> {
        self.last
    }

    /// The wall-clock time at `now`, extrapolated from the last TIME
    /// received; `None` before the first or after [`TimeOfDay::MAX`].
    pub fn time_at(&self, now: Instant) -> Option<TimeOfDay> {
        let (at, time) = self.last?;
        extrapolate(at, time, now)
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }
}

impl Service for TimeConsumer {
    type Event = TimeEvent;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        if frame.is_remote() || frame.id() != self.id {
            return;
        }
        let event = match TimeOfDay::decode(frame.data()) {
            Ok(time) => {
                self.last = Some((now, time));
                TimeEvent::Time {
                    time,
                    received: now,
                }
            }
            Err(error) => TimeEvent::Malformed {
                frame: *frame,
                error,
            },
        };
        self.events.push(event);
    }

    fn poll_event(&mut self) -> Option<TimeEvent> {
        self.events.pop()
    }
}
