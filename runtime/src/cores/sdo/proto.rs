//! The bytes of SDO frames (CiA 301 SDO protocols): every request a client
//! sends and every response a server sends, parsed and built here and only
//! here. Segments of a block transfer carry no command specifier, so they
//! have their own type, [`BlockSegment`], that the state machines use while a
//! sub-block is in flight.
//!
//! CiA 301 fixes the length of every SDO frame at 8 bytes; [`Request::parse`]
//! and [`Response::parse`] refuse other lengths.

use core::fmt;

use super::AbortCode;

mod layout;

use layout::*;

/// Data of an initiate request or response.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Initiate {
    /// Expedited: up to 4 bytes in the frame. `len` is the size the sender
    /// indicated (1 to 4); `None` when it did not (command `0x42`/`0x22`):
    /// the frame's 4 bytes are then all data, and the value may be shorter.
    Expedited { data: [u8; 4], len: Option<u8> },
    /// Segmented: the data follows in segments; the total size when indicated.
    Segmented { size: Option<u32> },
}

/// A frame from SDO client to SDO server.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Request {
    DownloadInitiate {
        index: u16,
        sub: u8,
        data: Initiate,
    },
    DownloadSegment {
        toggle: bool,
        last: bool,
        data: [u8; 7],
        len: u8,
    },
    UploadInitiate {
        index: u16,
        sub: u8,
    },
    UploadSegment {
        toggle: bool,
    },
    BlockDownloadInitiate {
        index: u16,
        sub: u8,
        crc: bool,
        size: Option<u32>,
    },
    /// `unused`: bytes of the last segment that carry no data (0 to 7).
    BlockDownloadEnd {
        unused: u8,
        crc: u16,
    },
    /// `pst`: protocol switch threshold (0: the server must not switch).
    BlockUploadInitiate {
        index: u16,
        sub: u8,
        crc: bool,
        block_size: u8,
        pst: u8,
    },
    BlockUploadStart,
    BlockUploadAck {
        ack_seq: u8,
        block_size: u8,
    },
    BlockUploadEnd,
    Abort {
        index: u16,
        sub: u8,
        code: AbortCode,
    },
}

/// A frame from SDO server to SDO client.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Response {
    DownloadInitiate {
        index: u16,
        sub: u8,
    },
    DownloadSegment {
        toggle: bool,
    },
    UploadInitiate {
        index: u16,
        sub: u8,
        data: Initiate,
    },
    UploadSegment {
        toggle: bool,
        last: bool,
        data: [u8; 7],
        len: u8,
    },
    BlockDownloadInitiate {
        index: u16,
        sub: u8,
        crc: bool,
        block_size: u8,
    },
    BlockDownloadAck {
        ack_seq: u8,
        block_size: u8,
    },
    BlockDownloadEnd,
    BlockUploadInitiate {
        index: u16,
        sub: u8,
        crc: bool,
        size: Option<u32>,
    },
    /// `unused`: bytes of the last segment that carry no data (0 to 7).
    BlockUploadEnd {
        unused: u8,
        crc: u16,
    },
    Abort {
        index: u16,
        sub: u8,
        code: AbortCode,
    },
}

/// One segment of a block: sequence number 1 to 127, a last-segment flag and
/// 7 bytes (the last segment's unused bytes are told by the end frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockSegment {
    pub seq: u8,
    pub last: bool,
    pub data: [u8; 7],
}

/// Why a frame is not a valid SDO frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ParseError {
    /// Not 8 data bytes (or a remote frame).
    Length(usize),
    /// A response of `len` data bytes whose command needs `needed` (CiA 301
    /// frames have 8; a response may leave out trailing bytes it does not
    /// use, but not these).
    Short { len: usize, needed: usize },
    /// An unknown command specifier or sub-command.
    Command(u8),
    /// A field out of range (a segment length, a sequence number of 0 or 128+).
    Field(u8),
}

impl ParseError {
    /// The abort code a peer answers this error with.
    pub const fn abort_code(self) -> AbortCode {
        AbortCode::InvalidCommand
    }
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParseError::Length(n) => write!(f, "SDO frame has {n} data bytes, not 8"),
            ParseError::Short { len, needed } => write!(
                f,
                "SDO response has {len} data bytes; its command needs at least {needed}"
            ),
            ParseError::Command(b) => write!(f, "unknown SDO command byte {b:#04x}"),
            ParseError::Field(b) => write!(f, "SDO command byte {b:#04x} has a field out of range"),
        }
    }
}

