//! CiA 301 basic data types (codes 0x0001–0x001B) as the IR names them.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

/// A CiA 301 data type. Codes outside the standard table are kept as
/// [`DataType::Other`] so that a device-specific type (DEFTYPE/DEFSTRUCT or a
/// vendor code) survives reading; the reader reports it as a diagnostic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "SCREAMING_SNAKE_CASE"))]
pub enum DataType {
    Boolean,
    Integer8,
    Integer16,
    Integer32,
    Unsigned8,
    Unsigned16,
    Unsigned32,
    Real32,
    VisibleString,
    OctetString,
    UnicodeString,
    TimeOfDay,
    TimeDifference,
    Domain,
    Integer24,
    Real64,
    Integer40,
    Integer48,
    Integer56,
    Integer64,
    Unsigned24,
    Unsigned40,
    Unsigned48,
    Unsigned56,
    Unsigned64,
    /// A code that is not one of the standard basic types above.
    Other(u16),
}

/// How a value of a data type is written in the IR.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ValueKind {
    /// Integers, BOOLEAN and the TIME types (kept as their raw integer).
    Integer {
        signed: bool,
        bits: u32,
    },
    Real {
        bits: u32,
    },
    Text,
    Bytes,
}

impl DataType {
    /// The data type for a CiA 301 code; unknown codes give [`DataType::Other`].
    pub fn from_code(code: u16) -> DataType {
        use DataType::*;
        match code {
            0x0001 => Boolean,
            0x0002 => Integer8,
            0x0003 => Integer16,
            0x0004 => Integer32,
            0x0005 => Unsigned8,
            0x0006 => Unsigned16,
            0x0007 => Unsigned32,
            0x0008 => Real32,
            0x0009 => VisibleString,
            0x000A => OctetString,
            0x000B => UnicodeString,
            0x000C => TimeOfDay,
            0x000D => TimeDifference,
            0x000F => Domain,
            0x0010 => Integer24,
            0x0011 => Real64,
            0x0012 => Integer40,
            0x0013 => Integer48,
            0x0014 => Integer56,
            0x0015 => Integer64,
            0x0016 => Unsigned24,
            0x0018 => Unsigned40,
            0x0019 => Unsigned48,
            0x001A => Unsigned56,
            0x001B => Unsigned64,
            other => Other(other),
        }
    }

    /// The CiA 301 code of this type.
    pub fn code(self) -> u16 {
        use DataType::*;
        match self {
            Boolean => 0x0001,
            Integer8 => 0x0002,
            Integer16 => 0x0003,
            Integer32 => 0x0004,
            Unsigned8 => 0x0005,
            Unsigned16 => 0x0006,
            Unsigned32 => 0x0007,
            Real32 => 0x0008,
            VisibleString => 0x0009,
            OctetString => 0x000A,
            UnicodeString => 0x000B,
            TimeOfDay => 0x000C,
            TimeDifference => 0x000D,
            Domain => 0x000F,
            Integer24 => 0x0010,
            Real64 => 0x0011,
            Integer40 => 0x0012,
            Integer48 => 0x0013,
            Integer56 => 0x0014,
            Integer64 => 0x0015,
            Unsigned24 => 0x0016,
            Unsigned40 => 0x0018,
            Unsigned48 => 0x0019,
            Unsigned56 => 0x001A,
            Unsigned64 => 0x001B,
            Other(code) => code,
        }
    }

    /// The CiA 301 name, e.g. `UNSIGNED16`.
    pub fn name(self) -> &'static str {
        use DataType::*;
        match self {
            Boolean => "BOOLEAN",
            Integer8 => "INTEGER8",
            Integer16 => "INTEGER16",
            Integer32 => "INTEGER32",
            Unsigned8 => "UNSIGNED8",
            Unsigned16 => "UNSIGNED16",
            Unsigned32 => "UNSIGNED32",
            Real32 => "REAL32",
            VisibleString => "VISIBLE_STRING",
            OctetString => "OCTET_STRING",
            UnicodeString => "UNICODE_STRING",
            TimeOfDay => "TIME_OF_DAY",
            TimeDifference => "TIME_DIFFERENCE",
            Domain => "DOMAIN",
            Integer24 => "INTEGER24",
            Real64 => "REAL64",
            Integer40 => "INTEGER40",
            Integer48 => "INTEGER48",
            Integer56 => "INTEGER56",
            Integer64 => "INTEGER64",
            Unsigned24 => "UNSIGNED24",
            Unsigned40 => "UNSIGNED40",
            Unsigned48 => "UNSIGNED48",
            Unsigned56 => "UNSIGNED56",
            Unsigned64 => "UNSIGNED64",
            Other(_) => "unknown",
        }
    }

    /// How values of this type are represented, or `None` for an unknown type.
    pub fn value_kind(self) -> Option<ValueKind> {
        use DataType::*;
        let int = |signed, bits| Some(ValueKind::Integer { signed, bits });
        match self {
            Boolean => int(false, 1),
            Integer8 => int(true, 8),
            Integer16 => int(true, 16),
            Integer24 => int(true, 24),
            Integer32 => int(true, 32),
            Integer40 => int(true, 40),
            Integer48 => int(true, 48),
            Integer56 => int(true, 56),
            Integer64 => int(true, 64),
            Unsigned8 => int(false, 8),
            Unsigned16 => int(false, 16),
            Unsigned24 => int(false, 24),
            Unsigned32 => int(false, 32),
            Unsigned40 => int(false, 40),
            Unsigned48 => int(false, 48),
            Unsigned56 => int(false, 56),
            Unsigned64 => int(false, 64),
            // TIME_OF_DAY and TIME_DIFFERENCE are 48-bit structures (ms + days);
            // their EDS values are written as one integer.
            TimeOfDay | TimeDifference => int(false, 48),
            Real32 => Some(ValueKind::Real { bits: 32 }),
            Real64 => Some(ValueKind::Real { bits: 64 }),
            VisibleString | UnicodeString => Some(ValueKind::Text),
            OctetString | Domain => Some(ValueKind::Bytes),
            Other(_) => None,
        }
    }

    /// The inclusive range of an integer type, or `None` for other types.
    pub fn integer_range(self) -> Option<(i128, i128)> {
        match self.value_kind()? {
            ValueKind::Integer { signed: true, bits } => {
                Some((-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1))
            }
            ValueKind::Integer {
                signed: false,
                bits,
            } => Some((0, (1i128 << bits) - 1)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_and_reserved_codes_are_other() {
        for code in 0..=0x40u16 {
            let t = DataType::from_code(code);
            assert_eq!(t.code(), code);
            let standard = (1..=0x1B).contains(&code) && code != 0x0E && code != 0x17;
            assert_eq!(!matches!(t, DataType::Other(_)), standard, "code {code:#x}");
        }
    }

    #[test]
    fn ranges() {
        assert_eq!(
            DataType::Integer24.integer_range(),
            Some((-(1 << 23), (1 << 23) - 1))
        );
        assert_eq!(
            DataType::Unsigned64.integer_range(),
            Some((0, u64::MAX as i128))
        );
        assert_eq!(DataType::Boolean.integer_range(), Some((0, 1)));
    }
}
