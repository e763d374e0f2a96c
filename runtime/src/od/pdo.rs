//! What generated default-PDO structs implement: [`Pdo`], its direction and
//! its length error.

use core::fmt;

use super::{NodeId, standard};

/// Whether a PDO is received or transmitted by the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PdoDirection {
    /// Received by the device (the master sends it).
    Rpdo,
    /// Transmitted by the device.
    Tpdo,
}

/// A PDO frame had the wrong length for its mapping.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PdoLengthError {
    pub expected: usize,
    pub actual: usize,
}

impl fmt::Display for PdoLengthError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "PDO has {} data bytes; its mapping needs exactly {}",
            self.actual, self.expected
        )
    }
}

impl core::error::Error for PdoLengthError {}

/// A generated default-PDO struct.
pub trait Pdo: Sized {
    const DIRECTION: PdoDirection;
    /// 1-based PDO number (TPDO1 = 1).
    const NUMBER: u16;
    /// Communication parameter object (0x1400.. or 0x1800..).
    const COMMUNICATION_INDEX: u16;
    /// Mapping parameter object (0x1600.. or 0x1A00..).
    const MAPPING_INDEX: u16;
    /// Data length in bytes.
    const LEN: usize;
    /// The mapping parameter's entries in order (`index << 16 | subindex <<
    /// 8 | bits`), dummy entries included: what a PDO configuration writes
    /// to sub 1.. of [`Pdo::MAPPING_INDEX`].
    const MAPPING: &'static [u32];
    /// The COB-ID entry's default for a node (sub 1 of
    /// [`Pdo::COMMUNICATION_INDEX`]), when the source gives one.
    fn default_cob_id(node_id: NodeId) -> Option<standard::PdoCobId>;
    /// Decodes a frame's data; it must be exactly [`Pdo::LEN`] bytes.
    fn decode(data: &[u8]) -> Result<Self, PdoLengthError>;
    /// Encodes into the first [`Pdo::LEN`] bytes of `out`; returns that length.
    fn encode_into(&self, out: &mut [u8; 8]) -> usize;
}
