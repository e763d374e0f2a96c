//! Values on the wire, by data type, from the IR at run time: decoding the
//! bytes of an SDO transfer or a PDO field, printing them with unit, scale,
//! named values and bit fields (the YAML semantic layer), parsing what a
//! user typed into the bytes to download, and the IR values of a DCF's
//! `ParameterValue`. The trace decoder and the live-bus commands of the
//! command line both use these rules.

use std::fmt::Write as _;

use eds2rust::ir::{BitField, DataType, Semantics, Value, ValueKind, ValueTable};

pub use crate::decoded::{Decoded, hex_bytes};
use crate::error::{UnknownType, ValueError};

/// The size in bytes of a fixed-size type; `None` for strings and domains.
pub fn fixed_size(t: DataType) -> Option<usize> {
    match t.value_kind()? {
        ValueKind::Integer { bits, .. } => Some((bits as usize).div_ceil(8)),
        ValueKind::Real { bits } => Some(bits as usize / 8),
        ValueKind::Text | ValueKind::Bytes => None,
    }
}

/// The value of `data` as `t`, and a note when the device sent more bytes
/// than the type has (their leading bytes are taken, as the runtime's typed
/// reads do).
pub fn decode(t: DataType, data: &[u8]) -> Result<(Decoded, Option<String>), ValueError> {
    let Some(kind) = t.value_kind() else {
        return Ok((Decoded::Bytes(data.to_vec()), None));
    };
    let mut note = None;
    let fixed = match fixed_size(t) {
        Some(size) => {
            if data.len() < size {
                return Err(ValueError::TooShort {
                    data_type: t,
                    data: data.to_vec(),
                    size,
                });
            }
            if data.len() > size {
                note = Some(format!(
                    "the device sent {} bytes for a {} of {size}; the first {size} taken",
                    data.len(),
                    t.name()
                ));
            }
            &data[..size]
        }
        None => data,
    };
    let too_short = || ValueError::TooShort {
        data_type: t,
        data: data.to_vec(),
        size: fixed.len(),
    };
    let value = match kind {
        ValueKind::Integer { signed, bits } => {
            let mut raw: u128 = 0;
            for (i, b) in fixed.iter().enumerate() {
                raw |= u128::from(*b) << (8 * i);
            }
            let width = if t == DataType::Boolean { 8 } else { bits };
            let v = if signed && width < 128 && raw & (1u128 << (width - 1)) != 0 {
                (raw as i128) - (1i128 << width)
            } else {
                raw as i128
            };
            if t == DataType::Boolean && v > 1 {
                return Err(ValueError::NotBoolean { raw: v });
            }
            Decoded::Int(v)
        }
        ValueKind::Real { bits: 32 } => {
            let b: [u8; 4] = fixed.try_into().map_err(|_| too_short())?;
            Decoded::Real(f64::from(f32::from_le_bytes(b)))
        }
        ValueKind::Real { .. } => {
            let b: [u8; 8] = fixed.try_into().map_err(|_| too_short())?;
            Decoded::Real(f64::from_le_bytes(b))
        }
        ValueKind::Text if t == DataType::UnicodeString => {
            let units: Vec<u16> = fixed
                .chunks(2)
                .map(|c| u16::from_le_bytes([c[0], c.get(1).copied().unwrap_or(0)]))
                .take_while(|&u| u != 0)
                .collect();
            Decoded::Text(String::from_utf16_lossy(&units))
        }
        ValueKind::Text => {
            let end = fixed.iter().position(|&b| b == 0).unwrap_or(fixed.len());
            Decoded::Text(fixed[..end].iter().map(|&b| char::from(b)).collect())
        }
        ValueKind::Bytes => Decoded::Bytes(fixed.to_vec()),
    };
    Ok((value, note))
}

