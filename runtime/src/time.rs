//! Time as the protocol cores see it: a monotonic instant in microseconds,
//! supplied by the caller (sans-IO: the cores never read a clock).
//!
//! Durations are `core::time::Duration` (the same type as
//! `std::time::Duration`). [`Instant`] arithmetic never panics: adding past
//! the end of time stops at [`Instant::MAX`], going back before the epoch
//! stops at [`Instant::ZERO`], and the `checked_` methods say when either
//! would happen. Sub-microsecond parts of a duration are dropped.
//!
//! [`Deadline`] is what the drivers ([`crate::blocking`], `tokio`) take
//! where a call waits until a point in time: an [`Instant`] of the cores
//! (`master.now() + Duration::from_millis(50)`), a `std::time::Instant`
//! or a `tokio::time::Instant`, or [`Deadline::NEVER`].

use core::ops::{Add, AddAssign, Sub, SubAssign};
use core::time::Duration;

/// A point on the caller's monotonic clock, in microseconds since an
/// arbitrary epoch (the drivers use the moment they started).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Instant(u64);

/// The whole microseconds of `duration`, `None` beyond `u64::MAX`.
const fn micros(duration: Duration) -> Option<u64> {
    let micros = duration.as_micros();
    if micros > u64::MAX as u128 {
        None
    } else {
        Some(micros as u64)
    }
}

impl Instant {
    /// The epoch.
    pub const ZERO: Instant = Instant(0);
    /// The end of time: where saturating arithmetic stops.
    pub const MAX: Instant = Instant(u64::MAX);

    pub const fn from_micros(micros: u64) -> Instant {
        Instant(micros)
    }

    /// `millis` milliseconds after the epoch ([`Instant::MAX`] when that
    /// does not fit).
    pub const fn from_millis(millis: u64) -> Instant {
        Instant(millis.saturating_mul(1000))
    }

    pub const fn as_micros(self) -> u64 {
        self.0
    }

    /// The time since the epoch.
    pub const fn since_epoch(self) -> Duration {
        Duration::from_micros(self.0)
    }

    /// Time from `earlier` to `self`, `None` when `earlier` is later.
    pub const fn checked_duration_since(self, earlier: Instant) -> Option<Duration> {
        match self.0.checked_sub(earlier.0) {
            Some(micros) => Some(Duration::from_micros(micros)),
            None => None,
        }
    }

    /// Time from `earlier` to `self`; zero when `earlier` is later.
    pub const fn saturating_duration_since(self, earlier: Instant) -> Duration {
        Duration::from_micros(self.0.saturating_sub(earlier.0))
    }

    /// Same as [`Instant::saturating_duration_since`] (as
    /// `std::time::Instant::duration_since`, it does not panic).
    pub const fn duration_since(self, earlier: Instant) -> Duration {
        self.saturating_duration_since(earlier)
    }

    /// `self + duration`, `None` past [`Instant::MAX`].
    pub const fn checked_add(self, duration: Duration) -> Option<Instant> {
        match micros(duration) {
            Some(micros) => match self.0.checked_add(micros) {
                Some(at) => Some(Instant(at)),
                None => None,
            },
            None => None,
        }
    }

    /// `self - duration`, `None` before [`Instant::ZERO`].
    pub const fn checked_sub(self, duration: Duration) -> Option<Instant> {
        match micros(duration) {
            Some(micros) => match self.0.checked_sub(micros) {
                Some(at) => Some(Instant(at)),
                None => None,
            },
            None => None,
        }
    }

    /// `self + duration`, saturating at [`Instant::MAX`] instead of wrapping.
    pub const fn saturating_add(self, duration: Duration) -> Instant {
        match self.checked_add(duration) {
            Some(at) => at,
            None => Instant::MAX,
        }
    }

    /// `self - duration`, saturating at [`Instant::ZERO`].
    pub const fn saturating_sub(self, duration: Duration) -> Instant {
        match self.checked_sub(duration) {
            Some(at) => at,
            None => Instant::ZERO,
        }
    }
}

