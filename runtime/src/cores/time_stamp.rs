//! The TIME service of CiA 301 (the "time stamp" object): the
//! TIME_OF_DAY and TIME_DIFFERENCE codec, civil dates, and the
//! [`TimeProducer`] and [`TimeConsumer`] cores.
//!
//! Not to be confused with [`crate::time`], the monotonic clock the cores are
//! fed with: this module is about the wall-clock time a TIME producer
//! broadcasts.
//!
//! # Frame
//!
//! One frame, COB-ID 0x100 by default (object 0x1012 "COB-ID time stamp",
//! see [`TimeCobId`]), 6 data bytes, the TIME_OF_DAY layout:
//!
//! | bytes | content |
//! |---|---|
//! | 0..=3 | UNSIGNED28 milliseconds after midnight, little endian; the top 4 bits of byte 3 are reserved (sent as 0) |
//! | 4..=5 | UNSIGNED16 days since 1984-01-01, little endian |
//!
//! TIME_DIFFERENCE has the same layout and stands for a duration.
//!
//! ```
//! use eds2rust_runtime::time_stamp::{DateTime, TimeConsumer, TimeEvent, TimeOfDay, TimeProducer};
//! use eds2rust_runtime::{Instant, Service};
//! use core::time::Duration;
//!
//! let t = TimeOfDay::from_civil(DateTime::new(2026, 12, 2, 12, 34, 56, 789))?;
//! // 45 296 789 ms = 0x02B3_2C95 after midnight of day 15 676 = 0x3D3C.
//! assert_eq!(t.encode(), [0x95, 0x2C, 0xB3, 0x02, 0x3C, 0x3D]);
//! assert_eq!(t.to_string(), "2026-12-02T12:34:56.789Z");
//!
//! let mut producer = TimeProducer::new(None);
//! producer.send(t);
//! let frame = producer.poll_transmit().unwrap();
//! assert_eq!(frame.to_string(), "100#952CB3023C3D");
//!
//! let mut consumer = TimeConsumer::new();
//! consumer.handle_frame(Instant::ZERO, &frame);
//! assert_eq!(
//!     consumer.poll_event(),
//!     Some(TimeEvent::Time { time: t, received: Instant::ZERO })
//! );
//! # Ok::<(), eds2rust_runtime::time_stamp::TimeError>(())
//! ```
//!
//! # Choices where CiA 301 is silent
//!
//! - Decoding is strict: exactly 6 bytes ([`TimeError::Length`] otherwise,
//!   for shorter and for longer frames alike), reserved bits clear
//!   ([`TimeError::ReservedBits`]), milliseconds below 86 400 000
//!   ([`TimeError::Millis`]). Every accepted frame is therefore the
//!   [`TimeOfDay::encode`] of its value, byte for byte.
//! - Times are UTC with no leap seconds (a day has 86 400 000 ms; second 60
//!   is refused as [`TimeError::InvalidCivil`]).
//! - The range is day 0 (1984-01-01) to day 65 535 (2163-06-06); a date
//!   outside it is [`TimeError::OutOfRange`], never a panic or a wrap.
//! - Sub-millisecond parts (of a `SystemTime`, an `Instant` or a `Duration`)
//!   are truncated.
//! - TIME_DIFFERENCE keeps its millisecond part below one day, like
//!   TIME_OF_DAY (a longer duration carries into the days).
//!
//! [`TimeOfDay`] does not implement [`crate::od::Scalar`]: its `from_raw`
//! cannot fail, while most 48-bit patterns are not valid times. Generated
//! code gives TIME_OF_DAY entries a `u64` value; [`TimeOfDay::from_raw48`]
//! and [`TimeOfDay::to_raw48`] convert.

use core::fmt;
use core::time::Duration;

mod civil;
mod service;
#[cfg(test)]
mod tests;

pub use civil::{DateTime, days_in_month, is_leap_year};
use civil::{civil_from_days, days_from_civil};

pub use service::{
    CONSUMER_EVENTS, TimeCobId, TimeConfigError, TimeConsumer, TimeEvent, TimeProducer, time_frame,
};

/// The default TIME COB-ID (11-bit).
pub const DEFAULT_COB_ID: u16 = crate::frame::cob::TIME;

