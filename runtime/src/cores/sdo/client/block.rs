//! Block download and block upload of the SDO client (CiA 301 SDO block
//! protocols): sub-blocks of up to 127 numbered segments, each acknowledged
//! by the receiver, and a final CRC-16 over the whole value.

use super::segmented::{reserve_bounded, too_long_code};
use super::{Ended, MAX_BLOCK_SIZE, Phase, SEGMENT_BYTES, SdoClient};
use crate::Instant;
use crate::sdo::AbortCode;
use crate::sdo::proto::{BlockSegment, ParseError, Request};

/// State of a block download between the server's initiate response and the
/// end frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct DownloadBlock {
    /// Both sides agreed on a CRC.
    crc: bool,
    /// Segments the server acknowledged, over all sub-blocks.
    confirmed: usize,
    /// Segments in the current sub-block: the server's block size, or fewer
    /// when less data is left (found out when the last one is sent, for a
    /// streamed value of unknown size).
    in_block: u8,
    /// Segments of the current sub-block handed out by `poll_transmit`.
    sent: u8,
}

impl DownloadBlock {
    /// Segments of the current sub-block remain to be sent.
    pub(super) fn has_unsent(&self) -> bool {
        self.sent < self.in_block
    }

    /// Bytes handed out so far (of `len` handed in), for progress reports.
    pub(super) fn bytes_sent(&self, len: usize) -> usize {
        self.confirmed
            .saturating_add(usize::from(self.sent))
            .saturating_mul(SEGMENT_BYTES)
            .min(len)
    }
}

/// State of a block upload from the server's initiate response to its end
/// frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct UploadBlock {
    /// Both sides agreed on a CRC.
    crc: bool,
    /// The size the server announced.
    size: Option<usize>,
    /// Sequence number of the last segment received in order in the current
    /// sub-block (0: none yet).
    last_good: u8,
    /// A segment of the current sub-block went missing: the rest of the
    /// sub-block is ignored and the server resends it after the ack.
    gap: bool,
    /// Bytes of the segments taken, 7 per segment (the end frame tells how
    /// many of the last one carry no data).
    received: usize,
}

impl UploadBlock {
    /// The size the server announced.
    pub(super) fn size(&self) -> Option<usize> {
        self.size
    }
}

/// Segments needed for `len` bytes (at least one, also for no data).
fn segment_count(len: usize) -> usize {
    len.div_ceil(SEGMENT_BYTES).max(1)
}

impl SdoClient {
    /// The server accepted a block download with its block size.
    pub(super) fn on_block_download_initiate(
        &mut self,
        now: Instant,
        index: u16,
        sub: u8,
        crc: bool,
        block_size: u8,
    ) -> Result<(), Ended> {
        self.check_ours(index, sub)?;
        self.start_sub_block(now, crc && self.config.crc, 0, block_size)
    }

    /// The server acknowledged `ack_seq` segments of the sub-block and asks
    /// for `block_size` segments in the next one.
    pub(super) fn on_block_download_ack(
        &mut self,
        now: Instant,
        block: DownloadBlock,
        ack_seq: u8,
        block_size: u8,
    ) -> Result<(), Ended> {
        if ack_seq > block.sent {
            return Err(self.fail(AbortCode::InvalidSequenceNumber));
        }
        let confirmed = block.confirmed.saturating_add(usize::from(ack_seq));
        self.start_sub_block(now, block.crc, confirmed, block_size)
    }

    /// Sends the next sub-block from segment `confirmed` on (through
    /// `poll_transmit`), or the end frame once every segment is confirmed.
    fn start_sub_block(
        &mut self,
        now: Instant,
        crc: bool,
        confirmed: usize,
        block_size: u8,
    ) -> Result<(), Ended> {
        if block_size == 0 || block_size > MAX_BLOCK_SIZE {
            return Err(self.fail(AbortCode::InvalidBlockSize));
        }
        self.out
            .release_before(confirmed.saturating_mul(SEGMENT_BYTES));
        // The segments of the value, once its length is known.
        let total = self.out.len().map(segment_count);
        if self.out.ended && total.is_some_and(|total| confirmed >= total) {
            let total = total.unwrap_or(1);
            let unused = total
                .saturating_mul(SEGMENT_BYTES)
                .saturating_sub(self.out.fed());
            let crc = if crc { self.out.crc.value() } else { 0 };
            let request = Request::BlockDownloadEnd {
                unused: unused as u8,
                crc,
            };
            self.request(now, request, Phase::BlockDownloadEnd);
            return Ok(());
        }
        let left = total.map_or(usize::MAX, |total| total.saturating_sub(confirmed));
        let in_block = left.min(usize::from(block_size)) as u8;
        self.wait(
            now,
            Phase::BlockDownload(DownloadBlock {
                crc,
                confirmed,
                in_block,
                sent: 0,
            }),
        );
        Ok(())
    }

