//! Expedited and segmented transfers (CiA 301 "SDO download" and "SDO
//! upload" protocols).

use super::super::proto::{Initiate, Response};
use super::{ObjectStore, SEGMENT, SdoServer, ServerEvent, State, append_bounded};
use crate::sdo::AbortCode;

impl<S: ObjectStore> SdoServer<S> {
    /// Download initiate: an expedited one is written at once; a segmented
    /// one is checked (size bound, store) and then awaits its segments.
    pub(super) fn download_initiate(&mut self, data: Initiate) {
        let (index, sub) = self.object;
        match data {
            Initiate::Expedited { data, len } => {
                // Without an indicated size, the frame's 4 bytes are the value.
                let len = usize::from(len.unwrap_or(4)).clamp(1, data.len());
                let value = data.get(..len).unwrap_or(&data);
                if len > self.config.max_download {
                    return self.fail(AbortCode::OutOfMemory);
                }
                let written = self
                    .store
                    .check_write(index, sub, Some(len))
                    .and_then(|()| self.store.write(index, sub, value));
                match written {
                    Ok(()) => {
                        self.send(Response::DownloadInitiate { index, sub });
                        self.succeed(ServerEvent::Downloaded { index, sub, len });
                    }
                    Err(code) => self.fail(code),
                }
            }
            Initiate::Segmented { size } => {
                let size = match self.download_size(size) {
                    Ok(size) => size,
                    Err(code) => return self.fail(code),
                };
                if let Some(size) = size {
                    self.buf.reserve_exact(size);
                }
                self.state = State::Download {
                    toggle: false,
                    size,
                };
                self.send(Response::DownloadInitiate { index, sub });
            }
        }
    }

    /// One download segment, `expected` being the toggle it must carry.
    pub(super) fn download_segment(
        &mut self,
        expected: bool,
        size: Option<usize>,
        toggle: bool,
        last: bool,
        data: &[u8; 7],
        len: u8,
    ) {
        if toggle != expected {
            return self.fail(AbortCode::ToggleBitNotAlternated);
        }
        let chunk = data.get(..usize::from(len)).unwrap_or(data);
        let new_len = self.buf.len().saturating_add(chunk.len());
        if let Some(size) = size
            && new_len > size
        {
            return self.fail(AbortCode::LengthTooHigh);
        }
        if new_len > self.config.max_download {
            return self.fail(AbortCode::OutOfMemory);
        }
        append_bounded(&mut self.buf, chunk, self.config.max_download);
        if !last {
            self.state = State::Download {
                toggle: !toggle,
                size,
            };
            self.send(Response::DownloadSegment { toggle });
            return;
        }
        self.complete_download(size, Response::DownloadSegment { toggle });
    }

    /// Upload initiate: reads the value; up to 4 bytes go expedited, more
    /// (or none) segmented.
    pub(super) fn upload_initiate(&mut self) {
        let (index, sub) = self.object;
        if let Err(code) = self.store.read(index, sub, &mut self.buf) {
            return self.fail(code);
        }
        let len = self.buf.len();
        if (1..=4).contains(&len) {
            let mut data = [0u8; 4];
            for (d, s) in data.iter_mut().zip(self.buf.iter()) {
                *d = *s;
            }
            self.send(Response::UploadInitiate {
                index,
                sub,
                data: Initiate::Expedited {
                    data,
                    len: Some(len as u8),
                },
            });
            self.succeed(ServerEvent::Uploaded { index, sub, len });
        } else {
            self.send(Response::UploadInitiate {
                index,
                sub,
                data: Initiate::Segmented {
                    size: u32::try_from(len).ok(),
                },
            });
            self.state = State::Upload {
                toggle: false,
                pos: 0,
            };
        }
    }

    /// An upload segment request: sends the next (up to) 7 bytes.
    pub(super) fn upload_segment(&mut self, expected: bool, pos: usize, toggle: bool) {
        if toggle != expected {
            return self.fail(AbortCode::ToggleBitNotAlternated);
        }
        let total = self.buf.len();
        let end = pos.saturating_add(SEGMENT).min(total);
        let mut data = [0u8; 7];
        let chunk = self.buf.get(pos..end).unwrap_or(&[]);
        let len = chunk.len() as u8;
        for (d, s) in data.iter_mut().zip(chunk.iter()) {
            *d = *s;
        }
        let last = end >= total;
        self.send(Response::UploadSegment {
            toggle,
            last,
            data,
            len,
        });
        if last {
            let (index, sub) = self.object;
            self.succeed(ServerEvent::Uploaded {
                index,
                sub,
                len: total,
            });
        } else {
            self.state = State::Upload {
                toggle: !toggle,
                pos: end,
            };
        }
    }
}
