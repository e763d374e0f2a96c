//! Streamed transfers: a download whose data the caller hands in while it
//! runs ([`SdoClient::download_stream`], [`SdoClient::feed`],
//! [`SdoClient::end_of_data`]) and an upload whose data the caller takes
//! while it runs ([`SdoClient::upload_stream`], [`SdoClient::received`],
//! [`SdoClient::consume`]). The client then holds a window of the value,
//! never all of it: for downloads the segments not yet confirmed by the
//! server plus what the next frames need ([`WINDOW`] bytes at most); for
//! uploads what arrived and was not taken yet.
//!
//! A segment is only sent once the client knows whether it is the last one:
//! with an announced size that is known from the start; without one, the
//! caller either hands in more than a segment beyond it or says the data
//! ends ([`SdoClient::end_of_data`]). Segmented downloads without a size
//! indication are CiA 301 (the initiate has `s = 0`), and so are block
//! downloads without one (the end frame tells the unused bytes of the last
//! segment).

use alloc::collections::VecDeque;
use core::fmt;

use super::{Busy, MAX_BLOCK_SIZE, Method, Phase, SEGMENT_BYTES, SdoClient};
use crate::Instant;
use crate::sdo::AbortCode;
use crate::sdo::proto::{CRC, Initiate, Request};

/// Most download bytes a streamed download holds: a whole sub-block of 127
/// segments that the server may ask to have resent, plus the next segment
/// (to know whether the one before it is the last).
pub const WINDOW: usize = (MAX_BLOCK_SIZE as usize + 1) * SEGMENT_BYTES + 1;