/// The bytes of `value` as `t` (little endian, two's complement).
pub fn encode(t: DataType, value: &Decoded) -> Result<Vec<u8>, ValueError> {
    let kind = t
        .value_kind()
        .ok_or(ValueError::NotBasic { data_type: t })?;
    match (kind, value) {
        (ValueKind::Integer { .. }, Decoded::Int(v)) => {
            let (low, high) = t.integer_range().unwrap_or((i128::MIN, i128::MAX));
            if *v < low || *v > high {
                return Err(ValueError::OutOfRange {
                    data_type: t,
                    value: *v,
                    low,
                    high,
                });
            }
            let size = fixed_size(t).unwrap_or(8);
            Ok((0..size).map(|i| (*v >> (8 * i)) as u8).collect())
        }
        (ValueKind::Real { bits: 32 }, Decoded::Real(v)) => Ok((*v as f32).to_le_bytes().to_vec()),
        (ValueKind::Real { .. }, Decoded::Real(v)) => Ok(v.to_le_bytes().to_vec()),
        (ValueKind::Real { bits: 32 }, Decoded::Int(v)) => Ok((*v as f32).to_le_bytes().to_vec()),
        (ValueKind::Real { .. }, Decoded::Int(v)) => Ok((*v as f64).to_le_bytes().to_vec()),
        (ValueKind::Text, Decoded::Text(s)) if t == DataType::UnicodeString => {
            Ok(s.encode_utf16().flat_map(u16::to_le_bytes).collect())
        }
        (ValueKind::Text, Decoded::Text(s)) => {
            if let Some(character) = s.chars().find(|c| !(' '..='~').contains(c)) {
                return Err(ValueError::NotVisible { character });
            }
            Ok(s.as_bytes().to_vec())
        }
        (ValueKind::Bytes, Decoded::Bytes(b)) => Ok(b.clone()),
        (_, other) => Err(ValueError::WrongKind {
            data_type: t,
            value: other.clone(),
        }),
    }
}

/// The value as the IR keeps it (a DCF `ParameterValue`).
pub fn to_ir(value: &Decoded) -> Value {
    match value {
        Decoded::Int(v) => Value::Integer(*v),
        Decoded::Real(v) => Value::Real(*v),
        Decoded::Text(s) => Value::Text(s.clone()),
        Decoded::Bytes(b) => Value::Bytes(b.clone()),
    }
}

/// An IR value (a DCF `ParameterValue`, node id resolved) as a decoded value.
pub fn from_ir(value: &Value) -> Decoded {
    match value {
        Value::Integer(v) => Decoded::Int(*v),
        Value::Real(v) => Decoded::Real(*v),
        Value::Text(s) => Decoded::Text(s.clone()),
        Value::Bytes(b) => Decoded::Bytes(b.clone()),
    }
}

/// The bare value, for scripts (`--quiet`): integers in decimal, reals as
/// the shortest decimal, text as it is, bytes as hex without spaces.
pub fn plain(value: &Decoded) -> String {
    match value {
        Decoded::Int(v) => v.to_string(),
        Decoded::Real(v) => v.to_string(),
        Decoded::Text(s) => s.clone(),
        Decoded::Bytes(b) => b.iter().fold(String::new(), |mut s, x| {
            let _ = write!(s, "{x:02X}");
            s
        }),
    }
}

/// The value for a person: by type (`592 (0x0250)`, `-5`, `true`, `1.5`,
/// `"text"`, `01 0A FF`), then what the semantic layer says about it (the
/// named value, the physical value with its unit, the state and the bit
/// fields that are set).
pub fn describe(t: DataType, semantics: &Semantics, value: &Decoded) -> String {
    match value {
        Decoded::Int(v) => {
            let mut s = int_text(t, *v);
            let extra = int_meaning(semantics, *v);
            if !extra.is_empty() {
                s.push(' ');
                s.push_str(&extra);
            }
            s
        }
        Decoded::Real(v) => {
            // A REAL32 as the shortest decimal of its f32.
            let n = if t == DataType::Real32 {
                (*v as f32).to_string()
            } else {
                v.to_string()
            };
            match &semantics.unit {
                Some(unit) => format!("{n} {unit}"),
                None => n,
            }
        }
        Decoded::Text(s) => format!("{s:?}"),
        Decoded::Bytes(b) => hex_bytes(b),
    }
}

/// An integer by its type: unsigned ones also in hex, as wide as the type.
fn int_text(t: DataType, v: i128) -> String {
    match t.value_kind() {
        Some(ValueKind::Integer { bits: 1, .. }) => (if v != 0 { "true" } else { "false" }).into(),
        Some(ValueKind::Integer {
            signed: false,
            bits,
        }) if v >= 0 => {
            let digits = (bits as usize).div_ceil(4);
            format!("{v} (0x{v:0digits$X})")
        }
        _ => v.to_string(),
    }
}

/// A float as the shortest decimal of its nine significant digits.
fn number(v: f64) -> String {
    round9(v).to_string()
}

/// The physical value of `raw` (scale, offset) with the unit, if any.
fn physical(raw: i128, scale: Option<f64>, offset: Option<f64>, unit: Option<&String>) -> String {
    if scale.is_none() && offset.is_none() {
        return unit.map(|u| format!("= {raw} {u}")).unwrap_or_default();
    }
    let v = raw as f64 * scale.unwrap_or(1.0) + offset.unwrap_or(0.0);
    match unit {
        Some(u) => format!("= {} {u}", number(v)),
        None => format!("= {}", number(v)),
    }
}

