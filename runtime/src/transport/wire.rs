//! The length of a classic CAN frame on the wire, bit by bit (ISO 11898-1
//! frame layout), for the bit-time model of the virtual bus.
//!
//! A base-format (11-bit) frame is, in order: SOF (1), identifier (11), RTR
//! (1), IDE (1), r0 (1), DLC (4), data (8 per byte; none in remote frames),
//! CRC sequence (15), CRC delimiter (1), ACK slot (1), ACK delimiter (1) and
//! EOF (7), followed by the intermission (3) before the next frame. An
//! extended-format (29-bit) frame has, after SOF: identifier A (11), SRR (1),
//! IDE (1), identifier B (18), RTR (1), r1 (1), r0 (1), then DLC onwards as
//! above. From SOF to the end of the CRC sequence the transmitter inserts a
//! complementary stuff bit after every five equal bits (a stuff bit counts
//! towards the next run); the fields from the CRC delimiter on are not
//! stuffed.

use crate::{CanId, Frame};

/// The generator polynomial of the CAN CRC-15 (x^15 + x^14 + x^10 + x^8 +
/// x^7 + x^4 + x^3 + 1), without its x^15 term.
pub const CRC15_POLY: u16 = 0x4599;

/// Bits after the CRC sequence that are never stuffed: CRC delimiter, ACK
/// slot, ACK delimiter and end of frame.
pub const TRAILER_BITS: u32 = 1 + 1 + 1 + 7;

/// The bus idle time between two frames.
pub const INTERMISSION_BITS: u32 = 3;

/// Where the bits of one frame come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WireLength {
    /// Bits from SOF to the end of the CRC sequence before stuffing.
    pub unstuffed: u32,
    /// Stuff bits the transmitter inserts into that part.
    pub stuff_bits: u32,
    /// The CRC-15 sequence the frame carries.
    pub crc: u16,
}

impl WireLength {
    /// The bits the frame occupies on the bus, intermission included (what
    /// bus-load figures count).
    pub const fn total(&self) -> u32 {
        self.unstuffed + self.stuff_bits + TRAILER_BITS + INTERMISSION_BITS
    }
}

/// Updates a CAN CRC-15 register with one bit.
const fn crc15_step(crc: u16, bit: bool) -> u16 {
    let feedback = bit != (crc & 0x4000 != 0);
    let shifted = (crc << 1) & 0x7FFF;
    if feedback {
        shifted ^ CRC15_POLY
    } else {
        shifted
    }
}

/// The CAN CRC-15 of a bit sequence (first bit first; register starts at 0).
pub fn crc15(bits: impl IntoIterator<Item = bool>) -> u16 {
    bits.into_iter().fold(0, crc15_step)
}

/// Follows the transmitted bits: counts them, the stuff bits inserted, and
/// the CRC of the bits it is told to cover.
struct Transmitter {
    crc: u16,
    last: bool,
    run: u32,
    bits: u32,
    stuff_bits: u32,
}

impl Transmitter {
    const fn new() -> Transmitter {
        // The idle bus is recessive (1); SOF (0) starts the first run.
        Transmitter {
            crc: 0,
            last: true,
            run: 0,
            bits: 0,
            stuff_bits: 0,
        }
    }

    fn bit(&mut self, bit: bool, in_crc: bool) {
        if in_crc {
            self.crc = crc15_step(self.crc, bit);
        }
        self.bits += 1;
        if bit == self.last {
            self.run += 1;
        } else {
            self.last = bit;
            self.run = 1;
        }
        if self.run == 5 {
            // The stuff bit is the complement and starts the next run.
            self.stuff_bits += 1;
            self.last = !bit;
            self.run = 1;
        }
    }

    /// The low `count` bits of `value`, most significant first.
    fn field(&mut self, value: u32, count: u32, in_crc: bool) {
        for shift in (0..count).rev() {
            self.bit((value >> shift) & 1 != 0, in_crc);
        }
    }
}

/// The bit layout of `frame` on the wire: its unstuffed length, the stuff
/// bits it really gets, and its CRC.
pub fn wire_length(frame: &Frame) -> WireLength {
    let mut tx = Transmitter::new();
    tx.bit(false, true); // SOF
    let rtr = frame.is_remote();
    match frame.id() {
        CanId::Standard(id) => {
            tx.field(u32::from(id), 11, true);
            tx.bit(rtr, true);
            tx.bit(false, true); // IDE: base format
            tx.bit(false, true); // r0
        }
        CanId::Extended(id) => {
            tx.field(id >> 18, 11, true); // identifier A
            tx.bit(true, true); // SRR
            tx.bit(true, true); // IDE: extended format
            tx.field(id, 18, true); // identifier B
            tx.bit(rtr, true);
            tx.bit(false, true); // r1
            tx.bit(false, true); // r0
        }
    }
    tx.field(frame.len() as u32, 4, true); // DLC
    for byte in frame.data() {
        tx.field(u32::from(*byte), 8, true);
    }
    let crc = tx.crc;
    tx.field(u32::from(crc), 15, false);
    WireLength {
        unstuffed: tx.bits,
        stuff_bits: tx.stuff_bits,
        crc,
    }
}

