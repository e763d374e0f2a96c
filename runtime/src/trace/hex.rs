//! The hex fields both trace formats share (candump and PCAN `.trc`):
//! data bytes and identifiers, total over any input.

use crate::CanId;

/// Two hex digits.
pub(crate) fn parse_hex_byte(text: &str) -> Option<u8> {
    match text.as_bytes() {
        [h, l] => Some(hex_value(*h)? << 4 | hex_value(*l)?),
        _ => None,
    }
}

/// One hex digit's value.
pub(crate) fn hex_value(digit: u8) -> Option<u8> {
    char::from(digit).to_digit(16).map(|v| v as u8)
}

/// The identifier `value`, standard (11 bits) or extended (29 bits) as
/// its field's width says; `None` when it is out of that range.
pub(crate) fn can_id(value: u32, standard: bool) -> Option<CanId> {
    if standard {
        u16::try_from(value).ok().and_then(CanId::standard)
    } else {
        CanId::extended(value)
    }
}
