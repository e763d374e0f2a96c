//! SDO client (CiA 301): one transfer at a time over one SDO channel, as a
//! sans-IO state machine driven through [`Service`].
//!
//! Expedited, segmented and block transfers in both directions; every frame
//! is built and parsed by [`super::proto`]. The client sends on
//! [`Channel::request`](super::Channel::request) and listens only to data frames on
//! [`Channel::response`](super::Channel::response) (11- or 29-bit, as the channel says); it ignores
//! everything else, and every frame while idle.
//!
//! Each step waits [`ClientConfig::timeout`] for the server's next frame. A
//! transfer ends with exactly one [`ClientEvent`]. When the client ends it
//! because of the server, it sends an abort frame with:
//! - 0x05040000 (timeout): no answer in time ([`SdoError::Timeout`]);
//! - 0x05040001 (command not valid): a frame that does not parse, or a
//!   response that does not fit the current step;
//! - 0x06040043 (general parameter incompatibility): an initiate response for
//!   another index or sub-index. CiA 301 has no dedicated code for this; the
//!   response does not fit the parameters of the request, which is what this
//!   code says, and it is the usual choice of SDO clients;
//! - 0x05030000: the toggle bit did not alternate;
//! - 0x05040002, 0x05040003, 0x05040004: an invalid block size, sequence
//!   number (0, above the block size, or an ack of segments never sent) or
//!   CRC in block transfers;
//! - 0x05040005 (out of memory): an upload larger than
//!   [`ClientConfig::max_upload`], announced or not; checked before anything
//!   is reserved;
//! - 0x06070010 (length mismatch): upload data longer or shorter than the
//!   size the server announced.
//!
//! An abort frame from the server ends the running transfer with
//! [`SdoError::RemoteAbort`] and nothing is sent.

mod block;
mod config;
mod segmented;
mod service;
mod stream;
#[cfg(test)]
mod tests;

use alloc::collections::VecDeque;
use alloc::vec::Vec;
use core::mem;

use super::proto::{Initiate, Request, Response};
use super::{AbortCode, MAX_BLOCK_SIZE, SdoError};
use crate::Instant;
#[cfg(doc)]
use crate::Service;

use crate::queue::Ring;
use block::{DownloadBlock, UploadBlock};
pub use config::{ClientConfig, Method};
pub use stream::WINDOW;
use stream::{Crc16, Outgoing};

/// Frames the client holds for `poll_transmit`.
const TX_SLOTS: usize = 4;

/// Data bytes in one segment (segmented and block transfers).
const SEGMENT_BYTES: usize = 7;
/// Events the client holds for [`Service::poll_event`]; starting a transfer
/// while this many wait is refused with [`Busy`].
pub const MAX_PENDING_EVENTS: usize = 8;

/// The client is already running a transfer (or holds
/// [`MAX_PENDING_EVENTS`] events the caller has not polled).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Busy;

/// The end of a transfer.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ClientEvent {
    /// An upload succeeded with this value.
    Uploaded {
        index: u16,
        sub: u8,
        data: Vec<u8>,
        /// `data` is the 4 bytes of an expedited response that indicated no
        /// size (command 0x42): the value may be shorter, and the bytes
        /// after it padding. False for every other upload, whose data is
        /// the value's exact length.
        padded: bool,
    },
    /// A download succeeded.
    Downloaded { index: u16, sub: u8 },
    /// A transfer ended without success.
    Failed {
        index: u16,
        sub: u8,
        error: SdoError,
    },
}

/// How far the running transfer got.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// Bytes sent (downloads) or received (uploads) so far.
    pub done: usize,
    /// Size of the value: known for downloads of a slice and streamed ones
    /// with a size, for uploads when the server announced it.
    pub total: Option<usize>,
}

/// Where the running transfer is; every variant but `Idle` waits for a frame
/// from the server (block downloads first send their segments).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Idle,
    /// Expedited download of `len` bytes sent.
    ExpeditedDownload {
        len: u8,
    },
    /// Segmented download initiate sent; segments follow its response.
    DownloadInitiate,
    /// The segment at `offset` (with `toggle`) waits for the caller's data
    /// (streamed downloads); nothing is due from the server.
    DownloadData {
        toggle: bool,
        offset: usize,
    },
    /// Download segment with `toggle` sent; `sent` bytes are out so far,
    /// `last` if it was the last segment.
    DownloadSegment {
        toggle: bool,
        sent: usize,
        last: bool,
    },
    /// Upload initiate sent.
    UploadInitiate,
    /// Upload segment request with `toggle` sent; `size` as announced.
    UploadSegment {
        toggle: bool,
        size: Option<usize>,
    },
    /// Block download initiate sent.
    BlockDownloadInitiate,
    /// Sending a sub-block, then waiting for its ack.
    BlockDownload(DownloadBlock),
    /// Block download end sent.
    BlockDownloadEnd,
    /// Block upload initiate sent.
    BlockUploadInitiate,
    /// Receiving the segments of a sub-block.
    BlockUpload(UploadBlock),
    /// The last segment was acked; waiting for the server's end frame.
    BlockUploadEnd(UploadBlock),
}