/// The name the entry's value table gives `raw`, if any (a named value or
/// range, or the table's fallback name outside its numeric range).
pub fn named_value(semantics: &Semantics, raw: i128) -> Option<String> {
    semantics.values.as_ref().and_then(|t| named(t, raw))
}

/// The physical value of `raw` when the entry has a scale or an offset.
pub fn physical_value(semantics: &Semantics, raw: i128) -> Option<f64> {
    if semantics.scale.is_none() && semantics.offset.is_none() {
        return None;
    }
    let v = raw as f64 * semantics.scale.unwrap_or(1.0) + semantics.offset.unwrap_or(0.0);
    Some(round9(v))
}

/// `v` rounded to nine significant digits: the decimal a scale factor
/// means (503 × 0.1 is 50.3, not 50.300000000000004).
fn round9(v: f64) -> f64 {
    if !v.is_finite() {
        return v;
    }
    format!("{v:.8e}").parse().unwrap_or(v)
}

/// The name of `raw` in a value table: a named value or range, or
/// `None` inside the numeric range; the fallback name otherwise.
fn named(table: &ValueTable, raw: i128) -> Option<String> {
    if let Some(n) = table.named.iter().find(|n| n.low <= raw && raw <= n.high) {
        return Some(n.name.clone());
    }
    match table.numeric {
        Some((low, high)) if low <= raw && raw <= high => None,
        _ => Some(table.other.clone()),
    }
}

fn int_meaning(sem: &Semantics, raw: i128) -> String {
    let mut parts = Vec::new();
    match sem.values.as_ref().map(|t| named(t, raw)) {
        Some(Some(name)) => parts.push(format!("{name:?}")),
        _ => {
            let p = physical(raw, sem.scale, sem.offset, sem.unit.as_ref());
            if !p.is_empty() {
                parts.push(p);
            }
        }
    }
    let bits = raw as u64;
    if let Some(p) = sem.patterns.iter().find(|p| bits & p.mask == p.value) {
        parts.push(format!("state {:?}", p.name));
    }
    let fields: Vec<String> = sem
        .bits
        .iter()
        .filter_map(|f| field_text(f, bits))
        .collect();
    if !fields.is_empty() {
        parts.push(format!("bits: {}", fields.join(", ")));
    }
    parts.join("; ")
}

/// A bit field that is set (one bit) or not zero (wider), with its value.
fn field_text(f: &BitField, raw: u64) -> Option<String> {
    let mask = if f.width >= 64 {
        u64::MAX
    } else {
        (1u64 << f.width) - 1
    };
    let v = raw.checked_shr(f.lsb).unwrap_or(0) & mask;
    if f.width == 1 {
        return (v == 1).then(|| format!("{:?}", f.name));
    }
    if v == 0 {
        return None;
    }
    let v = i128::from(v);
    let meaning = match f.values.as_ref().and_then(|t| named(t, v)) {
        Some(name) => format!("{name:?}"),
        None => {
            let p = physical(v, f.scale, None, f.unit.as_ref());
            if p.is_empty() {
                v.to_string()
            } else {
                format!("{v} {p}")
            }
        }
    };
    Some(format!("{:?}={meaning}", f.name))
}

/// Parses what the user typed as a value of `t`: integers in decimal or
/// `0x` hex, a named value of the entry (`"profile position"`, any case), a
/// physical value with the entry's unit (`12.5 mm`, `12.5mm`); booleans as
/// `true`/`false`/`1`/`0`; reals; text as it is; byte strings as hex
/// (`010AFF`, `01 0A FF`, `0x010AFF`).
pub fn parse(t: DataType, semantics: &Semantics, text: &str) -> Result<Decoded, ValueError> {
    let kind = t
        .value_kind()
        .ok_or(ValueError::NotBasic { data_type: t })?;
    let trimmed = text.trim();
    match kind {
        ValueKind::Integer { bits: 1, .. } => match trimmed.to_ascii_lowercase().as_str() {
            "true" | "1" | "on" => Ok(Decoded::Int(1)),
            "false" | "0" | "off" => Ok(Decoded::Int(0)),
            _ => Err(ValueError::NotBooleanText { text: text.into() }),
        },
        ValueKind::Integer { .. } => parse_int_value(t, semantics, trimmed).map(Decoded::Int),
        ValueKind::Real { .. } => {
            let number = strip_unit(trimmed, semantics.unit.as_deref());
            number
                .parse::<f64>()
                .map(Decoded::Real)
                .map_err(|_| ValueError::NotNumber { text: text.into() })
        }
        ValueKind::Text => Ok(Decoded::Text(text.to_string())),
        ValueKind::Bytes => parse_hex(trimmed).map(Decoded::Bytes),
    }
}

fn strip_unit<'a>(text: &'a str, unit: Option<&str>) -> &'a str {
    match unit {
        Some(u) if !u.is_empty() => text.strip_suffix(u).map_or(text, str::trim_end),
        _ => text,
    }
}

