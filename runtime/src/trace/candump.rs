//! Reading and writing `candump` output (classic CAN frames only).
//!
//! Three line forms are understood, a leading `(seconds.fraction)` timestamp
//! being optional in each:
//!
//! - the log form of `candump -l`: `(1436509052.249713) vcan0 123#11223344`;
//! - the default text form: `  vcan0  123   [4]  11 22 33 44`, remote frames
//!   as `  vcan0  123   [0]  remote request`;
//! - the compact frame alone, as [`Frame`]'s `Display` writes it:
//!   `123#11223344` (no interface: [`LogLine::interface`] is empty).
//!
//! In the compact form an identifier of 3 hex digits is a standard one and
//! of 8 digits an extended one; data are hex byte pairs, optionally
//! separated by `.`; `R` marks a remote frame, optionally followed by its
//! length (`123#R`, `123#R5`). CAN FD frames (`123##1...`) are refused.
//!
//! Blank lines are skipped. Every other line that does not parse gives a
//! [`ParseError`] with its line number; the [`Reader`] then goes on with the
//! next line. Lines longer than [`MAX_LINE_LEN`] bytes are refused without
//! being stored.

use core::fmt;
use core::time::Duration;
use std::io::{self, BufRead, Write};
use std::string::{String, ToString};

use super::lines::{LineError, Lines};
use crate::{CanId, Frame};

mod parse;
#[cfg(test)]
mod tests;

pub use parse::{LogLineRef, parse_frame, parse_line, parse_line_ref};

pub use super::lines::MAX_LINE_LEN;

/// The interface name the [`Writer`] uses in the log and text forms for a
/// line whose interface is empty.
pub const DEFAULT_INTERFACE: &str = "can0";

/// One line of a candump file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LogLine {
    /// The time in parentheses, when the line has one.
    pub timestamp: Option<Duration>,
    /// The interface name; empty for a compact frame alone.
    pub interface: String,
    /// The frame.
    pub frame: Frame,
}

impl LogLine {
    /// A line with a timestamp.
    pub fn new(timestamp: Duration, interface: &str, frame: Frame) -> LogLine {
        LogLine {
            timestamp: Some(timestamp),
            interface: interface.to_string(),
            frame,
        }
    }

    /// The line written in `format` (without the line end).
    pub fn display(&self, format: Format) -> impl fmt::Display + '_ {
        Display { line: self, format }
    }
}

/// The line forms a [`Writer`] can write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Format {
    /// `(1436509052.249713) vcan0 123#11223344`, what `candump -l` writes and
    /// `canplayer` reads. A line without timestamp gets `(0.000000)`.
    #[default]
    Log,
    /// `  vcan0  123   [4]  11 22 33 44`, what `candump` prints; with a
    /// timestamp in front when the line has one.
    Text,
    /// `123#11223344`: the frame alone (timestamp and interface dropped).
    Compact,
}

/// Why a line could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reason {
    /// The line is not UTF-8 text.
    NotUtf8,
    /// The line is longer than [`MAX_LINE_LEN`] bytes.
    TooLong,
    /// The timestamp is not `(seconds.fraction)` with at most 9 fraction
    /// digits.
    BadTimestamp,
    /// The line ends before the named part.
    Missing(&'static str),
    /// The identifier is not 3 (standard) or 8 (extended) hex digits.
    BadIdentifier,
    /// The identifier is above 0x7FF (standard) or 0x1FFFFFFF (extended).
    IdentifierOutOfRange(u32),
    /// The data are not pairs of hex digits.
    BadData,
    /// More than 8 data bytes.
    TooManyBytes(usize),
    /// The length is not a digit from 0 to 8 (`R5`, `[4]`).
    BadLength,
    /// The text form announces `declared` bytes but lists `actual`.
    LengthMismatch {
        /// The length in brackets.
        declared: usize,
        /// The bytes listed.
        actual: usize,
    },
    /// A CAN FD frame (`##`): only classic CAN is supported.
    CanFd,
    /// Text after a complete line.
    Trailing,
}

impl fmt::Display for Reason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reason::NotUtf8 => f.write_str("the line is not UTF-8 text"),
            Reason::TooLong => write!(f, "the line is longer than {MAX_LINE_LEN} bytes"),
            Reason::BadTimestamp => f.write_str(
                "bad timestamp: expected (seconds.fraction) with at most 9 fraction digits",
            ),
            Reason::Missing(what) => write!(f, "the line ends before the {what}"),
            Reason::BadIdentifier => {
                f.write_str("bad CAN identifier: expected 3 hex digits (standard) or 8 (extended)")
            }
            Reason::IdentifierOutOfRange(id) => {
                write!(f, "CAN identifier {id:#X} is out of range")
            }
            Reason::BadData => f.write_str("bad data: expected pairs of hex digits"),
            Reason::TooManyBytes(n) => {
                write!(f, "{n} data bytes; a classic CAN frame holds at most 8")
            }
            Reason::BadLength => f.write_str("bad length: expected a digit from 0 to 8"),
            Reason::LengthMismatch { declared, actual } => {
                write!(f, "the length says {declared} bytes but {actual} follow")
            }
            Reason::CanFd => f.write_str("CAN FD frames (##) are not supported"),
            Reason::Trailing => f.write_str("unexpected text after the frame"),
        }
    }
}

