//! SYNC (CiA 301): the producer that paces synchronous PDOs and a consumer
//! that reports received SYNC frames.
//!
//! Frame: COB-ID 0x080 by default (object 0x1005). Without a counter it has no
//! data; with one (object 0x1019 "synchronous counter overflow value", 2 to
//! 240) it carries one byte counting 1, 2, ... up to the overflow value, then
//! starting again at 1.

use core::fmt;
use core::time::Duration;

use crate::frame::cob;
use crate::queue::Ring;
use crate::time::Periodic;
use crate::{Frame, Instant, Service};

/// The shortest SYNC period: 1 µs, the unit of object 0x1006.
const MIN_PERIOD: Duration = Duration::from_micros(1);

/// The default SYNC COB-ID.
pub const DEFAULT_COB_ID: u16 = cob::SYNC;

/// A SYNC producer configuration CiA 301 does not allow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum SyncConfigError {
    /// A counter overflow value outside 2..=240.
    CounterOverflow(u8),
    /// A COB-ID above 0x7FF.
    CobId(u16),
}

impl fmt::Display for SyncConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SyncConfigError::CounterOverflow(v) => write!(
                f,
                "SYNC counter overflow value {v} is invalid; CiA 301 allows 2 to 240"
            ),
            SyncConfigError::CobId(id) => {
                write!(f, "SYNC COB-ID {id:#x} is not an 11-bit identifier")
            }
        }
    }
}

impl core::error::Error for SyncConfigError {}

/// A SYNC frame on `cob_id` (masked to 11 bits), with the counter byte when
/// `counter` is given.
pub const fn sync_frame(cob_id: u16, counter: Option<u8>) -> Frame {
    match counter {
        Some(c) => Frame::standard(cob_id, [c, 0, 0, 0, 0, 0, 0, 0], 1),
        None => Frame::standard(cob_id, [0; 8], 0),
    }
}

/// Decodes a SYNC frame on `cob_id`: `Some(None)` without a counter,
/// `Some(Some(counter))` with one, `None` for other frames (other ids, remote
/// frames, more than one data byte).
pub fn parse_sync_on(cob_id: u16, frame: &Frame) -> Option<Option<u8>> {
    if frame.is_remote() || frame.standard_id() != Some(cob_id) {
        return None;
    }
    match *frame.data() {
        [] => Some(None),
        [counter] => Some(Some(counter)),
        _ => None,
    }
}

/// [`parse_sync_on`] with the default COB-ID 0x080.
pub fn parse_sync(frame: &Frame) -> Option<Option<u8>> {
    parse_sync_on(DEFAULT_COB_ID, frame)
}

/// SYNC producer. After [`SyncProducer::start`] a SYNC is due every period,
/// the first one period after the start; without a period (`None`) it
/// produces nothing. A period below 1 µs, the unit of object 0x1006,
/// counts as 1 µs.
/// Frames are built when polled: a SYNC due while the previous one was not
/// yet polled is merged with it, so the counter never skips a value. If the
/// clock jumps over several periods, one SYNC is sent and the next is
/// scheduled one period after `now`.
#[derive(Debug, Clone)]
pub struct SyncProducer {
    cob_id: u16,
    schedule: Periodic,
    overflow: Option<u8>,
    counter: u8,
    pending: bool,
}

impl SyncProducer {
    /// A stopped producer on COB-ID 0x080 (period: object 0x1006; counter
    /// overflow: object 0x1019, `None` for frames without a counter).
    pub fn new(
        period: Option<Duration>,
        counter_overflow: Option<u8>,
    ) -> Result<Self, SyncConfigError> {
        SyncProducer::with_cob_id(DEFAULT_COB_ID, period, counter_overflow)
    }

    /// A stopped producer on `cob_id`.
    pub fn with_cob_id(
        cob_id: u16,
        period: Option<Duration>,
        counter_overflow: Option<u8>,
    ) -> Result<Self, SyncConfigError> {
        if cob_id > 0x7FF {
            return Err(SyncConfigError::CobId(cob_id));
        }
        if let Some(v) = counter_overflow
            && !(2..=240).contains(&v)
        {
            return Err(SyncConfigError::CounterOverflow(v));
        }
        Ok(SyncProducer {
            cob_id,
            schedule: Periodic::new(period, MIN_PERIOD),
            overflow: counter_overflow,
            counter: 1,
            pending: false,
        })
    }

    /// The COB-ID the SYNC frames are sent on.
    pub const fn cob_id(&self) -> u16 {
        self.cob_id
    }

