//! The fields of SDO frames, read and written for both directions: the
//! address, the initiate and segment layouts, the block frames, the abort.

use super::{AbortCode, Initiate, ParseError};

pub(super) fn eight(data: &[u8]) -> Result<&[u8; 8], ParseError> {
    data.try_into().map_err(|_| ParseError::Length(data.len()))
}

pub(super) fn address(d: &[u8; 8]) -> (u16, u8) {
    (u16::from_le_bytes([d[1], d[2]]), d[3])
}

pub(super) fn put_address(d: &mut [u8; 8], index: u16, sub: u8) {
    d[1..3].copy_from_slice(&index.to_le_bytes());
    d[3] = sub;
}

pub(super) fn u32_at(d: &[u8; 8]) -> u32 {
    u32::from_le_bytes([d[4], d[5], d[6], d[7]])
}

pub(super) fn bit(b: u8, n: u8) -> bool {
    b >> n & 1 != 0
}

/// Initiate (download request or upload response): `e` bit 1, `s` bit 0,
/// `n` bits 3-2.
pub(super) fn parse_initiate(d: &[u8; 8]) -> Initiate {
    let b = d[0];
    let (expedited, sized) = (bit(b, 1), bit(b, 0));
    if expedited {
        let len = sized.then(|| 4 - (b >> 2 & 3));
        Initiate::Expedited {
            data: [d[4], d[5], d[6], d[7]],
            len,
        }
    } else {
        Initiate::Segmented {
            size: sized.then(|| u32_at(d)),
        }
    }
}

pub(super) fn put_initiate(d: &mut [u8; 8], data: &Initiate) {
    match *data {
        Initiate::Expedited { data, len: None } => {
            d[0] |= 0b10;
            d[4..8].copy_from_slice(&data);
        }
        Initiate::Expedited {
            data,
            len: Some(len),
        } => {
            let len = len.clamp(1, 4);
            d[0] |= (4 - len) << 2 | 0b11;
            d[4..8].copy_from_slice(&data);
            // Bytes beyond the length are zero on the bus.
            for b in &mut d[4 + len as usize..8] {
                *b = 0;
            }
        }
        Initiate::Segmented { size } => {
            if let Some(size) = size {
                d[0] |= 1;
                d[4..8].copy_from_slice(&size.to_le_bytes());
            }
        }
    }
}

/// Segment (download request or upload response): `t` bit 4, `n` bits 3-1,
/// `c` bit 0.
pub(super) fn parse_segment(d: &[u8; 8]) -> (bool, bool, [u8; 7], u8) {
    let b = d[0];
    let mut data = [0u8; 7];
    data.copy_from_slice(&d[1..8]);
    (bit(b, 4), bit(b, 0), data, 7 - (b >> 1 & 7))
}

pub(super) fn put_segment(d: &mut [u8; 8], toggle: bool, last: bool, data: &[u8; 7], len: u8) {
    let len = len.min(7);
    d[0] |= (toggle as u8) << 4 | (7 - len) << 1 | last as u8;
    d[1..1 + len as usize].copy_from_slice(&data[..len as usize]);
}

/// The size of a block initiate of the data's sender (block download
/// request, block upload response): bytes 4-7 when `s` (bit 1) is set.
pub(super) fn block_size_field(d: &[u8; 8]) -> Option<u32> {
    bit(d[0], 1).then(|| u32_at(d))
}

/// The end of a block transfer sent by the data's sender: unused bytes of
/// the last segment in bits 4-2, the CRC in bytes 1-2.
pub(super) fn block_end(d: &[u8; 8]) -> (u8, u16) {
    (d[0] >> 2 & 7, u16::from_le_bytes([d[1], d[2]]))
}

/// A block initiate of the data's sender: CRC flag bit 2, size flag bit 1,
/// the size in bytes 4-7.
pub(super) fn put_block_send(d: &mut [u8; 8], index: u16, sub: u8, crc: bool, size: Option<u32>) {
    d[0] = 0xC0 | (crc as u8) << 2 | (size.is_some() as u8) << 1;
    put_address(d, index, sub);
    d[4..8].copy_from_slice(&size.unwrap_or(0).to_le_bytes());
}

pub(super) fn put_block_end(d: &mut [u8; 8], unused: u8, crc: u16) {
    d[0] = 0xC1 | (unused & 7) << 2;
    d[1..3].copy_from_slice(&crc.to_le_bytes());
}

/// A block initiate of the data's receiver (block upload request, block
/// download response): CRC flag bit 2, the block size in byte 4.
pub(super) fn put_block_receive(d: &mut [u8; 8], index: u16, sub: u8, crc: bool, block_size: u8) {
    d[0] = 0xA0 | (crc as u8) << 2;
    put_address(d, index, sub);
    d[4] = block_size;
}

/// The receiver's acknowledgement of a sub-block: the last sequence number
/// received in byte 1, the next block size in byte 2.
pub(super) fn put_block_ack(d: &mut [u8; 8], ack_seq: u8, block_size: u8) {
    d[0] = 0xA2;
    d[1] = ack_seq;
    d[2] = block_size;
}

pub(super) fn put_abort(d: &mut [u8; 8], index: u16, sub: u8, code: AbortCode) {
    d[0] = 0x80;
    put_address(d, index, sub);
    d[4..8].copy_from_slice(&code.code().to_le_bytes());
}
