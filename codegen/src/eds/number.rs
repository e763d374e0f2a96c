//! Literals of CiA 306: integers (decimal, `0x` hex, leading-`0` octal),
//! `$NODEID` formulas, REAL values (decimal or hex bit pattern), hex strings.

use std::borrow::Cow;

use crate::ir::{DataType, Literal, Value, ValueKind, node_formula_problem};

/// Why a literal could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LiteralError(pub String);

/// `text` without its white space (borrowed when it has none).
fn without_space(text: &str) -> Cow<'_, str> {
    if text.bytes().all(|b| b.is_ascii_graphic()) {
        Cow::Borrowed(text)
    } else {
        Cow::Owned(text.chars().filter(|c| !c.is_whitespace()).collect())
    }
}

/// The byte position of the first `$NODEID` in `text`, in any case.
fn find_node_id(text: &str) -> Option<usize> {
    const NODE_ID: &str = "$NODEID";
    text.match_indices('$').map(|(pos, _)| pos).find(|&pos| {
        text.get(pos..pos + NODE_ID.len())
            .is_some_and(|s| s.eq_ignore_ascii_case(NODE_ID))
    })
}

/// Parses an unsigned or signed integer: `123`, `-5`, `0x1A`, `017` (octal), `0`.
pub fn parse_int(text: &str) -> Result<i128, LiteralError> {
    let t = without_space(text);
    let (negative, digits) = match t.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, t.strip_prefix('+').unwrap_or(&t)),
    };
    let (radix, body) = if let Some(hex) = digits
        .strip_prefix("0x")
        .or_else(|| digits.strip_prefix("0X"))
    {
        (16, hex)
    } else if digits.len() > 1 && digits.starts_with('0') {
        (8, &digits[1..])
    } else {
        (10, digits)
    };
    if body.is_empty() {
        return Err(LiteralError(format!("`{text}` is not a number")));
    }
    let magnitude = u128::from_str_radix(body, radix).map_err(|_| {
        let what = match radix {
            16 => "hexadecimal",
            8 => "octal (it starts with 0)",
            _ => "decimal",
        };
        LiteralError(format!("`{text}` is not a valid {what} number"))
    })?;
    if magnitude > u64::MAX as u128 {
        return Err(LiteralError(format!("`{text}` does not fit in 64 bits")));
    }
    let value = magnitude as i128;
    Ok(if negative { -value } else { value })
}

/// Parses an integer that may contain `$NODEID` (`$NODEID+0x180`, `0x180 + $NODEID`).
/// Returns the constant part and whether the node id is added.
pub fn parse_int_expr(text: &str) -> Result<(i128, bool), LiteralError> {
    let compact = without_space(text);
    let Some(pos) = find_node_id(&compact) else {
        return parse_int(&compact).map(|v| (v, false));
    };
    let before = &compact[..pos];
    let after = &compact[pos + "$NODEID".len()..];
    if find_node_id(&compact[pos + 1..]).is_some() {
        return Err(LiteralError(format!(
            "`{text}` names $NODEID more than once"
        )));
    }
    let constant = match (before, after) {
        ("", "") => 0,
        ("", rest) => {
            let rest = rest.strip_prefix('+').ok_or_else(|| {
                LiteralError(format!(
                    "`{text}`: only `$NODEID + value` and `value + $NODEID` are supported"
                ))
            })?;
            parse_int(rest)?
        }
        (rest, "") => {
            let rest = rest.strip_suffix('+').ok_or_else(|| {
                LiteralError(format!(
                    "`{text}`: only `$NODEID + value` and `value + $NODEID` are supported"
                ))
            })?;
            parse_int(rest)?
        }
        _ => {
            return Err(LiteralError(format!(
                "`{text}`: only `$NODEID + value` and `value + $NODEID` are supported"
            )));
        }
    };
    Ok((constant, true))
}

/// Parses a hex byte string such as `0102AB` or `01 02 AB`.
pub fn parse_hex_bytes(text: &str) -> Result<Vec<u8>, LiteralError> {
    let digits = without_space(text);
    let digits = digits
        .strip_prefix("0x")
        .or_else(|| digits.strip_prefix("0X"))
        .unwrap_or(&digits);
    if !digits.len().is_multiple_of(2) || !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(LiteralError(format!(
            "`{text}` is not a string of hex bytes"
        )));
    }
    (0..digits.len())
        .step_by(2)
        .map(|i| {
            u8::from_str_radix(&digits[i..i + 2], 16)
                .map_err(|_| LiteralError(format!("`{text}` is not hex")))
        })
        .collect()
}

