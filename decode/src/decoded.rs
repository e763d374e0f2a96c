//! A decoded value, and bytes in hex as values print them.

use std::fmt::Write as _;

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
