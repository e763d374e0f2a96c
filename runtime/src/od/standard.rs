//! Value types CiA 301 fixes for the entries every PDO has: the generated
//! code of any device uses these for sub 1, 2, 3 and 5 of the PDO
//! communication parameters (0x1400–0x15FF, 0x1800–0x19FF), so that a
//! device with 512 PDOs gets no code of its own for them.
//!
//! Each converts from and to the raw value (`const fn from_raw`/`to_raw`)
//! and implements [`Scalar`].

use core::fmt;
use core::time::Duration;

use super::Scalar;
use crate::CanId;

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

/// The COB-ID entry of a PDO (sub 1 of its communication parameter), the
/// one type for it everywhere: PDO receiver and transmitter, PDO
/// configuration, generated and derived PDO structs. Bits 0–28 hold the
/// CAN identifier (0–10 for an 11-bit one), bit 29 selects a 29-bit
/// identifier (extended frame), bit 30 set means no RTR allowed, bit 31 set
/// means the PDO is not valid (it does not exist; its mapping may be
/// changed). [`PdoCobId::can_id`] gives the identifier on the bus.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct PdoCobId(pub u32);

raw_value!(PdoCobId, u32);

impl PdoCobId {
    const EXTENDED: u32 = 1 << 29;
    const NO_RTR: u32 = 1 << 30;
    const NOT_VALID: u32 = 1 << 31;
    const ID_29: u32 = 0x1FFF_FFFF;

    /// A valid COB-ID for `id`, RTR allowed, bit 29 set for an extended
    /// identifier.
    #[inline]
    pub const fn new(id: CanId) -> Self {
        Self(0).with_can_id(id)
    }
    /// The identifier on the bus: bits 0–28 with bit 29 set, else bits
    /// 0–10 (bits 11–28 of an 11-bit entry are ignored here; see
    /// [`PdoCobId::checked_can_id`]).
    #[inline]
    pub const fn can_id(self) -> CanId {
        if self.is_extended() {
            CanId::Extended(self.0 & Self::ID_29)
        } else {
            CanId::Standard((self.0 & 0x7FF) as u16)
        }
    }
    /// The identifier on the bus; an error when bit 29 is clear but bits
    /// 11–28 are not all zero (no 11-bit identifier).
    #[inline]
    pub const fn checked_can_id(self) -> Result<CanId, CobIdError> {
        if !self.is_extended() && self.0 & 0x1FFF_F800 != 0 {
            return Err(CobIdError::OutOfRange(self));
        }
        Ok(self.can_id())
    }
    /// Bit 29 set: a 29-bit identifier (extended frame).
    #[inline]
    pub const fn is_extended(self) -> bool {
        self.0 & Self::EXTENDED != 0
    }
    /// Bit 30 clear: remote frames may request the PDO.
    #[inline]
    pub const fn rtr_allowed(self) -> bool {
        self.0 & Self::NO_RTR == 0
    }
    /// Bit 31 clear: the PDO exists and is used.
    #[inline]
    pub const fn is_valid(self) -> bool {
        self.0 & Self::NOT_VALID == 0
    }
    /// The same with identifier `id` (bit 29 follows its kind).
    #[inline]
    pub const fn with_can_id(self, id: CanId) -> Self {
        let flags = self.0 & (Self::NO_RTR | Self::NOT_VALID);
        match id {
            CanId::Standard(id) => Self(flags | (id as u32 & 0x7FF)),
            CanId::Extended(id) => Self(flags | Self::EXTENDED | (id & Self::ID_29)),
        }
    }
    /// The same with bit 31 clear (`true`) or set (`false`).
    #[inline]
    pub const fn with_valid(self, valid: bool) -> Self {
        self.with(Self::NOT_VALID, !valid)
    }
    /// The same with bit 30 clear (`true`) or set (`false`).
    #[inline]
    pub const fn with_rtr_allowed(self, allowed: bool) -> Self {
        self.with(Self::NO_RTR, !allowed)
    }
    const fn with(self, bit: u32, on: bool) -> Self {
        Self(if on { self.0 | bit } else { self.0 & !bit })
    }
}

/// `0x80000185 (0x185, not valid)`: the entry, then what it says.
impl fmt::Display for PdoCobId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:#010X} ({}", self.0, self.can_id())?;
        if !self.is_valid() {
            f.write_str(", not valid")?;
        }
        if !self.rtr_allowed() {
            f.write_str(", no RTR")?;
        }
        f.write_str(")")
    }
}

impl fmt::Debug for PdoCobId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "PdoCobId({:#010X})", self.0)
    }
}

/// A PDO COB-ID entry that names no identifier.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CobIdError {
    /// Bit 29 is clear (an 11-bit identifier) but bits 11 to 28 are not
    /// all zero.
    OutOfRange(PdoCobId),
}

impl fmt::Display for CobIdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CobIdError::OutOfRange(v) => write!(
                f,
                "COB-ID {:#010X} has bits set between bit 11 and bit 28 but bit 29 clear; \
                 an 11-bit identifier ends at 0x7FF (set bit 29 for a 29-bit one)",
                v.0
            ),
        }
    }
}

impl core::error::Error for CobIdError {}

/// How a PDO is triggered (sub 2 of its communication parameter).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TransmissionType {
    /// 0: synchronous, acyclic (sent at the SYNC after an event).
    SynchronousAcyclic,
    /// 1–240: synchronous, every n-th SYNC (a value outside 1–240 is
    /// not one: [`TransmissionType::from_raw`] never makes it).
    SynchronousCyclic(u8),
    /// 241–251: reserved.
    Reserved(u8),
    /// 252: on RTR only, data sampled at SYNC.
    RtrSynchronous,
    /// 253: on RTR only, event-driven.
    RtrEventDriven,
    /// 254: event-driven, manufacturer-specific events.
    EventDrivenManufacturer,
    /// 255: event-driven, device-profile events.
    EventDrivenProfile,
}

