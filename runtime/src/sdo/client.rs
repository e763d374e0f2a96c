//! SDO client: SKELETON — the public API is fixed; the helper implementing it
//! replaces every `todo!()`.

use alloc::vec::Vec;
use core::time::Duration;

use super::{Channel, DEFAULT_TIMEOUT, SdoError};
use crate::{Frame, Instant, Service};

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

/// Client settings.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClientConfig {
    pub channel: Channel,
    /// Time the server has to answer each frame.
    pub timeout: Duration,
    /// Block size asked for in block uploads (1 to 127).
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
}

impl ClientConfig {
    pub fn new(channel: Channel) -> ClientConfig {
        ClientConfig {
            channel,
            timeout: DEFAULT_TIMEOUT,
            block_size: super::MAX_BLOCK_SIZE,
            crc: true,
            max_upload: 1 << 20,
            block_download_above: None,
            block_upload: false,
        }
    }
}

/// The client is already running a transfer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Busy;

/// The end of a transfer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ClientEvent {
    Uploaded {
        index: u16,
        sub: u8,
        data: Vec<u8>,
    },
    Downloaded {
        index: u16,
        sub: u8,
    },
    Failed {
        index: u16,
        sub: u8,
        error: SdoError,
    },
}

/// SDO client for one channel; one transfer at a time.
#[derive(Debug)]
pub struct SdoClient {
    config: ClientConfig,
}

impl SdoClient {
    pub fn new(config: ClientConfig) -> SdoClient {
        SdoClient { config }
    }
    pub fn config(&self) -> &ClientConfig {
        &self.config
    }
    /// No transfer running.
    pub fn is_idle(&self) -> bool {
        todo!()
    }
    pub fn upload(&mut self, now: Instant, index: u16, sub: u8) -> Result<(), Busy> {
        self.upload_with(now, index, sub, Method::Auto)
    }
    pub fn upload_with(
        &mut self,
        _now: Instant,
        _index: u16,
        _sub: u8,
        _method: Method,
    ) -> Result<(), Busy> {
        todo!()
    }
    pub fn download(&mut self, now: Instant, index: u16, sub: u8, data: &[u8]) -> Result<(), Busy> {
        self.download_with(now, index, sub, data, Method::Auto)
    }
    pub fn download_with(
        &mut self,
        _now: Instant,
        _index: u16,
        _sub: u8,
        _data: &[u8],
        _method: Method,
    ) -> Result<(), Busy> {
        todo!()
    }
    /// Aborts the running transfer with `code` (sends the abort frame; the
    /// transfer ends with `Failed { error: LocalAbort(code) }`).
    pub fn abort(&mut self, _code: super::AbortCode) {
        todo!()
    }
}

impl Service for SdoClient {
    type Event = ClientEvent;
    fn handle_frame(&mut self, _now: Instant, _frame: &Frame) {
        todo!()
    }
    fn handle_timeout(&mut self, _now: Instant) {
        todo!()
    }
    fn poll_transmit(&mut self) -> Option<Frame> {
        todo!()
    }
    fn poll_event(&mut self) -> Option<ClientEvent> {
        todo!()
    }
    fn poll_timeout(&self) -> Option<Instant> {
        todo!()
    }
}
