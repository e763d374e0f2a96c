//! The line parser of [`super`]: total over any input (every failure is a
//! [`Reason`], nothing panics).

use core::time::Duration;
use std::string::ToString;

use super::{LogLine, Reason};
use crate::trace::hex::{can_id, hex_value, parse_hex_byte};
use crate::{CanId, Frame};

/// One candump line borrowing its interface name from the text: what
/// [`parse_line_ref`] gives, without the allocation of a [`LogLine`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LogLineRef<'a> {
    /// The time in parentheses, when the line has one.
    pub timestamp: Option<Duration>,
    /// The interface name; empty for a compact frame alone.
    pub interface: &'a str,
    /// The frame.
    pub frame: Frame,
}

impl LogLineRef<'_> {
    /// The owned [`LogLine`] (copies the interface name).
    pub fn to_owned_line(&self) -> LogLine {
        LogLine {
            timestamp: self.timestamp,
            interface: self.interface.to_string(),
            frame: self.frame,
        }
    }
}

/// Parses one line in any of the three forms (see [`super`]); `Ok(None)` for
/// a blank line.
pub fn parse_line(line: &str) -> Result<Option<LogLine>, Reason> {
    parse_line_ref(line).map(|parsed| parsed.map(|l| l.to_owned_line()))
}

/// [`parse_line`] without allocating: the interface name stays a slice of
/// `line`. Accepts and refuses exactly the same lines.
pub fn parse_line_ref(line: &str) -> Result<Option<LogLineRef<'_>>, Reason> {
    let mut tokens = line.split_ascii_whitespace().peekable();
    let timestamp = match tokens.peek() {
        None => return Ok(None),
        Some(first) if first.starts_with('(') => {
            let ts = parse_timestamp(first)?;
            tokens.next();
            Some(ts)
        }
        Some(_) => None,
    };
    let first = tokens.next().ok_or(Reason::Missing("interface"))?;
    if first.contains('#') {
        // The compact frame alone.
        let frame = parse_frame(first)?;
        return finish(tokens, timestamp, "", frame);
    }
    let interface = first;
    let second = tokens.next().ok_or(Reason::Missing("frame"))?;
    if second.contains('#') {
        // The log form.
        let frame = parse_frame(second)?;
        return finish(tokens, timestamp, interface, frame);
    }
    // The text form: identifier, [length], bytes or "remote request".
    let id = parse_id(second)?;
    let len_token = tokens.next().ok_or(Reason::Missing("length"))?;
    let declared = len_token
        .strip_prefix('[')
        .and_then(|t| t.strip_suffix(']'))
        .and_then(parse_len)
        .ok_or(Reason::BadLength)?;
    let mut data = [0u8; 8];
    let mut count = 0usize;
    let mut remote = false;
    while let Some(token) = tokens.next() {
        if token == "remote" && count == 0 {
            match tokens.next() {
                Some("request") => {
                    remote = true;
                    break;
                }
                _ => return Err(Reason::BadData),
            }
        }
        let byte = parse_hex_byte(token).ok_or(Reason::BadData)?;
        if let Some(slot) = data.get_mut(count) {
            *slot = byte;
        }
        count += 1;
    }
    let frame = if remote {
        Frame::remote(id, declared)
    } else {
        if count > 8 {
            return Err(Reason::TooManyBytes(count));
        }
        if count != usize::from(declared) {
            return Err(Reason::LengthMismatch {
                declared: usize::from(declared),
                actual: count,
            });
        }
        Frame::new(id, data.get(..count).unwrap_or(&[]))
    }
    .map_err(|_| Reason::BadLength)?;
    finish(tokens, timestamp, interface, frame)
}

/// Ends a line: nothing may follow the frame.
fn finish<'a>(
    mut rest: impl Iterator<Item = &'a str>,
    timestamp: Option<Duration>,
    interface: &'a str,
    frame: Frame,
) -> Result<Option<LogLineRef<'a>>, Reason> {
    if rest.next().is_some() {
        return Err(Reason::Trailing);
    }
    Ok(Some(LogLineRef {
        timestamp,
        interface,
        frame,
    }))
}

/// Parses the compact form `123#11223344` (also `12345678#`, `123#R`,
/// `123#R5`, `123#11.22.33`).
pub fn parse_frame(text: &str) -> Result<Frame, Reason> {
    let (id, rest) = text.split_once('#').ok_or(Reason::Missing("'#'"))?;
    if rest.starts_with('#') {
        return Err(Reason::CanFd);
    }
    let id = parse_id(id)?;
    if let Some(len) = rest.strip_prefix(['R', 'r']) {
        let len = if len.is_empty() {
            0
        } else {
            parse_len(len).ok_or(Reason::BadLength)?
        };
        return Frame::remote(id, len).map_err(|_| Reason::BadLength);
    }
    let mut data = [0u8; 8];
    let mut count = 0usize;
    let mut digits = rest.bytes().filter(|&b| b != b'.');
    while let Some(high) = digits.next() {
        let low = digits.next().ok_or(Reason::BadData)?;
        let byte = hex_value(high)
            .zip(hex_value(low))
            .map(|(h, l)| h << 4 | l)
            .ok_or(Reason::BadData)?;
        if let Some(slot) = data.get_mut(count) {
            *slot = byte;
        }
        count += 1;
    }
    if count > 8 {
        return Err(Reason::TooManyBytes(count));
    }
    Frame::new(id, data.get(..count).unwrap_or(&[])).map_err(|_| Reason::TooManyBytes(count))
}

/// 3 hex digits: standard; 8: extended.
fn parse_id(text: &str) -> Result<CanId, Reason> {
    if !text.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(Reason::BadIdentifier);
    }
    let value = match text.len() {
        3 | 8 => u32::from_str_radix(text, 16).map_err(|_| Reason::BadIdentifier)?,
        _ => return Err(Reason::BadIdentifier),
    };
    can_id(value, text.len() == 3).ok_or(Reason::IdentifierOutOfRange(value))
}

/// A single digit 0 to 8.
fn parse_len(text: &str) -> Option<u8> {
    match text.as_bytes() {
        [d @ b'0'..=b'8'] => Some(d - b'0'),
        _ => None,
    }
}

/// `(seconds.fraction)`: up to 9 fraction digits; seconds alone allowed.
fn parse_timestamp(token: &str) -> Result<Duration, Reason> {
    let inner = token
        .strip_prefix('(')
        .and_then(|t| t.strip_suffix(')'))
        .ok_or(Reason::BadTimestamp)?;
    let (secs, frac) = inner.split_once('.').unwrap_or((inner, ""));
    let all_digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if secs.is_empty() || !all_digits(secs) || !all_digits(frac) || frac.len() > 9 {
        return Err(Reason::BadTimestamp);
    }
    let secs: u64 = secs.parse().map_err(|_| Reason::BadTimestamp)?;
    let mut nanos = 0u32;
    for (i, d) in frac.bytes().enumerate() {
        // At most 9 digits: the place value 10^(8 - i) fits in u32.
        let place = 10u32.pow(8 - i as u32);
        nanos += u32::from(d - b'0') * place;
    }
    Ok(Duration::new(secs, nanos))
}
