//! Expedited and segmented transfers (the standard SDO protocols of
//! CiA 301), and the bounded upload buffer that block uploads share.

use alloc::collections::TryReserveError;
use alloc::vec::Vec;

use super::{Ended, Phase, SdoClient};
use crate::Instant;
use crate::sdo::AbortCode;
use crate::sdo::proto::{Initiate, Request};

/// Smallest capacity the upload buffer grows to when the size is unknown.
const MIN_GROWTH: usize = 64;

impl SdoClient {
    /// Checks a size the server announced against `max_upload` and reserves
    /// it; fails the transfer with out of memory when it does not fit.
    pub(super) fn reserve_announced(&mut self, size: Option<u32>) -> Result<Option<usize>, Ended> {
        let Some(size) = size else {
            return Ok(None);
        };
        match usize::try_from(size) {
            // A streamed upload holds only what was not taken: nothing to
            // reserve.
            Ok(size) if size <= self.config.max_upload && self.streamed_upload => Ok(Some(size)),
            Ok(size)
                if size <= self.config.max_upload && self.buf.try_reserve_exact(size).is_ok() =>
            {
                Ok(Some(size))
            }
            _ => Err(self.fail(AbortCode::OutOfMemory)),
        }
    }

    /// Appends upload data, bounded by the announced `size` (else by
    /// `max_upload`); fails the transfer when it does not fit.
    pub(super) fn append_upload(&mut self, bytes: &[u8], size: Option<usize>) -> Result<(), Ended> {
        let limit = size.unwrap_or(self.config.max_upload);
        if self.upload_total().saturating_add(bytes.len()) > limit {
            return Err(self.fail(too_long_code(size)));
        }
        let room = limit.saturating_sub(self.taken);
        if reserve_bounded(&mut self.buf, bytes.len(), room).is_err() {
            return Err(self.fail(AbortCode::OutOfMemory));
        }
        self.buf.extend_from_slice(bytes);
        Ok(())
    }

    /// Sends the download segment starting at byte `offset`, or waits for
    /// the caller's data when a streamed download does not have it yet.
    pub(super) fn send_download_segment(&mut self, now: Instant, offset: usize, toggle: bool) {
        self.out.release_before(offset);
        let Some((data, len, last)) = self.out.segment_at(offset) else {
            self.phase = Phase::DownloadData { toggle, offset };
            return;
        };
        self.send(Request::DownloadSegment {
            toggle,
            last,
            data,
            len: len as u8,
        });
        self.wait(
            now,
            Phase::DownloadSegment {
                toggle,
                sent: offset + len,
                last,
            },
        );
    }

    /// The server's answer to an upload initiate (also when it switched from
    /// a block upload to the standard protocol).
    pub(super) fn on_upload_initiate(
        &mut self,
        now: Instant,
        index: u16,
        sub: u8,
        data: Initiate,
    ) -> Result<(), Ended> {
        self.check_ours(index, sub)?;
        match data {
            Initiate::Expedited { data, len } => {
                let bytes = data.get(..usize::from(len.unwrap_or(4))).unwrap_or(&data);
                self.append_upload(bytes, None)?;
                self.padded = len.is_none();
                Err(self.finish_upload())
            }
            Initiate::Segmented { size } => {
                let size = self.reserve_announced(size)?;
                self.send(Request::UploadSegment { toggle: false });
                self.wait(
                    now,
                    Phase::UploadSegment {
                        toggle: false,
                        size,
                    },
                );
                Ok(())
            }
        }
    }

    /// An upload segment with the expected toggle bit.
    pub(super) fn on_upload_segment(
        &mut self,
        now: Instant,
        toggle: bool,
        size: Option<usize>,
        bytes: &[u8],
        last: bool,
    ) -> Result<(), Ended> {
        self.append_upload(bytes, size)?;
        if !last {
            self.send(Request::UploadSegment { toggle: !toggle });
            self.wait(
                now,
                Phase::UploadSegment {
                    toggle: !toggle,
                    size,
                },
            );
            return Ok(());
        }
        if size.is_some_and(|size| size != self.upload_total()) {
            return Err(self.fail(AbortCode::LengthMismatch));
        }
        Err(self.finish_upload())
    }
}

/// The abort code for upload data beyond the announced size, or beyond
/// `max_upload` when no size was announced.
pub(super) fn too_long_code(size: Option<usize>) -> AbortCode {
    if size.is_some() {
        AbortCode::LengthMismatch
    } else {
        AbortCode::OutOfMemory
    }
}

/// Makes room for `additional` more bytes, growing geometrically but never
/// beyond `limit` (`buf.len() + additional` must not exceed it).
pub(super) fn reserve_bounded(
    buf: &mut Vec<u8>,
    additional: usize,
    limit: usize,
) -> Result<(), TryReserveError> {
    let needed = buf.len().saturating_add(additional);
    if needed <= buf.capacity() {
        return Ok(());
    }
    let target = buf
        .capacity()
        .saturating_mul(2)
        .max(MIN_GROWTH)
        .min(limit)
        .max(needed);
    buf.try_reserve_exact(target - buf.len())
}
