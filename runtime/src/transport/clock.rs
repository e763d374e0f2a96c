//! The bridge between a time source and the caller-supplied
//! [`crate::Instant`] of the protocol cores.
//!
//! A [`Clock`] reads one of three sources: the std clock ([`Clock::new`],
//! the default), tokio's clock (`crate::tokio::clock`, which follows
//! tokio's paused clock in tests), or a [`ManualClock`] that moves only
//! when told to (tests of the blocking drivers: no real waiting).

use core::time::Duration;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::Instant;

/// Thirty years: where [`Clock::to_std`] stops when an instant lies beyond
/// what `std::time::Instant` can hold.
const FAR_FUTURE: Duration = Duration::from_secs(30 * 365 * 24 * 3600);

/// Maps a time source to [`crate::Instant`]: microseconds since the
/// clock's origin (the moment it was created, unless given). Clones share
/// the source: clones of a manual clock see the same time.
#[derive(Debug, Clone)]
pub struct Clock {
    origin: std::time::Instant,
    source: Source,
}

/// Where [`Clock::now`] reads the time.
#[derive(Debug, Clone)]
enum Source {
    /// `std::time::Instant::now()`.
    System,
    /// `tokio::time::Instant::now()` (the paused clock in tests).
    #[cfg(feature = "tokio")]
    Tokio,
    /// The microseconds a [`ManualClock`] holds.
    Manual(Arc<AtomicU64>),
}

impl Clock {
    /// A clock on the std clock whose origin is now.
    pub fn new() -> Clock {
        Clock::starting_at(std::time::Instant::now())
    }

    /// A clock on the std clock whose origin is `origin`.
    pub const fn starting_at(origin: std::time::Instant) -> Clock {
        Clock {
            origin,
            source: Source::System,
        }
    }

    /// A clock on tokio's clock whose origin is tokio's now (see
    /// `crate::tokio::clock`).
    #[cfg(feature = "tokio")]
    pub(crate) fn following_tokio() -> Clock {
        Clock {
            origin: ::tokio::time::Instant::now().into_std(),
            source: Source::Tokio,
        }
    }

    /// The std instant that maps to [`Instant::ZERO`]. For a manual clock,
    /// the moment its [`ManualClock`] was created.
    pub const fn origin(&self) -> std::time::Instant {
        self.origin
    }

    /// Whether this clock moves only when its [`ManualClock`] is advanced.
    pub fn is_manual(&self) -> bool {
        matches!(self.source, Source::Manual(_))
    }

    /// The current time.
    pub fn now(&self) -> Instant {
        match &self.source {
            Source::System => self.at(std::time::Instant::now()),
            #[cfg(feature = "tokio")]
            Source::Tokio => self.at(::tokio::time::Instant::now().into_std()),
            Source::Manual(micros) => Instant::from_micros(micros.load(Ordering::Acquire)),
        }
    }

    /// Moves a manual clock to `to` (never backwards); `false`, and no
    /// effect, on the std and tokio clocks. The blocking drivers call it
    /// instead of waiting when the bus has nothing for them.
    pub(crate) fn skip_to(&self, to: Instant) -> bool {
        match &self.source {
            Source::Manual(micros) => {
                micros.fetch_max(to.as_micros(), Ordering::AcqRel);
                true
            }
            _ => false,
        }
    }

    /// The instant of `time`, rounded down to whole microseconds; instants
    /// before the origin map to [`Instant::ZERO`].
    pub fn at(&self, time: std::time::Instant) -> Instant {
        let since = time.saturating_duration_since(self.origin);
        Instant::from_micros(u64::try_from(since.as_micros()).unwrap_or(u64::MAX))
    }

    /// The std instant of `instant`. Instants too far ahead for the platform
    /// clock give a point about thirty years after the origin (a deadline
    /// that never comes in practice).
    pub fn to_std(&self, instant: Instant) -> std::time::Instant {
        let since = Duration::from_micros(instant.as_micros());
        self.origin
            .checked_add(since)
            .or_else(|| self.origin.checked_add(FAR_FUTURE))
            .unwrap_or(self.origin)
    }
}

impl Default for Clock {
    /// Same as [`Clock::new`].
    fn default() -> Clock {
        Clock::new()
    }
}

