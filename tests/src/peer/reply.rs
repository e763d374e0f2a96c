//! The replies of the peer: outcomes and hex values.

use serde_json::Value;

/// How a command ended, from its reply.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// `"ok": true`: the whole reply.
    Done(Value),
    /// An SDO abort with this code (python-canopen's `SdoAbortedError`).
    Abort(u32),
    /// Any other Python exception, as text.
    Error(String),
}

impl Outcome {
    /// Classifies a reply of the peer.
    pub fn of(reply: Value) -> Outcome {
        if let Some(code) = reply.get("abort").and_then(Value::as_u64) {
            return Outcome::Abort(u32::try_from(code).unwrap_or(u32::MAX));
        }
        if reply.get("ok") == Some(&Value::Bool(true)) {
            return Outcome::Done(reply);
        }
        match reply.get("error").and_then(Value::as_str) {
            Some(text) => Outcome::Error(text.to_string()),
            None => Outcome::Error(format!("unexpected reply {reply}")),
        }
    }

    /// The bytes of a successful reply's `"value"`.
    pub fn value(&self) -> Result<Vec<u8>, String> {
        match self {
            Outcome::Done(reply) => match reply.get("value").and_then(Value::as_str) {
                Some(text) => unhex(text),
                None => Err(format!("no value in {reply}")),
            },
            other => Err(format!("expected a value, got {other:?}")),
        }
    }
}

/// Uppercase hex of bytes, as the peer takes values (`"0A1B"`).
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02X}")).collect()
}

/// Bytes from a hex string of a reply's `"value"`.
pub fn unhex(text: &str) -> Result<Vec<u8>, String> {
    if !text.len().is_multiple_of(2) {
        return Err(format!("odd-length hex {text:?}"));
    }
    text.as_bytes()
        .chunks(2)
        .map(|pair| {
            std::str::from_utf8(pair)
                .ok()
                .and_then(|p| u8::from_str_radix(p, 16).ok())
                .ok_or_else(|| format!("bad hex {text:?}"))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_round_trips() {
        assert_eq!(hex(&[0, 0x1A, 0xFF]), "001AFF");
        assert_eq!(unhex("001AFF").unwrap(), vec![0, 0x1A, 0xFF]);
        assert_eq!(unhex("").unwrap(), Vec::<u8>::new());
        assert!(unhex("0").is_err());
        assert!(unhex("zz").is_err());
    }
}