/// Saturating: see [`Instant::saturating_add`].
impl Add<Duration> for Instant {
    type Output = Instant;
    fn add(self, rhs: Duration) -> Instant {
        self.saturating_add(rhs)
    }
}

impl AddAssign<Duration> for Instant {
    fn add_assign(&mut self, rhs: Duration) {
        *self = self.saturating_add(rhs);
    }
}

/// Saturating: see [`Instant::saturating_sub`].
impl Sub<Duration> for Instant {
    type Output = Instant;
    fn sub(self, rhs: Duration) -> Instant {
        self.saturating_sub(rhs)
    }
}

impl SubAssign<Duration> for Instant {
    fn sub_assign(&mut self, rhs: Duration) {
        *self = self.saturating_sub(rhs);
    }
}

/// Saturating: zero when `rhs` is later (see
/// [`Instant::saturating_duration_since`]).
impl Sub<Instant> for Instant {
    type Output = Duration;
    fn sub(self, rhs: Instant) -> Duration {
        self.saturating_duration_since(rhs)
    }
}

/// The earlier of two optional deadlines (`None` means "no deadline").
pub fn earliest(a: Option<Instant>, b: Option<Instant>) -> Option<Instant> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, None) => a,
        (None, b) => b,
    }
}

/// The next deadline of a periodic task due at `due`, handled at `now`:
/// one period after `due`, or one period after `now` if that is already
/// past (the clock jumped; missed periods are skipped, not caught up).
pub(crate) fn next_period(due: Instant, now: Instant, period: Duration) -> Instant {
    let next = due + period;
    if next > now { next } else { now + period }
}

/// A period raised to `min` (a zero one would be due again at once, for
/// ever): what the producers do with a `Some` period shorter than the unit
/// of their object.
const fn at_least(period: Option<Duration>, min: Duration) -> Option<Duration> {
    match period {
        Some(p) if p.as_nanos() < min.as_nanos() => Some(min),
        other => other,
    }
}

/// The schedule of a periodic producer (heartbeat, SYNC, TIME): its period
/// (`None`: nothing periodic; a `Some` below the unit of its object counts
/// as that unit), whether it was started, and when it is next due. A jump
/// of the clock over several periods gives one due period, and the next one
/// period after `now` (see [`next_period`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Periodic {
    period: Option<Duration>,
    min: Duration,
    running: bool,
    next: Option<Instant>,
}

impl Periodic {
    /// A stopped schedule with `period`, raised to `min`.
    pub(crate) const fn new(period: Option<Duration>, min: Duration) -> Periodic {
        Periodic {
            period: at_least(period, min),
            min,
            running: false,
            next: None,
        }
    }

    /// The period (`None`: nothing periodic).
    pub(crate) const fn period(&self) -> Option<Duration> {
        self.period
    }

    /// Whether the schedule was started (and not stopped).
    pub(crate) const fn is_running(&self) -> bool {
        self.running
    }

    /// When the next period is due; `None` when stopped or without a period.
    pub(crate) const fn next(&self) -> Option<Instant> {
        self.next
    }

    /// Starts (or restarts): the first period is due one period after `now`.
    pub(crate) fn start(&mut self, now: Instant) {
        self.running = true;
        self.next = self.period.map(|period| now + period);
    }

    /// Starts (or restarts) with the first period due at `now`.
    pub(crate) fn start_at_once(&mut self, now: Instant) {
        self.running = true;
        self.next = self.period.map(|_| now);
    }

    /// Stops: nothing is due until the next start.
    pub(crate) fn stop(&mut self) {
        self.running = false;
        self.next = None;
    }

    /// Changes the period; when running, the next one is due one new period
    /// after `now` (`None` pauses, a later period resumes).
    pub(crate) fn set_period(&mut self, now: Instant, period: Option<Duration>) {
        self.period = at_least(period, self.min);
        if self.running {
            self.next = self.period.map(|period| now + period);
        }
    }