/// Time that moves only when told to: the handle of a manual [`Clock`]
/// for tests.
///
/// Give [`ManualClock::clock`] to a blocking driver
/// (`blocking::Master::with_clock`, `blocking::drive`, `blocking::serve`,
/// `blocking::SdoClient::with_clock`). Those drivers never sleep on a
/// manual clock: when the bus has no frame ready, the clock jumps to the
/// end of the wait (the next timer of the cores or the call's deadline,
/// whichever comes first), as if the bus had stayed silent until then. So
/// a timeout of one second takes no real time, and a peer must have its
/// answer on the bus before the driver looks (a peer that answers from
/// another thread may be too late: script such peers on the test's
/// thread, or use the std clock). Every blocking driver waiting on the
/// clock moves it, so run one driver on it at a time. The tokio drivers
/// take tokio's paused clock instead (`crate::tokio::clock`).
///
/// ```
/// use core::time::Duration;
/// use eds2rust_runtime::Instant;
/// use eds2rust_runtime::transport::clock::ManualClock;
///
/// let time = ManualClock::new();
/// let clock = time.clock();
/// assert_eq!(clock.now(), Instant::ZERO);
/// time.advance(Duration::from_millis(5));
/// assert_eq!(clock.now(), Instant::from_millis(5));
/// ```
#[derive(Debug, Clone)]
pub struct ManualClock {
    origin: std::time::Instant,
    micros: Arc<AtomicU64>,
}

impl ManualClock {
    /// A manual clock standing at [`Instant::ZERO`].
    pub fn new() -> ManualClock {
        ManualClock {
            origin: std::time::Instant::now(),
            micros: Arc::new(AtomicU64::new(0)),
        }
    }

    /// A [`Clock`] that reads this time (any number of them share it).
    pub fn clock(&self) -> Clock {
        Clock {
            origin: self.origin,
            source: Source::Manual(Arc::clone(&self.micros)),
        }
    }

    /// The current time.
    pub fn now(&self) -> Instant {
        Instant::from_micros(self.micros.load(Ordering::Acquire))
    }

    /// Moves the time forward by `by` (saturating at [`Instant::MAX`]).
    pub fn advance(&self, by: Duration) {
        self.advance_to(self.now() + by);
    }

    /// Moves the time to `to`; an earlier `to` leaves it where it is (time
    /// never runs backwards).
    pub fn advance_to(&self, to: Instant) {
        self.micros.fetch_max(to.as_micros(), Ordering::AcqRel);
    }
}

impl Default for ManualClock {
    /// Same as [`ManualClock::new`].
    fn default() -> ManualClock {
        ManualClock::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_both_ways() {
        let origin = std::time::Instant::now();
        let clock = Clock::starting_at(origin);
        assert_eq!(clock.at(origin), Instant::ZERO);
        let later = origin + Duration::from_micros(1_234_567);
        assert_eq!(clock.at(later), Instant::from_micros(1_234_567));
        assert_eq!(clock.to_std(Instant::from_micros(1_234_567)), later);
        // Sub-microsecond parts round down.
        assert_eq!(
            clock.at(origin + Duration::from_nanos(1_999)),
            Instant::from_micros(1)
        );
    }

    #[test]
    fn before_origin_is_zero_and_far_future_saturates() {
        let origin = std::time::Instant::now();
        let clock = Clock::starting_at(origin + Duration::from_secs(5));
        assert_eq!(clock.at(origin), Instant::ZERO);
        let far = clock.to_std(Instant::from_micros(u64::MAX));
        assert!(far > clock.origin() + Duration::from_secs(3600));
    }

    #[test]
    fn the_system_clock_follows_std_time() {
        let clock = Clock::new();
        let before = std::time::Instant::now();
        let now = clock.now();
        let after = std::time::Instant::now();
        assert!(clock.at(before) <= now && now <= clock.at(after));
        assert!(!clock.is_manual());
        assert!(!clock.skip_to(Instant::from_millis(1)));
    }

    #[test]
    fn a_manual_clock_moves_only_forward_and_when_told() {
        let time = ManualClock::new();
        let clock = time.clock();
        let copy = clock.clone();
        assert!(clock.is_manual());
        assert_eq!(clock.now(), Instant::ZERO);
        time.advance(Duration::from_millis(3));
        assert_eq!(copy.now(), Instant::from_millis(3));
        time.advance_to(Instant::from_millis(1));
        assert_eq!(clock.now(), Instant::from_millis(3));
        assert!(clock.skip_to(Instant::from_millis(8)));
        assert_eq!(time.now(), Instant::from_millis(8));
        assert!(clock.skip_to(Instant::from_millis(2)));
        assert_eq!(time.now(), Instant::from_millis(8));
        // Std instants map as from the moment the manual clock was made.
        assert_eq!(
            clock.to_std(Instant::from_millis(8)),
            clock.origin() + Duration::from_millis(8)
        );
    }
}
