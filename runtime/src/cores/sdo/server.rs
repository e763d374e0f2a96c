//! SDO server (CiA 301) as a sans-IO state machine over an [`ObjectStore`].
//!
//! It serves expedited, segmented and block downloads and uploads, one
//! transfer at a time, and answers on [`Channel::response`] every request it
//! receives on [`Channel::request`] (other frames are ignored). Every frame
//! is parsed and built by [`super::proto`]. Besides its own channel
//! ([`ServerConfig::channel`], the default SDO) it can listen on additional
//! channels, 11- or 29-bit ([`SdoServer::set_extra_channels`], what a
//! device's 0x1201–0x127F configure). It still runs one transfer at a time:
//! a request on another channel while one runs is answered there with abort
//! 0x08000022 (not now: the present device state).
//!
//! Choices where CiA 301 leaves room:
//! - An initiate request while a transfer runs restarts: the old transfer is
//!   dropped without an abort frame and without an event, and the new request
//!   is served. (While a block-download sub-block is in flight every frame is
//!   a segment, so there an initiate cannot be told apart and is not
//!   recognised.)
//! - Block uploads ignore the protocol switch threshold: the server always
//!   answers a block upload request with a block upload.
//! - An expedited download without a size indication writes all 4 bytes.
//! - A request that belongs to no transfer (a segment while idle, an unknown
//!   command) is answered with abort 0x05040001 (index and sub-index 0) and
//!   no event; an abort while idle is ignored.
//! - Downloads are buffered completely and written to the store in one
//!   [`ObjectStore::write`] once the last byte arrived; uploads read the
//!   value completely with [`ObjectStore::read`] when they start.
//!
//! The transfer buffer is reused across transfers; it holds at most
//! `max_download` (rounded up to whole segments) for downloads and the value
//! for uploads, and is shrunk back after an upload of a larger value.

use alloc::vec::Vec;
use core::time::Duration;

use super::proto::{ParseError, Request, Response};
use super::{AbortCode, Channel, DEFAULT_TIMEOUT, MAX_BLOCK_SIZE, SdoError};
use crate::{CanId, Frame, Instant, Service};

mod block;
mod memory;
mod segmented;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_block;

pub use memory::{MemoryStore, StoredValue};

use crate::queue::Ring;
use block::{BlockDownload, BlockUpload};

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
#[non_exhaustive]
pub struct ServerConfig {
    /// The COB-IDs the server listens (request) and answers (response) on.
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
    /// Defaults for `channel`: 500 ms timeout, block size 127, CRC on,
    /// downloads up to 1 MiB.
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
#[non_exhaustive]
pub enum ServerEvent {
    /// A value was written to the store.
    Downloaded {
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
        /// Bytes written.
        len: usize,
    },
    /// A value was read and sent completely.
    Uploaded {
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
        /// Bytes sent.
        len: usize,
    },
    /// A transfer ended without success.
    Failed {
        /// Object index of the transfer.
        index: u16,
        /// Sub-index of the transfer.
        sub: u8,
        /// How it ended.
        error: SdoError,
    },
}

/// The transfer in progress. The object it concerns is
/// [`SdoServer::object`]; its data lives in [`SdoServer::buf`].
#[derive(Debug)]
enum State {
    Idle,
    /// Segmented download: waiting for the next segment.
    Download {
        /// Toggle bit the next segment must carry.
        toggle: bool,
        /// The size the client announced.
        size: Option<usize>,
    },
    /// Segmented upload: `buf[pos..]` is still to be sent.
    Upload {
        toggle: bool,
        pos: usize,
    },
    BlockDownload(BlockDownload),
    BlockUpload(BlockUpload),
}

/// Frames waiting in [`SdoServer::poll_transmit`]: one per input normally;
/// the spare room covers callers that feed several frames before draining.
const OUTBOX: usize = 4;

/// SDO server for one channel over an object store.
#[derive(Debug)]
pub struct SdoServer<S> {
    config: ServerConfig,
    store: S,
    state: State,
    /// Index and sub-index of the running transfer.
    object: (u16, u8),
    /// Download data received so far, or the value being uploaded.
    buf: Vec<u8>,
    /// When the client's next frame is due (running transfers only).
    deadline: Option<Instant>,
    /// Additional channels besides the configured one.
    extra: Vec<Channel>,
    /// The channel of the running transfer (the configured one while idle).
    active: Channel,
    /// Responses and the identifier each goes out on.
    outbox: Ring<(CanId, [u8; 8]), OUTBOX>,
    events: Ring<ServerEvent, OUTBOX>,
}

impl<S: ObjectStore> SdoServer<S> {
    /// An idle server; nothing is allocated until the first transfer that
    /// needs a buffer.
    pub fn new(config: ServerConfig, store: S) -> SdoServer<S> {
        SdoServer {
            active: config.channel,
            config,
            store,
            state: State::Idle,
            object: (0, 0),
            buf: Vec::new(),
            deadline: None,
            extra: Vec::new(),
            outbox: Ring::new(),
            events: Ring::new(),
        }
    }

