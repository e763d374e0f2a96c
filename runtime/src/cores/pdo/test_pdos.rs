//! Hand-written PDO structs (what generated code implements) that the PDO
//! cores' tests share.

use crate::od::standard::PdoCobId;
use crate::od::{self, NodeId, PdoDirection, PdoLengthError};

/// PDO 1 of a drive, a 16-bit word and a 32-bit signed value (6 bytes):
/// as an RPDO ([`Command`]) the control word and target position, as a
/// TPDO ([`Status`]) the status word and actual position.
#[derive(Debug, PartialEq)]
pub(crate) struct WordAndLong<const RPDO: bool> {
    pub(crate) word: u16,
    pub(crate) long: i32,
}

/// RPDO1: control word (0x6040) and target position (0x607A), COB-ID
/// 0x200 + node.
pub(crate) type Command = WordAndLong<true>;
/// TPDO1: status word (0x6041) and actual position (0x6064), COB-ID
/// 0x180 + node, no RTR.
pub(crate) type Status = WordAndLong<false>;

impl<const RPDO: bool> od::Pdo for WordAndLong<RPDO> {
    const DIRECTION: PdoDirection = if RPDO {
        PdoDirection::Rpdo
    } else {
        PdoDirection::Tpdo
    };
    const NUMBER: u16 = 1;
    const COMMUNICATION_INDEX: u16 = if RPDO { 0x1400 } else { 0x1800 };
    const MAPPING_INDEX: u16 = if RPDO { 0x1600 } else { 0x1A00 };
    const LEN: usize = 6;
    const MAPPING: &'static [u32] = if RPDO {
        &[0x6040_0010, 0x607A_0020]
    } else {
        &[0x6041_0010, 0x6064_0020]
    };
    fn default_cob_id(node: NodeId) -> Option<PdoCobId> {
        let base = if RPDO { 0x200 } else { 0x4000_0180 };
        Some(PdoCobId(base + u32::from(node.get())))
    }
    fn decode(data: &[u8]) -> Result<Self, PdoLengthError> {
        match *data {
            [a, b, c, d, e, f] => Ok(WordAndLong {
                word: u16::from_le_bytes([a, b]),
                long: i32::from_le_bytes([c, d, e, f]),
            }),
            _ => Err(PdoLengthError {
                expected: 6,
                actual: data.len(),
            }),
        }
    }
    fn encode_into(&self, out: &mut [u8; 8]) -> usize {
        out[..2].copy_from_slice(&self.word.to_le_bytes());
        out[2..6].copy_from_slice(&self.long.to_le_bytes());
        6
    }
}
