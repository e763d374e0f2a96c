//! Block transfers (CiA 301 "SDO block download" and "SDO block upload").

use super::super::proto::{BlockSegment, CRC, Request, Response};
use super::{
    MAX_BLOCK_SIZE, ObjectStore, SEGMENT, SdoServer, ServerEvent, State, append_bounded,
    offered_block_size, padded_len, segment_error,
};
use crate::sdo::AbortCode;

/// A running block download.
#[derive(Debug)]
pub(in crate::sdo::server) struct BlockDownload {
    /// CRC agreed by both sides.
    crc: bool,
    /// Size the client announced.
    size: Option<usize>,
    /// Most bytes the buffer may hold, counted in whole segments.
    limit: usize,
    /// Segments in the current sub-block.
    block_size: u8,
    /// Sequence number of the next in-order segment.
    next_seq: u8,
    /// A segment went missing: the rest of the sub-block is ignored.
    gap: bool,
    /// The last segment arrived in order: the end request is due.
    ended: bool,
}

impl BlockDownload {
    /// Whether segments (rather than the end request) are expected.
    pub(super) fn in_sub_block(&self) -> bool {
        !self.ended
    }

    /// Takes one segment; appends it to `buf` when it is the next in order.
    fn accept(
        &mut self,
        segment: &BlockSegment,
        buf: &mut alloc::vec::Vec<u8>,
        next_block: u8,
    ) -> Step {
        if segment.seq > self.block_size {
            return Step::Fail(AbortCode::InvalidSequenceNumber);
        }
        if !self.gap && segment.seq == self.next_seq {
            if buf.len().saturating_add(SEGMENT) > self.limit {
                return Step::Fail(if self.size.is_some() {
                    AbortCode::LengthTooHigh
                } else {
                    AbortCode::OutOfMemory
                });
            }
            append_bounded(buf, &segment.data, self.limit);
            self.next_seq = self.next_seq.saturating_add(1);
            self.ended = segment.last;
        } else if segment.seq > self.next_seq {
            self.gap = true;
        }
        // Older sequence numbers are repeats and change nothing.
        if segment.last || segment.seq == self.block_size {
            let ack_seq = self.next_seq.saturating_sub(1);
            self.next_seq = 1;
            self.gap = false;
            self.block_size = next_block;
            Step::Ack(ack_seq)
        } else {
            Step::Continue
        }
    }
}

/// What a block-download segment leads to.
enum Step {
    /// Wait for more segments.
    Continue,
    /// The sub-block ended: acknowledge this sequence number.
    Ack(u8),
    /// Abort the transfer.
    Fail(AbortCode),
}

/// A running block upload.
#[derive(Debug)]
pub(in crate::sdo::server) struct BlockUpload {
    /// CRC agreed by both sides.
    crc: bool,
    /// Segments per sub-block, as the client last asked.
    block_size: u8,
    /// Segments the value takes (at least one, even when it is empty).
    total_segments: usize,
    /// Segments the client has acknowledged.
    acked: usize,
    phase: UploadPhase,
}

#[derive(Debug, Clone, Copy)]
enum UploadPhase {
    /// Initiate answered; the client's start request is due.
    AwaitStart,
    /// Sending a sub-block of `count` segments, `sent` of them handed out;
    /// once all are sent, the client's acknowledgement is due.
    SubBlock { sent: u8, count: u8 },
    /// End frame sent; the client's end response is due.
    AwaitEnd,
}

impl BlockUpload {
    /// The sub-block starting at the first unacknowledged segment.
    fn next_sub_block(&self) -> UploadPhase {
        let remaining = self.total_segments.saturating_sub(self.acked);
        let count = remaining.min(usize::from(self.block_size)) as u8;
        UploadPhase::SubBlock { sent: 0, count }
    }
}

impl<S: ObjectStore> SdoServer<S> {
    /// Block download initiate: checks the size bound and the store, then
    /// offers the block size and the CRC.
    pub(super) fn block_download_initiate(&mut self, crc: bool, size: Option<u32>) {
        let size = match self.download_size(size) {
            Ok(size) => size,
            Err(code) => return self.fail(code),
        };
        let (index, sub) = self.object;
        let limit = padded_len(size.unwrap_or(self.config.max_download));
        if size.is_some() {
            self.buf.reserve_exact(limit);
        }
        let crc = crc && self.config.crc;
        let block_size = offered_block_size(&self.config);
        self.state = State::BlockDownload(BlockDownload {
            crc,
            size,
            limit,
            block_size,
            next_seq: 1,
            gap: false,
            ended: false,
        });
        self.send(Response::BlockDownloadInitiate {
            index,
            sub,
            crc,
            block_size,
        });
    }

    /// A frame received while a block-download sub-block is in flight: an
    /// abort, or a segment.
    pub(super) fn block_download_frame(&mut self, data: &[u8]) {
        if BlockSegment::is_abort(data) {
            let code = match Request::parse(data) {
                Ok(Request::Abort { code, .. }) => code,
                _ => AbortCode::GeneralError,
            };
            return self.remote_abort(code);
        }
        // An empty value may come without any segment (python-canopen's
        // client sends the end request right after the initiate): for an
        // announced size of 0, an end request before the first segment ends
        // the transfer.
        if let State::BlockDownload(transfer) = &mut self.state
            && transfer.size == Some(0)
            && transfer.next_seq == 1
            && !transfer.gap
            && self.buf.is_empty()
            && let Ok(Request::BlockDownloadEnd { crc, .. }) = Request::parse(data)
        {
            transfer.ended = true;
            return self.block_download_end(0, crc);
        }
        let segment = match BlockSegment::parse(data) {
            Ok(segment) => segment,
            Err(error) => return self.fail(segment_error(error)),
        };
        let next_block = offered_block_size(&self.config);
        let State::BlockDownload(transfer) = &mut self.state else {
            return;
        };
        match transfer.accept(&segment, &mut self.buf, next_block) {
            Step::Continue => {}
            Step::Ack(ack_seq) => self.send(Response::BlockDownloadAck {
                ack_seq,
                block_size: next_block,
            }),
            Step::Fail(code) => self.fail(code),
        }
    }

