//! The field parsers of [`super`]: total over any input (every failure is
//! a [`Reason`], nothing panics).

use core::time::Duration;

use super::Reason;
use crate::trace::hex::{can_id, parse_hex_byte};
use crate::{CanId, Frame};

/// Data bytes, exactly `len` of them.
pub(super) fn parse_data<'a>(
    tokens: impl Iterator<Item = &'a str>,
    id: CanId,
    len: u8,
) -> Result<Frame, Reason> {
    let mut data = [0u8; 8];
    let mut count = 0usize;
    for token in tokens {
        let byte = parse_hex_byte(token).ok_or(Reason::BadData)?;
        if let Some(slot) = data.get_mut(count) {
            *slot = byte;
        }
        count += 1;
    }
    if count != usize::from(len) {
        return Err(Reason::LengthMismatch {
            declared: usize::from(len),
            actual: count,
        });
    }
    Frame::new(id, data.get(..count).unwrap_or(&[])).map_err(|_| Reason::BadLength)
}

/// Up to 4 hex digits: standard; 5 to 8: extended.
pub(super) fn parse_id(text: &str) -> Result<CanId, Reason> {
    if text.is_empty() || text.len() > 8 || !text.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(Reason::BadIdentifier);
    }
    let value = u32::from_str_radix(text, 16).map_err(|_| Reason::BadIdentifier)?;
    can_id(value, text.len() <= 4).ok_or(Reason::IdentifierOutOfRange(value))
}

/// A length of 0 to 8 (one or two digits).
pub(super) fn parse_len(text: &str) -> Result<u8, Reason> {
    match text.as_bytes() {
        [d @ b'0'..=b'8'] => Ok(d - b'0'),
        [b'0', d @ b'0'..=b'8'] => Ok(d - b'0'),
        _ => Err(Reason::BadLength),
    }
}

pub(super) fn is_digits(text: &str) -> bool {
    !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit())
}

/// Milliseconds with an optional fraction (`1841`, `1059.9`, `1059.900`);
/// digits past the nanosecond are cut.
pub(super) fn parse_offset(text: &str) -> Result<Duration, Reason> {
    let (int, frac) = text.split_once('.').unwrap_or((text, ""));
    if !is_digits(int) || !frac.bytes().all(|b| b.is_ascii_digit()) {
        return Err(Reason::BadOffset);
    }
    let millis: u64 = int.parse().map_err(|_| Reason::BadOffset)?;
    let mut nanos = 0u32;
    for (i, d) in frac.bytes().take(6).enumerate() {
        // Six digits at most: the place value 10^(5 - i) fits in u32.
        nanos += u32::from(d - b'0') * 10u32.pow(5 - i as u32);
    }
    Ok(Duration::from_millis(millis) + Duration::from_nanos(u64::from(nanos)))
}

/// The days between 1899-12-30 (day 0 of `$STARTTIME`) and 1970-01-01.
const UNIX_EPOCH_DAY: f64 = 25_569.0;

/// `$STARTTIME` as time since the Unix epoch; `None` before 1970. A `;`
/// after the number (seen in PEAK's own 1.2 sample) is allowed.
pub(super) fn parse_start_time(text: &str) -> Result<Option<Duration>, Reason> {
    let text = text.strip_suffix(';').unwrap_or(text).trim_ascii();
    let plain = text.bytes().all(|b| b.is_ascii_digit() || b == b'.');
    let days: f64 = match text.parse() {
        Ok(days) if plain => days,
        _ => return Err(Reason::BadStartTime),
    };
    let seconds = (days - UNIX_EPOCH_DAY) * 86_400.0;
    Ok(Duration::try_from_secs_f64(seconds).ok())
}
