//! Reading PEAK-System trace files (`.trc`, as PCAN-View, PCAN-Explorer and
//! the PCAN-Basic tracer write them): classic CAN frames only.
//!
//! Lines starting with `;` are comments, except three header directives:
//! `;$FILEVERSION=2.1` (the layout of the lines that follow),
//! `;$STARTTIME=44548.6028595139` (the start of the trace in days since
//! 1899-12-30, the fraction being the time of day) and, in version 2,
//! `;$COLUMNS=N,O,T,B,I,d,R,L,D`. A message line is whitespace-separated
//! columns; its time offset is in milliseconds from the start of the trace.
//! The layouts by version:
//!
//! - 1.0 (files without `$FILEVERSION`): number with `)`, offset,
//!   identifier, data length code, data bytes:
//!   `1)  1841  0123  3  11 22 33`;
//! - 1.1: a type after the offset, `Rx` or `Tx` for a frame:
//!   `1)  1059.9  Rx  0300  2  11 22`;
//! - 1.2: a bus number before the type: `1)  1059.900  1  Rx  0300  2  11 22`;
//! - 1.3: a reserved `-` after the identifier:
//!   `1)  1059.900 1  Rx  0300 -  2  11 22`;
//! - 2.0 and 2.1: the columns `;$COLUMNS=` lists, in this order: `N` number
//!   (optional), `O` offset, `T` type, `B` bus (optional), `I` identifier,
//!   `d` direction (`Rx`/`Tx`, optional), `R` reserved (optional), `L` data
//!   length code or `l` data length, `D` data. Without the directive 2.0
//!   means `N,O,T,I,d,l,D` (`1  1059.900 DT  0300 Rx 2  11 22`) and 2.1
//!   `N,O,T,B,I,d,R,L,D` (`1  1059.900 DT 1  0300 Rx -  2  11 22`). Type
//!   `DT` is a data frame, `RR` a remote frame.
//!
//! Identifiers are hex: up to 4 digits a standard (11-bit) one, 5 to 8 an
//! extended (29-bit) one (PEAK writes 4 and 8). In version 1 a remote frame
//! has `RTR` where its data would be.
//!
//! Messages that are not classic CAN frames are recognised and given as
//! [`Message::Other`]: error frames (`ERROR` data in 1.0, type `Error`,
//! `ER`), bus warnings (identifier `FFFFFFFF`, type `Warng`), hardware
//! status (`ST`), error counter changes (`EC`), events (`EV`) and CAN FD
//! frames (`FD`, `FB`, `FE`, `BI`).
//!
//! Without `$FILEVERSION` the layout of a version 1 line is told from its
//! shape (where a type word and a `-` stand), and that of a version 2 line
//! from whether it starts with a number and a bus number follows the type.

use core::fmt;
use core::str::SplitAsciiWhitespace;
use core::time::Duration;

use crate::Frame;

mod columns;
mod fields;
#[cfg(test)]
mod tests;

pub use columns::{Column, Columns};
use fields::{is_digits, parse_data, parse_id, parse_len, parse_offset, parse_start_time};

/// The layouts of `$FILEVERSION`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Version {
    V1_0,
    V1_1,
    V1_2,
    V1_3,
    V2_0,
    V2_1,
}

impl Version {
    /// `"1.1"` → [`Version::V1_1`], and so on.
    pub fn parse(text: &str) -> Option<Version> {
        Some(match text {
            "1.0" => Version::V1_0,
            "1.1" => Version::V1_1,
            "1.2" => Version::V1_2,
            "1.3" => Version::V1_3,
            "2.0" => Version::V2_0,
            "2.1" => Version::V2_1,
            _ => return None,
        })
    }

    /// The version as the header writes it (`"2.1"`).
    pub const fn as_str(self) -> &'static str {
        match self {
            Version::V1_0 => "1.0",
            Version::V1_1 => "1.1",
            Version::V1_2 => "1.2",
            Version::V1_3 => "1.3",
            Version::V2_0 => "2.0",
            Version::V2_1 => "2.1",
        }
    }
}

impl fmt::Display for Version {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A recognised message that is not a classic CAN data or remote frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Other {
    /// An error frame (`ERROR` data in 1.0, type `Error`, type `ER`).
    ErrorFrame,
    /// A bus state warning (identifier `FFFFFFFF`, type `Warng`).
    BusWarning,
    /// A hardware status message (`ST`).
    Status,
    /// A change of the error counters (`EC`).
    ErrorCounter,
    /// A user-defined event (`EV`).
    Event,
    /// A CAN FD frame (`FD`, `FB`, `FE`, `BI`).
    CanFd,
}

impl fmt::Display for Other {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Other::ErrorFrame => "error frame",
            Other::BusWarning => "bus state warning",
            Other::Status => "hardware status message",
            Other::ErrorCounter => "error counter change",
            Other::Event => "event",
            Other::CanFd => "CAN FD frame",
        })
    }
}