    /// The settings.
    pub fn config(&self) -> &ServerConfig {
        &self.config
    }

    /// The object store.
    pub fn store(&self) -> &S {
        &self.store
    }

    /// The object store, mutably (the application updating its values).
    pub fn store_mut(&mut self) -> &mut S {
        &mut self.store
    }

    /// Gives the object store back.
    pub fn into_store(self) -> S {
        self.store
    }

    /// Moves the server to `channel` (the node id changed, for example by
    /// LSS and reset communication). A running transfer is dropped without
    /// an answer, as the node it belonged to is gone.
    pub fn set_channel(&mut self, channel: Channel) {
        self.config.channel = channel;
        self.drop_transfer();
    }

    /// Accepts downloads of up to `bytes` from now on (the configured
    /// `max_download`).
    pub fn set_max_download(&mut self, bytes: usize) {
        self.config.max_download = bytes;
    }

    /// Listens on `channels` as well as on the configured one (a device's
    /// additional server SDO parameters 0x1201–0x127F; build them with
    /// [`Channel::from_cob_ids`]). A running transfer on a channel no longer
    /// listened to is dropped without an answer.
    pub fn set_extra_channels(&mut self, channels: Vec<Channel>) {
        self.extra = channels;
        if self.active != self.config.channel && !self.extra.contains(&self.active) {
            self.drop_transfer();
        }
    }

    /// The additional channels.
    pub fn extra_channels(&self) -> &[Channel] {
        &self.extra
    }

    fn drop_transfer(&mut self) {
        self.state = State::Idle;
        self.deadline = None;
        self.buf.clear();
        self.active = self.config.channel;
    }

    /// A request on `channel` while a transfer on another one runs: abort
    /// 0x08000022 there (its index and sub-index when the frame has them),
    /// nothing for an abort.
    fn refuse_while_busy(&mut self, channel: Channel, data: &[u8]) {
        let (index, sub) = match Request::parse(data) {
            Ok(Request::Abort { .. }) => return,
            Ok(
                Request::DownloadInitiate { index, sub, .. }
                | Request::UploadInitiate { index, sub }
                | Request::BlockDownloadInitiate { index, sub, .. }
                | Request::BlockUploadInitiate { index, sub, .. },
            ) => (index, sub),
            _ => (0, 0),
        };
        let abort = Response::Abort {
            index,
            sub,
            code: AbortCode::CannotTransferDeviceState,
        };
        self.outbox.push((channel.response, abort.encode()));
    }

    /// The channel whose requests arrive on `id`.
    fn channel_of(&self, id: CanId) -> Option<Channel> {
        core::iter::once(&self.config.channel)
            .chain(&self.extra)
            .find(|c| c.request == id)
            .copied()
    }

    /// No transfer running.
    pub fn is_idle(&self) -> bool {
        matches!(self.state, State::Idle)
    }

    /// Capacity of the transfer buffer in bytes (memory held between
    /// transfers; bounded by `max_download` and the largest value uploaded).
    pub fn buffer_capacity(&self) -> usize {
        self.buf.capacity()
    }

