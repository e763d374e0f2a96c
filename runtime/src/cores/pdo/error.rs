//! [`PdoError`]: why sending or receiving a typed PDO through a master
//! failed (inside the drivers' `Error::Pdo`).

use core::fmt;
use core::time::Duration;

use super::{TransmitterConfigError, WatchError};
use crate::CanId;
use crate::frame::FrameError;
use crate::od::{NodeId, PdoDirection, PdoLengthError};

/// Why a master's PDO call (`send_pdo`, `next_pdo`, ...) failed.
#[derive(Debug)]
#[non_exhaustive]
pub enum PdoError {
    /// The PDO struct gives no default COB-ID (a PDO above the fourth of
    /// its direction): use the `_on` call with its COB-ID.
    NoDefaultCobId {
        /// The node the PDO was meant for.
        node: NodeId,
        /// RPDO or TPDO.
        direction: PdoDirection,
        /// The PDO's number.
        number: u16,
    },
    /// The PDO receiver refused to watch the PDO.
    Watch(WatchError),
    /// No transmitter could be made for the PDO.
    Transmitter(TransmitterConfigError),
    /// The PDO struct encoded more than 8 bytes.
    Frame(FrameError),
    /// A PDO came with another length than the struct's mapping.
    Length {
        /// The identifier it came on.
        can_id: CanId,
        /// The lengths.
        error: PdoLengthError,
    },
    /// No PDO came within the time given.
    Timeout {
        /// The identifier waited on.
        can_id: CanId,
        /// The time waited.
        waited: Duration,
    },
}

impl fmt::Display for PdoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PdoError::NoDefaultCobId {
                node,
                direction,
                number,
            } => write!(
                f,
                "node {node}: {direction:?}{number} has no default COB-ID; give its COB-ID \
                 (the `_on` call)"
            ),
            PdoError::Watch(e) => write!(f, "cannot receive the PDO: {e}"),
            PdoError::Transmitter(e) => write!(f, "cannot send the PDO: {e}"),
            PdoError::Frame(e) => write!(f, "cannot send the PDO: {e}"),
            PdoError::Length { can_id, error } => write!(f, "PDO on {can_id}: {error}"),
            PdoError::Timeout { can_id, waited } => {
                write!(f, "no PDO on {can_id} within {waited:?}")
            }
        }
    }
}

impl core::error::Error for PdoError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            PdoError::Watch(e) => Some(e),
            PdoError::Transmitter(e) => Some(e),
            PdoError::Frame(e) => Some(e),
            PdoError::Length { error, .. } => Some(error),
            _ => None,
        }
    }
}

impl From<WatchError> for PdoError {
    fn from(e: WatchError) -> Self {
        PdoError::Watch(e)
    }
}

impl From<TransmitterConfigError> for PdoError {
    fn from(e: TransmitterConfigError) -> Self {
        PdoError::Transmitter(e)
    }
}

impl From<FrameError> for PdoError {
    fn from(e: FrameError) -> Self {
        PdoError::Frame(e)
    }
}
