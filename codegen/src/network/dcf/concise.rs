//! The concise DCF (CiA 302-3, the format of object 0x1F22 and of
//! dcfgen's `.bin` files): a little-endian u32 count, then per entry a u16
//! index, a u8 sub-index, a u32 size and that many bytes of data.

use crate::network::config::ConciseEntry;

/// One decoded entry of a concise DCF.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Write {
    pub index: u16,
    pub sub_index: u8,
    pub data: Vec<u8>,
}

/// Why a byte string is not a concise DCF.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DecodeError {
    /// Byte offset where decoding stopped.
    pub offset: usize,
    pub message: String,
}

impl std::fmt::Display for DecodeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "byte {}: {}", self.offset, self.message)
    }
}

impl std::error::Error for DecodeError {}

/// Encodes `entries` in order.
pub fn encode(entries: &[ConciseEntry]) -> Vec<u8> {
    let size: usize = entries.iter().map(|e| 7 + e.data.len()).sum();
    let mut out = Vec::with_capacity(4 + size);
    // A concise DCF counts its entries in 32 bits; a bus file cannot come near.
    out.extend_from_slice(&(entries.len() as u32).to_le_bytes());
    for entry in entries {
        out.extend_from_slice(&entry.index.to_le_bytes());
        out.push(entry.sub_index);
        out.extend_from_slice(&(entry.data.len() as u32).to_le_bytes());
        out.extend_from_slice(&entry.data);
    }
    out
}

/// Decodes a concise DCF into its entries, in order. Bytes after the last
/// counted entry are an error, as is a count or size past the end.
pub fn decode(bytes: &[u8]) -> Result<Vec<Write>, DecodeError> {
    let mut at = 0usize;
    let take = |at: &mut usize, n: usize, what: &str| -> Result<&[u8], DecodeError> {
        let end = at.checked_add(n).filter(|&end| end <= bytes.len());
        match end {
            Some(end) => {
                let slice = &bytes[*at..end];
                *at = end;
                Ok(slice)
            }
            None => Err(DecodeError {
                offset: *at,
                message: format!(
                    "{what} needs {n} bytes, {} are left",
                    bytes.len().saturating_sub(*at)
                ),
            }),
        }
    };
    let count = u32::from_le_bytes(
        take(&mut at, 4, "the entry count")?
            .try_into()
            .unwrap_or([0; 4]),
    );
    let mut entries = Vec::new();
    for n in 0..count {
        let head = take(&mut at, 7, &format!("the header of entry {}", n + 1))?;
        let index = u16::from_le_bytes([head[0], head[1]]);
        let sub_index = head[2];
        let size = u32::from_le_bytes([head[3], head[4], head[5], head[6]]);
        let size = usize::try_from(size).unwrap_or(usize::MAX);
        let data = take(
            &mut at,
            size,
            &format!("the data of entry {} (0x{index:04X}/{sub_index})", n + 1),
        )?;
        entries.push(Write {
            index,
            sub_index,
            data: data.to_vec(),
        });
    }
    if at != bytes.len() {
        return Err(DecodeError {
            offset: at,
            message: format!(
                "{} bytes after the last of {count} entries",
                bytes.len() - at
            ),
        });
    }
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(index: u16, sub_index: u8, data: &[u8]) -> ConciseEntry {
        ConciseEntry {
            index,
            sub_index,
            data: data.to_vec(),
            spot: None,
        }
    }

    #[test]
    fn encodes_count_header_and_data_little_endian() {
        let bytes = encode(&[entry(0x1017, 0, &[0xE8, 0x03]), entry(0x60C2, 1, &[0x0F])]);
        assert_eq!(
            bytes,
            [
                2, 0, 0, 0, // count
                0x17, 0x10, 0, 2, 0, 0, 0, 0xE8, 0x03, // 0x1017/0 = 1000
                0xC2, 0x60, 1, 1, 0, 0, 0, 0x0F, // 0x60C2/1 = 15
            ]
        );
    }

    #[test]
    fn decodes_what_it_encodes() {
        let entries = [entry(0x1400, 1, &[3, 2, 0, 0x80]), entry(0x1600, 0, &[0])];
        let decoded = decode(&encode(&entries)).unwrap();
        let back: Vec<_> = decoded
            .into_iter()
            .map(|w| entry(w.index, w.sub_index, &w.data))
            .collect();
        assert_eq!(back, entries);
        assert_eq!(decode(&encode(&[])).unwrap(), []);
    }

    #[test]
    fn refuses_truncated_and_trailing_bytes() {
        let bytes = encode(&[entry(0x1017, 0, &[0xE8, 0x03])]);
        for cut in 0..bytes.len() {
            assert!(decode(&bytes[..cut]).is_err(), "cut at {cut}");
        }
        let mut long = bytes.clone();
        long.push(0);
        assert_eq!(decode(&long).unwrap_err().offset, bytes.len());
        // A size near u32::MAX does not allocate or overflow.
        let huge = [1, 0, 0, 0, 0x17, 0x10, 0, 0xFF, 0xFF, 0xFF, 0xFF];
        assert!(decode(&huge).is_err());
    }
}