    /// Queues a response frame.
    fn send(&mut self, response: Response) {
        self.outbox.push((self.active.response, response.encode()));
    }

    /// Ends the running transfer: back to idle, no deadline. A buffer grown
    /// past the download bound by an upload is shrunk back.
    fn finish(&mut self) {
        self.state = State::Idle;
        self.deadline = None;
        let bound = padded_len(self.config.max_download);
        if self.buf.capacity() > bound {
            self.buf.clear();
            self.buf.shrink_to(bound);
        }
    }

    /// Ends the running transfer successfully with `event`.
    fn succeed(&mut self, event: ServerEvent) {
        self.events.push(event);
        self.finish();
    }

    /// Aborts the transfer of [`SdoServer::object`] with `code`: sends the
    /// abort frame, reports `Failed { LocalAbort(code) }` and goes idle.
    fn fail(&mut self, code: AbortCode) {
        let (index, sub) = self.object;
        self.send(Response::Abort { index, sub, code });
        self.events.push(ServerEvent::Failed {
            index,
            sub,
            error: SdoError::LocalAbort(code),
        });
        self.finish();
    }

    /// The size a download initiate announced, checked: within
    /// `max_download` (else OutOfMemory) and accepted by the store for the
    /// object (else the store's abort code).
    fn download_size(&mut self, size: Option<u32>) -> Result<Option<usize>, AbortCode> {
        let size = match size.map(usize::try_from) {
            None => None,
            Some(Ok(size)) if size <= self.config.max_download => Some(size),
            Some(_) => return Err(AbortCode::OutOfMemory),
        };
        let (index, sub) = self.object;
        self.store.check_write(index, sub, size)?;
        Ok(size)
    }

    /// Ends a download whose value is in the buffer: checks its length
    /// against the announced `size`, writes it to the store, answers with
    /// `reply` and reports it; a wrong length or a refused write aborts
    /// instead.
    fn complete_download(&mut self, size: Option<usize>, reply: Response) {
        let len = self.buf.len();
        if let Some(size) = size
            && len != size
        {
            return self.fail(length_error(len, size));
        }
        let (index, sub) = self.object;
        match self.store.write(index, sub, &self.buf) {
            Ok(()) => {
                self.send(reply);
                self.succeed(ServerEvent::Downloaded { index, sub, len });
            }
            Err(code) => self.fail(code),
        }
    }

    /// A request that does not fit the current state: aborts the running
    /// transfer, or answers with an abort when there is none.
    fn reject(&mut self, code: AbortCode) {
        if self.is_idle() {
            self.send(Response::Abort {
                index: 0,
                sub: 0,
                code,
            });
        } else {
            self.fail(code);
        }
    }

    /// The client aborted: the transfer ends without a frame.
    fn remote_abort(&mut self, code: AbortCode) {
        if self.is_idle() {
            return;
        }
        let (index, sub) = self.object;
        self.events.push(ServerEvent::Failed {
            index,
            sub,
            error: SdoError::RemoteAbort(code),
        });
        self.finish();
    }

    /// Starts serving a new transfer of (index, sub): any running one is
    /// dropped (a client may restart), the buffer is emptied.
    fn begin(&mut self, index: u16, sub: u8) {
        self.state = State::Idle;
        self.object = (index, sub);
        self.buf.clear();
    }