impl Request {
    /// The object whose transfer an initiate request starts; `None` for
    /// other requests.
    #[cfg(feature = "alloc")]
    pub(crate) fn initiated_object(&self) -> Option<(u16, u8)> {
        match *self {
            Request::DownloadInitiate { index, sub, .. }
            | Request::UploadInitiate { index, sub }
            | Request::BlockDownloadInitiate { index, sub, .. }
            | Request::BlockUploadInitiate { index, sub, .. } => Some((index, sub)),
            _ => None,
        }
    }

    pub fn parse(data: &[u8]) -> Result<Request, ParseError> {
        let d = eight(data)?;
        let b = d[0];
        let (index, sub) = address(d);
        Ok(match b >> 5 {
            0 => {
                let (toggle, last, data, len) = parse_segment(d);
                Request::DownloadSegment {
                    toggle,
                    last,
                    data,
                    len,
                }
            }
            1 => Request::DownloadInitiate {
                index,
                sub,
                data: parse_initiate(d),
            },
            2 => Request::UploadInitiate { index, sub },
            3 => Request::UploadSegment { toggle: bit(b, 4) },
            4 => Request::Abort {
                index,
                sub,
                code: AbortCode::from_code(u32_at(d)),
            },
            5 => match b & 3 {
                0 => Request::BlockUploadInitiate {
                    index,
                    sub,
                    crc: bit(b, 2),
                    block_size: d[4],
                    pst: d[5],
                },
                1 => Request::BlockUploadEnd,
                2 => Request::BlockUploadAck {
                    ack_seq: d[1],
                    block_size: d[2],
                },
                _ => Request::BlockUploadStart,
            },
            6 if b & 1 == 0 => {
                let crc = bit(b, 2);
                let size = block_size_field(d);
                Request::BlockDownloadInitiate {
                    index,
                    sub,
                    crc,
                    size,
                }
            }
            6 => {
                let (unused, crc) = block_end(d);
                Request::BlockDownloadEnd { unused, crc }
            }
            _ => return Err(ParseError::Command(b)),
        })
    }

    pub fn encode(&self) -> [u8; 8] {
        let mut d = [0u8; 8];
        match *self {
            Request::DownloadInitiate {
                index,
                sub,
                ref data,
            } => {
                d[0] = 0x20;
                put_address(&mut d, index, sub);
                put_initiate(&mut d, data);
            }
            Request::DownloadSegment {
                toggle,
                last,
                ref data,
                len,
            } => {
                put_segment(&mut d, toggle, last, data, len);
            }
            Request::UploadInitiate { index, sub } => {
                d[0] = 0x40;
                put_address(&mut d, index, sub);
            }
            Request::UploadSegment { toggle } => d[0] = 0x60 | (toggle as u8) << 4,
            Request::BlockDownloadInitiate {
                index,
                sub,
                crc,
                size,
            } => {
                put_block_send(&mut d, index, sub, crc, size);
            }
            Request::BlockDownloadEnd { unused, crc } => put_block_end(&mut d, unused, crc),
            Request::BlockUploadInitiate {
                index,
                sub,
                crc,
                block_size,
                pst,
            } => {
                put_block_receive(&mut d, index, sub, crc, block_size);
                d[5] = pst;
            }
            Request::BlockUploadStart => d[0] = 0xA3,
            Request::BlockUploadAck {
                ack_seq,
                block_size,
            } => put_block_ack(&mut d, ack_seq, block_size),
            Request::BlockUploadEnd => d[0] = 0xA1,
            Request::Abort { index, sub, code } => put_abort(&mut d, index, sub, code),
        }
        d
    }
}

/// The data bytes a response with command byte `b` uses: real devices
/// send shorter frames (a 5-byte expedited response for one data byte),
/// and the bytes after these carry nothing. An unknown command needs its
/// first byte only (it fails to parse anyway).
pub const fn response_len(b: u8) -> usize {
    let n = (b >> 2 & 3) as usize; // unused bytes of an expedited response
    match b >> 5 {
        // Upload segment: the command, then 7 - n data bytes.
        0 => 8 - (b >> 1 & 7) as usize,
        1 => 1,
        2 => match b & 3 {
            0b11 => 8 - n,
            0b00 => 4,
            _ => 8, // expedited without size: all 4 bytes; or the size
        },
        3 => 4,
        4 => 8,
        5 => match b & 3 {
            0 => 5,
            1 => 1,
            2 => 3,
            _ => 1,
        },
        6 => match b & 3 {
            0b00 => 4,
            0b10 => 8,
            _ => 3,
        },
        _ => 1,
    }
}

