//! Why a value could not be decoded, encoded or parsed, and why a trace
//! could not be decoded.

use core::fmt;
use std::io;

use eds2rust::ir::DataType;
use eds2rust_runtime::trace::TraceError;

use crate::decoded::{Decoded, hex_bytes};

/// Why bytes are no value of a data type, a value cannot be sent as one,
/// or typed text does not parse as one.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ValueError {
    /// Fewer bytes than the data type has.
    TooShort {
        data_type: DataType,
        data: Vec<u8>,
        /// The size of the data type, in bytes.
        size: usize,
    },
    /// A BOOLEAN other than 0 or 1.
    NotBoolean { raw: i128 },
    /// A data type that is no basic type (no value to decode or encode).
    NotBasic { data_type: DataType },
    /// An integer outside the range of the data type.
    OutOfRange {
        data_type: DataType,
        value: i128,
        low: i128,
        high: i128,
    },
    /// A character that a VISIBLE_STRING cannot hold.
    NotVisible { character: char },
    /// A value of another kind than the data type's (text for an integer).
    WrongKind { data_type: DataType, value: Decoded },
    /// Typed text that is no BOOLEAN.
    NotBooleanText { text: String },
    /// Typed text that is no number, for a REAL.
    NotNumber { text: String },
    /// A physical value that falls between two steps of the entry's scale.
    NotWholeSteps {
        text: String,
        scale: f64,
        unit: Option<String>,
    },
    /// Typed text that is no integer, named value or physical value of the
    /// entry; `names` are the entry's named values (quoted).
    NotInteger {
        text: String,
        data_type: DataType,
        names: Vec<String>,
    },
    /// Typed text that is no hex bytes.
    NotHex { text: String },
}

impl fmt::Display for ValueError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ValueError::TooShort {
                data_type,
                data,
                size,
            } => write!(
                f,
                "{} bytes ({}) cannot be a {} ({size} bytes)",
                data.len(),
                hex_bytes(data),
                data_type.name()
            ),
            ValueError::NotBoolean { raw } => write!(f, "{raw:#04X} is not a BOOLEAN (0 or 1)"),
            ValueError::NotBasic { data_type } => {
                write!(f, "data type {:#06X} is not a basic type", data_type.code())
            }
            ValueError::OutOfRange {
                data_type,
                value,
                low,
                high,
            } => write!(
                f,
                "{value} is outside the range of {} ({low} to {high})",
                data_type.name()
            ),
            ValueError::NotVisible { character } => write!(
                f,
                "{character:?} is not a visible character (a VISIBLE_STRING holds 0x20 to 0x7E)"
            ),
            ValueError::WrongKind { data_type, value } => {
                write!(f, "{value:?} is not a value of {}", data_type.name())
            }
            ValueError::NotBooleanText { text } => {
                write!(f, "`{text}` is not a BOOLEAN (true, false, 1 or 0)")
            }
            ValueError::NotNumber { text } => write!(f, "`{text}` is not a number"),
            ValueError::NotWholeSteps { text, scale, unit } => write!(
                f,
                "{text} is not a whole number of steps of {scale} {}",
                unit.as_deref().unwrap_or("")
            ),
            ValueError::NotInteger {
                text,
                data_type,
                names,
            } => {
                write!(f, "`{text}` is not valid for {}", data_type.name())?;
                if !names.is_empty() {
                    write!(f, " (a number or one of {})", names.join(", "))?;
                }
                Ok(())
            }
            ValueError::NotHex { text } => write!(
                f,
                "`{text}` is not hex bytes (two hex digits a byte, e.g. 010AFF or \"01 0A FF\")"
            ),
        }
    }
}

impl std::error::Error for ValueError {}

/// A `--type` name that names no data type.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct UnknownType {
    /// The name as given.
    pub name: String,
}

impl fmt::Display for UnknownType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "`{}` is not a type: u8 u16 u24 u32 u40 u48 u56 u64, i8 .. i64, bool, \
             f32, f64, str, unicode, bytes, domain",
            self.name
        )
    }
}

impl std::error::Error for UnknownType {}

/// Why [`crate::decode_trace`] stopped.
#[derive(Debug)]
#[non_exhaustive]
pub enum TraceDecodeError {
    /// The trace could not be read (a failure of its reader, with the line).
    Read(TraceError),
    /// The sink failed (writing the output).
    Sink(io::Error),
}

impl fmt::Display for TraceDecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            // "line N: reading the trace failed: ..."
            TraceDecodeError::Read(e) => write!(f, "{e}"),
            TraceDecodeError::Sink(e) => write!(f, "writing the records: {e}"),
        }
    }
}

impl std::error::Error for TraceDecodeError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            TraceDecodeError::Read(e) => Some(e),
            TraceDecodeError::Sink(e) => Some(e),
        }
    }
}