/// What a message line holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Message {
    /// A classic CAN data or remote frame.
    Frame(Frame),
    /// A message of another kind, to be skipped by a CAN 2.0 reader.
    Other(Other),
}

/// One message line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Record {
    /// The time offset from the start of the trace.
    pub time: Duration,
    /// The message.
    pub message: Message,
}

/// Why a line could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reason {
    /// `$FILEVERSION` names no known version.
    UnknownVersion,
    /// `$STARTTIME` is not a non-negative number of days.
    BadStartTime,
    /// `$COLUMNS` is not a valid column list; the text says why.
    BadColumns(&'static str),
    /// The line ends before the named column.
    Missing(&'static str),
    /// The message number is not digits (`12` or `12)`).
    BadNumber,
    /// The time offset is not milliseconds (`1059.900`).
    BadOffset,
    /// A version 1 type other than `Rx`, `Tx`, `Warng` and `Error`.
    BadType,
    /// A version 2 type other than the known two-letter codes.
    UnknownType,
    /// The bus is not a number (or `-` in version 2).
    BadBus,
    /// The identifier is not 1 to 8 hex digits.
    BadIdentifier,
    /// The identifier is above 0x7FF (standard) or 0x1FFFFFFF (extended).
    IdentifierOutOfRange(u32),
    /// The direction is not `Rx` or `Tx`.
    BadDirection,
    /// The reserved column is not `-`.
    BadReserved,
    /// The length is not a number from 0 to 8.
    BadLength,
    /// A data byte is not two hex digits.
    BadData,
    /// The length says `declared` bytes but `actual` follow.
    LengthMismatch {
        /// The length column.
        declared: usize,
        /// The bytes listed.
        actual: usize,
    },
    /// Text after a remote frame.
    Trailing,
}

impl fmt::Display for Reason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reason::UnknownVersion => {
                f.write_str("unknown $FILEVERSION: expected 1.0, 1.1, 1.2, 1.3, 2.0 or 2.1")
            }
            Reason::BadStartTime => {
                f.write_str("bad $STARTTIME: expected days since 1899-12-30 (44548.6028595139)")
            }
            Reason::BadColumns(why) => write!(f, "bad $COLUMNS: {why}"),
            Reason::Missing(what) => write!(f, "the trace line ends before the {what}"),
            Reason::BadNumber => f.write_str("bad message number: expected digits"),
            Reason::BadOffset => {
                f.write_str("bad time offset: expected milliseconds such as 1059.900")
            }
            Reason::BadType => f.write_str("bad message type: expected Rx, Tx, Warng or Error"),
            Reason::UnknownType => f.write_str(
                "unknown message type: expected DT, RR, FD, FB, FE, BI, ER, ST, EC or EV",
            ),
            Reason::BadBus => f.write_str("bad bus: expected a bus number"),
            Reason::BadIdentifier => {
                f.write_str("bad CAN identifier: expected 4 hex digits (standard) or 8 (extended)")
            }
            Reason::IdentifierOutOfRange(id) => {
                write!(f, "CAN identifier {id:#X} is out of range")
            }
            Reason::BadDirection => f.write_str("bad direction: expected Rx or Tx"),
            Reason::BadReserved => f.write_str("bad reserved column: expected -"),
            Reason::BadLength => f.write_str("bad data length: expected a number from 0 to 8"),
            Reason::BadData => f.write_str("bad data: expected bytes of two hex digits"),
            Reason::LengthMismatch { declared, actual } => {
                write!(f, "the length says {declared} bytes but {actual} follow")
            }
            Reason::Trailing => f.write_str("unexpected text after the remote frame"),
        }
    }
}

/// Whether `line` has the shape of a message line: it starts with a message
/// number (`12)` in version 1, `12` in version 2) or a time offset
/// (`1059.900`, version 2 without the `N` column).
pub fn is_message_line(line: &str) -> bool {
    let Some(first) = line.split_ascii_whitespace().next() else {
        return false;
    };
    let number = first.strip_suffix(')').unwrap_or(first);
    if number.len() < first.len() {
        return is_digits(number);
    }
    let (int, frac) = first.split_once('.').unwrap_or((first, "0"));
    is_digits(int) && is_digits(frac)
}

