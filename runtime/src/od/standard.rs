//! Value types CiA 301 fixes for the entries every PDO has: the generated
//! code of any device uses these for sub 1, 2, 3 and 5 of the PDO
//! communication parameters (0x1400–0x15FF, 0x1800–0x19FF), so that a
//! device with 512 PDOs gets no code of its own for them.
//!
//! Each holds the raw value (`pub` field, `const fn from_raw`/`to_raw`) and
//! implements [`Scalar`].

use core::time::Duration;

use super::Scalar;

macro_rules! raw_value {
    ($name:ident, $raw:ty) => {
        impl $name {
            /// The value of a raw entry value.
            #[inline]
            pub const fn from_raw(raw: $raw) -> Self {
                Self(raw)
            }
            /// The raw entry value.
            #[inline]
            pub const fn to_raw(self) -> $raw {
                self.0
            }
        }
        impl Scalar for $name {
            #[inline(always)]
            fn to_raw(self) -> u64 {
                u64::from(self.0)
            }
            #[inline(always)]
            fn from_raw(raw: u64) -> Self {
                Self(raw as $raw)
            }
        }
    };
}

/// The COB-ID of a PDO (sub 1 of its communication parameter): the CAN-ID
/// in bits 0–28 (0–10 for an 11-bit CAN-ID), bit 29 extended frame, bit 30
/// no RTR allowed, bit 31 not valid (the PDO does not exist; its mapping
/// may be changed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct PdoCobId(pub u32);

raw_value!(PdoCobId, u32);

impl PdoCobId {
    const EXTENDED: u32 = 1 << 29;
    const NO_RTR: u32 = 1 << 30;
    const NOT_VALID: u32 = 1 << 31;

    /// The CAN-ID (bits 0–28).
    #[inline]
    pub const fn can_id(self) -> u32 {
        self.0 & 0x1FFF_FFFF
    }
    /// Bit 29: a 29-bit CAN-ID.
    #[inline]
    pub const fn extended_frame(self) -> bool {
        self.0 & Self::EXTENDED != 0
    }
    /// Bit 30: no remote transmission request allowed.
    #[inline]
    pub const fn no_rtr(self) -> bool {
        self.0 & Self::NO_RTR != 0
    }
    /// Bit 31: the PDO does not exist (is not valid).
    #[inline]
    pub const fn not_valid(self) -> bool {
        self.0 & Self::NOT_VALID != 0
    }
    /// The same with another CAN-ID (its low 29 bits).
    #[inline]
    pub const fn with_can_id(self, can_id: u32) -> Self {
        Self(self.0 & !0x1FFF_FFFF | can_id & 0x1FFF_FFFF)
    }
    /// The same with bit 29 set or clear.
    #[inline]
    pub const fn with_extended_frame(self, on: bool) -> Self {
        self.with(Self::EXTENDED, on)
    }
    /// The same with bit 30 set or clear.
    #[inline]
    pub const fn with_no_rtr(self, on: bool) -> Self {
        self.with(Self::NO_RTR, on)
    }
    /// The same with bit 31 set or clear.
    #[inline]
    pub const fn with_not_valid(self, on: bool) -> Self {
        self.with(Self::NOT_VALID, on)
    }
    const fn with(self, bit: u32, on: bool) -> Self {
        Self(if on { self.0 | bit } else { self.0 & !bit })
    }
}

/// How a PDO is triggered (sub 2 of its communication parameter).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct TransmissionType(pub u8);

raw_value!(TransmissionType, u8);

/// The meaning of a [`TransmissionType`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TransmissionKind {
    /// 0: synchronous, acyclic (sent at the SYNC after an event).
    SynchronousAcyclic,
    /// 1–240: synchronous, every n-th SYNC.
    Synchronous(u8),
    /// 252: on RTR only, data sampled at SYNC.
    RtrSynchronous,
    /// 253: on RTR only, event-driven.
    RtrEventDriven,
    /// 254: event-driven, manufacturer-specific events.
    EventDrivenManufacturer,
    /// 255: event-driven, device-profile events.
    EventDrivenProfile,
    /// 241–251: reserved.
    Reserved(u8),
}

impl TransmissionType {
    /// Event-driven, device-profile events (255).
    pub const EVENT_DRIVEN: TransmissionType = TransmissionType(255);

    /// What the value means.
    pub const fn kind(self) -> TransmissionKind {
        match self.0 {
            0 => TransmissionKind::SynchronousAcyclic,
            n @ 1..=240 => TransmissionKind::Synchronous(n),
            252 => TransmissionKind::RtrSynchronous,
            253 => TransmissionKind::RtrEventDriven,
            254 => TransmissionKind::EventDrivenManufacturer,
            255 => TransmissionKind::EventDrivenProfile,
            n => TransmissionKind::Reserved(n),
        }
    }
    /// Whether the PDO follows SYNC (0–240, 252).
    pub const fn is_synchronous(self) -> bool {
        matches!(self.0, 0..=240 | 252)
    }
}

/// The inhibit time of a PDO (sub 3), in multiples of 100 µs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct InhibitTime(pub u16);

raw_value!(InhibitTime, u16);

impl InhibitTime {
    /// The time.
    pub const fn duration(self) -> Duration {
        Duration::from_micros(self.0 as u64 * 100)
    }
    /// The value in milliseconds (0.1 ms per raw step).
    pub fn millis(self) -> f64 {
        f64::from(self.0) * 0.1
    }
}

/// The event timer of a PDO (sub 5) in ms; 0 is off. For an RPDO it is the
/// deadline by which the next PDO must come.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct EventTimer(pub u16);

raw_value!(EventTimer, u16);

impl EventTimer {
    /// The time, `None` when the timer is off (0).
    pub const fn duration(self) -> Option<Duration> {
        match self.0 {
            0 => None,
            ms => Some(Duration::from_millis(ms as u64)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cob_id_bits() {
        let cob = PdoCobId::from_raw(0x8000_0185);
        assert!(cob.not_valid() && !cob.no_rtr() && !cob.extended_frame());
        assert_eq!(cob.can_id(), 0x185);
        assert_eq!(cob.with_not_valid(false).to_raw(), 0x185);
        assert_eq!(cob.with_can_id(0x1ABC_DEF0).can_id(), 0x1ABC_DEF0);
        assert_eq!(
            <PdoCobId as Scalar>::from_raw(0x4000_0000).to_raw(),
            0x4000_0000
        );
    }

    #[test]
    fn transmission_types_and_timers() {
        assert_eq!(
            TransmissionType(0).kind(),
            TransmissionKind::SynchronousAcyclic
        );
        assert_eq!(TransmissionType(3).kind(), TransmissionKind::Synchronous(3));
        assert_eq!(
            TransmissionType(245).kind(),
            TransmissionKind::Reserved(245)
        );
        assert_eq!(
            TransmissionType::EVENT_DRIVEN.kind(),
            TransmissionKind::EventDrivenProfile
        );
        assert!(TransmissionType(252).is_synchronous() && !TransmissionType(254).is_synchronous());
        assert_eq!(InhibitTime(15).duration(), Duration::from_micros(1500));
        assert_eq!(EventTimer(0).duration(), None);
        assert_eq!(EventTimer(100).duration(), Some(Duration::from_millis(100)));
    }
}