/// Milliseconds in a day (no leap seconds).
pub const MS_PER_DAY: u32 = 86_400_000;

/// Days from the Unix epoch (1970-01-01) to the CANopen epoch (1984-01-01):
/// 14 years of 365 days plus the leap days of 1972, 1976 and 1980.
pub const UNIX_DAYS_AT_EPOCH: u32 = 14 * 365 + 3;

/// Length of a TIME_OF_DAY or TIME_DIFFERENCE value on the bus.
pub const ENCODED_LEN: usize = 6;

/// Why a time could not be decoded or converted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum TimeError {
    /// The data is not exactly 6 bytes long (the number it has).
    Length(usize),
    /// Reserved bits 28 to 31 of the millisecond field are set (their value,
    /// 1 to 15).
    ReservedBits(u8),
    /// A millisecond part of 86 400 000 or more.
    Millis(u32),
    /// A raw value with bits above bit 47 set.
    Raw48(u64),
    /// A date outside 1984-01-01 to 2163-06-06 (or a duration of more than
    /// 65 535 days): the day number since 1984-01-01 it would have had.
    OutOfRange {
        /// Days since 1984-01-01 (negative before it); saturated at the
        /// `i64` range.
        days: i64,
    },
    /// A civil date and time that does not exist (month 13, 2023-02-29,
    /// hour 24, second 60, ...).
    InvalidCivil(DateTime),
}

impl fmt::Display for TimeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TimeError::Length(n) => write!(
                f,
                "{n} data bytes; TIME_OF_DAY and TIME_DIFFERENCE have exactly 6"
            ),
            TimeError::ReservedBits(bits) => write!(
                f,
                "reserved bits 28 to 31 of the millisecond field are {bits:#x}; CiA 301 sends them as 0"
            ),
            TimeError::Millis(ms) => write!(
                f,
                "{ms} milliseconds after midnight; a day has {MS_PER_DAY}"
            ),
            TimeError::Raw48(raw) => write!(f, "raw time value {raw:#x} is wider than 48 bits"),
            TimeError::OutOfRange { days } => write!(
                f,
                "day {days} since 1984-01-01 is outside 0 to 65535 (1984-01-01 to 2163-06-06)"
            ),
            TimeError::InvalidCivil(dt) => write!(f, "{dt} is not a valid UTC date and time"),
        }
    }
}

impl core::error::Error for TimeError {}

/// The 6 bytes of a (days, ms) pair; `ms` must be below [`MS_PER_DAY`].
const fn encode_parts(days: u16, ms: u32) -> [u8; 6] {
    let m = ms.to_le_bytes();
    let d = days.to_le_bytes();
    [m[0], m[1], m[2], m[3] & 0x0F, d[0], d[1]]
}

/// The (days, ms) pair of 6 bytes, checked.
const fn decode_parts(data: &[u8]) -> Result<(u16, u32), TimeError> {
    let [b0, b1, b2, b3, b4, b5] = *data else {
        return Err(TimeError::Length(data.len()));
    };
    if b3 & 0xF0 != 0 {
        return Err(TimeError::ReservedBits(b3 >> 4));
    }
    let ms = u32::from_le_bytes([b0, b1, b2, b3]);
    if ms >= MS_PER_DAY {
        return Err(TimeError::Millis(ms));
    }
    Ok((u16::from_le_bytes([b4, b5]), ms))
}

/// The (days, ms) pair of the raw 48-bit form (`days << 32 | ms`, the bus
/// bytes read as one little-endian integer).
const fn parts_from_raw48(raw: u64) -> Result<(u16, u32), TimeError> {
    if raw >> 48 != 0 {
        return Err(TimeError::Raw48(raw));
    }
    let b = raw.to_le_bytes();
    decode_parts(&[b[0], b[1], b[2], b[3], b[4], b[5]])
}

/// The (days, ms) pair of a count of milliseconds, checked against the
/// 16-bit day range.
const fn parts_from_millis(total: u64) -> Result<(u16, u32), TimeError> {
    let days = total / MS_PER_DAY as u64;
    if days > u16::MAX as u64 {
        let days = if days > i64::MAX as u64 {
            i64::MAX
        } else {
            days as i64
        };
        return Err(TimeError::OutOfRange { days });
    }
    Ok((days as u16, (total % MS_PER_DAY as u64) as u32))
}

