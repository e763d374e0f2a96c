//! From upload data to an entry's typed value, with what real devices send:
//! one rule for every driver's typed reads (blocking, tokio, the masters).
//!
//! - Data of the type's size is the value.
//! - An expedited response that indicated no size (command `0x42`) carries
//!   4 bytes; a 1-, 2- or 3-byte value is their leading bytes, the rest is
//!   padding. Nothing is reported: this is CiA 301.
//! - Data that the server *said* is longer than the type (many devices
//!   answer `0x43`, 4 bytes, for an UNSIGNED8) is a device's mistake: the
//!   leading bytes are taken and a [`LengthNote`] says so, unless
//!   [`ClientConfig::strict_lengths`](super::client::ClientConfig::strict_lengths)
//!   asks for a length error instead.
//! - Data shorter than the type is always a length error.

use core::fmt;

use crate::od::{self, DataType, Entry, Scalar, ValueError};

/// A typed read took the leading bytes of a value the server announced as
/// longer than the entry's data type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LengthNote {
    pub index: u16,
    pub sub: u8,
    /// The entry's data type.
    pub data_type: DataType,
    /// The bytes the server sent.
    pub received: usize,
}

impl LengthNote {
    /// The size of the data type, in bytes.
    pub const fn expected(&self) -> usize {
        match self.data_type.size() {
            Some(size) => size,
            None => 0,
        }
    }
}

impl fmt::Display for LengthNote {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let expected = self.expected();
        let what = if expected == 1 {
            "byte was"
        } else {
            "bytes were"
        };
        write!(
            f,
            "{:#06X} sub {}: the server sent {} bytes for a {:?} of {expected}; the leading {what} taken",
            self.index, self.sub, self.received, self.data_type
        )
    }
}

/// The value of entry `E` (at sub-index `sub`) from the data of an upload;
/// `padded` is [`ClientEvent::Uploaded::padded`](super::client::ClientEvent).
/// With `strict`, data longer than the type is a length error.
pub fn decode_upload<E>(
    sub: u8,
    data: &[u8],
    padded: bool,
    strict: bool,
) -> Result<(E::Value, Option<LengthNote>), ValueError>
where
    E: Entry,
    E::Access: od::Read,
    E::Value: Scalar,
{
    let size = E::DATA_TYPE
        .size()
        .ok_or(ValueError::NotFixedSize(E::DATA_TYPE))?;
    if data.len() <= size || padded {
        let lead = data.get(..size).unwrap_or(data);
        return Ok((od::decode_value::<E>(lead)?, None));
    }
    if strict {
        return Err(ValueError::Length {
            expected: size,
            actual: data.len(),
        });
    }
    let note = LengthNote {
        index: E::INDEX,
        sub,
        data_type: E::DATA_TYPE,
        received: data.len(),
    };
    let lead = data.get(..size).unwrap_or(data);
    Ok((od::decode_value::<E>(lead)?, Some(note)))
}

/// Where a driver keeps the notes of its typed reads until the caller takes
/// them: the newest [`NOTES_KEPT`], older ones dropped.
pub const NOTES_KEPT: usize = 64;

/// Appends `note` to `notes`, dropping the oldest beyond [`NOTES_KEPT`].
#[cfg(feature = "std")]
pub(crate) fn keep<T>(notes: &mut alloc::collections::VecDeque<T>, note: T) {
    if notes.len() >= NOTES_KEPT {
        notes.pop_front();
    }
    notes.push_back(note);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::access;

    /// A read-only entry at (`$index`, 0) of `$ty`.
    macro_rules! ro_entry {
        ($name:ident, $index:literal, $ty:ident, $value:ty) => {
            struct $name;
            impl Entry for $name {
                const INDEX: u16 = $index;
                const SUBINDEX: u8 = 0;
                const NAME: &'static str = stringify!($name);
                const DATA_TYPE: DataType = DataType::$ty;
                const PDO_MAPPABLE: bool = false;
                type Access = access::Ro;
                type Value = $value;
            }
        };
    }

    ro_entry!(U8Entry, 0x2000, Unsigned8, u8);
    ro_entry!(I16Entry, 0x2001, Integer16, i16);
    ro_entry!(U24Entry, 0x2002, Unsigned24, u32);

    #[test]
    fn padded_expedited_data_gives_its_leading_bytes_silently() {
        let four = [0x05, 0xFF, 0x12, 0x34];
        assert_eq!(
            decode_upload::<U8Entry>(0, &four, true, true),
            Ok((5, None))
        );
        assert_eq!(
            decode_upload::<I16Entry>(0, &four, true, true),
            Ok((-251, None))
        );
        assert_eq!(
            decode_upload::<U24Entry>(0, &four, true, true),
            Ok((0x12_FF05, None))
        );
    }

    #[test]
    fn announced_longer_data_is_taken_with_a_note_or_refused_when_strict() {
        let four = [0x07, 0, 0, 0];
        let note = LengthNote {
            index: 0x2000,
            sub: 0,
            data_type: DataType::Unsigned8,
            received: 4,
        };
        assert_eq!(
            decode_upload::<U8Entry>(0, &four, false, false),
            Ok((7, Some(note)))
        );
        assert_eq!(
            note.to_string(),
            "0x2000 sub 0: the server sent 4 bytes for a Unsigned8 of 1; the leading byte was taken"
        );
        assert_eq!(
            decode_upload::<U8Entry>(0, &four, false, true),
            Err(ValueError::Length {
                expected: 1,
                actual: 4
            })
        );
    }

    #[test]
    fn short_data_is_an_error_either_way() {
        for padded in [false, true] {
            assert_eq!(
                decode_upload::<I16Entry>(0, &[1], padded, false),
                Err(ValueError::Length {
                    expected: 2,
                    actual: 1
                })
            );
        }
    }
}