/// A transfer ended while handling a step (the event is queued).
struct Ended;

/// SDO client for one channel; one transfer at a time.
///
/// Drain [`Service::poll_transmit`] and [`Service::poll_event`] after every
/// input (as the [`Service`] contract asks): the client keeps at most four
/// frames to send (dropping the oldest beyond that) and
/// [`MAX_PENDING_EVENTS`] events.
#[derive(Debug)]
pub struct SdoClient {
    config: ClientConfig,
    phase: Phase,
    /// Object of the running (or last) transfer.
    index: u16,
    sub: u8,
    /// When the server's next frame is due (meaningful while not idle).
    deadline: Instant,
    /// Upload data received and not taken. Its capacity stays within
    /// `max_upload` between transfers.
    buf: Vec<u8>,
    /// The value of the running download (all of it, or a window).
    out: Outgoing,
    /// The upload being finished came in an expedited response without
    /// size indication.
    padded: bool,
    /// The running upload is streamed: the caller takes its data.
    streamed_upload: bool,
    /// Upload bytes the caller took ([`SdoClient::consume`]).
    taken: usize,
    /// CRC of the taken upload bytes.
    in_crc: Crc16,
    /// Frames built and not yet taken by `poll_transmit`; a caller that
    /// drains after every input never has more than two waiting. When full
    /// (the caller stopped draining) the oldest is dropped.
    tx: Ring<[u8; 8], TX_SLOTS>,
    events: VecDeque<ClientEvent>,
}

impl SdoClient {
    /// An idle client.
    pub fn new(config: ClientConfig) -> SdoClient {
        SdoClient {
            config,
            phase: Phase::Idle,
            index: 0,
            sub: 0,
            deadline: Instant::ZERO,
            buf: Vec::new(),
            out: Outgoing::new(),
            padded: false,
            streamed_upload: false,
            taken: 0,
            in_crc: Crc16::new(),
            tx: Ring::new(),
            events: VecDeque::new(),
        }
    }

    /// The settings the client was made with.
    pub fn config(&self) -> &ClientConfig {
        &self.config
    }

    /// Capacity of the transfer buffer in bytes (memory held between
    /// transfers; bounded by `max_upload` and the largest download).
    pub fn buffer_capacity(&self) -> usize {
        self.buf.capacity() + self.out.bytes.capacity()
    }

    /// No transfer running.
    pub fn is_idle(&self) -> bool {
        self.phase == Phase::Idle
    }

    /// How far the running transfer got; `None` while idle.
    pub fn progress(&self) -> Option<Progress> {
        let got = self.upload_total();
        let fed = self.out.fed();
        let total = self.out.len();
        let (done, total) = match self.phase {
            Phase::Idle => return None,
            Phase::ExpeditedDownload { len } => (0, Some(usize::from(len))),
            Phase::DownloadInitiate | Phase::BlockDownloadInitiate => (0, total),
            Phase::DownloadData { offset, .. } => (offset, total),
            Phase::DownloadSegment { sent, .. } => (sent, total),
            Phase::BlockDownload(block) => (block.bytes_sent(fed), total),
            Phase::BlockDownloadEnd => (fed, total),
            Phase::UploadInitiate | Phase::BlockUploadInitiate => (0, None),
            Phase::UploadSegment { size, .. } => (got, size),
            Phase::BlockUpload(block) | Phase::BlockUploadEnd(block) => (got, block.size()),
        };
        Some(Progress { done, total })
    }

    /// Starts reading (index, sub) with [`Method::Auto`].
    pub fn upload(&mut self, now: Instant, index: u16, sub: u8) -> Result<(), Busy> {
        self.upload_with(now, index, sub, Method::Auto)
    }

