//! The PDO codec: how the fields of a PDO sit in its data bytes. One
//! implementation for every PDO struct: the generator's default-PDO structs
//! and `#[derive(Pdo)]` structs both expand to calls of these functions
//! with constant offsets and widths, which the compiler folds into the
//! loads, shifts and masks a hand-written codec has: a field of 8, 16 or 32
//! bits at a byte offset is read from its own bytes (`from_le_bytes` of
//! them), any other from the whole data word. The decoder of recorded
//! traces reads fields with [`field`], the same rule with offsets known at
//! run time.
//!
//! The data of a PDO (at most 8 bytes) is one little-endian `u64` word:
//! byte 0 holds bits 0 to 7. A field of `width` bits at `offset` holds the
//! low `width` bits of its value's raw form ([`Scalar::to_raw`]); reading it
//! back sign-extends from `width` for a signed data type, which is the form
//! [`Scalar::from_raw`] takes. Gaps (dummy entries) read as nothing and are
//! written as zeros.
//!
//! [`Scalar::to_raw`]: crate::od::Scalar::to_raw
//! [`Scalar::from_raw`]: crate::od::Scalar::from_raw

use crate::od::{DataType, PdoLengthError};

/// The data of a frame, checked to be exactly `LEN` bytes (`LEN` at most
/// 8, checked at compile time); [`get`] reads its fields.
#[inline(always)]
pub fn load<const LEN: usize>(data: &[u8]) -> Result<&[u8; LEN], PdoLengthError> {
    const { assert!(LEN <= 8, "a PDO has at most 8 data bytes") };
    match <&[u8; LEN]>::try_from(data) {
        Ok(bytes) => Ok(bytes),
        Err(_) => Err(PdoLengthError {
            expected: LEN,
            actual: data.len(),
        }),
    }
}

/// The data as one little-endian word (byte 0 in bits 0 to 7).
#[inline(always)]
pub fn word<const LEN: usize>(bytes: &[u8; LEN]) -> u64 {
    // Byte by byte with constant indices: the compiler builds the word
    // with the loads a hand-written `from_le_bytes([b[0], .., 0])` has.
    let byte = |i: usize| if i < LEN { bytes[i] } else { 0 };
    u64::from_le_bytes([
        byte(0),
        byte(1),
        byte(2),
        byte(3),
        byte(4),
        byte(5),
        byte(6),
        byte(7),
    ])
}

/// The data of a frame of any length as one little-endian word (its first
/// 8 bytes; missing bytes read as zero), for layouts known only at run
/// time ([`field`]).
pub fn word_of(data: &[u8]) -> u64 {
    let mut bytes = [0u8; 8];
    let n = data.len().min(8);
    bytes[..n].copy_from_slice(&data[..n]);
    u64::from_le_bytes(bytes)
}

/// The field of `width` bits at `offset` in the data, in the raw form
/// `Scalar::from_raw` takes (see [`field`]). A field of 8, 16 or 32 bits at
/// a byte offset is read from its own bytes, as a hand-written decoder
/// reads it; any other from the whole word. Both give the same value.
#[inline(always)]
pub fn get<const LEN: usize>(d: &[u8; LEN], offset: u32, width: u32, signed: bool) -> u64 {
    let i = (offset / 8) as usize;
    let aligned = offset.is_multiple_of(8) && i + (width / 8) as usize <= LEN;
    match (aligned, width, signed) {
        (true, 8, false) => u64::from(d[i]),
        (true, 8, true) => d[i] as i8 as u64,
        (true, 16, false) => u64::from(u16::from_le_bytes([d[i], d[i + 1]])),
        (true, 16, true) => i16::from_le_bytes([d[i], d[i + 1]]) as u64,
        (true, 32, false) => u64::from(u32::from_le_bytes([d[i], d[i + 1], d[i + 2], d[i + 3]])),
        (true, 32, true) => i32::from_le_bytes([d[i], d[i + 1], d[i + 2], d[i + 3]]) as u64,
        _ => field(word(d), offset, width, signed),
    }
}

/// The first `LEN` bytes of a word (`LEN` at most 8, checked at compile
/// time).
#[inline(always)]
pub fn store<const LEN: usize>(word: u64) -> [u8; LEN] {
    const { assert!(LEN <= 8, "a PDO has at most 8 data bytes") };
    let mut out = [0u8; LEN];
    out.copy_from_slice(&word.to_le_bytes()[..LEN]);
    out
}

/// The mask of the low `width` bits (1 to 64).
#[inline(always)]
pub const fn mask(width: u32) -> u64 {
    if width >= 64 {
        u64::MAX
    } else {
        (1u64 << width) - 1
    }
}

/// The field of `width` bits at `offset` of a PDO's data as one word, in
/// the raw form `Scalar::from_raw` takes: sign-extended from `width` when
/// `signed`. For a layout known only at run time; [`get`] is this with a
/// layout the compiler knows.
#[inline(always)]
pub const fn field(word: u64, offset: u32, width: u32, signed: bool) -> u64 {
    let bits = (word >> offset) & mask(width);
    if signed && width < 64 {
        let shift = 64 - width;
        (((bits << shift) as i64) >> shift) as u64
    } else {
        bits
    }
}

