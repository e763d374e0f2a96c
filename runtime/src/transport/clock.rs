//! The bridge between the std clock and the caller-supplied
//! [`crate::Instant`] of the protocol cores.

use core::time::Duration;

use crate::Instant;

/// Thirty years: where [`Clock::to_std`] stops when an instant lies beyond
/// what `std::time::Instant` can hold.
const FAR_FUTURE: Duration = Duration::from_secs(30 * 365 * 24 * 3600);

/// Maps `std::time::Instant` to [`crate::Instant`]: microseconds since the
/// clock's origin (the moment it was created, unless given).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Clock {
    origin: std::time::Instant,
}

impl Clock {
    /// A clock whose origin is now.
    pub fn new() -> Clock {
        Clock::starting_at(std::time::Instant::now())
    }

    /// A clock whose origin is `origin`.
    pub const fn starting_at(origin: std::time::Instant) -> Clock {
        Clock { origin }
    }

    /// The std instant that maps to [`Instant::ZERO`].
    pub const fn origin(&self) -> std::time::Instant {
        self.origin
    }

    /// The current time.
    pub fn now(&self) -> Instant {
        self.at(std::time::Instant::now())
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
    fn now_advances() {
        let clock = Clock::new();
        let a = clock.now();
        std::thread::sleep(Duration::from_millis(2));
        let b = clock.now();
        assert!(b.saturating_duration_since(a) >= Duration::from_millis(2));
    }
}