/// The bits `frame` occupies on the bus, stuff bits and intermission
/// included.
pub fn frame_bits(frame: &Frame) -> u32 {
    wire_length(frame).total()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bits of `bytes`, most significant first.
    fn bits_of(bytes: &[u8]) -> impl Iterator<Item = bool> + '_ {
        bytes
            .iter()
            .flat_map(|b| (0..8).rev().map(move |s| (b >> s) & 1 != 0))
    }

    #[test]
    fn crc15_agrees_with_the_crc_crate() {
        // An independent implementation: the `crc` crate's CRC-15/CAN works
        // on whole bytes, and leading zero bits do not change a CRC whose
        // register starts at 0.
        let reference = crc::Crc::<u16>::new(&crc::CRC_15_CAN);
        for msg in [
            &b"123456789"[..],
            &[0x00],
            &[0xFF, 0x01],
            &[0x70, 0x10, 0x05],
        ] {
            assert_eq!(crc15(bits_of(msg)), reference.checksum(msg), "{msg:02X?}");
        }
        assert_eq!(crc15(bits_of(b"123456789")), 0x059E); // the catalog's check value
    }

    #[test]
    fn heartbeat_frame_by_hand() {
        // 0x701#05 (heartbeat of node 1, operational).
        // Unstuffed, SOF to data (27 bits):
        //   SOF 0 | ID 111 0000 0001 | RTR 0 IDE 0 r0 0 | DLC 0001 | 0000 0101
        // CRC-15 of those 27 bits: 0x4D0E = 100 1101 0000 1110 (checked below
        // against the `crc` crate: 5 zero bits in front make 4 whole bytes,
        // 0x03 0x80 0x81 0x05, and do not change the CRC).
        // Stuffing, SOF..CRC (42 bits), stuff bits in brackets:
        //   0 111 00000[1] 00 1 000 00[1] 0 1 00000[1] 101 | CRC 100110100001110
        //   - ID bits 4..8 are five 0s: stuff 1; two more 0s, the last ID bit 1;
        //   - RTR, IDE, r0 and DLC bits 3..2 are five 0s: stuff 1;
        //   - DLC bits 1..0 are 01; data bits 7..3 are five 0s: stuff 1;
        //   - the rest (101, then the CRC) never has five equal bits in a
        //     row (the stuff bit 1 before "101" makes a run of two 1s).
        // Total: 42 + 3 stuff + 10 (CRC delimiter, ACK slot and delimiter,
        // EOF) + 3 intermission = 58 bits.
        let frame = Frame::new(CanId::Standard(0x701), &[0x05]).unwrap();
        let reference = crc::Crc::<u16>::new(&crc::CRC_15_CAN);
        assert_eq!(reference.checksum(&[0x03, 0x80, 0x81, 0x05]), 0x4D0E);
        let wire = wire_length(&frame);
        assert_eq!(wire.crc, 0x4D0E);
        assert_eq!(wire.unstuffed, 42);
        assert_eq!(wire.stuff_bits, 3);
        assert_eq!(frame_bits(&frame), 58);
    }

    #[test]
    fn all_zero_frame_by_hand() {
        // 0x000#: SOF, ID, RTR, IDE, r0 and DLC are 19 zero bits, whose CRC
        // is 0, so SOF..CRC is 34 zeros: a stuff bit after every five (after
        // zeros 5, 10, 15, 20, 25 and 30; the last run is four) = 6 stuff
        // bits. 34 + 6 + 10 + 3 = 53.
        let frame = Frame::new(CanId::Standard(0), &[]).unwrap();
        let wire = wire_length(&frame);
        assert_eq!((wire.crc, wire.unstuffed, wire.stuff_bits), (0, 34, 6));
        assert_eq!(frame_bits(&frame), 53);
    }

    #[test]
    fn eight_byte_frames_lie_in_the_classic_bounds() {
        // Base format with 8 data bytes: 34 + 64 = 98 stuffed-region bits,
        // + 10 trailer + 3 intermission = 111 without any stuff bit. At most
        // one stuff bit per 4 bits after the first 5: (98 - 1) / 4 = 24, so
        // at most 135 (132 without the intermission).
        let mut seed = 0x1234_5678_9ABC_DEF0u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let fixed: [[u8; 8]; 4] = [[0; 8], [0xFF; 8], [0x55; 8], [0x0F; 8]];
        for i in 0..2000u32 {
            let data = match fixed.get(i as usize) {
                Some(d) => *d,
                None => next().to_le_bytes(),
            };
            let id = (next() & 0x7FF) as u16;
            let frame = Frame::new(CanId::Standard(id), &data).unwrap();
            let bits = frame_bits(&frame);
            assert!((111..=135).contains(&bits), "{frame}: {bits}");
        }
        // 0x555#55..55: SOF..data alternate except "RTR IDE r0 DLC" = 000
        // 1000 followed by data bit 0: runs of at most four, so no stuff
        // bit there; the CRC (0x1B04 = 001101100000100) adds one after its
        // five 0s: 98 + 1 + 10 + 3 = 112.
        let wire = wire_length(&Frame::new(CanId::Standard(0x555), &[0x55; 8]).unwrap());
        assert_eq!(wire.crc, 0x1B04);
        assert_eq!(
            (wire.unstuffed, wire.stuff_bits, wire.total()),
            (98, 1, 112)
        );
    }

    #[test]
    fn extended_and_remote_layouts() {
        // Extended: 1 + 11 + 1 + 1 + 18 + 1 + 2 + 4 = 39 bits before data,
        // + 15 CRC.
        let ext = Frame::new(CanId::Extended(0x1ABC_DEF0), &[1, 2, 3]).unwrap();
        assert_eq!(wire_length(&ext).unstuffed, 39 + 24 + 15);
        // A remote frame sends its DLC but no data.
        let rtr = Frame::remote(CanId::Standard(0x701), 1).unwrap();
        assert_eq!(wire_length(&rtr).unstuffed, 19 + 15);
    }
}
