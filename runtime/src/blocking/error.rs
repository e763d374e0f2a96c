//! The error of the SDO driver calls.

use core::fmt;
use std::io;

use crate::od;
use crate::sdo::SdoError;

/// What an SDO driver call can fail with.
#[derive(Debug)]
pub enum Error {
    /// The transfer failed: aborted by either side, or timed out.
    Sdo(SdoError),
    /// The value had the wrong length for its data type.
    Value(od::ValueError),
    /// The bus failed (the transfer was aborted locally).
    Io(io::Error),
    /// The client core refused to start a transfer.
    Busy,
    /// The data source of a streamed download failed, ended before the
    /// size it announced, or went beyond it (the transfer was aborted
    /// locally with 0x08000000).
    Source(io::Error),
    /// The sink of a streamed upload failed (the transfer was aborted
    /// locally with 0x08000000).
    Sink(io::Error),
    /// An uploaded VISIBLE_STRING holds `byte` at `offset`, outside the
    /// visible characters 0x20 to 0x7E.
    NotVisible {
        /// Position in the uploaded data.
        offset: usize,
        /// The byte found there.
        byte: u8,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Sdo(e) => e.fmt(f),
            Error::Value(e) => write!(f, "bad value: {e}"),
            Error::Io(e) => write!(f, "CAN bus error: {e}"),
            Error::Busy => f.write_str("the SDO client is busy with another transfer"),
            Error::Source(e) => write!(f, "the data to download failed: {e}"),
            Error::Sink(e) => write!(f, "the uploaded data could not be written: {e}"),
            Error::NotVisible { offset, byte } => write!(
                f,
                "byte {byte:#04X} at offset {offset} is not a visible character (0x20 to 0x7E)"
            ),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Sdo(e) => Some(e),
            Error::Io(e) | Error::Source(e) | Error::Sink(e) => Some(e),
            _ => None,
        }
    }
}

impl From<SdoError> for Error {
    fn from(e: SdoError) -> Error {
        Error::Sdo(e)
    }
}

impl From<od::ValueError> for Error {
    fn from(e: od::ValueError) -> Error {
        Error::Value(e)
    }
}

impl From<io::Error> for Error {
    fn from(e: io::Error) -> Error {
        Error::Io(e)
    }
}