/// The state of a trace: version, columns and start time from the header.
#[derive(Debug, Clone, Default)]
pub struct Parser {
    version: Option<Version>,
    columns: Option<Columns>,
    start: Option<Duration>,
}

impl Parser {
    /// A parser before any header: lines are read by their shape.
    pub const fn new() -> Parser {
        Parser {
            version: None,
            columns: None,
            start: None,
        }
    }

    /// The `$FILEVERSION` of the header, if any.
    pub fn version(&self) -> Option<Version> {
        self.version
    }

    /// The `$COLUMNS` of the header, if any.
    pub fn columns(&self) -> Option<Columns> {
        self.columns
    }

    /// `$STARTTIME` as time since the Unix epoch; `None` without one or
    /// before 1970.
    pub fn start_time(&self) -> Option<Duration> {
        self.start
    }

    /// Parses one line: a header or comment line (starting with `;`) updates
    /// the state and, like a blank line, gives `Ok(None)`.
    pub fn parse_line(&mut self, line: &str) -> Result<Option<Record>, Reason> {
        let text = line.trim_ascii();
        if text.is_empty() {
            return Ok(None);
        }
        if text.starts_with(';') {
            self.parse_header(text)?;
            return Ok(None);
        }
        self.parse_message(text).map(Some)
    }

    /// Applies a header line (`;$KEY=value`); other `;` lines are comments.
    /// `$FILEVERSION` starts a new header: columns and start time are reset.
    pub fn parse_header(&mut self, line: &str) -> Result<(), Reason> {
        let Some(body) = line.trim_ascii().strip_prefix(";$") else {
            return Ok(());
        };
        let Some((key, value)) = body.split_once('=') else {
            return Ok(());
        };
        let key = key.trim_ascii();
        let value = value.trim_ascii();
        if key.eq_ignore_ascii_case("FILEVERSION") {
            self.version = None;
            self.columns = None;
            self.start = None;
            self.version = Some(Version::parse(value).ok_or(Reason::UnknownVersion)?);
        } else if key.eq_ignore_ascii_case("STARTTIME") {
            self.start = parse_start_time(value)?;
        } else if key.eq_ignore_ascii_case("COLUMNS") {
            self.columns = Some(Columns::parse(value)?);
        }
        Ok(())
    }

    /// Parses a message line in the layout of the header (or, without one,
    /// of the line's shape).
    pub fn parse_message(&self, line: &str) -> Result<Record, Reason> {
        let mut tokens = line.split_ascii_whitespace();
        let first = tokens.next().ok_or(Reason::Missing("message number"))?;
        if let Some(number) = first.strip_suffix(')') {
            if !is_digits(number) {
                return Err(Reason::BadNumber);
            }
            let layout = match self.version {
                Some(Version::V1_0) => V1Layout::V1_0,
                Some(Version::V1_1) => V1Layout::V1_1,
                Some(Version::V1_2) => V1Layout::V1_2,
                Some(Version::V1_3) => V1Layout::V1_3,
                _ => V1Layout::guess(tokens.clone()),
            };
            return parse_v1(tokens, layout);
        }
        let columns = match (self.version, self.columns) {
            (_, Some(columns)) => columns,
            (Some(Version::V2_0), None) => Columns::V2_0,
            (Some(Version::V2_1), None) => Columns::V2_1,
            _ => Columns::guess(first, tokens.clone()),
        };
        parse_v2(first, tokens, &columns)
    }
}

/// Which optional columns a version 1 line has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct V1Layout {
    bus: bool,
    kind: bool,
    reserved: bool,
}

impl V1Layout {
    const V1_0: V1Layout = V1Layout {
        bus: false,
        kind: false,
        reserved: false,
    };
    const V1_1: V1Layout = V1Layout {
        kind: true,
        ..V1Layout::V1_0
    };
    const V1_2: V1Layout = V1Layout {
        bus: true,
        ..V1Layout::V1_1
    };
    const V1_3: V1Layout = V1Layout {
        reserved: true,
        ..V1Layout::V1_2
    };

    /// The layout of the columns after the offset: a type word first (1.1),
    /// second (1.2, after the bus) or absent (1.0); a `-` after the
    /// identifier is the reserved column of 1.3.
    fn guess(mut after_number: SplitAsciiWhitespace<'_>) -> V1Layout {
        after_number.next(); // the offset
        let mut next = || after_number.next().unwrap_or("");
        let (a, b, c, d) = (next(), next(), next(), next());
        if is_v1_type(a) {
            V1Layout {
                bus: false,
                kind: true,
                reserved: c == "-",
            }
        } else if is_v1_type(b) {
            V1Layout {
                bus: true,
                kind: true,
                reserved: d == "-",
            }
        } else {
            V1Layout {
                reserved: b == "-",
                ..V1Layout::V1_0
            }
        }
    }
}