/// A TIME_OF_DAY value: a UTC instant between 1984-01-01T00:00:00.000Z and
/// 2163-06-06T23:59:59.999Z at millisecond resolution, as days since
/// 1984-01-01 and milliseconds after midnight (always below
/// [`MS_PER_DAY`]).
///
/// Ordered by time. `Display` is ISO 8601: `2026-12-02T12:34:56.789Z`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TimeOfDay {
    // Field order: the derived `Ord` compares days first.
    days: u16,
    ms: u32,
}

impl TimeOfDay {
    /// 1984-01-01T00:00:00.000Z, the CANopen epoch (all six bytes zero).
    pub const EPOCH: TimeOfDay = TimeOfDay { days: 0, ms: 0 };
    /// 2163-06-06T23:59:59.999Z, the latest time the format holds.
    pub const MAX: TimeOfDay = TimeOfDay {
        days: u16::MAX,
        ms: MS_PER_DAY - 1,
    };

    /// The time `ms` milliseconds after midnight of day `days` since
    /// 1984-01-01; fails when `ms` is 86 400 000 or more.
    pub const fn new(days: u16, ms: u32) -> Result<TimeOfDay, TimeError> {
        if ms >= MS_PER_DAY {
            return Err(TimeError::Millis(ms));
        }
        Ok(TimeOfDay { days, ms })
    }

    /// Days since 1984-01-01.
    pub const fn days(self) -> u16 {
        self.days
    }

    /// Milliseconds after midnight (0 to 86 399 999).
    pub const fn millis(self) -> u32 {
        self.ms
    }

    /// The 6 bytes on the bus (the data of a TIME frame).
    pub const fn encode(self) -> [u8; 6] {
        encode_parts(self.days, self.ms)
    }

    /// Decodes the 6 bytes of a TIME_OF_DAY (strict, see the module docs).
    pub const fn decode(data: &[u8]) -> Result<TimeOfDay, TimeError> {
        match decode_parts(data) {
            Ok((days, ms)) => Ok(TimeOfDay { days, ms }),
            Err(e) => Err(e),
        }
    }

    /// The raw 48-bit form: the bus bytes as one little-endian integer
    /// (`days << 32 | ms`), as an SDO upload of a TIME_OF_DAY entry into a
    /// `u64` gives it.
    pub const fn to_raw48(self) -> u64 {
        (self.days as u64) << 32 | self.ms as u64
    }

    /// The time of a raw 48-bit value (see [`TimeOfDay::to_raw48`]).
    pub const fn from_raw48(raw: u64) -> Result<TimeOfDay, TimeError> {
        match parts_from_raw48(raw) {
            Ok((days, ms)) => Ok(TimeOfDay { days, ms }),
            Err(e) => Err(e),
        }
    }

    /// Milliseconds since 1984-01-01T00:00:00.000Z.
    pub const fn epoch_millis(self) -> u64 {
        self.days as u64 * MS_PER_DAY as u64 + self.ms as u64
    }

    /// The time `millis` milliseconds after 1984-01-01T00:00:00.000Z.
    pub const fn from_epoch_millis(millis: u64) -> Result<TimeOfDay, TimeError> {
        match parts_from_millis(millis) {
            Ok((days, ms)) => Ok(TimeOfDay { days, ms }),
            Err(e) => Err(e),
        }
    }

    /// Milliseconds since the Unix epoch, 1970-01-01T00:00:00.000Z.
    pub const fn unix_millis(self) -> i64 {
        self.epoch_millis() as i64 + UNIX_DAYS_AT_EPOCH as i64 * MS_PER_DAY as i64
    }

    /// The time `millis` milliseconds after the Unix epoch (negative:
    /// before it, and so out of range).
    pub const fn from_unix_millis(millis: i64) -> Result<TimeOfDay, TimeError> {
        let offset = UNIX_DAYS_AT_EPOCH as i64 * MS_PER_DAY as i64;
        if millis < offset {
            // Rounds toward negative infinity: -1 ms is day -1. In i128,
            // so that `i64::MIN` cannot overflow; the quotient fits `i64`.
            let days = (millis as i128 - offset as i128).div_euclid(MS_PER_DAY as i128);
            return Err(TimeError::OutOfRange { days: days as i64 });
        }
        TimeOfDay::from_epoch_millis((millis - offset) as u64)
    }