/// A running CRC-16 of block transfers.
#[derive(Clone)]
pub(super) struct Crc16(crc::Digest<'static, u16>);

impl Crc16 {
    pub(super) fn new() -> Crc16 {
        Crc16(CRC.digest())
    }

    pub(super) fn update(&mut self, bytes: &[u8]) {
        self.0.update(bytes);
    }

    pub(super) fn value(&self) -> u16 {
        self.0.clone().finalize()
    }
}

impl fmt::Debug for Crc16 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Crc16({:#06x})", self.value())
    }
}

/// The outgoing value of a download: all of it, or a window of a stream.
#[derive(Debug)]
pub(super) struct Outgoing {
    /// The value's bytes from `base` on.
    pub(super) bytes: VecDeque<u8>,
    /// Offset in the value of `bytes[0]`.
    pub(super) base: usize,
    /// The value ends after the bytes handed in (always for a download of a
    /// slice).
    pub(super) ended: bool,
    /// The size the initiate announced.
    pub(super) size: Option<usize>,
    /// Whether the caller hands the data in while the transfer runs.
    pub(super) streamed: bool,
    /// CRC of the bytes handed in so far.
    pub(super) crc: Crc16,
}

impl Outgoing {
    pub(super) fn new() -> Outgoing {
        Outgoing {
            bytes: VecDeque::new(),
            base: 0,
            ended: true,
            size: None,
            streamed: false,
            crc: Crc16::new(),
        }
    }

    /// Empties it for a new transfer, keeping the capacity.
    pub(super) fn reset(&mut self, streamed: bool, size: Option<usize>) {
        self.bytes.clear();
        self.base = 0;
        // A stream of an announced 0 bytes has ended before it began.
        self.ended = !streamed || size == Some(0);
        self.size = size;
        self.streamed = streamed;
        self.crc = Crc16::new();
    }

    /// Bytes of the value handed in so far.
    pub(super) fn fed(&self) -> usize {
        self.base + self.bytes.len()
    }

    /// The value's length, once known.
    pub(super) fn len(&self) -> Option<usize> {
        self.size.or(self.ended.then(|| self.fed()))
    }

    /// Appends bytes of the value.
    pub(super) fn push(&mut self, data: &[u8]) {
        self.bytes.extend(data);
        self.crc.update(data);
        if self.size == Some(self.fed()) {
            self.ended = true;
        }
    }

    /// Forgets the bytes before `offset` (the server confirmed them).
    pub(super) fn release_before(&mut self, offset: usize) {
        let n = offset.saturating_sub(self.base).min(self.bytes.len());
        self.bytes.drain(..n);
        self.base += n;
    }

    /// The segment at `offset`: its bytes, their number and whether it is
    /// the last; `None` while that is not known yet (more data must come).
    pub(super) fn segment_at(&self, offset: usize) -> Option<([u8; SEGMENT_BYTES], usize, bool)> {
        let available = self.fed().saturating_sub(offset);
        if !self.ended && available <= SEGMENT_BYTES {
            return None;
        }
        let len = available.min(SEGMENT_BYTES);
        let mut data = [0u8; SEGMENT_BYTES];
        let start = offset.saturating_sub(self.base);
        for (slot, byte) in data.iter_mut().zip(self.bytes.range(start..start + len)) {
            *slot = *byte;
        }
        Some((data, len, self.ended && available <= SEGMENT_BYTES))
    }
}

impl SdoClient {
    /// Starts writing a value to (index, sub) whose data the caller hands in
    /// while the transfer runs, with [`SdoClient::feed`] whenever
    /// [`SdoClient::wants_data`] is above 0, and [`SdoClient::end_of_data`]
    /// at its end (not needed with a `size`: the value ends there). With
    /// `size` the initiate announces it; without, it does not (CiA 301
    /// allows both). [`Method::Block`] (or [`Method::Auto`] with
    /// `block_download_above` below `size`) uses a block download, any other
    /// a segmented one: expedited transfers need the data at the start.
    pub fn download_stream(
        &mut self,
        now: Instant,
        index: u16,
        sub: u8,
        size: Option<u32>,
        method: Method,
    ) -> Result<(), Busy> {
        self.start(index, sub)?;
        self.out.reset(true, size.map(|s| s as usize));
        self.initiate_download(now, size, method);
        Ok(())
    }

    /// Sends the initiate of a segmented or block download (of the value in
    /// `self.out`): block with [`Method::Block`], or with [`Method::Auto`]
    /// when `block_download_above` is below the size.
    pub(super) fn initiate_download(&mut self, now: Instant, size: Option<u32>, method: Method) {
        let (index, sub) = (self.index, self.sub);
        let auto = matches!(
            (self.config.block_download_above, size),
            (Some(above), Some(size)) if size as usize > above
        );
        if method.is_block(auto) {
            let crc = self.config.crc;
            let request = Request::BlockDownloadInitiate {
                index,
                sub,
                crc,
                size,
            };
            self.request(now, request, Phase::BlockDownloadInitiate);
        } else {
            let data = Initiate::Segmented { size };
            let request = Request::DownloadInitiate { index, sub, data };
            self.request(now, request, Phase::DownloadInitiate);
        }
    }

    /// How many more bytes a streamed download takes now; 0 while it has
    /// what its next frames need, after its end, and for other transfers.
    pub fn wants_data(&self) -> usize {
        if !self.out.streamed || self.out.ended || !self.is_download() {
            return 0;
        }
        let room = WINDOW.saturating_sub(self.out.bytes.len());
        match self.out.size {
            Some(size) => room.min(size.saturating_sub(self.out.fed())),
            None => room,
        }
    }

    /// Hands in the next bytes of a streamed download; returns how many it
    /// took (at most [`SdoClient::wants_data`]). Frames the data completes
    /// are ready in `poll_transmit` right after.
    pub fn feed(&mut self, now: Instant, data: &[u8]) -> usize {
        let take = data.len().min(self.wants_data());
        if take == 0 {
            return 0;
        }
        self.out.push(data.get(..take).unwrap_or(data));
        self.resume(now);
        take
    }

    /// Says a streamed download's data ends here. With an announced size
    /// that was not reached, the transfer is aborted with 0x08000000
    /// (general error) and fails with that code.
    pub fn end_of_data(&mut self, now: Instant) {
        if !self.out.streamed || self.out.ended || !self.is_download() {
            return;
        }
        if self.out.size.is_some_and(|size| self.out.fed() < size) {
            self.fail(AbortCode::GeneralError);
            return;
        }
        self.out.ended = true;
        self.resume(now);
    }

    /// Sends what waited for data.
    fn resume(&mut self, now: Instant) {
        if let Phase::DownloadData { toggle, offset } = self.phase {
            self.send_download_segment(now, offset, toggle);
        }
    }

    fn is_download(&self) -> bool {
        matches!(
            self.phase,
            Phase::DownloadInitiate
                | Phase::DownloadData { .. }
                | Phase::DownloadSegment { .. }
                | Phase::BlockDownloadInitiate
                | Phase::BlockDownload(_)
        )
    }

    /// Starts reading (index, sub) into the caller's hands while the
    /// transfer runs: take [`SdoClient::received`] and
    /// [`SdoClient::consume`] it after every input; the end event carries
    /// the rest. `max_upload` still bounds the value, but only what was not
    /// taken is held (nothing is reserved for an announced size).
    pub fn upload_stream(
        &mut self,
        now: Instant,
        index: u16,
        sub: u8,
        method: Method,
    ) -> Result<(), Busy> {
        self.upload_with(now, index, sub, method)?;
        self.streamed_upload = true;
        Ok(())
    }

    /// Upload data that arrived and is final: of a block upload, all but the
    /// last segment's bytes (which may be padding until the end frame).
    pub fn received(&self) -> &[u8] {
        let held = match self.phase {
            Phase::BlockUpload(_) | Phase::BlockUploadEnd(_) => SEGMENT_BYTES,
            _ => 0,
        };
        let ready = self.buf.len().saturating_sub(held);
        self.buf.get(..ready).unwrap_or(&[])
    }

    /// Drops the first `n` bytes of [`SdoClient::received`]: the caller has
    /// them.
    pub fn consume(&mut self, n: usize) {
        let n = n.min(self.received().len());
        if let Some(taken) = self.buf.get(..n) {
            self.in_crc.update(taken);
        }
        self.buf.drain(..n);
        self.taken += n;
    }

    /// Upload bytes received so far, taken or not.
    pub(super) fn upload_total(&self) -> usize {
        self.taken + self.buf.len()
    }
}
