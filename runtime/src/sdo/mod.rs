//! SDO: service data objects (CiA 301), client and server as sans-IO state
//! machines. [`proto`] holds the frame layouts, [`abort`] the abort codes;
//! the client and the server (which need `alloc` to buffer data) share the
//! types below.

pub mod abort;
pub mod proto;
pub mod typed;

#[cfg(feature = "alloc")]
pub mod client;
#[cfg(feature = "alloc")]
pub mod server;

use core::fmt;
use core::time::Duration;

pub use abort::AbortCode;

use crate::frame::cob;
use crate::od::NodeId;

/// How a transfer ended when it did not succeed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SdoError {
    /// The peer aborted the transfer with this code.
    RemoteAbort(AbortCode),
    /// This side aborted the transfer (and sent the abort frame): the peer
    /// broke the protocol, refused data, or announced more than the bound.
    LocalAbort(AbortCode),
    /// The peer did not answer within the timeout; this side sent abort
    /// 0x05040000.
    Timeout,
    /// The server sent a frame that is no valid SDO response (an unknown
    /// command, or shorter than its command needs); this side sent abort
    /// 0x05040001. `frame[..len]` is the frame's data.
    BadResponse {
        frame: [u8; 8],
        len: u8,
        error: proto::ParseError,
    },
}

impl SdoError {
    /// The abort code that ended the transfer (the timeout code for timeouts).
    pub const fn code(self) -> AbortCode {
        match self {
            SdoError::RemoteAbort(c) | SdoError::LocalAbort(c) => c,
            SdoError::Timeout => AbortCode::Timeout,
            SdoError::BadResponse { error, .. } => error.abort_code(),
        }
    }
}

impl fmt::Display for SdoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SdoError::RemoteAbort(c) => write!(f, "the SDO peer aborted the transfer: {c}"),
            SdoError::LocalAbort(c) => write!(f, "aborted the SDO transfer: {c}"),
            SdoError::Timeout => f.write_str("the SDO peer did not answer in time"),
            SdoError::BadResponse { frame, len, error } => {
                f.write_str("the SDO server sent an invalid response [")?;
                for (i, b) in frame.iter().take(usize::from(*len)).enumerate() {
                    let sep = if i == 0 { "" } else { " " };
                    write!(f, "{sep}{b:02X}")?;
                }
                write!(f, "]: {error}; aborted with {}", error.abort_code())
            }
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for SdoError {}

/// The COB-IDs of one SDO channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Channel {
    /// Client to server (default 0x600 + node).
    pub request: u16,
    /// Server to client (default 0x580 + node).
    pub response: u16,
}

impl Channel {
    /// The default SDO channel of a node (CiA 301 predefined connection set).
    pub const fn default_for(node: NodeId) -> Channel {
        Channel {
            request: cob::sdo_rx(node),
            response: cob::sdo_tx(node),
        }
    }
}

/// Largest block size CiA 301 allows (segments per sub-block).
pub const MAX_BLOCK_SIZE: u8 = 127;

/// Default time a peer has to answer one SDO frame.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_millis(500);