    /// Dispatches one parsed request.
    fn handle_request(&mut self, request: Request) {
        if let Some((index, sub)) = request.initiated_object() {
            self.begin(index, sub);
        }
        match request {
            Request::Abort { code, .. } => self.remote_abort(code),
            Request::DownloadInitiate { data, .. } => self.download_initiate(data),
            Request::UploadInitiate { .. } => self.upload_initiate(),
            Request::BlockDownloadInitiate { crc, size, .. } => {
                self.block_download_initiate(crc, size);
            }
            Request::BlockUploadInitiate {
                crc, block_size, ..
            } => self.block_upload_initiate(crc, block_size),
            Request::DownloadSegment {
                toggle,
                last,
                data,
                len,
            } => match self.state {
                State::Download {
                    toggle: expected,
                    size,
                } => self.download_segment(expected, size, toggle, last, &data, len),
                _ => self.reject(AbortCode::InvalidCommand),
            },
            Request::UploadSegment { toggle } => match self.state {
                State::Upload {
                    toggle: expected,
                    pos,
                } => self.upload_segment(expected, pos, toggle),
                _ => self.reject(AbortCode::InvalidCommand),
            },
            Request::BlockDownloadEnd { unused, crc } => self.block_download_end(unused, crc),
            Request::BlockUploadStart => self.block_upload_start(),
            Request::BlockUploadAck {
                ack_seq,
                block_size,
            } => self.block_upload_ack(ack_seq, block_size),
            Request::BlockUploadEnd => self.block_upload_end(),
        }
    }
}

impl<S: ObjectStore> Service for SdoServer<S> {
    type Event = ServerEvent;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        if frame.is_remote() {
            return;
        }
        let Some(channel) = self.channel_of(frame.id()) else {
            return;
        };
        let data = frame.data();
        if channel != self.active {
            if self.is_idle() {
                self.active = channel;
            } else {
                self.refuse_while_busy(channel, data);
                return;
            }
        }
        if let State::BlockDownload(ref transfer) = self.state
            && transfer.in_sub_block()
        {
            // Segments carry no command specifier: everything but an abort
            // is a segment here.
            self.block_download_frame(data);
        } else {
            match Request::parse(data) {
                Ok(request) => self.handle_request(request),
                Err(_) => self.reject(AbortCode::InvalidCommand),
            }
        }
        self.deadline = if self.is_idle() {
            None
        } else {
            Some(now.saturating_add(self.config.timeout))
        };
    }

    fn handle_timeout(&mut self, now: Instant) {
        match self.deadline {
            Some(deadline) if now >= deadline && !self.is_idle() => {
                let (index, sub) = self.object;
                self.send(Response::Abort {
                    index,
                    sub,
                    code: AbortCode::Timeout,
                });
                self.events.push(ServerEvent::Failed {
                    index,
                    sub,
                    error: SdoError::Timeout,
                });
                self.finish();
            }
            _ => {}
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        let (id, data) = match self.outbox.pop() {
            Some(out) => out,
            None => (self.active.response, self.next_upload_segment()?),
        };
        Some(Frame::with_id(id, data, 8))
    }

    fn poll_event(&mut self) -> Option<ServerEvent> {
        self.events.pop()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.deadline
    }
}

/// Data bytes per segment (segmented and block transfers).
const SEGMENT: usize = 7;

/// `len` rounded up to whole segments (at least one), saturating.
fn padded_len(len: usize) -> usize {
    len.div_ceil(SEGMENT).max(1).saturating_mul(SEGMENT)
}

/// Appends `data` to `buf`, growing its capacity by doubling but not past
/// `limit` (unless `data` itself needs more), so that a download never
/// holds more memory than its bound.
fn append_bounded(buf: &mut Vec<u8>, data: &[u8], limit: usize) {
    let needed = buf.len().saturating_add(data.len());
    if needed > buf.capacity() {
        let target = buf.capacity().saturating_mul(2).min(limit).max(needed);
        buf.reserve_exact(target.saturating_sub(buf.len()));
    }
    buf.extend_from_slice(data);
}

/// The block size the server offers: the configured one, kept in 1..=127.
fn offered_block_size(config: &ServerConfig) -> u8 {
    config.block_size.clamp(1, MAX_BLOCK_SIZE)
}

/// The abort code for a received length that differs from the expected one.
fn length_error(actual: usize, expected: usize) -> AbortCode {
    if actual > expected {
        AbortCode::LengthTooHigh
    } else {
        AbortCode::LengthTooLow
    }
}

/// The abort code for a block segment that does not parse.
fn segment_error(error: ParseError) -> AbortCode {
    match error {
        ParseError::Field(_) => AbortCode::InvalidSequenceNumber,
        other => other.abort_code(),
    }
}