    /// Starts reading (index, sub); the value arrives in
    /// [`ClientEvent::Uploaded`].
    pub fn upload_with(
        &mut self,
        now: Instant,
        index: u16,
        sub: u8,
        method: Method,
    ) -> Result<(), Busy> {
        self.start(index, sub)?;
        if method.is_block(self.config.block_upload) {
            let (crc, block_size) = (self.config.crc, self.block_size());
            let request = Request::BlockUploadInitiate {
                index,
                sub,
                crc,
                block_size,
                pst: 0,
            };
            self.request(now, request, Phase::BlockUploadInitiate);
        } else {
            let request = Request::UploadInitiate { index, sub };
            self.request(now, request, Phase::UploadInitiate);
        }
        Ok(())
    }

    /// Starts writing `data` to (index, sub) with [`Method::Auto`].
    pub fn download(&mut self, now: Instant, index: u16, sub: u8, data: &[u8]) -> Result<(), Busy> {
        self.download_with(now, index, sub, data, Method::Auto)
    }

    /// Starts writing `data` to (index, sub) (the client keeps a copy); the
    /// end arrives as [`ClientEvent::Downloaded`] or `Failed`. Data of more
    /// than `u32::MAX` bytes cannot be announced: it is refused at once with
    /// `Failed { error: LocalAbort(LengthTooHigh) }`, and nothing is sent.
    pub fn download_with(
        &mut self,
        now: Instant,
        index: u16,
        sub: u8,
        data: &[u8],
        method: Method,
    ) -> Result<(), Busy> {
        self.start(index, sub)?;
        let Ok(size) = u32::try_from(data.len()) else {
            self.refuse(AbortCode::LengthTooHigh);
            return Ok(());
        };
        let standard = matches!(method, Method::Auto | Method::Standard);
        if standard && (1..=4).contains(&data.len()) {
            let mut bytes = [0u8; 4];
            for (slot, byte) in bytes.iter_mut().zip(data) {
                *slot = *byte;
            }
            let len = Some(size as u8);
            let data = Initiate::Expedited { data: bytes, len };
            let request = Request::DownloadInitiate { index, sub, data };
            self.request(now, request, Phase::ExpeditedDownload { len: size as u8 });
            return Ok(());
        }
        self.out.reset(false, Some(data.len()));
        if self.out.bytes.try_reserve_exact(data.len()).is_err() {
            self.refuse(AbortCode::OutOfMemory);
            return Ok(());
        }
        self.out.push(data);
        self.out.ended = true;
        self.initiate_download(now, Some(size), method);
        Ok(())
    }

    /// Aborts the running transfer with `code` (sends the abort frame; the
    /// transfer ends with `Failed { error: LocalAbort(code) }`). Does nothing
    /// while idle.
    pub fn abort(&mut self, code: AbortCode) {
        if !self.is_idle() {
            self.fail(code);
        }
    }

    fn start(&mut self, index: u16, sub: u8) -> Result<(), Busy> {
        if !self.is_idle() || self.events.len() >= MAX_PENDING_EVENTS {
            return Err(Busy);
        }
        self.index = index;
        self.sub = sub;
        self.buf.clear();
        self.out.reset(false, None);
        self.padded = false;
        self.streamed_upload = false;
        self.taken = 0;
        self.in_crc = Crc16::new();
        Ok(())
    }

    /// The block size the client asks for, within 1 to 127.
    fn block_size(&self) -> u8 {
        self.config.block_size.clamp(1, MAX_BLOCK_SIZE)
    }

    fn send(&mut self, request: Request) {
        self.tx.push(request.encode());
    }

    /// Sends `request` and waits for the answer in `phase`.
    fn request(&mut self, now: Instant, request: Request, phase: Phase) {
        self.send(request);
        self.wait(now, phase);
    }

    /// Enters `phase`, waiting for the server until `now` plus the timeout.
    fn wait(&mut self, now: Instant, phase: Phase) {
        self.phase = phase;
        self.deadline = now + self.config.timeout;
    }

    fn is_ours(&self, index: u16, sub: u8) -> bool {
        index == self.index && sub == self.sub
    }

    /// An answer about (index, sub): `Ok` when that is the object of the
    /// transfer, else the transfer ends (ParameterIncompatible).
    fn check_ours(&mut self, index: u16, sub: u8) -> Result<(), Ended> {
        if self.is_ours(index, sub) {
            Ok(())
        } else {
            Err(self.fail(AbortCode::ParameterIncompatible))
        }
    }