fn is_v1_type(token: &str) -> bool {
    matches!(token, "Rx" | "Tx" | "Warng" | "Error")
}

/// The columns of a version 1 line after its number.
fn parse_v1(mut tokens: SplitAsciiWhitespace<'_>, layout: V1Layout) -> Result<Record, Reason> {
    let mut next = |what| tokens.next().ok_or(Reason::Missing(what));
    let time = parse_offset(next("time offset")?)?;
    let other = |other| {
        Ok(Record {
            time,
            message: Message::Other(other),
        })
    };
    if layout.bus && !is_digits(next("bus")?) {
        return Err(Reason::BadBus);
    }
    if layout.kind {
        match next("message type")? {
            "Rx" | "Tx" => {}
            "Warng" => return other(Other::BusWarning),
            "Error" => return other(Other::ErrorFrame),
            _ => return Err(Reason::BadType),
        }
    }
    let id = next("identifier")?;
    if id.eq_ignore_ascii_case("FFFFFFFF") {
        return other(Other::BusWarning);
    }
    let id = parse_id(id)?;
    if layout.reserved && next("reserved column")? != "-" {
        return Err(Reason::BadReserved);
    }
    let len = parse_len(next("data length code")?)?;
    let mut data = tokens.clone();
    match data.next() {
        Some("ERROR") => return other(Other::ErrorFrame),
        Some("RTR") => {
            if data.next().is_some() {
                return Err(Reason::Trailing);
            }
            let frame = Frame::remote(id, len).map_err(|_| Reason::BadLength)?;
            return Ok(Record {
                time,
                message: Message::Frame(frame),
            });
        }
        _ => {}
    }
    let frame = parse_data(tokens, id, len)?;
    Ok(Record {
        time,
        message: Message::Frame(frame),
    })
}

/// A version 2 line in the layout of `columns`.
fn parse_v2(
    first: &str,
    rest: SplitAsciiWhitespace<'_>,
    columns: &Columns,
) -> Result<Record, Reason> {
    let mut tokens = core::iter::once(first).chain(rest);
    let mut next = |what| tokens.next().ok_or(Reason::Missing(what));
    let mut time = Duration::ZERO;
    let mut id = None;
    let mut len = 0;
    let mut remote = false;
    for column in columns.as_slice() {
        match column {
            Column::Number => {
                if !is_digits(next("message number")?) {
                    return Err(Reason::BadNumber);
                }
            }
            Column::Offset => time = parse_offset(next("time offset")?)?,
            Column::Type => {
                let other = match next("message type")? {
                    "DT" => None,
                    "RR" => {
                        remote = true;
                        None
                    }
                    "FD" | "FB" | "FE" | "BI" => Some(Other::CanFd),
                    "ER" => Some(Other::ErrorFrame),
                    "ST" => Some(Other::Status),
                    "EC" => Some(Other::ErrorCounter),
                    "EV" => Some(Other::Event),
                    _ => return Err(Reason::UnknownType),
                };
                if let Some(other) = other {
                    return Ok(Record {
                        time,
                        message: Message::Other(other),
                    });
                }
            }
            Column::Bus => {
                let bus = next("bus")?;
                if bus != "-" && !is_digits(bus) {
                    return Err(Reason::BadBus);
                }
            }
            Column::Id => id = Some(parse_id(next("identifier")?)?),
            Column::Direction => {
                if !matches!(next("direction")?, "Rx" | "Tx") {
                    return Err(Reason::BadDirection);
                }
            }
            Column::Reserved => {
                if next("reserved column")? != "-" {
                    return Err(Reason::BadReserved);
                }
            }
            Column::Dlc | Column::Length => len = parse_len(next("data length")?)?,
            Column::Data => break,
        }
    }
    // Validated columns always hold `I`; a default identifier is never used.
    let id = id.ok_or(Reason::Missing("identifier"))?;
    let frame = if remote {
        if tokens.next().is_some() {
            return Err(Reason::Trailing);
        }
        Frame::remote(id, len).map_err(|_| Reason::BadLength)?
    } else {
        parse_data(tokens, id, len)?
    };
    Ok(Record {
        time,
        message: Message::Frame(frame),
    })
}