    /// The communication cycle period (`None`: no SYNC).
    pub const fn period(&self) -> Option<Duration> {
        self.schedule.period()
    }

    /// The counter overflow value, `None` without a counter.
    pub const fn counter_overflow(&self) -> Option<u8> {
        self.overflow
    }

    /// Whether the producer has been started (and not stopped); it sends
    /// nothing without a period.
    pub const fn is_running(&self) -> bool {
        self.schedule.is_running()
    }

    /// Starts producing: the counter restarts at 1, the first SYNC is due
    /// one period after `now`.
    pub fn start(&mut self, now: Instant) {
        self.schedule.start(now);
        self.counter = 1;
        self.pending = false;
    }

    /// Stops producing (a pending SYNC is discarded).
    pub fn stop(&mut self) {
        self.schedule.stop();
        self.pending = false;
    }

    /// Changes the period (object 0x1006 written); when running, the next
    /// SYNC is due one new period after `now` (`None` pauses the producer,
    /// a later period resumes it).
    pub fn set_period(&mut self, now: Instant, period: Option<Duration>) {
        self.schedule.set_period(now, period);
    }
}

impl Service for SyncProducer {
    type Event = core::convert::Infallible;

    /// The producer does not react to frames.
    fn handle_frame(&mut self, _now: Instant, _frame: &Frame) {}

    fn handle_timeout(&mut self, now: Instant) {
        if self.schedule.fire(now) {
            self.pending = true;
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        if !self.pending {
            return None;
        }
        self.pending = false;
        let counter = self.overflow.map(|overflow| {
            let value = self.counter;
            self.counter = if value >= overflow { 1 } else { value + 1 };
            value
        });
        Some(sync_frame(self.cob_id, counter))
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.schedule.next()
    }
}

/// What a [`SyncConsumer`] received.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum SyncEvent {
    /// A SYNC, with its counter when it carries one.
    Sync {
        /// The counter byte, `None` for a SYNC without data.
        counter: Option<u8>,
    },
    /// A data frame on the SYNC COB-ID with more than one byte (CiA 301
    /// error code 0x8240 "unexpected SYNC data length").
    BadLength {
        /// The number of data bytes received.
        len: usize,
    },
}

/// Number of events a [`SyncConsumer`] keeps; when full, the oldest is
/// dropped and counted.
pub const CONSUMER_EVENTS: usize = 8;

/// SYNC consumer: reports each SYNC received on its COB-ID.
#[derive(Debug, Clone)]
pub struct SyncConsumer {
    cob_id: u16,
    last: Option<Option<u8>>,
    events: Ring<SyncEvent, CONSUMER_EVENTS>,
}

default_is_new!(SyncConsumer);

impl SyncConsumer {
    /// A consumer on COB-ID 0x080.
    pub const fn new() -> SyncConsumer {
        SyncConsumer::with_cob_id(DEFAULT_COB_ID)
    }

    /// A consumer on `cob_id` (only 11-bit frames can match).
    pub const fn with_cob_id(cob_id: u16) -> SyncConsumer {
        SyncConsumer {
            cob_id,
            last: None,
            events: Ring::new(),
        }
    }

    /// The COB-ID listened on.
    pub const fn cob_id(&self) -> u16 {
        self.cob_id
    }

    /// The counter of the last SYNC: `None` before the first one,
    /// `Some(None)` if it had no counter.
    pub const fn last_counter(&self) -> Option<Option<u8>> {
        self.last
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }
}