impl Response {
    /// Parses a response of up to 8 data bytes. A shorter frame is taken
    /// when it holds every byte its command uses ([`response_len`]); the
    /// missing trailing bytes read as 0.
    pub fn parse(data: &[u8]) -> Result<Response, ParseError> {
        let Some(&b) = data.first() else {
            return Err(ParseError::Short { len: 0, needed: 1 });
        };
        let needed = response_len(b);
        if data.len() > 8 {
            return Err(ParseError::Length(data.len()));
        }
        if data.len() < needed {
            return Err(ParseError::Short {
                len: data.len(),
                needed,
            });
        }
        let mut padded = [0u8; 8];
        padded[..data.len()].copy_from_slice(data);
        let d = &padded;
        let b = d[0];
        let (index, sub) = address(d);
        Ok(match b >> 5 {
            0 => {
                let (toggle, last, data, len) = parse_segment(d);
                Response::UploadSegment {
                    toggle,
                    last,
                    data,
                    len,
                }
            }
            1 => Response::DownloadSegment { toggle: bit(b, 4) },
            2 => Response::UploadInitiate {
                index,
                sub,
                data: parse_initiate(d),
            },
            3 => Response::DownloadInitiate { index, sub },
            4 => Response::Abort {
                index,
                sub,
                code: AbortCode::from_code(u32_at(d)),
            },
            5 => match b & 3 {
                0 => Response::BlockDownloadInitiate {
                    index,
                    sub,
                    crc: bit(b, 2),
                    block_size: d[4],
                },
                1 => Response::BlockDownloadEnd,
                2 => Response::BlockDownloadAck {
                    ack_seq: d[1],
                    block_size: d[2],
                },
                _ => return Err(ParseError::Command(b)),
            },
            6 if b & 1 == 0 => {
                let crc = bit(b, 2);
                let size = block_size_field(d);
                Response::BlockUploadInitiate {
                    index,
                    sub,
                    crc,
                    size,
                }
            }
            6 => {
                let (unused, crc) = block_end(d);
                Response::BlockUploadEnd { unused, crc }
            }
            _ => return Err(ParseError::Command(b)),
        })
    }

    pub fn encode(&self) -> [u8; 8] {
        let mut d = [0u8; 8];
        match *self {
            Response::DownloadInitiate { index, sub } => {
                d[0] = 0x60;
                put_address(&mut d, index, sub);
            }
            Response::DownloadSegment { toggle } => d[0] = 0x20 | (toggle as u8) << 4,
            Response::UploadInitiate {
                index,
                sub,
                ref data,
            } => {
                d[0] = 0x40;
                put_address(&mut d, index, sub);
                put_initiate(&mut d, data);
            }
            Response::UploadSegment {
                toggle,
                last,
                ref data,
                len,
            } => {
                put_segment(&mut d, toggle, last, data, len);
            }
            Response::BlockDownloadInitiate {
                index,
                sub,
                crc,
                block_size,
            } => put_block_receive(&mut d, index, sub, crc, block_size),
            Response::BlockDownloadAck {
                ack_seq,
                block_size,
            } => put_block_ack(&mut d, ack_seq, block_size),
            Response::BlockDownloadEnd => d[0] = 0xA1,
            Response::BlockUploadInitiate {
                index,
                sub,
                crc,
                size,
            } => {
                put_block_send(&mut d, index, sub, crc, size);
            }
            Response::BlockUploadEnd { unused, crc } => put_block_end(&mut d, unused, crc),
            Response::Abort { index, sub, code } => put_abort(&mut d, index, sub, code),
        }
        d
    }
}

impl BlockSegment {
    /// Parses a segment. A first byte of 0x80 (sequence number 0 with the
    /// last flag) is how an abort looks; callers check for it with
    /// [`BlockSegment::is_abort`] first.
    pub fn parse(data: &[u8]) -> Result<BlockSegment, ParseError> {
        let d = eight(data)?;
        let seq = d[0] & 0x7F;
        if seq == 0 {
            return Err(ParseError::Field(d[0]));
        }
        let mut bytes = [0u8; 7];
        bytes.copy_from_slice(&d[1..8]);
        Ok(BlockSegment {
            seq,
            last: bit(d[0], 7),
            data: bytes,
        })
    }

    /// Whether a frame received during a sub-block is an abort instead of a segment.
    pub fn is_abort(data: &[u8]) -> bool {
        data.len() == 8 && data[0] == 0x80
    }

    pub fn encode(&self) -> [u8; 8] {
        let mut d = [0u8; 8];
        d[0] = (self.last as u8) << 7 | (self.seq & 0x7F);
        d[1..8].copy_from_slice(&self.data);
        d
    }
}

/// CRC-16 of block transfers: CCITT polynomial 0x1021, initial value 0, no
/// reflection (the "XMODEM" parameters).
pub static CRC: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_XMODEM);

#[cfg(test)]
mod tests;