/// `word` with the low `width` bits of `raw` put at `offset` (the bits
/// there must be zero: every field is put once into a zeroed word).
#[inline(always)]
pub const fn put(word: u64, offset: u32, width: u32, raw: u64) -> u64 {
    word | (raw & mask(width)) << offset
}

/// The number of data bytes for `bits` mapped bits.
pub const fn len(bits: u32) -> usize {
    bits.div_ceil(8) as usize
}

/// The width of a mapped entry of `data_type`: `bits` when it is given
/// (a mapping shorter than the type), else the type's size; 0 for a type
/// without a fixed size (which no PDO maps).
pub const fn width(data_type: DataType, bits: Option<u32>) -> u32 {
    match (bits, data_type.size()) {
        (Some(bits), _) => bits,
        (None, Some(bytes)) => bytes as u32 * 8,
        (None, None) => 0,
    }
}

/// A mapping parameter's entry: `index << 16 | subindex << 8 | bits`.
pub const fn mapping_entry(index: u16, subindex: u8, bits: u32) -> u32 {
    (index as u32) << 16 | (subindex as u32) << 8 | bits
}

/// The dummy mapping entries (CiA 301 objects 0x0001 to 0x0007) that fill
/// a gap of `bits` bits: as many UNSIGNED32 (0x0007), UNSIGNED16 (0x0006),
/// UNSIGNED8 (0x0005) and BOOLEAN (0x0001) dummies as fit, in that order;
/// the entries are written into `out` and their number returned.
pub const fn dummy_entries(mut bits: u32, out: &mut [u32; 64]) -> usize {
    let mut n = 0;
    let sizes: [(u16, u32); 4] = [(0x0007, 32), (0x0006, 16), (0x0005, 8), (0x0001, 1)];
    let mut k = 0;
    while k < sizes.len() {
        let (index, size) = sizes[k];
        while bits >= size && n < 64 {
            out[n] = mapping_entry(index, 0, size);
            n += 1;
            bits -= size;
        }
        k += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_round_trip_at_any_offset() {
        let word = put(put(0, 0, 16, 0x1234), 16, 4, 0xFF);
        assert_eq!(word, 0x000F_1234);
        assert_eq!(field(word, 0, 16, false), 0x1234);
        assert_eq!(field(word, 16, 4, false), 0xF);
        // Signed: sign-extended from the field's width.
        assert_eq!(field(word, 16, 4, true) as i64, -1);
        assert_eq!(field(put(0, 3, 64 - 3, u64::MAX), 3, 61, true) as i64, -1);
        assert_eq!(field(u64::MAX, 0, 64, true), u64::MAX);
    }

    /// `get` reads whole-byte fields from their bytes and the others from
    /// the word: the same values as `field` for every offset and width.
    #[test]
    fn get_is_field_of_the_word() {
        let bytes = [0x81, 0xF2, 0x03, 0x94, 0xA5, 0x06, 0xB7, 0xC8];
        let data = load::<8>(&bytes).unwrap();
        let w = u64::from_le_bytes(bytes);
        assert_eq!(word(data), w);
        assert_eq!(word_of(&bytes), w);
        assert_eq!(word_of(&bytes[..3]), 0x03_F281);
        for offset in 0..64 {
            for width in 1..=64 - offset {
                for signed in [false, true] {
                    let (ours, theirs) = (
                        get(data, offset, width, signed),
                        field(w, offset, width, signed),
                    );
                    assert_eq!(
                        ours, theirs,
                        "offset {offset}, width {width}, signed {signed}"
                    );
                }
            }
        }
        let short = load::<3>(&bytes[..3]).unwrap();
        assert_eq!(word(short), 0x03_F281);
        assert_eq!(get(short, 8, 16, true), field(0x03_F281, 8, 16, true));
        assert_eq!(get(short, 16, 16, false), 0x03);
    }

    #[test]
    fn bytes_are_exactly_len() {
        assert_eq!(load::<3>(&[1, 2, 3]).map(word), Ok(0x0003_0201));
        assert_eq!(
            load::<3>(&[1, 2]),
            Err(PdoLengthError {
                expected: 3,
                actual: 2
            })
        );
        assert_eq!(store::<3>(0x0003_0201), [1, 2, 3]);
        assert_eq!(store::<8>(u64::MAX), [0xFF; 8]);
        assert_eq!(load::<0>(&[]).map(word), Ok(0));
    }

    #[test]
    fn gaps_are_dummy_entries() {
        let mut out = [0u32; 64];
        let n = dummy_entries(57, &mut out);
        assert_eq!(
            out[..n],
            [0x0007_0020, 0x0006_0010, 0x0005_0008, 0x0001_0001]
        );
        assert_eq!(dummy_entries(0, &mut out), 0);
        assert_eq!(width(DataType::Integer24, None), 24);
        assert_eq!(width(DataType::Unsigned32, Some(4)), 4);
        assert_eq!(len(57), 8);
    }
}
