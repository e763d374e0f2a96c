//! What the client is told: its settings and the transfer method.

use core::time::Duration;

use crate::sdo::{Channel, DEFAULT_TIMEOUT, MAX_BLOCK_SIZE};

/// How a transfer is carried out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Downloads: expedited up to 4 bytes, block above
    /// [`ClientConfig::block_download_above`] (when set), segmented otherwise.
    /// Uploads: block when [`ClientConfig::block_upload`], else standard.
    #[default]
    Auto,
    /// The standard protocol: expedited when the data fits 4 bytes (the
    /// server decides for uploads), segmented otherwise.
    Standard,
    /// Segmented even for 4 bytes or less (downloads; uploads as Standard).
    Segmented,
    /// Block transfer.
    Block,
}

impl Method {
    /// Whether a transfer by this method is a block transfer: always with
    /// [`Method::Block`], never with `Standard` or `Segmented`, and with
    /// [`Method::Auto`] when `auto` (what the configuration says).
    pub(super) const fn is_block(self, auto: bool) -> bool {
        match self {
            Method::Block => true,
            Method::Auto => auto,
            Method::Standard | Method::Segmented => false,
        }
    }
}

/// Client settings.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct ClientConfig {
    /// The COB-IDs the client sends requests on and receives responses from.
    pub channel: Channel,
    /// Time the server has to answer each frame.
    pub timeout: Duration,
    /// Block size asked for in block uploads (1 to 127; other values are
    /// clamped into that range).
    pub block_size: u8,
    /// Offer CRC in block transfers.
    pub crc: bool,
    /// Largest upload accepted; a server announcing more gets abort
    /// 0x05040005 (out of memory) before anything is allocated.
    pub max_upload: usize,
    /// Use block download (with [`Method::Auto`]) above this many bytes.
    pub block_download_above: Option<usize>,
    /// Use block upload with [`Method::Auto`].
    pub block_upload: bool,
    /// Typed reads refuse a value longer than the entry's data type (a
    /// device answering 4 bytes for an UNSIGNED8) with a length error,
    /// instead of taking its leading bytes and leaving a
    /// [`LengthNote`](crate::sdo::typed::LengthNote).
    pub strict_lengths: bool,
}

impl ClientConfig {
    /// Defaults: 500 ms timeout, block size 127, CRC offered, uploads up to
    /// 1 MiB, no block transfers with [`Method::Auto`].
    pub fn new(channel: Channel) -> ClientConfig {
        ClientConfig {
            channel,
            timeout: DEFAULT_TIMEOUT,
            block_size: MAX_BLOCK_SIZE,
            crc: true,
            max_upload: 1 << 20,
            block_download_above: None,
            block_upload: false,
            strict_lengths: false,
        }
    }
}
