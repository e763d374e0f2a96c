//! Reading recorded CAN traces in any supported text form, told apart line
//! by line (classic CAN frames only).
//!
//! The accepted forms:
//!
//! - the three forms of [`candump`] (read by [`candump::parse_line_ref`]):
//!   the log form `(1436509052.249713) vcan0 123#11223344`, the text form
//!   `  vcan0  123   [4]  11 22 33 44` (a timestamp in front optional) and
//!   the compact frame alone `123#11223344`. Their `(seconds.fraction)`
//!   timestamp is kept as it is: usually seconds since the Unix epoch;
//! - the PEAK-System `.trc` trace files of versions 1.0 to 2.1 (see
//!   [`trc`]): `     1)      1841.0  Rx         0001  8  00 11 22 33 44 55 66 77`,
//!   `     1      1059.900 DT     0300 Rx 2  11 22`,
//!   `     1      1059.900 DT 1      0300 Rx -  2  11 22` and the other
//!   layouts. Their time is the offset from the start of the trace
//!   ([`Reader::trc_start_time`] has the start itself).
//!
//! A line starting with `;` is a comment, or a `.trc` header directive
//! (`;$FILEVERSION=2.1`, `;$STARTTIME=...`, `;$COLUMNS=...`) that sets the
//! layout of the `.trc` lines after it; comments may be in any 8-bit
//! encoding. A line starting with a message number (`1)`, `1`) or a time
//! offset (`1059.900`) is a `.trc` message; any other line is read as
//! candump. One file may mix the forms.
//!
//! Blank and comment lines give nothing; every frame gives a [`TraceLine`].
//! A line that does not parse, is not UTF-8 or is longer than
//! [`candump::MAX_LINE_LEN`] bytes (it is then not stored) gives a
//! [`TraceError`] with its line number, and reading goes on with the next
//! line. So does a `.trc` message that is not a classic CAN frame (an error
//! frame, a status or a CAN FD frame): its error has the kind
//! [`ErrorKind::Skipped`], a note rather than a fault. Only a failure to read
//! the input ends the reader.

use core::fmt;
use core::time::Duration;
use std::format;
use std::io::BufRead;
use std::string::{String, ToString};

use crate::Frame;
use candump::MAX_LINE_LEN;
use lines::{LineError, Lines};

pub mod candump;
mod hex;
mod lines;
pub mod trc;

#[cfg(test)]
mod test_support;
#[cfg(test)]
mod tests;

/// One frame of a trace.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TraceLine {
    /// The 1-based line number.
    pub line: usize,
    /// The candump timestamp, or the `.trc` offset from the start of the
    /// trace; `None` for a candump line without timestamp.
    pub time: Option<Duration>,
    /// The frame.
    pub frame: Frame,
}

/// What kind of problem a [`TraceError`] reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// The line is not a valid line of any form.
    Malformed,
    /// The line is a valid message that is not a classic CAN frame (error
    /// frame, bus status, event, CAN FD); a reader of CAN 2.0 frames may
    /// skip it silently.
    Skipped,
    /// Reading the input failed; the reader stops.
    Io,
}

/// A line that gave no frame, with its 1-based number.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct TraceError {
    /// The 1-based line number (for [`ErrorKind::Io`], the line being read).
    pub line: usize,
    /// The kind of problem.
    pub kind: ErrorKind,
    /// What is wrong, and what was expected.
    pub message: String,
}

impl TraceError {
    /// Whether this is only a note about a message that is not a classic
    /// CAN frame ([`ErrorKind::Skipped`]).
    pub fn is_skipped(&self) -> bool {
        self.kind == ErrorKind::Skipped
    }
}

impl fmt::Display for TraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

impl std::error::Error for TraceError {}

/// Reads trace lines of any form; an iterator of
/// `Result<TraceLine, TraceError>`.
#[derive(Debug)]
pub struct Reader<R> {
    lines: Lines<R>,
    trc: trc::Parser,
}

/// A reader of an in-memory trace.
pub fn parse_str(text: &str) -> Reader<&[u8]> {
    Reader::new(text.as_bytes())
}

impl<R: BufRead> Reader<R> {
    /// A reader of `input`, starting at line 1.
    pub fn new(input: R) -> Reader<R> {
        Reader {
            lines: Lines::new(input, 128),
            trc: trc::Parser::new(),
        }
    }

    /// The number of the last line read (1-based; 0 before the first).
    pub fn line_number(&self) -> usize {
        self.lines.number()
    }