impl Service for SyncConsumer {
    type Event = SyncEvent;

    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        if frame.is_remote() || frame.standard_id() != Some(self.cob_id) {
            return;
        }
        match parse_sync_on(self.cob_id, frame) {
            Some(counter) => {
                self.last = Some(counter);
                self.events.push(SyncEvent::Sync { counter });
            }
            None => self.events.push(SyncEvent::BadLength { len: frame.len() }),
        }
    }

    fn poll_event(&mut self) -> Option<SyncEvent> {
        self.events.pop()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CanId;
    use crate::cores::testing::{assert_due, data, events, frames, ms};

    #[test]
    fn frames_without_counter() {
        let mut p = SyncProducer::new(Some(Duration::from_millis(10)), None).unwrap();
        assert_eq!(p.poll_timeout(), None);
        p.start(ms(100));
        assert!(frames(&mut p).is_empty());
        assert_due(&mut p, 110, &[data(0x080, &[])]);
        assert_eq!(frames(&mut p)[..], []);
        assert_eq!(p.poll_timeout(), Some(ms(120)));
    }

    #[test]
    fn counter_wraps_at_the_overflow_value() {
        let mut p = SyncProducer::new(Some(Duration::from_millis(1)), Some(3)).unwrap();
        p.start(ms(0));
        let mut sent = Vec::new();
        for t in 1..=7 {
            p.handle_timeout(ms(t));
            sent.extend(frames(&mut p));
        }
        let expected: Vec<Frame> = [1, 2, 3, 1, 2, 3, 1]
            .iter()
            .map(|c| data(0x080, &[*c]))
            .collect();
        assert_eq!(sent, expected);
        // Restarting resets the counter to 1.
        p.start(ms(10));
        p.handle_timeout(ms(11));
        assert_eq!(frames(&mut p), [data(0x080, &[0x01])]);
    }

    #[test]
    fn counter_reaches_240() {
        let mut p =
            SyncProducer::with_cob_id(0x081, Some(Duration::from_millis(1)), Some(240)).unwrap();
        p.start(ms(0));
        let mut last = Vec::new();
        for t in 1..=241 {
            p.handle_timeout(ms(t));
            last = frames(&mut p);
            if t == 240 {
                assert_eq!(last, [data(0x081, &[240])]);
            }
        }
        assert_eq!(last, [data(0x081, &[1])]);
    }

    #[test]
    fn invalid_configuration_is_refused() {
        for v in [0u8, 1, 241, 255] {
            assert_eq!(
                SyncProducer::new(Some(Duration::from_millis(1)), Some(v)).err(),
                Some(SyncConfigError::CounterOverflow(v))
            );
        }
        assert!(SyncProducer::new(Some(Duration::from_millis(1)), Some(2)).is_ok());
        assert_eq!(
            SyncProducer::with_cob_id(0x800, Some(Duration::from_millis(1)), None).err(),
            Some(SyncConfigError::CobId(0x800))
        );
    }

    #[test]
    fn big_time_jump_sends_one_frame() {
        let mut p = SyncProducer::new(Some(Duration::from_millis(1)), Some(10)).unwrap();
        p.start(ms(0));
        p.handle_timeout(ms(3_600_000));
        assert_eq!(frames(&mut p), [data(0x080, &[1])]);
        assert_eq!(p.poll_timeout(), Some(ms(3_600_001)));
        // Unpolled SYNCs are merged: the counter does not skip.
        p.handle_timeout(ms(3_600_001));
        p.handle_timeout(ms(3_600_002));
        assert_eq!(frames(&mut p), [data(0x080, &[2])]);
    }

    #[test]
    fn period_changes_and_zero_period() {
        let mut p = SyncProducer::new(None, None).unwrap();
        p.set_period(ms(0), Some(Duration::from_millis(20)));
        assert_eq!(p.poll_timeout(), None);
        p.set_period(ms(0), None);
        p.start(ms(0));
        assert!(p.is_running());
        assert_eq!(p.poll_timeout(), None);
        p.set_period(ms(5), Some(Duration::from_millis(20)));
        assert_eq!(p.poll_timeout(), Some(ms(25)));
        p.set_period(ms(10), Some(Duration::from_millis(50)));
        assert_eq!(p.poll_timeout(), Some(ms(60)));
        p.set_period(ms(20), None);
        assert_eq!(p.poll_timeout(), None);
        p.stop();
        p.set_period(ms(30), Some(Duration::from_millis(50)));
        assert_eq!(p.poll_timeout(), None);
    }

    #[test]
    fn parse_and_consume() {
        assert_eq!(parse_sync(&data(0x080, &[])), Some(None));
        assert_eq!(parse_sync(&data(0x080, &[0x05])), Some(Some(5)));
        assert_eq!(parse_sync(&data(0x080, &[0x05, 0x00])), None);
        assert_eq!(parse_sync(&data(0x081, &[])), None);
        assert_eq!(
            parse_sync(&Frame::remote(CanId::Standard(0x080), 0).unwrap()),
            None
        );
        let mut c = SyncConsumer::new();
        assert_eq!(c.last_counter(), None);
        c.handle_frame(ms(0), &data(0x080, &[7]));
        c.handle_frame(ms(0), &data(0x080, &[]));
        c.handle_frame(ms(0), &data(0x080, &[1, 2]));
        c.handle_frame(ms(0), &data(0x081, &[]));
        c.handle_frame(ms(0), &Frame::new(CanId::Extended(0x080), &[]).unwrap());
        assert_eq!(
            events(&mut c),
            [
                SyncEvent::Sync { counter: Some(7) },
                SyncEvent::Sync { counter: None },
                SyncEvent::BadLength { len: 2 }
            ]
        );
        assert_eq!(c.last_counter(), Some(None));
    }
}
