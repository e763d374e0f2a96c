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

use crate::frame::{CanId, cob};
use crate::od::NodeId;

/// How a transfer ended when it did not succeed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
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

/// The identifiers of one SDO channel: 11-bit, or 29-bit for the
/// additional channels CiA 301 allows (SDO parameter COB-IDs with bit 29).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Channel {
    /// Client to server (default 0x600 + node).
    pub request: CanId,
    /// Server to client (default 0x580 + node).
    pub response: CanId,
}

/// Why an SDO parameter's COB-IDs name no channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ChannelError {
    /// Bit 31 of this COB-ID is set: the SDO is not valid (not in use).
    NotValid(u32),
    /// An 11-bit COB-ID (bit 29 clear) above 0x7FF.
    NotStandard(u32),
}

impl fmt::Display for ChannelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ChannelError::NotValid(v) => {
                write!(
                    f,
                    "SDO COB-ID {v:#010X} has bit 31 set: the SDO is not valid"
                )
            }
            ChannelError::NotStandard(v) => write!(
                f,
                "SDO COB-ID {v:#010X} names an 11-bit identifier (bit 29 clear) above 0x7FF"
            ),
        }
    }
}

impl core::error::Error for ChannelError {}

/// The identifier of one SDO parameter COB-ID (CiA 301: bit 31 set = not
/// valid, bit 30 dynamic allocation, bit 29 set = 29-bit identifier, the
/// identifier in bits 0 to 28).
const fn id_of(cob_id: u32) -> Result<CanId, ChannelError> {
    if cob_id & 1 << 31 != 0 {
        return Err(ChannelError::NotValid(cob_id));
    }
    if cob_id & 1 << 29 != 0 {
        return Ok(CanId::Extended(cob_id & 0x1FFF_FFFF));
    }
    let id = cob_id & 0x1FFF_FFFF;
    if id > 0x7FF {
        return Err(ChannelError::NotStandard(cob_id));
    }
    Ok(CanId::Standard(id as u16))
}

/// The SDO parameter COB-ID of `id` (valid, static).
const fn cob_id_of(id: CanId) -> u32 {
    match id {
        CanId::Standard(id) => id as u32,
        CanId::Extended(id) => 1 << 29 | (id & 0x1FFF_FFFF),
    }
}

impl Channel {
    /// The default SDO channel of a node (CiA 301 predefined connection set).
    pub const fn default_for(node: NodeId) -> Channel {
        Channel::standard(cob::sdo_rx(node), cob::sdo_tx(node))
    }

    /// A channel of 11-bit identifiers (masked to 11 bits).
    pub const fn standard(request: u16, response: u16) -> Channel {
        Channel {
            request: CanId::Standard(request & 0x7FF),
            response: CanId::Standard(response & 0x7FF),
        }
    }

    /// A channel of 29-bit identifiers (masked to 29 bits).
    pub const fn extended(request: u32, response: u32) -> Channel {
        Channel {
            request: CanId::Extended(request & 0x1FFF_FFFF),
            response: CanId::Extended(response & 0x1FFF_FFFF),
        }
    }

    /// The channel of an SDO parameter record's COB-IDs (sub 1 client to
    /// server, sub 2 server to client: 0x1200–0x127F of a server,
    /// 0x1280–0x12FF of a client).
    pub const fn from_cob_ids(
        client_to_server: u32,
        server_to_client: u32,
    ) -> Result<Channel, ChannelError> {
        let request = match id_of(client_to_server) {
            Ok(id) => id,
            Err(e) => return Err(e),
        };
        let response = match id_of(server_to_client) {
            Ok(id) => id,
            Err(e) => return Err(e),
        };
        Ok(Channel { request, response })
    }

    /// The COB-IDs (client to server, server to client) an SDO parameter
    /// record holds for this channel: valid, bit 29 set for 29-bit ones.
    pub const fn cob_ids(self) -> (u32, u32) {
        (cob_id_of(self.request), cob_id_of(self.response))
    }
}

/// Largest block size CiA 301 allows (segments per sub-block).
pub const MAX_BLOCK_SIZE: u8 = 127;

/// Default time a peer has to answer one SDO frame.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_millis(500);