/// Parses a REAL32/REAL64 value: a decimal number or a hex bit pattern.
pub fn parse_real(text: &str, bits: u32) -> Result<f64, LiteralError> {
    let t = text.trim();
    if let Some(hex) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        let pattern = u64::from_str_radix(hex, 16)
            .map_err(|_| LiteralError(format!("`{text}` is not a hex bit pattern")))?;
        return if bits == 32 {
            let p = u32::try_from(pattern).map_err(|_| {
                LiteralError(format!("`{text}` is wider than the 32 bits of a REAL32"))
            })?;
            Ok(f64::from(f32::from_bits(p)))
        } else {
            Ok(f64::from_bits(pattern))
        };
    }
    let v: f64 = t
        .parse()
        .map_err(|_| LiteralError(format!("`{text}` is not a number")))?;
    if bits == 32 && v.is_finite() && (v as f32).is_infinite() {
        return Err(LiteralError(format!("`{text}` is out of range for REAL32")));
    }
    Ok(if bits == 32 { f64::from(v as f32) } else { v })
}

/// What reading a literal of a data type gave: the literal and, possibly, a
/// warning about how it was normalised.
pub struct Parsed {
    pub literal: Literal,
    pub warning: Option<String>,
    /// The warning is about a `$NODEID` formula that fits some node ids
    /// (but not all): a problem of some configurations, not of the value.
    pub fits_some_node_ids: bool,
}

/// Reads `text` as a value of `data_type`. `None` for an unknown data type.
pub fn parse_value(text: &str, data_type: DataType) -> Option<Result<Parsed, LiteralError>> {
    let kind = data_type.value_kind()?;
    let literal = |value, plus_node_id| Literal {
        value,
        plus_node_id,
        text: text.to_string(),
    };
    Some(match kind {
        ValueKind::Integer { signed, bits } => parse_int_expr(text).map(|(v, rel)| {
            let (lo, hi) = data_type.integer_range().expect("integer type has a range");
            let mut warning = None;
            let mut fits_some_node_ids = false;
            let mut v = v;
            if rel && let Some((w, some)) = node_formula_problem(text, v, data_type) {
                warning = Some(w);
                fits_some_node_ids = some;
            }
            if !rel && (v < lo || v > hi) {
                let is_hex = text
                    .trim()
                    .to_ascii_lowercase()
                    .trim_start_matches('-')
                    .starts_with("0x");
                if signed && is_hex && v >= 0 && v < (1i128 << bits) {
                    // A hex literal of a signed type is its two's-complement bit pattern.
                    v -= 1i128 << bits;
                } else if v < lo || v > hi {
                    warning = Some(format!(
                        "{} is out of range for {} ({lo}..={hi})",
                        text.trim(),
                        data_type.name()
                    ));
                }
            }
            Parsed {
                literal: literal(Value::Integer(v), rel),
                warning,
                fits_some_node_ids,
            }
        }),
        ValueKind::Real { bits } => parse_real(text, bits).map(|v| Parsed {
            literal: literal(Value::Real(v), false),
            warning: None,
            fits_some_node_ids: false,
        }),
        ValueKind::Text => Ok(Parsed {
            literal: literal(Value::Text(text.to_string()), false),
            warning: None,
            fits_some_node_ids: false,
        }),
        ValueKind::Bytes => parse_hex_bytes(text).map(|b| Parsed {
            literal: literal(Value::Bytes(b), false),
            warning: None,
            fits_some_node_ids: false,
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers() {
        assert_eq!(parse_int("0x1A"), Ok(26));
        assert_eq!(parse_int("017"), Ok(15));
        assert_eq!(parse_int("0"), Ok(0));
        assert_eq!(parse_int("-12"), Ok(-12));
        assert_eq!(parse_int("0xFFFFFFFFFFFFFFFF"), Ok(u64::MAX as i128));
        assert!(parse_int("08").is_err());
        assert!(parse_int("0x").is_err());
        assert!(parse_int("12a").is_err());
    }

    #[test]
    fn node_id_formulas() {
        assert_eq!(parse_int_expr("$NODEID+0x180"), Ok((0x180, true)));
        assert_eq!(parse_int_expr(" 0x180 + $NodeId "), Ok((0x180, true)));
        assert_eq!(parse_int_expr("$NODEID"), Ok((0, true)));
        assert!(parse_int_expr("$NODEID*2").is_err());
        assert!(parse_int_expr("1+$NODEID+2").is_err());
    }

    #[test]
    fn reals_and_bytes() {
        assert_eq!(parse_real("0x3F800000", 32), Ok(1.0));
        assert_eq!(parse_real("1.5", 32), Ok(1.5));
        assert_eq!(parse_real("-2e3", 64), Ok(-2000.0));
        assert_eq!(parse_hex_bytes("01 0a FF"), Ok(vec![1, 10, 255]));
        assert!(parse_hex_bytes("abc").is_err());
    }

    #[test]
    fn signed_hex_is_a_bit_pattern() {
        let p = parse_value("0xFFFF", DataType::Integer16).unwrap().unwrap();
        assert_eq!(p.literal.value, Value::Integer(-1));
        assert!(p.warning.is_none());
        let p = parse_value("300", DataType::Unsigned8).unwrap().unwrap();
        assert!(p.warning.is_some());
    }
}