    /// The time of a civil UTC date and time.
    pub const fn from_civil(dt: DateTime) -> Result<TimeOfDay, TimeError> {
        if !dt.is_valid() {
            return Err(TimeError::InvalidCivil(dt));
        }
        let days = days_from_civil(dt.year as i64, dt.month as i64, dt.day as i64)
            - UNIX_DAYS_AT_EPOCH as i64;
        if days < 0 || days > u16::MAX as i64 {
            return Err(TimeError::OutOfRange { days });
        }
        let ms = dt.hour as u32 * 3_600_000
            + dt.minute as u32 * 60_000
            + dt.second as u32 * 1000
            + dt.millisecond as u32;
        Ok(TimeOfDay {
            days: days as u16,
            ms,
        })
    }

    /// The civil UTC date and time.
    pub const fn to_civil(self) -> DateTime {
        let (year, month, day) = civil_from_days(self.days as i64 + UNIX_DAYS_AT_EPOCH as i64);
        let ms = self.ms;
        DateTime {
            // 1984 to 2163: fits.
            year: year as u16,
            month,
            day,
            hour: (ms / 3_600_000) as u8,
            minute: (ms / 60_000 % 60) as u8,
            second: (ms / 1000 % 60) as u8,
            millisecond: (ms % 1000) as u16,
        }
    }

    /// `self + d`, `None` after [`TimeOfDay::MAX`].
    pub const fn checked_add(self, d: TimeDifference) -> Option<TimeOfDay> {
        match TimeOfDay::from_epoch_millis(self.epoch_millis() + d.total_millis()) {
            Ok(t) => Some(t),
            Err(_) => None,
        }
    }

    /// `self - d`, `None` before [`TimeOfDay::EPOCH`].
    pub const fn checked_sub(self, d: TimeDifference) -> Option<TimeOfDay> {
        match self.epoch_millis().checked_sub(d.total_millis()) {
            Some(ms) => match TimeOfDay::from_epoch_millis(ms) {
                Ok(t) => Some(t),
                Err(_) => None,
            },
            None => None,
        }
    }

    /// The time from `earlier` to `self`, `None` if `earlier` is later.
    pub const fn checked_difference(self, earlier: TimeOfDay) -> Option<TimeDifference> {
        match self.epoch_millis().checked_sub(earlier.epoch_millis()) {
            Some(ms) => match TimeDifference::from_millis(ms) {
                Ok(d) => Some(d),
                Err(_) => None,
            },
            None => None,
        }
    }

    /// The time of a `SystemTime` (UTC; sub-millisecond parts truncated).
    #[cfg(feature = "std")]
    pub fn from_system_time(t: std::time::SystemTime) -> Result<TimeOfDay, TimeError> {
        let millis = match t.duration_since(std::time::UNIX_EPOCH) {
            Ok(after) => i64::try_from(after.as_millis()).unwrap_or(i64::MAX),
            // Before 1970, and so before 1984: out of range either way.
            // Rounded toward the past, like the truncation after 1970.
            Err(before) => {
                let d = before.duration();
                let partial = i64::from(d.subsec_nanos() % 1_000_000 != 0);
                i64::try_from(d.as_millis())
                    .map_or(i64::MIN, |ms| ms.saturating_neg().saturating_sub(partial))
            }
        };
        TimeOfDay::from_unix_millis(millis)
    }

    /// This time as a `SystemTime`; `None` if the platform's `SystemTime`
    /// cannot hold it.
    #[cfg(feature = "std")]
    pub fn to_system_time(self) -> Option<std::time::SystemTime> {
        let millis = u64::try_from(self.unix_millis()).ok()?;
        std::time::UNIX_EPOCH.checked_add(Duration::from_millis(millis))
    }
}

#[cfg(feature = "std")]
impl TryFrom<std::time::SystemTime> for TimeOfDay {
    type Error = TimeError;

    /// [`TimeOfDay::from_system_time`].
    fn try_from(t: std::time::SystemTime) -> Result<TimeOfDay, TimeError> {
        TimeOfDay::from_system_time(t)
    }
}

/// ISO 8601 in UTC with milliseconds: `2026-12-02T12:34:56.789Z`.
impl fmt::Display for TimeOfDay {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.to_civil().fmt(f)
    }
}

