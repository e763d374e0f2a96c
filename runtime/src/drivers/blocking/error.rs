//! The one error of the drivers' calls: SDO clients, the blocking and tokio
//! masters and their CiA 402 drive handles.

use core::fmt;
use core::time::Duration;
use std::boxed::Box;
use std::io;
use std::string::String;

use crate::cia402::session::OperationError;
use crate::od::{self, NodeId};
use crate::pdo::blocking::PdoConfigError;
use crate::pdo::{PdoError, WatchError};
use crate::sdo::SdoError;

pub use super::master::LssRequestError;

/// What a driver call can fail with: an SDO transfer, an NMT command, an
/// LSS request, a CiA 402 request, a PDO configuration, or the bus and the
/// driver under them.
///
/// `node` is the node the call talked to; `None` for an
/// [`SdoClient`](super::SdoClient) on a channel that is no node's default.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// An SDO transfer of (index, sub) failed: aborted by either side, or
    /// one step went unanswered for the client's timeout.
    Sdo {
        /// The node.
        node: Option<NodeId>,
        /// The object index.
        index: u16,
        /// The sub-index.
        sub: u8,
        /// How the transfer ended.
        error: SdoError,
    },
    /// The whole SDO transfer of (index, sub) took longer than `limit`
    /// (one client timeout per step it can have), although each step was
    /// answered in time; the driver aborted it with 0x05040000.
    TransferTooLong {
        /// The node.
        node: Option<NodeId>,
        /// The object index.
        index: u16,
        /// The sub-index.
        sub: u8,
        /// The limit on the whole transfer.
        limit: Duration,
    },
    /// The value of (index, sub) had the wrong length for its data type.
    Value {
        /// The node.
        node: Option<NodeId>,
        /// The object index.
        index: u16,
        /// The sub-index.
        sub: u8,
        /// What was wrong with it.
        error: od::ValueError,
    },
    /// An uploaded VISIBLE_STRING of (index, sub) holds `byte` at
    /// `offset`, outside the visible characters 0x20 to 0x7E.
    NotVisible {
        /// The node.
        node: Option<NodeId>,
        /// The object index.
        index: u16,
        /// The sub-index.
        sub: u8,
        /// Position in the uploaded data.
        offset: usize,
        /// The byte found there.
        byte: u8,
    },
    /// The node's SDO client core refused to start a transfer: a transfer
    /// started on the core directly has not ended.
    SdoBusy {
        /// The node.
        node: Option<NodeId>,
    },
    /// The data source of a streamed download failed, ended before the
    /// size it announced, or went beyond it (the transfer was aborted
    /// locally with 0x08000000).
    Source(io::Error),
    /// The sink of a streamed upload failed (the transfer was aborted
    /// locally with 0x08000000).
    Sink(io::Error),
    /// The NMT command queue stayed full: the driver could not send the
    /// queued commands.
    NmtQueueFull,
    /// An LSS request failed.
    Lss(LssRequestError),
    /// A CiA 402 request failed on the drive, or was refused before
    /// anything was sent (a missing object, the wrong state).
    Cia402(OperationError),
    /// A PDO configuration failed (its step and the SDO error inside).
    PdoConfig(Box<PdoConfigError>),
    /// Sending or receiving a typed PDO failed: no default COB-ID, a
    /// receiver or transmitter that refused it, a frame of the wrong
    /// length, or none within the time given.
    Pdo(PdoError),
    /// The deadline of [`Master::run_until`](super::Master::run_until)
    /// passed before the awaited event.
    DeadlinePassed,
    /// The tokio master's driver is not running any more: the bus failed,
    /// its `tokio::Driver` was dropped, or every handle was.
    DriverStopped {
        /// Why it stopped.
        reason: String,
    },
    /// The bus failed.
    Io(io::Error),
}

/// `(index, sub)` as the messages write it.
struct Object(u16, u8);

impl fmt::Display for Object {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:#06X}:{}", self.0, self.1)
    }
}

/// "node 5" or "the SDO server" as the messages write it.
struct Peer(Option<NodeId>);