    /// The next segment of the running sub-block, built in place.
    pub(super) fn next_block_segment(&mut self) -> Option<[u8; 8]> {
        let Phase::BlockDownload(mut block) = self.phase else {
            return None;
        };
        if !block.has_unsent() {
            return None;
        }
        let segment = block.confirmed.saturating_add(usize::from(block.sent));
        // A streamed value may not have the segment's data yet.
        let (data, _, last) = self.out.segment_at(segment.saturating_mul(SEGMENT_BYTES))?;
        block.sent += 1;
        if last {
            // The value ends here: so does the sub-block.
            block.in_block = block.sent;
        }
        let encoded = BlockSegment {
            seq: block.sent,
            last,
            data,
        }
        .encode();
        self.phase = Phase::BlockDownload(block);
        Some(encoded)
    }

    /// The server's answer to a block upload initiate: checks the announced
    /// size, reserves it and starts the first sub-block.
    pub(super) fn on_block_upload_initiate(
        &mut self,
        now: Instant,
        index: u16,
        sub: u8,
        crc: bool,
        size: Option<u32>,
    ) -> Result<(), Ended> {
        self.check_ours(index, sub)?;
        let size = self.reserve_announced(size)?;
        self.send(Request::BlockUploadStart);
        self.wait(
            now,
            Phase::BlockUpload(UploadBlock {
                crc: crc && self.config.crc,
                size,
                last_good: 0,
                gap: false,
                received: 0,
            }),
        );
        Ok(())
    }

    /// A frame received while a sub-block is under way (not an abort).
    pub(super) fn on_block_upload_segment(
        &mut self,
        now: Instant,
        mut block: UploadBlock,
        frame: &[u8],
    ) {
        let block_size = self.block_size();
        let segment = match BlockSegment::parse(frame) {
            Ok(segment) if segment.seq <= block_size => segment,
            Ok(_) | Err(ParseError::Field(_)) => {
                self.fail(AbortCode::InvalidSequenceNumber);
                return;
            }
            Err(error) => {
                self.fail(error.abort_code());
                return;
            }
        };
        let in_order = !block.gap && segment.seq == block.last_good.saturating_add(1);
        if in_order {
            if self.take_block_data(&mut block, &segment.data).is_err() {
                return;
            }
            block.last_good = segment.seq;
        } else {
            block.gap = true;
        }
        if !segment.last && segment.seq != block_size {
            self.wait(now, Phase::BlockUpload(block));
            return;
        }
        // End of the sub-block: acknowledge what arrived in order; after a
        // gap the server resends the rest in the next sub-block.
        self.send(Request::BlockUploadAck {
            ack_seq: block.last_good,
            block_size,
        });
        block.last_good = 0;
        block.gap = false;
        let phase = if in_order && segment.last {
            Phase::BlockUploadEnd(block)
        } else {
            Phase::BlockUpload(block)
        };
        self.wait(now, phase);
    }

    /// Keeps the data of an in-order segment: up to the announced size (or
    /// `max_upload`); a segment beyond that fails the transfer.
    fn take_block_data(
        &mut self,
        block: &mut UploadBlock,
        data: &[u8; SEGMENT_BYTES],
    ) -> Result<(), Ended> {
        let limit = block.size.unwrap_or(self.config.max_upload);
        // Only the last segment may reach beyond the limit (by its unused
        // bytes); once the limit is reached, no further segment may come.
        if block.received > 0 && block.received >= limit {
            return Err(self.fail(too_long_code(block.size)));
        }
        let take = limit.saturating_sub(self.upload_total()).min(SEGMENT_BYTES);
        let bytes = data.get(..take).unwrap_or(data);
        let room = limit.saturating_sub(self.taken);
        if reserve_bounded(&mut self.buf, bytes.len(), room).is_err() {
            return Err(self.fail(AbortCode::OutOfMemory));
        }
        self.buf.extend_from_slice(bytes);
        block.received = block.received.saturating_add(SEGMENT_BYTES);
        Ok(())
    }

    /// The server's end frame: checks length and CRC, confirms and completes.
    pub(super) fn on_block_upload_end(
        &mut self,
        block: UploadBlock,
        unused: u8,
        crc: u16,
    ) -> Result<(), Ended> {
        let len = block.received.saturating_sub(usize::from(unused));
        if block.size.is_some_and(|size| size != len) {
            return Err(self.fail(AbortCode::LengthMismatch));
        }
        if len > self.upload_total() {
            // Only possible without an announced size, past `max_upload`.
            return Err(self.fail(AbortCode::OutOfMemory));
        }
        // The bytes taken so far are final (the last segment is held back).
        self.buf.truncate(len.saturating_sub(self.taken));
        if block.crc {
            let mut check = self.in_crc.clone();
            check.update(&self.buf);
            if check.value() != crc {
                return Err(self.fail(AbortCode::CrcError));
            }
        }
        self.send(Request::BlockUploadEnd);
        Err(self.finish_upload())
    }
}