    /// Block download end: checks the unused-byte count, the CRC and the
    /// size, then writes the value.
    pub(super) fn block_download_end(&mut self, unused: u8, crc: u16) {
        let (agreed_crc, size) = match &self.state {
            State::BlockDownload(transfer) if transfer.ended => (transfer.crc, transfer.size),
            _ => return self.reject(AbortCode::InvalidCommand),
        };
        let received = self.buf.len();
        let unused = usize::from(unused);
        // Seven unused bytes only describe an empty value (one blank segment).
        let len = match received.checked_sub(unused) {
            Some(len) if unused < SEGMENT || received == SEGMENT => len,
            _ => return self.fail(AbortCode::InvalidCommand),
        };
        self.buf.truncate(len);
        if agreed_crc && CRC.checksum(&self.buf) != crc {
            return self.fail(AbortCode::CrcError);
        }
        self.complete_download(size, Response::BlockDownloadEnd);
    }

    /// Block upload initiate: checks the client's block size, reads the
    /// value and announces its size. The protocol switch threshold is
    /// ignored (always a block upload).
    pub(super) fn block_upload_initiate(&mut self, crc: bool, block_size: u8) {
        if !(1..=MAX_BLOCK_SIZE).contains(&block_size) {
            return self.fail(AbortCode::InvalidBlockSize);
        }
        let (index, sub) = self.object;
        if let Err(code) = self.store.read(index, sub, &mut self.buf) {
            return self.fail(code);
        }
        let len = self.buf.len();
        let crc = crc && self.config.crc;
        self.state = State::BlockUpload(BlockUpload {
            crc,
            block_size,
            total_segments: len.div_ceil(SEGMENT).max(1),
            acked: 0,
            phase: UploadPhase::AwaitStart,
        });
        self.send(Response::BlockUploadInitiate {
            index,
            sub,
            crc,
            size: u32::try_from(len).ok(),
        });
    }

    /// Block upload start: the first sub-block is sent by `poll_transmit`.
    pub(super) fn block_upload_start(&mut self) {
        match &mut self.state {
            State::BlockUpload(transfer) if matches!(transfer.phase, UploadPhase::AwaitStart) => {
                transfer.phase = transfer.next_sub_block();
            }
            _ => self.reject(AbortCode::InvalidCommand),
        }
    }

    /// The next segment of the sub-block being sent, if any.
    pub(super) fn next_upload_segment(&mut self) -> Option<[u8; 8]> {
        let State::BlockUpload(transfer) = &mut self.state else {
            return None;
        };
        let UploadPhase::SubBlock { sent, count } = &mut transfer.phase else {
            return None;
        };
        if *sent >= *count {
            return None;
        }
        *sent += 1;
        let seq = *sent;
        let segment = transfer.acked.saturating_add(usize::from(seq) - 1);
        let start = segment.saturating_mul(SEGMENT);
        let end = start.saturating_add(SEGMENT).min(self.buf.len());
        let mut data = [0u8; 7];
        if let Some(chunk) = self.buf.get(start..end) {
            for (d, s) in data.iter_mut().zip(chunk.iter()) {
                *d = *s;
            }
        }
        let last = segment.saturating_add(1) >= transfer.total_segments;
        Some(BlockSegment { seq, last, data }.encode())
    }

    /// Block upload acknowledgement: the next sub-block resumes after the
    /// last segment the client acknowledged; when all are, the end frame
    /// goes out.
    pub(super) fn block_upload_ack(&mut self, ack_seq: u8, block_size: u8) {
        let State::BlockUpload(transfer) = &mut self.state else {
            return self.reject(AbortCode::InvalidCommand);
        };
        let UploadPhase::SubBlock { count, .. } = transfer.phase else {
            return self.reject(AbortCode::InvalidCommand);
        };
        if ack_seq > count {
            return self.fail(AbortCode::InvalidSequenceNumber);
        }
        if !(1..=MAX_BLOCK_SIZE).contains(&block_size) {
            return self.fail(AbortCode::InvalidBlockSize);
        }
        transfer.acked = transfer.acked.saturating_add(usize::from(ack_seq));
        transfer.block_size = block_size;
        if transfer.acked < transfer.total_segments {
            transfer.phase = transfer.next_sub_block();
            return;
        }
        transfer.phase = UploadPhase::AwaitEnd;
        let len = self.buf.len();
        let unused = transfer
            .total_segments
            .saturating_mul(SEGMENT)
            .saturating_sub(len) as u8;
        let crc = if transfer.crc {
            CRC.checksum(&self.buf)
        } else {
            0
        };
        self.send(Response::BlockUploadEnd { unused, crc });
    }

    /// The client's end response: the upload is complete.
    pub(super) fn block_upload_end(&mut self) {
        match &self.state {
            State::BlockUpload(transfer) if matches!(transfer.phase, UploadPhase::AwaitEnd) => {
                let (index, sub) = self.object;
                let len = self.buf.len();
                self.succeed(ServerEvent::Uploaded { index, sub, len });
            }
            _ => self.reject(AbortCode::InvalidCommand),
        }
    }
}
