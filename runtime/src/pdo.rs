//! PDO: process data objects (CiA 301), master side.
//!
//! The master transmits the devices' RPDOs and receives their TPDOs:
//! - [`PdoTransmitter`]: one PDO the master sends, with the CiA 301
//!   transmission types (synchronous acyclic and cyclic, paced by SYNC
//!   frames; event-driven with inhibit time and event timer).
//! - [`PdoReceiver`]: a fixed number of PDOs the master listens to; it keeps
//!   the last data of each, reports length errors and reception timeouts,
//!   and decodes generated [`od::Pdo`] structs.
//! - [`PdoConfig`]: the SDO writes that configure a PDO's mapping and
//!   communication parameters in the order CiA 301 prescribes, with the
//!   read-backs that verify them, as a plan of [`Step`]s; with `std`,
//!   [`blocking::configure_pdo`] runs it over a blocking SDO client.
//!
//! The cores need only `core` and allocate nothing.
//!
//! A PDO's COB-ID entry (sub 1 of the communication parameter) is a 32-bit
//! value: bits 0 to 10 hold the 11-bit identifier, bit 29 selects a 29-bit
//! identifier (not supported here), bit 30 set means "no RTR allowed" and
//! bit 31 set means the PDO is invalid (disabled). [`CobId`] reads it.

use core::fmt;

use crate::od;

mod config;
#[doc(hidden)]
pub mod derive;
pub mod layout;
mod receiver;
mod transmitter;

#[cfg(feature = "std")]
pub mod blocking;

pub use config::{ConfigCheckError, MAX_ENTRIES, PdoConfig, Step, StepAction, StepKind, Steps};
pub use receiver::{PdoEvent, PdoReceiver, RECEIVER_EVENTS, WatchError};
pub use transmitter::{PdoTransmitter, TransmitterConfig, TransmitterConfigError};

/// Bit 31 of a COB-ID entry: the PDO is invalid (disabled).
pub const COB_ID_INVALID: u32 = 1 << 31;
/// Bit 30 of a COB-ID entry: no RTR allowed on this PDO.
pub const COB_ID_NO_RTR: u32 = 1 << 30;
/// Bit 29 of a COB-ID entry: the identifier has 29 bits (CAN extended frame).
pub const COB_ID_EXTENDED: u32 = 1 << 29;

/// A PDO COB-ID entry with an 11-bit identifier, read from its 32-bit value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct CobId {
    /// The 11-bit CAN identifier.
    pub id: u16,
    /// Bit 31 clear: the PDO exists and is used.
    pub valid: bool,
    /// Bit 30 clear: remote frames may request the PDO.
    pub rtr_allowed: bool,
}

impl CobId {
    /// Reads a COB-ID entry; 29-bit identifiers (bit 29 set) and bits set
    /// between bit 11 and bit 28 are refused.
    pub const fn parse(value: u32) -> Result<CobId, CobIdError> {
        if value & COB_ID_EXTENDED != 0 {
            return Err(CobIdError::Extended(value));
        }
        if value & 0x1FFF_F800 != 0 {
            return Err(CobIdError::OutOfRange(value));
        }
        Ok(CobId {
            id: (value & 0x7FF) as u16,
            valid: value & COB_ID_INVALID == 0,
            rtr_allowed: value & COB_ID_NO_RTR == 0,
        })
    }

    /// The 32-bit entry value.
    pub const fn to_u32(self) -> u32 {
        let mut value = self.id as u32 & 0x7FF;
        if !self.valid {
            value |= COB_ID_INVALID;
        }
        if !self.rtr_allowed {
            value |= COB_ID_NO_RTR;
        }
        value
    }
}

/// A COB-ID entry this PDO engine cannot use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CobIdError {
    /// Bit 29 is set: a 29-bit identifier; only 11-bit ones are supported.
    Extended(u32),
    /// Bits 11 to 28 are not all zero, but bit 29 is clear.
    OutOfRange(u32),
}

impl fmt::Display for CobIdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CobIdError::Extended(v) => write!(
                f,
                "COB-ID {v:#010X} has bit 29 set (a 29-bit identifier); only 11-bit identifiers are supported"
            ),
            CobIdError::OutOfRange(v) => write!(
                f,
                "COB-ID {v:#010X} has bits set between bit 11 and bit 28; an 11-bit identifier ends at 0x7FF"
            ),
        }
    }
}

impl core::error::Error for CobIdError {}

/// The default COB-ID of `P` for `node`, read: `None` when the generated
/// struct has none or it is not a valid 11-bit COB-ID entry.
pub fn default_cob_id<P: od::Pdo>(node: od::NodeId) -> Option<CobId> {
    P::default_cob_id(node).and_then(|v| CobId::parse(v).ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cob_id_bits_follow_cia_301() {
        assert_eq!(
            CobId::parse(0x0000_01A0),
            Ok(CobId {
                id: 0x1A0,
                valid: true,
                rtr_allowed: true
            })
        );
        assert_eq!(
            CobId::parse(0xC000_0220),
            Ok(CobId {
                id: 0x220,
                valid: false,
                rtr_allowed: false
            })
        );
        assert_eq!(
            CobId::parse(0x2000_0180),
            Err(CobIdError::Extended(0x2000_0180))
        );
        assert_eq!(
            CobId::parse(0x0000_0800),
            Err(CobIdError::OutOfRange(0x0000_0800))
        );
        assert_eq!(
            CobId::parse(0x1000_0001),
            Err(CobIdError::OutOfRange(0x1000_0001))
        );
        for v in [0x0000_01A0, 0x8000_0220, 0x4000_07FF, 0xC000_0000] {
            assert_eq!(CobId::parse(v).map(CobId::to_u32), Ok(v));
        }
    }
}
