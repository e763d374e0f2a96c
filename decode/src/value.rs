//! Values on the wire, by data type, from the IR at run time: decoding the
//! bytes of an SDO transfer or a PDO field, printing them with unit, scale,
//! named values and bit fields (the YAML semantic layer), parsing what a
//! user typed into the bytes to download, and the IR values of a DCF's
//! `ParameterValue`. The trace decoder and the live-bus commands of the
//! command line both use these rules.

use std::fmt::Write as _;

use eds2rust::ir::{BitField, DataType, Semantics, Value, ValueKind, ValueTable};

/// Longest byte string printed whole; longer ones are cut with their length.
const BYTES_SHOWN: usize = 64;

/// A decoded value.
#[derive(Debug, Clone, PartialEq)]
pub enum Decoded {
    /// Integers, BOOLEAN (0/1) and the TIME types (their raw 48 bits).
    Int(i128),
    Real(f64),
    Text(String),
    Bytes(Vec<u8>),
}

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
pub fn decode(t: DataType, data: &[u8]) -> Result<(Decoded, Option<String>), String> {
    let Some(kind) = t.value_kind() else {
        return Ok((Decoded::Bytes(data.to_vec()), None));
    };
    let mut note = None;
    let fixed = match fixed_size(t) {
        Some(size) => {
            if data.len() < size {
                return Err(format!(
                    "{} bytes ({}) cannot be a {} ({size} bytes)",
                    data.len(),
                    hex_bytes(data),
                    t.name()
                ));
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
                return Err(format!("{v:#04X} is not a BOOLEAN (0 or 1)"));
            }
            Decoded::Int(v)
        }
        ValueKind::Real { bits: 32 } => {
            let b: [u8; 4] = fixed.try_into().map_err(|_| "REAL32 needs 4 bytes")?;
            Decoded::Real(f64::from(f32::from_le_bytes(b)))
        }
        ValueKind::Real { .. } => {
            let b: [u8; 8] = fixed.try_into().map_err(|_| "REAL64 needs 8 bytes")?;
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
pub fn encode(t: DataType, value: &Decoded) -> Result<Vec<u8>, String> {
    let kind = t
        .value_kind()
        .ok_or_else(|| format!("data type {:#06X} is not a basic type", t.code()))?;
    match (kind, value) {
        (ValueKind::Integer { .. }, Decoded::Int(v)) => {
            let (low, high) = t.integer_range().unwrap_or((i128::MIN, i128::MAX));
            if *v < low || *v > high {
                return Err(format!(
                    "{v} is outside the range of {} ({low} to {high})",
                    t.name()
                ));
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
            if let Some(c) = s.chars().find(|c| !(' '..='~').contains(c)) {
                return Err(format!(
                    "{c:?} is not a visible character (a VISIBLE_STRING holds 0x20 to 0x7E)"
                ));
            }
            Ok(s.as_bytes().to_vec())
        }
        (ValueKind::Bytes, Decoded::Bytes(b)) => Ok(b.clone()),
        (_, other) => Err(format!("{other:?} is not a value of {}", t.name())),
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

/// Bytes in hex, space-separated (`01 0A FF`); `(empty)` for none.
pub fn hex_bytes(data: &[u8]) -> String {
    if data.is_empty() {
        return "(empty)".into();
    }
    let mut s = String::new();
    for (i, b) in data.iter().take(BYTES_SHOWN).enumerate() {
        let sep = if i == 0 { "" } else { " " };
        let _ = write!(s, "{sep}{b:02X}");
    }
    if data.len() > BYTES_SHOWN {
        let _ = write!(s, " ... ({} bytes)", data.len());
    }
    s
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
pub fn parse(t: DataType, semantics: &Semantics, text: &str) -> Result<Decoded, String> {
    let kind = t
        .value_kind()
        .ok_or_else(|| format!("data type {:#06X} is not a basic type", t.code()))?;
    let trimmed = text.trim();
    match kind {
        ValueKind::Integer { bits: 1, .. } => match trimmed.to_ascii_lowercase().as_str() {
            "true" | "1" | "on" => Ok(Decoded::Int(1)),
            "false" | "0" | "off" => Ok(Decoded::Int(0)),
            _ => Err(format!("`{text}` is not a BOOLEAN (true, false, 1 or 0)")),
        },
        ValueKind::Integer { .. } => parse_int_value(t, semantics, trimmed).map(Decoded::Int),
        ValueKind::Real { .. } => {
            let number = strip_unit(trimmed, semantics.unit.as_deref());
            number
                .parse::<f64>()
                .map(Decoded::Real)
                .map_err(|_| format!("`{text}` is not a number"))
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

fn parse_int_value(t: DataType, sem: &Semantics, text: &str) -> Result<i128, String> {
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
                return Err(format!(
                    "{text} is not a whole number of steps of {} {}",
                    sem.scale.unwrap_or(1.0),
                    sem.unit.as_deref().unwrap_or("")
                ));
            }
            return Ok(rounded as i128);
        }
    }
    let mut message = format!("`{text}` is not valid for {}", t.name());
    if let Some(table) = &sem.values {
        let names: Vec<String> = table
            .named
            .iter()
            .filter(|n| !n.is_range())
            .map(|n| format!("{:?}", n.name))
            .collect();
        if !names.is_empty() {
            let _ = write!(message, " (a number or one of {})", names.join(", "));
        }
    }
    Err(message)
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
pub fn parse_hex(text: &str) -> Result<Vec<u8>, String> {
    let body = text
        .strip_prefix("0x")
        .or_else(|| text.strip_prefix("0X"))
        .unwrap_or(text);
    let digits: String = body
        .chars()
        .filter(|c| !matches!(c, ' ' | ':' | '-' | '_'))
        .collect();
    if !digits.len().is_multiple_of(2) || !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(format!(
            "`{text}` is not hex bytes (two hex digits a byte, e.g. 010AFF or \"01 0A FF\")"
        ));
    }
    Ok((0..digits.len() / 2)
        .map(|i| u8::from_str_radix(&digits[2 * i..2 * i + 2], 16).unwrap_or(0))
        .collect())
}

/// The data type a `--type` name stands for: `u8`..`u64`, `i8`..`i64`,
/// `bool`, `f32`, `f64`, `str`, `unicode`, `bytes`, `domain`, or a CiA 301
/// name (`UNSIGNED16`).
pub fn parse_type(name: &str) -> Result<DataType, String> {
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
            return Err(format!(
                "`{name}` is not a type: u8 u16 u24 u32 u40 u48 u56 u64, i8 .. i64, bool, \
                 f32, f64, str, unicode, bytes, domain"
            ));
        }
    };
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use eds2rust::ir::{NamedValue, Origin};

    #[test]
    fn integers_round_trip_by_type() {
        for (t, v) in [
            (DataType::Unsigned8, 200),
            (DataType::Integer8, -5),
            (DataType::Integer24, -0x7F_FFFF),
            (DataType::Unsigned64, u64::MAX as i128),
            (DataType::Integer64, i64::MIN as i128),
            (DataType::Boolean, 1),
        ] {
            let bytes = encode(t, &Decoded::Int(v)).unwrap();
            assert_eq!(bytes.len(), fixed_size(t).unwrap());
            assert_eq!(decode(t, &bytes).unwrap(), (Decoded::Int(v), None), "{t:?}");
        }
        assert!(encode(DataType::Unsigned8, &Decoded::Int(256)).is_err());
        assert!(encode(DataType::Integer8, &Decoded::Int(-129)).is_err());
        let (v, note) = decode(DataType::Unsigned8, &[7, 0, 0, 0]).unwrap();
        assert_eq!(v, Decoded::Int(7));
        assert!(note.unwrap().contains("4 bytes"));
        assert!(decode(DataType::Unsigned16, &[7]).is_err());
    }

    #[test]
    fn parse_and_describe_with_semantics() {
        let origin = Origin::default();
        let sem = Semantics {
            unit: Some("mm".into()),
            scale: Some(0.1),
            values: Some(ValueTable {
                numeric: Some((0, 0xFAFF)),
                named: vec![NamedValue {
                    low: 0xFB00,
                    high: 0xFB00,
                    name: "clear error".into(),
                    text: None,
                    rust_name: None,
                    origin,
                }],
                other: "invalid".into(),
            }),
            ..Semantics::default()
        };
        let t = DataType::Unsigned16;
        assert_eq!(parse(t, &sem, "12.5 mm").unwrap(), Decoded::Int(125));
        assert_eq!(parse(t, &sem, "12.5mm").unwrap(), Decoded::Int(125));
        assert_eq!(parse(t, &sem, "0x7D").unwrap(), Decoded::Int(125));
        assert_eq!(parse(t, &sem, "Clear Error").unwrap(), Decoded::Int(0xFB00));
        assert!(parse(t, &sem, "12.55 mm").is_err());
        assert_eq!(
            describe(t, &sem, &Decoded::Int(125)),
            "125 (0x007D) = 12.5 mm"
        );
        assert_eq!(
            describe(t, &sem, &Decoded::Int(0xFB00)),
            "64256 (0xFB00) \"clear error\""
        );
        assert_eq!(
            describe(t, &sem, &Decoded::Int(0xFC00)),
            "64512 (0xFC00) \"invalid\""
        );
    }

    #[test]
    fn strings_bytes_and_types() {
        let none = Semantics::default();
        assert_eq!(
            parse(DataType::OctetString, &none, "01 0a FF").unwrap(),
            Decoded::Bytes(vec![1, 10, 255])
        );
        assert!(parse_hex("0").is_err());
        assert_eq!(
            decode(DataType::VisibleString, b"ab\0\0").unwrap().0,
            Decoded::Text("ab".into())
        );
        assert!(encode(DataType::VisibleString, &Decoded::Text("é".into())).is_err());
        assert_eq!(parse_type("U16").unwrap(), DataType::Unsigned16);
        assert_eq!(parse_type("UNSIGNED16").unwrap(), DataType::Unsigned16);
        assert!(parse_type("u12").is_err());
        assert_eq!(parse_int("-0x10"), Some(-16));
        assert_eq!(parse_int("1_000"), Some(1000));
        assert_eq!(parse_int("abc"), None);
        assert_eq!(
            describe(DataType::Real32, &none, &Decoded::Real(f64::from(0.1f32))),
            "0.1"
        );
    }
}