/// A line that could not be read, with its 1-based number.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct ParseError {
    /// The 1-based line number.
    pub line: usize,
    /// What is wrong with it.
    pub reason: Reason,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.reason)
    }
}

impl std::error::Error for ParseError {}

/// What a [`Reader`] can fail with.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// Reading the input failed; the reader stops.
    Io(io::Error),
    /// A line did not parse; the reader goes on with the next one.
    Parse(ParseError),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io(e) => write!(f, "reading the candump input failed: {e}"),
            Error::Parse(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io(e) => Some(e),
            Error::Parse(e) => Some(e),
        }
    }
}

impl From<ParseError> for Error {
    fn from(e: ParseError) -> Error {
        Error::Parse(e)
    }
}

/// Reads candump lines in any of the three forms; an iterator of
/// `Result<LogLine, Error>` that skips blank lines.
#[derive(Debug)]
pub struct Reader<R> {
    lines: Lines<R>,
}

impl<R: BufRead> Reader<R> {
    /// A reader of `input`, starting at line 1.
    pub fn new(input: R) -> Reader<R> {
        Reader {
            lines: Lines::new(input, 0),
        }
    }

    /// The number of the last line read (1-based; 0 before the first).
    pub fn line_number(&self) -> usize {
        self.lines.number()
    }

    /// Gives the input back.
    pub fn into_inner(self) -> R {
        self.lines.into_inner()
    }
}

impl<R: BufRead> Iterator for Reader<R> {
    type Item = Result<LogLine, Error>;

    fn next(&mut self) -> Option<Self::Item> {
        self.lines.next_item(|line, bytes| {
            let error = |reason| Some(Err(Error::Parse(ParseError { line, reason })));
            let bytes = match bytes {
                Ok(bytes) => bytes,
                Err(LineError::Io(e)) => return Some(Err(Error::Io(e))),
                Err(LineError::TooLong) => return error(Reason::TooLong),
            };
            let Ok(text) = core::str::from_utf8(bytes) else {
                return error(Reason::NotUtf8);
            };
            match parse_line(text) {
                Ok(line) => line.map(Ok),
                Err(reason) => error(reason),
            }
        })
    }
}

/// Writes candump lines in one [`Format`], one per line (`\n`).
#[derive(Debug)]
pub struct Writer<W> {
    output: W,
    format: Format,
}

impl<W: Write> Writer<W> {
    /// A writer of `format` lines to `output`.
    pub fn new(output: W, format: Format) -> Writer<W> {
        Writer { output, format }
    }

    /// The form it writes.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Writes one line.
    pub fn write(&mut self, line: &LogLine) -> io::Result<()> {
        writeln!(self.output, "{}", line.display(self.format))
    }

    /// Writes one frame with the given timestamp and interface.
    pub fn write_frame(
        &mut self,
        timestamp: Option<Duration>,
        interface: &str,
        frame: &Frame,
    ) -> io::Result<()> {
        let line = LogLine {
            timestamp,
            interface: interface.to_string(),
            frame: *frame,
        };
        self.write(&line)
    }

    /// Flushes the output.
    pub fn flush(&mut self) -> io::Result<()> {
        self.output.flush()
    }

    /// The output.
    pub fn get_mut(&mut self) -> &mut W {
        &mut self.output
    }

    /// Gives the output back (unflushed).
    pub fn into_inner(self) -> W {
        self.output
    }
}

/// A [`LogLine`] in one [`Format`] (see [`LogLine::display`]).
struct Display<'a> {
    line: &'a LogLine,
    format: Format,
}

/// `(seconds.micros)`; sub-microsecond parts are cut (candump's precision).
struct Timestamp(Duration);

impl fmt::Display for Timestamp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}.{:06})", self.0.as_secs(), self.0.subsec_micros())
    }
}

impl fmt::Display for Display<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let line = self.line;
        let interface = if line.interface.is_empty() {
            DEFAULT_INTERFACE
        } else {
            &line.interface
        };
        match self.format {
            Format::Compact => write!(f, "{}", line.frame),
            Format::Log => {
                let ts = Timestamp(line.timestamp.unwrap_or_default());
                write!(f, "{ts} {interface} {}", line.frame)
            }
            Format::Text => {
                if let Some(ts) = line.timestamp {
                    write!(f, "{}", Timestamp(ts))?;
                }
                write!(f, "  {interface}  ")?;
                match line.frame.id() {
                    CanId::Standard(id) => write!(f, "{id:03X}")?,
                    CanId::Extended(id) => write!(f, "{id:08X}")?,
                }
                write!(f, "   [{}]", line.frame.len())?;
                if line.frame.is_remote() {
                    return f.write_str("  remote request");
                }
                if !line.frame.is_empty() {
                    f.write_str(" ")?;
                }
                for byte in line.frame.data() {
                    write!(f, " {byte:02X}")?;
                }
                Ok(())
            }
        }
    }
}