    /// Whether a period is due at `now`; if so the next one is scheduled.
    pub(crate) fn fire(&mut self, now: Instant) -> bool {
        match self.next {
            Some(due) if due <= now => {
                self.next = self.period.map(|period| next_period(due, now, period));
                true
            }
            _ => false,
        }
    }
}

/// The point in time until which a driver call may wait, on the driver's
/// clock.
///
/// Every driver function with a `deadline` parameter takes `impl
/// Into<Deadline>`:
/// - an [`Instant`] of the cores, e.g. `master.now() +
///   Duration::from_millis(50)` (the driver's [`crate::transport::Clock`]
///   gives the cores' time);
/// - with `std`, a `std::time::Instant`, mapped through the driver's clock
///   (rounded up to whole microseconds, so that the call never ends before
///   it), and `Option<std::time::Instant>` (`None`: no deadline; this is
///   what [`crate::blocking::serve`] took before);
/// - with `tokio`, a `tokio::time::Instant`;
/// - [`Deadline::NEVER`].
///
/// A parameter named `timeout` is a `Duration` from the moment of the call
/// instead.
///
/// Equality compares what the deadline was made from: a `std::time::Instant`
/// and the [`Instant`] it maps to are different values until
/// [`Deadline::on`] resolves them on a clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Deadline(Repr);

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Repr {
    Never,
    At(Instant),
    #[cfg(feature = "std")]
    Std(std::time::Instant),
}

impl Deadline {
    /// No deadline: wait until the call's condition holds.
    pub const NEVER: Deadline = Deadline(Repr::Never);

    /// The deadline `instant` on the cores' clock.
    pub const fn at(instant: Instant) -> Deadline {
        Deadline(Repr::At(instant))
    }

    /// Whether this is [`Deadline::NEVER`].
    pub const fn is_never(&self) -> bool {
        matches!(self.0, Repr::Never)
    }

    /// The deadline as an instant of the cores that see time through
    /// `clock`; `None` for [`Deadline::NEVER`]. A `std::time::Instant` is
    /// rounded up to the next whole microsecond (one before the clock's
    /// origin gives [`Instant::ZERO`]: already passed).
    #[cfg(feature = "std")]
    pub fn on(self, clock: &crate::transport::Clock) -> Option<Instant> {
        match self.0 {
            Repr::Never => None,
            Repr::At(at) => Some(at),
            Repr::Std(time) => {
                let at = clock.at(time);
                if clock.to_std(at) < time {
                    Some(at + Duration::from_micros(1))
                } else {
                    Some(at)
                }
            }
        }
    }
}

impl From<Instant> for Deadline {
    fn from(instant: Instant) -> Deadline {
        Deadline::at(instant)
    }
}

#[cfg(feature = "std")]
impl From<std::time::Instant> for Deadline {
    fn from(time: std::time::Instant) -> Deadline {
        Deadline(Repr::Std(time))
    }
}

/// `None` is [`Deadline::NEVER`]. (The only `Option` conversion, so that a
/// bare `None` needs no type annotation; for an optional [`Instant`] use
/// `opt.map_or(Deadline::NEVER, Deadline::at)`.)
#[cfg(feature = "std")]
impl From<Option<std::time::Instant>> for Deadline {
    fn from(time: Option<std::time::Instant>) -> Deadline {
        time.map_or(Deadline::NEVER, Deadline::from)
    }
}

