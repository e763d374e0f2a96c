//! SDO server: SKELETON — the public API is fixed; the helper implementing it
//! replaces every `todo!()`.

use alloc::vec::Vec;
use core::time::Duration;

use super::{AbortCode, Channel, DEFAULT_TIMEOUT, SdoError};
use crate::{Frame, Instant, Service};

/// The object dictionary behind an SDO server.
pub trait ObjectStore {
    /// Reads the whole value of (index, sub) into `out` (which is empty).
    fn read(&mut self, index: u16, sub: u8, out: &mut Vec<u8>) -> Result<(), AbortCode>;
    /// Checked when a download starts, before any data arrives: does the
    /// object exist, is it writable, and does `size` (when announced) fit?
    fn check_write(&mut self, index: u16, sub: u8, size: Option<usize>) -> Result<(), AbortCode> {
        let _ = (index, sub, size);
        Ok(())
    }
    /// Writes a complete value.
    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode>;
}

/// Server settings.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ServerConfig {
    pub channel: Channel,
    /// Time the client has to send its next frame.
    pub timeout: Duration,
    /// Block size offered in block downloads (1 to 127).
    pub block_size: u8,
    /// Support CRC in block transfers.
    pub crc: bool,
    /// Largest download accepted (abort 0x05040005 above it).
    pub max_download: usize,
}

impl ServerConfig {
    pub fn new(channel: Channel) -> ServerConfig {
        ServerConfig {
            channel,
            timeout: DEFAULT_TIMEOUT,
            block_size: super::MAX_BLOCK_SIZE,
            crc: true,
            max_download: 1 << 20,
        }
    }
}

/// What the server did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ServerEvent {
    /// A value was written to the store.
    Downloaded { index: u16, sub: u8, len: usize },
    /// A value was read and sent completely.
    Uploaded { index: u16, sub: u8, len: usize },
    /// A transfer ended without success.
    Failed {
        index: u16,
        sub: u8,
        error: SdoError,
    },
}

/// SDO server for one channel over an object store.
#[derive(Debug)]
pub struct SdoServer<S> {
    config: ServerConfig,
    store: S,
}

impl<S: ObjectStore> SdoServer<S> {
    pub fn new(config: ServerConfig, store: S) -> SdoServer<S> {
        SdoServer { config, store }
    }
    pub fn config(&self) -> &ServerConfig {
        &self.config
    }
    pub fn store(&self) -> &S {
        &self.store
    }
    pub fn store_mut(&mut self) -> &mut S {
        &mut self.store
    }
    pub fn into_store(self) -> S {
        self.store
    }
    /// No transfer running.
    pub fn is_idle(&self) -> bool {
        todo!()
    }
}

impl<S: ObjectStore> Service for SdoServer<S> {
    type Event = ServerEvent;
    fn handle_frame(&mut self, _now: Instant, _frame: &Frame) {
        todo!()
    }
    fn handle_timeout(&mut self, _now: Instant) {
        todo!()
    }
    fn poll_transmit(&mut self) -> Option<Frame> {
        todo!()
    }
    fn poll_event(&mut self) -> Option<ServerEvent> {
        todo!()
    }
    fn poll_timeout(&self) -> Option<Instant> {
        todo!()
    }
}