fn parse_int_value(t: DataType, sem: &Semantics, text: &str) -> Result<i128, ValueError> {
    if let Some(v) = parse_int(text) {
        return Ok(v);
    }
    let unquoted = text.trim_matches('"');
    if let Some(table) = &sem.values
        && let Some(n) = table
            .named
            .iter()
            .find(|n| !n.is_range() && n.name.eq_ignore_ascii_case(unquoted))
    {
        return Ok(n.low);
    }
    if sem.unit.is_some() || sem.scale.is_some() {
        let number = strip_unit(text, sem.unit.as_deref());
        if let Ok(x) = number.parse::<f64>() {
            let raw = (x - sem.offset.unwrap_or(0.0)) / sem.scale.unwrap_or(1.0);
            let rounded = raw.round();
            if (raw - rounded).abs() > 1e-6 * rounded.abs().max(1.0) {
                return Err(ValueError::NotWholeSteps {
                    text: text.into(),
                    scale: sem.scale.unwrap_or(1.0),
                    unit: sem.unit.clone(),
                });
            }
            return Ok(rounded as i128);
        }
    }
    let names = sem.values.as_ref().map_or_else(Vec::new, |table| {
        table
            .named
            .iter()
            .filter(|n| !n.is_range())
            .map(|n| format!("{:?}", n.name))
            .collect()
    });
    Err(ValueError::NotInteger {
        text: text.into(),
        data_type: t,
        names,
    })
}

/// An integer in decimal (optionally negative) or `0x` hex; `_` allowed.
pub fn parse_int(text: &str) -> Option<i128> {
    let cleaned: String = text.chars().filter(|&c| c != '_').collect();
    let (negative, body) = match cleaned.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, cleaned.strip_prefix('+').unwrap_or(&cleaned)),
    };
    let v = if let Some(hex) = body.strip_prefix("0x").or_else(|| body.strip_prefix("0X")) {
        i128::from_str_radix(hex, 16).ok()?
    } else if !body.is_empty() && body.bytes().all(|b| b.is_ascii_digit()) {
        body.parse().ok()?
    } else {
        return None;
    };
    Some(if negative { -v } else { v })
}

/// Hex bytes: `010AFF`, `01 0A FF`, `01:0a:ff` or `0x010AFF`; empty is none.
pub fn parse_hex(text: &str) -> Result<Vec<u8>, ValueError> {
    let body = text
        .strip_prefix("0x")
        .or_else(|| text.strip_prefix("0X"))
        .unwrap_or(text);
    let digits: String = body
        .chars()
        .filter(|c| !matches!(c, ' ' | ':' | '-' | '_'))
        .collect();
    if !digits.len().is_multiple_of(2) || !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(ValueError::NotHex { text: text.into() });
    }
    Ok((0..digits.len() / 2)
        .map(|i| u8::from_str_radix(&digits[2 * i..2 * i + 2], 16).unwrap_or(0))
        .collect())
}

/// The data type a `--type` name stands for: `u8`..`u64`, `i8`..`i64`,
/// `bool`, `f32`, `f64`, `str`, `unicode`, `bytes`, `domain`, or a CiA 301
/// name (`UNSIGNED16`).
pub fn parse_type(name: &str) -> Result<DataType, UnknownType> {
    use DataType::*;
    let t = match name.to_ascii_lowercase().as_str() {
        "bool" | "boolean" => Boolean,
        "i8" | "integer8" => Integer8,
        "i16" | "integer16" => Integer16,
        "i24" | "integer24" => Integer24,
        "i32" | "integer32" => Integer32,
        "i40" | "integer40" => Integer40,
        "i48" | "integer48" => Integer48,
        "i56" | "integer56" => Integer56,
        "i64" | "integer64" => Integer64,
        "u8" | "unsigned8" => Unsigned8,
        "u16" | "unsigned16" => Unsigned16,
        "u24" | "unsigned24" => Unsigned24,
        "u32" | "unsigned32" => Unsigned32,
        "u40" | "unsigned40" => Unsigned40,
        "u48" | "unsigned48" => Unsigned48,
        "u56" | "unsigned56" => Unsigned56,
        "u64" | "unsigned64" => Unsigned64,
        "f32" | "real32" => Real32,
        "f64" | "real64" => Real64,
        "str" | "string" | "visible_string" => VisibleString,
        "unicode" | "unicode_string" => UnicodeString,
        "bytes" | "octet_string" => OctetString,
        "domain" => Domain,
        _ => {
            return Err(UnknownType { name: name.into() });
        }
    };
    Ok(t)
}

#[cfg(test)]
mod tests;