#[cfg(feature = "tokio")]
impl From<::tokio::time::Instant> for Deadline {
    fn from(time: ::tokio::time::Instant) -> Deadline {
        Deadline::from(time.into_std())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const END: Instant = Instant::MAX;

    #[test]
    fn arithmetic_saturates_instead_of_panicking() {
        let t = Instant::from_millis(5);
        assert_eq!(t + Duration::from_millis(1), Instant::from_micros(6000));
        assert_eq!(t - Duration::from_millis(1), Instant::from_micros(4000));
        assert_eq!(t - Duration::from_secs(1), Instant::ZERO);
        assert_eq!(END + Duration::from_micros(1), END);
        assert_eq!(t + Duration::MAX, END);
        assert_eq!(t - Duration::MAX, Instant::ZERO);
        let mut u = t;
        u += Duration::from_millis(2);
        u -= Duration::from_millis(1);
        assert_eq!(u, Instant::from_millis(6));
        // Sub-microsecond parts are dropped.
        assert_eq!(t + Duration::from_nanos(1999), Instant::from_micros(5001));
        assert_eq!(Instant::from_millis(u64::MAX), END);
    }

    #[test]
    fn differences() {
        let a = Instant::from_millis(5);
        let b = Instant::from_millis(8);
        assert_eq!(b - a, Duration::from_millis(3));
        assert_eq!(a - b, Duration::ZERO);
        assert_eq!(b.duration_since(a), Duration::from_millis(3));
        assert_eq!(a.duration_since(b), Duration::ZERO);
        assert_eq!(b.saturating_duration_since(a), Duration::from_millis(3));
        assert_eq!(b.checked_duration_since(a), Some(Duration::from_millis(3)));
        assert_eq!(a.checked_duration_since(b), None);
        assert_eq!(END - Instant::ZERO, Duration::from_micros(u64::MAX));
        assert_eq!(a.since_epoch(), Duration::from_millis(5));
    }

    #[test]
    fn checked_ops() {
        let t = Instant::from_micros(10);
        assert_eq!(
            t.checked_add(Duration::from_micros(5)),
            Some(Instant::from_micros(15))
        );
        assert_eq!(
            t.checked_sub(Duration::from_micros(10)),
            Some(Instant::ZERO)
        );
        assert_eq!(t.checked_sub(Duration::from_micros(11)), None);
        assert_eq!(END.checked_add(Duration::from_micros(1)), None);
        assert_eq!(t.checked_add(Duration::MAX), None);
        assert_eq!(t.checked_sub(Duration::MAX), None);
        assert_eq!(END.checked_add(Duration::ZERO), Some(END));
    }

    #[test]
    fn const_arithmetic() {
        const AT: Instant = Instant::from_millis(1).saturating_add(Duration::from_millis(2));
        const BACK: Option<Instant> = AT.checked_sub(Duration::from_millis(3));
        assert_eq!(AT, Instant::from_millis(3));
        assert_eq!(BACK, Some(Instant::ZERO));
    }

    #[test]
    fn earliest_of_optional_deadlines() {
        let a = Some(Instant::from_millis(1));
        let b = Some(Instant::from_millis(2));
        assert_eq!(earliest(a, b), a);
        assert_eq!(earliest(None, b), b);
        assert_eq!(earliest(a, None), a);
        assert_eq!(earliest(None, None), None);
    }

    #[cfg(feature = "std")]
    #[test]
    fn deadlines_resolve_on_a_clock() {
        use crate::transport::Clock;
        let origin = std::time::Instant::now();
        let clock = Clock::starting_at(origin);
        let at = Instant::from_millis(7);
        assert_eq!(Deadline::from(at).on(&clock), Some(at));
        assert_eq!(Deadline::NEVER.on(&clock), None);
        assert!(Deadline::NEVER.is_never() && !Deadline::at(at).is_never());
        let std_at = origin + Duration::from_millis(7);
        assert_eq!(Deadline::from(std_at).on(&clock), Some(at));
        // Rounded up: the deadline is never earlier than asked.
        let between = origin + Duration::from_nanos(7_000_500);
        assert_eq!(
            Deadline::from(between).on(&clock),
            Some(Instant::from_micros(7001))
        );
        // Before the origin: already passed.
        let late = Clock::starting_at(origin + Duration::from_secs(1));
        assert_eq!(Deadline::from(origin).on(&late), Some(Instant::ZERO));
        assert_eq!(Deadline::from(None::<std::time::Instant>), Deadline::NEVER);
        assert_eq!(Deadline::from(Some(std_at)).on(&clock), Some(at));
    }
}