/// A TIME_DIFFERENCE value: a duration of up to 65 535 days and
/// 86 399 999 ms, at millisecond resolution (same layout as
/// [`TimeOfDay`]).
///
/// `Display` is an ISO 8601 duration: `P1DT2H3M4.005S`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct TimeDifference {
    days: u16,
    ms: u32,
}

impl TimeDifference {
    /// No time.
    pub const ZERO: TimeDifference = TimeDifference { days: 0, ms: 0 };
    /// The longest duration the format holds.
    pub const MAX: TimeDifference = TimeDifference {
        days: u16::MAX,
        ms: MS_PER_DAY - 1,
    };

    /// `days` days and `ms` milliseconds; fails when `ms` is 86 400 000 or
    /// more.
    pub const fn new(days: u16, ms: u32) -> Result<TimeDifference, TimeError> {
        if ms >= MS_PER_DAY {
            return Err(TimeError::Millis(ms));
        }
        Ok(TimeDifference { days, ms })
    }

    /// Whole days.
    pub const fn days(self) -> u16 {
        self.days
    }

    /// Milliseconds beyond the whole days (0 to 86 399 999).
    pub const fn millis(self) -> u32 {
        self.ms
    }

    /// The whole duration in milliseconds.
    pub const fn total_millis(self) -> u64 {
        self.days as u64 * MS_PER_DAY as u64 + self.ms as u64
    }

    /// The duration of `millis` milliseconds; fails beyond
    /// [`TimeDifference::MAX`].
    pub const fn from_millis(millis: u64) -> Result<TimeDifference, TimeError> {
        match parts_from_millis(millis) {
            Ok((days, ms)) => Ok(TimeDifference { days, ms }),
            Err(e) => Err(e),
        }
    }

    /// A `Duration` (sub-millisecond part truncated); fails beyond
    /// [`TimeDifference::MAX`].
    pub const fn from_duration(d: Duration) -> Result<TimeDifference, TimeError> {
        let days = d.as_secs() / 86_400;
        if days > u16::MAX as u64 {
            // At most u64::MAX / 86 400: fits.
            return Err(TimeError::OutOfRange { days: days as i64 });
        }
        // Below 65 536 days: fits.
        TimeDifference::from_millis(d.as_millis() as u64)
    }

    /// As a `Duration`.
    pub const fn to_duration(self) -> Duration {
        Duration::from_millis(self.total_millis())
    }

    /// The 6 bytes on the bus.
    pub const fn encode(self) -> [u8; 6] {
        encode_parts(self.days, self.ms)
    }

    /// Decodes the 6 bytes of a TIME_DIFFERENCE (strict, like
    /// [`TimeOfDay::decode`]).
    pub const fn decode(data: &[u8]) -> Result<TimeDifference, TimeError> {
        match decode_parts(data) {
            Ok((days, ms)) => Ok(TimeDifference { days, ms }),
            Err(e) => Err(e),
        }
    }

    /// The raw 48-bit form (`days << 32 | ms`).
    pub const fn to_raw48(self) -> u64 {
        (self.days as u64) << 32 | self.ms as u64
    }

    /// The duration of a raw 48-bit value.
    pub const fn from_raw48(raw: u64) -> Result<TimeDifference, TimeError> {
        match parts_from_raw48(raw) {
            Ok((days, ms)) => Ok(TimeDifference { days, ms }),
            Err(e) => Err(e),
        }
    }
}

impl TryFrom<Duration> for TimeDifference {
    type Error = TimeError;

    /// [`TimeDifference::from_duration`].
    fn try_from(d: Duration) -> Result<TimeDifference, TimeError> {
        TimeDifference::from_duration(d)
    }
}

impl From<TimeDifference> for Duration {
    fn from(d: TimeDifference) -> Duration {
        d.to_duration()
    }
}

/// ISO 8601 duration, all fields given: `P0DT0H0M0.000S`, `P1DT2H3M4.005S`.
impl fmt::Display for TimeDifference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let ms = self.ms;
        write!(
            f,
            "P{}DT{}H{}M{}.{:03}S",
            self.days,
            ms / 3_600_000,
            ms / 60_000 % 60,
            ms / 1000 % 60,
            ms % 1000
        )
    }
}