    /// Ends the transfer: sends abort `code` and reports `LocalAbort(code)`.
    fn fail(&mut self, code: AbortCode) -> Ended {
        self.send(Request::Abort {
            index: self.index,
            sub: self.sub,
            code,
        });
        self.finish_failed(SdoError::LocalAbort(code))
    }

    /// Refuses a transfer before anything was sent.
    fn refuse(&mut self, code: AbortCode) {
        self.finish_failed(SdoError::LocalAbort(code));
    }

    fn finish_failed(&mut self, error: SdoError) -> Ended {
        self.finish(ClientEvent::Failed {
            index: self.index,
            sub: self.sub,
            error,
        })
    }

    fn finish_download(&mut self) -> Ended {
        self.finish(ClientEvent::Downloaded {
            index: self.index,
            sub: self.sub,
        })
    }

    fn finish_upload(&mut self) -> Ended {
        let data = mem::take(&mut self.buf);
        self.finish(ClientEvent::Uploaded {
            index: self.index,
            sub: self.sub,
            data,
            padded: self.padded,
        })
    }

    /// Goes idle with `event`, keeping the buffer only when it is not larger
    /// than an upload may be.
    fn finish(&mut self, event: ClientEvent) -> Ended {
        self.phase = Phase::Idle;
        if self.buf.capacity() > self.config.max_upload {
            self.buf = Vec::new();
        } else {
            self.buf.clear();
        }
        let window = self.config.max_upload.max(WINDOW);
        if self.out.bytes.capacity() > window {
            self.out.bytes = VecDeque::new();
        } else {
            self.out.bytes.clear();
        }
        self.events.push_back(event);
        Ended
    }

    /// Handles a server frame other than a block upload segment.
    fn on_response(&mut self, now: Instant, response: Response) {
        if let Response::Abort { code, .. } = response {
            self.finish_failed(SdoError::RemoteAbort(code));
            return;
        }
        // Each handler queues its own frames and events; whether the
        // transfer ended is of no further use here.
        let _ = match (self.phase, response) {
            (
                Phase::ExpeditedDownload { .. } | Phase::DownloadInitiate,
                Response::DownloadInitiate { index, sub },
            ) => {
                if !self.is_ours(index, sub) {
                    Err(self.fail(AbortCode::ParameterIncompatible))
                } else if self.phase == Phase::DownloadInitiate {
                    self.send_download_segment(now, 0, false);
                    Ok(())
                } else {
                    Err(self.finish_download())
                }
            }
            (
                Phase::DownloadSegment { toggle, sent, last },
                Response::DownloadSegment { toggle: echo },
            ) => {
                if echo != toggle {
                    Err(self.fail(AbortCode::ToggleBitNotAlternated))
                } else if last {
                    Err(self.finish_download())
                } else {
                    self.send_download_segment(now, sent, !toggle);
                    Ok(())
                }
            }
            (
                Phase::UploadInitiate | Phase::BlockUploadInitiate,
                Response::UploadInitiate { index, sub, data },
            ) => self.on_upload_initiate(now, index, sub, data),
            (
                Phase::UploadSegment { toggle, size },
                Response::UploadSegment {
                    toggle: echo,
                    last,
                    data,
                    len,
                },
            ) => {
                if echo != toggle {
                    Err(self.fail(AbortCode::ToggleBitNotAlternated))
                } else {
                    let bytes = data.get(..usize::from(len)).unwrap_or(&data);
                    self.on_upload_segment(now, toggle, size, bytes, last)
                }
            }
            (
                Phase::BlockDownloadInitiate,
                Response::BlockDownloadInitiate {
                    index,
                    sub,
                    crc,
                    block_size,
                },
            ) => self.on_block_download_initiate(now, index, sub, crc, block_size),
            (
                Phase::BlockDownload(block),
                Response::BlockDownloadAck {
                    ack_seq,
                    block_size,
                },
            ) => self.on_block_download_ack(now, block, ack_seq, block_size),
            (Phase::BlockDownloadEnd, Response::BlockDownloadEnd) => Err(self.finish_download()),
            (
                Phase::BlockUploadInitiate,
                Response::BlockUploadInitiate {
                    index,
                    sub,
                    crc,
                    size,
                },
            ) => self.on_block_upload_initiate(now, index, sub, crc, size),
            (Phase::BlockUploadEnd(block), Response::BlockUploadEnd { unused, crc }) => {
                self.on_block_upload_end(block, unused, crc)
            }
            _ => Err(self.fail(AbortCode::InvalidCommand)),
        };
    }
}