impl fmt::Display for Peer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(node) => write!(f, "node {node}"),
            None => f.write_str("the SDO server"),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Sdo {
                node,
                index,
                sub,
                error,
            } => {
                write!(
                    f,
                    "SDO transfer of {} with {}: {error}",
                    Object(*index, *sub),
                    Peer(*node)
                )?;
                if *error == SdoError::Timeout {
                    f.write_str(
                        "; check that the node is powered, connected and has this node id",
                    )?;
                }
                Ok(())
            }
            Error::TransferTooLong {
                node,
                index,
                sub,
                limit,
            } => write!(
                f,
                "SDO transfer of {} with {} took longer than its limit of {limit:?} and was aborted; \
                 raise the client's timeout for large or slow transfers",
                Object(*index, *sub),
                Peer(*node)
            ),
            Error::Value {
                node,
                index,
                sub,
                error,
            } => write!(
                f,
                "bad value of {} on {}: {error}",
                Object(*index, *sub),
                Peer(*node)
            ),
            Error::NotVisible {
                node,
                index,
                sub,
                offset,
                byte,
            } => write!(
                f,
                "{} on {}: byte {byte:#04X} at offset {offset} is not a visible character \
                 (0x20 to 0x7E); read the raw bytes instead",
                Object(*index, *sub),
                Peer(*node)
            ),
            Error::SdoBusy { node } => write!(
                f,
                "the SDO client of {} is busy with a transfer started on its core; \
                 wait for that transfer's event first",
                Peer(*node)
            ),
            Error::Source(e) => write!(f, "the data to download failed: {e}"),
            Error::Sink(e) => write!(f, "the uploaded data could not be written: {e}"),
            Error::NmtQueueFull => f.write_str(
                "the NMT command queue is full and its frames could not be sent; check the bus",
            ),
            Error::Lss(e) => e.fmt(f),
            Error::Cia402(e) => e.fmt(f),
            Error::PdoConfig(e) => e.fmt(f),
            Error::Pdo(e) => e.fmt(f),
            Error::DeadlinePassed => f.write_str("the deadline passed before the awaited event"),
            Error::DriverStopped { reason } => write!(
                f,
                "the master's driver stopped ({reason}); keep Driver::run running while the master is used"
            ),
            Error::Io(e) => write!(f, "CAN bus error: {e}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Sdo { error, .. } => Some(error),
            Error::Io(e) | Error::Source(e) | Error::Sink(e) => Some(e),
            Error::Lss(e) => Some(e),
            Error::Cia402(e) => Some(e),
            Error::PdoConfig(e) => Some(e),
            Error::Pdo(e) => Some(e),
            _ => None,
        }
    }
}

impl Error {
    /// The SDO error of a failed transfer (`None` for other errors).
    pub fn sdo_error(&self) -> Option<SdoError> {
        match self {
            Error::Sdo { error, .. } => Some(*error),
            _ => None,
        }
    }
}

impl From<io::Error> for Error {
    fn from(e: io::Error) -> Error {
        Error::Io(e)
    }
}

impl From<LssRequestError> for Error {
    fn from(e: LssRequestError) -> Error {
        Error::Lss(e)
    }
}

impl From<OperationError> for Error {
    fn from(e: OperationError) -> Error {
        Error::Cia402(e)
    }
}

impl From<PdoConfigError> for Error {
    fn from(e: PdoConfigError) -> Error {
        Error::PdoConfig(Box::new(e))
    }
}

impl From<PdoError> for Error {
    fn from(e: PdoError) -> Error {
        Error::Pdo(e)
    }
}

impl From<WatchError> for Error {
    fn from(e: WatchError) -> Error {
        Error::Pdo(PdoError::Watch(e))
    }
}

impl From<Error> for io::Error {
    /// The bus error itself, or the error as `io::ErrorKind::Other` (for
    /// callers that return `io::Result`).
    fn from(e: Error) -> io::Error {
        match e {
            Error::Io(e) => e,
            other => io::Error::other(other),
        }
    }
}