    /// The `.trc` version of the last `$FILEVERSION` header, if any.
    pub fn trc_version(&self) -> Option<trc::Version> {
        self.trc.version()
    }

    /// The `$STARTTIME` of the last `.trc` header as time since the Unix
    /// epoch; `None` without one (or before 1970).
    pub fn trc_start_time(&self) -> Option<Duration> {
        self.trc.start_time()
    }

    /// Gives the input back.
    pub fn into_inner(self) -> R {
        self.lines.into_inner()
    }
}

impl<R: BufRead> Iterator for Reader<R> {
    type Item = Result<TraceLine, TraceError>;

    fn next(&mut self) -> Option<Self::Item> {
        let trc = &mut self.trc;
        self.lines.next_item(|line, bytes| {
            let parsed = match bytes {
                Ok(bytes) => parse_bytes(trc, bytes),
                Err(LineError::TooLong) => Err(Problem::TooLong),
                Err(LineError::Io(e)) => {
                    return Some(Err(TraceError {
                        line,
                        kind: ErrorKind::Io,
                        message: format!("reading the trace failed: {e}"),
                    }));
                }
            };
            match parsed {
                Ok(None) => None,
                Ok(Some((time, frame))) => Some(Ok(TraceLine { line, time, frame })),
                Err(problem) => Some(Err(problem.into_error(line))),
            }
        })
    }
}

/// Why a line gave no frame (turned into a [`TraceError`] with its text).
#[derive(Debug)]
enum Problem {
    NotUtf8,
    TooLong,
    Candump(candump::Reason),
    Unrecognised,
    Trc(trc::Reason),
    Skipped(trc::Other),
}

impl Problem {
    fn into_error(self, line: usize) -> TraceError {
        let kind = match self {
            Problem::Skipped(_) => ErrorKind::Skipped,
            _ => ErrorKind::Malformed,
        };
        let message = match self {
            Problem::NotUtf8 => "the line is not UTF-8 text".to_string(),
            Problem::TooLong => format!("the line is longer than {MAX_LINE_LEN} bytes"),
            Problem::Candump(reason) => reason.to_string(),
            Problem::Unrecognised => "unrecognised line: expected a candump frame \
                 (`123#1122`, `can0  123  [2]  11 22`) or a PCAN trace message"
                .to_string(),
            Problem::Trc(reason) => reason.to_string(),
            Problem::Skipped(other) => {
                format!("skipped a {other}: not a classic CAN data or remote frame")
            }
        };
        TraceError {
            line,
            kind,
            message,
        }
    }
}

/// One line (without its line end, at most [`MAX_LINE_LEN`] bytes) in
/// any form.
fn parse_bytes(
    trc: &mut trc::Parser,
    bytes: &[u8],
) -> Result<Option<(Option<Duration>, Frame)>, Problem> {
    let Ok(text) = core::str::from_utf8(bytes) else {
        // A comment is skipped whatever its encoding (PEAK writes 8-bit
        // text, file names in comments may be Latin-1); a directive is not.
        let start = bytes.trim_ascii_start();
        if start.starts_with(b";") && !start.starts_with(b";$") {
            return Ok(None);
        }
        return Err(Problem::NotUtf8);
    };
    parse_text(trc, text)
}

/// One line of text in any form.
fn parse_text(
    trc: &mut trc::Parser,
    text: &str,
) -> Result<Option<(Option<Duration>, Frame)>, Problem> {
    let text = text.trim_ascii();
    if text.is_empty() {
        return Ok(None);
    }
    if text.starts_with(';') {
        trc.parse_header(text).map_err(Problem::Trc)?;
        return Ok(None);
    }
    if trc::is_message_line(text) {
        let record = trc.parse_message(text).map_err(Problem::Trc)?;
        return match record.message {
            trc::Message::Frame(frame) => Ok(Some((Some(record.time), frame))),
            trc::Message::Other(other) => Err(Problem::Skipped(other)),
        };
    }
    match candump::parse_line_ref(text) {
        Ok(Some(line)) => Ok(Some((line.timestamp, line.frame))),
        Ok(None) => Ok(None),
        Err(reason) if looks_like_candump(text) => Err(Problem::Candump(reason)),
        Err(_) => Err(Problem::Unrecognised),
    }
}

/// Whether a line that failed to parse carries a mark of a candump form (a
/// `(` timestamp, a `#` frame or a `[n]` length), so that candump's own
/// reason fits it better than "unrecognised".
fn looks_like_candump(text: &str) -> bool {
    text.starts_with('(')
        || text.contains('#')
        || text.split_ascii_whitespace().any(|t| t.starts_with('['))
}