impl Default for TransmissionType {
    /// 0, the value of an entry never written.
    fn default() -> Self {
        TransmissionType::SynchronousAcyclic
    }
}

impl TransmissionType {
    /// The type of a raw entry value.
    #[inline]
    pub const fn from_raw(raw: u8) -> Self {
        match raw {
            0 => TransmissionType::SynchronousAcyclic,
            n @ 1..=240 => TransmissionType::SynchronousCyclic(n),
            n @ 241..=251 => TransmissionType::Reserved(n),
            252 => TransmissionType::RtrSynchronous,
            253 => TransmissionType::RtrEventDriven,
            254 => TransmissionType::EventDrivenManufacturer,
            255 => TransmissionType::EventDrivenProfile,
        }
    }
    /// The raw entry value.
    #[inline]
    pub const fn to_raw(self) -> u8 {
        match self {
            TransmissionType::SynchronousAcyclic => 0,
            TransmissionType::SynchronousCyclic(n) | TransmissionType::Reserved(n) => n,
            TransmissionType::RtrSynchronous => 252,
            TransmissionType::RtrEventDriven => 253,
            TransmissionType::EventDrivenManufacturer => 254,
            TransmissionType::EventDrivenProfile => 255,
        }
    }
    /// Whether the PDO follows SYNC (0–240, 252).
    pub const fn is_synchronous(self) -> bool {
        matches!(self.to_raw(), 0..=240 | 252)
    }
}

impl Scalar for TransmissionType {
    #[inline(always)]
    fn to_raw(self) -> u64 {
        u64::from(TransmissionType::to_raw(self))
    }
    #[inline(always)]
    fn from_raw(raw: u64) -> Self {
        TransmissionType::from_raw(raw as u8)
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
    fn cob_id_bits_follow_cia_301() {
        let cob = PdoCobId::from_raw(0x8000_0185);
        assert!(!cob.is_valid() && cob.rtr_allowed() && !cob.is_extended());
        assert_eq!(cob.can_id(), CanId::Standard(0x185));
        assert_eq!(cob.with_valid(true).to_raw(), 0x185);
        assert!(!PdoCobId::from_raw(0x4000_0000).rtr_allowed());
        assert_eq!(
            <PdoCobId as Scalar>::from_raw(0x4000_0000).to_raw(),
            0x4000_0000
        );
        assert_eq!(
            PdoCobId::from_raw(0x0000_0800).checked_can_id(),
            Err(CobIdError::OutOfRange(PdoCobId(0x800)))
        );
        assert_eq!(
            PdoCobId::from_raw(0x2000_0800).checked_can_id(),
            Ok(CanId::Extended(0x800))
        );
    }

    #[test]
    fn cob_id_round_trips_through_its_parts() {
        // 11-bit: entry -> (identifier, flags) -> entry.
        for raw in [0x0000_01A0, 0x8000_0220, 0x4000_07FF, 0xC000_0000] {
            let cob = PdoCobId::from_raw(raw);
            let id = cob.checked_can_id().unwrap();
            assert!(matches!(id, CanId::Standard(_)));
            let rebuilt = PdoCobId::new(id)
                .with_valid(cob.is_valid())
                .with_rtr_allowed(cob.rtr_allowed());
            assert_eq!(rebuilt.to_raw(), raw);
        }
        // 29-bit.
        for raw in [0x2000_0000, 0x3FFF_FFFF, 0xA123_4567, 0x6000_0180] {
            let cob = PdoCobId::from_raw(raw);
            let id = cob.checked_can_id().unwrap();
            assert!(matches!(id, CanId::Extended(_)));
            let rebuilt = PdoCobId::new(id)
                .with_valid(cob.is_valid())
                .with_rtr_allowed(cob.rtr_allowed());
            assert_eq!(rebuilt.to_raw(), raw);
        }
        assert_eq!(PdoCobId::new(CanId::Extended(0x185)).to_raw(), 0x2000_0185);
        assert_eq!(PdoCobId::new(CanId::Standard(0x185)).to_raw(), 0x185);
    }

    #[test]
    fn cob_id_formats_entry_and_identifier() {
        assert_eq!(
            PdoCobId::from_raw(0xC000_0185).to_string(),
            "0xC0000185 (0x185, not valid, no RTR)"
        );
        assert_eq!(
            PdoCobId::from_raw(0x2000_0185).to_string(),
            "0x20000185 (0x00000185)"
        );
        assert_eq!(format!("{:?}", PdoCobId(0x185)), "PdoCobId(0x00000185)");
    }

    #[test]
    fn transmission_types_round_trip() {
        for raw in 0..=255u8 {
            assert_eq!(TransmissionType::from_raw(raw).to_raw(), raw);
        }
        assert_eq!(
            TransmissionType::from_raw(0),
            TransmissionType::SynchronousAcyclic
        );
        assert_eq!(
            TransmissionType::from_raw(3),
            TransmissionType::SynchronousCyclic(3)
        );
        assert_eq!(
            TransmissionType::from_raw(245),
            TransmissionType::Reserved(245)
        );
        assert!(
            TransmissionType::from_raw(252).is_synchronous()
                && !TransmissionType::from_raw(254).is_synchronous()
        );
    }

    #[test]
    fn times() {
        assert_eq!(InhibitTime(15).duration(), Duration::from_micros(1500));
        assert_eq!(EventTimer(0).duration(), None);
        assert_eq!(EventTimer(100).duration(), Some(Duration::from_millis(100)));
    }
}
