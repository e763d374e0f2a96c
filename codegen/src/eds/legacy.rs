//! The bytes of a file that is not UTF-8, as text: UTF-16 when a
//! byte-order mark says so, else Windows-1252. The same decoding as the
//! WHATWG Encoding Standard's `decode` with Windows-1252 as the fallback
//! (BOM sniffing, malformed sequences replaced by U+FFFD), without an
//! encoding library in every build script's dependencies.

/// What a file was read as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Encoding {
    /// No byte-order mark: Windows-1252 (Latin-1 with printable 0x80–0x9F).
    Windows1252,
    /// The file starts with this byte-order mark, removed from the text.
    Bom(&'static str),
}

impl Encoding {
    /// Its name in the Encoding Standard (`windows-1252`, `UTF-16LE`, ...).
    pub(crate) fn name(self) -> &'static str {
        match self {
            Encoding::Windows1252 => "windows-1252",
            Encoding::Bom(name) => name,
        }
    }
}

/// `bytes` as text and what they were read as.
pub(crate) fn decode(bytes: &[u8]) -> (String, Encoding) {
    if let Some(rest) = bytes.strip_prefix(b"\xEF\xBB\xBF") {
        (
            String::from_utf8_lossy(rest).into_owned(),
            Encoding::Bom("UTF-8"),
        )
    } else if let Some(rest) = bytes.strip_prefix(b"\xFF\xFE") {
        (utf16(rest, u16::from_le_bytes), Encoding::Bom("UTF-16LE"))
    } else if let Some(rest) = bytes.strip_prefix(b"\xFE\xFF") {
        (utf16(rest, u16::from_be_bytes), Encoding::Bom("UTF-16BE"))
    } else {
        (
            bytes.iter().map(|&b| windows_1252(b)).collect(),
            Encoding::Windows1252,
        )
    }
}

/// UTF-16 code units of `bytes` (`unit` makes one of two bytes), as the
/// standard's UTF-16 decoder reads them: an unpaired surrogate becomes
/// U+FFFD, and so does an odd last byte (one U+FFFD for both when it
/// follows an unpaired leading surrogate).
fn utf16(bytes: &[u8], unit: fn([u8; 2]) -> u16) -> String {
    let pairs = bytes.chunks_exact(2);
    let odd = !pairs.remainder().is_empty();
    let mut text = String::with_capacity(bytes.len());
    let mut lead: Option<u16> = None;
    for pair in pairs {
        let u = unit([pair[0], pair[1]]);
        if let Some(high) = lead.take() {
            if (0xDC00..0xE000).contains(&u) {
                let c = 0x10000 + ((u32::from(high) - 0xD800) << 10) + (u32::from(u) - 0xDC00);
                text.push(char::from_u32(c).unwrap_or(char::REPLACEMENT_CHARACTER));
                continue;
            }
            text.push(char::REPLACEMENT_CHARACTER);
        }
        match u {
            0xD800..0xDC00 => lead = Some(u),
            0xDC00..0xE000 => text.push(char::REPLACEMENT_CHARACTER),
            _ => text.push(char::from_u32(u32::from(u)).unwrap_or(char::REPLACEMENT_CHARACTER)),
        }
    }
    if lead.is_some() || odd {
        text.push(char::REPLACEMENT_CHARACTER);
    }
    text
}

/// One byte of Windows-1252 (the standard's index: 0x80–0x9F are
/// typographic characters, the five it leaves undefined stay C1 controls).
fn windows_1252(b: u8) -> char {
    const HIGH: [char; 32] = [
        '\u{20AC}', '\u{0081}', '\u{201A}', '\u{0192}', '\u{201E}', '\u{2026}', '\u{2020}',
        '\u{2021}', '\u{02C6}', '\u{2030}', '\u{0160}', '\u{2039}', '\u{0152}', '\u{008D}',
        '\u{017D}', '\u{008F}', '\u{0090}', '\u{2018}', '\u{2019}', '\u{201C}', '\u{201D}',
        '\u{2022}', '\u{2013}', '\u{2014}', '\u{02DC}', '\u{2122}', '\u{0161}', '\u{203A}',
        '\u{0153}', '\u{009D}', '\u{017E}', '\u{0178}',
    ];
    match b {
        0x80..=0x9F => HIGH[usize::from(b - 0x80)],
        _ => char::from(b),
    }
}

#[cfg(test)]
mod tests {
    use super::{Encoding, decode};
    use proptest::prelude::*;

    /// encoding_rs (a dev-dependency only) as the reference.
    fn reference(bytes: &[u8]) -> (String, Encoding) {
        let (text, encoding, _) = encoding_rs::WINDOWS_1252.decode(bytes);
        let ours = if encoding == encoding_rs::WINDOWS_1252 {
            Encoding::Windows1252
        } else {
            Encoding::Bom(encoding.name())
        };
        assert_eq!(ours.name(), encoding.name());
        (text.into_owned(), ours)
    }

    #[test]
    fn every_byte_of_windows_1252() {
        let all: Vec<u8> = (0..=255).collect();
        // Not starting with a byte-order mark.
        assert_eq!(decode(&all), reference(&all));
    }

    #[test]
    fn byte_order_marks_and_their_edges() {
        let cases: &[&[u8]] = &[
            b"",
            b"\xEF\xBB\xBF",
            b"\xEF\xBB\xBFa\xFFb\xE2\x82",
            b"\xEF\xBB",
            b"\xFF\xFE",
            b"\xFF\xFEa",
            b"\xFF\xFEa\x00b",
            b"\xFF\xFE\x00\xD8",
            b"\xFF\xFE\x00\xD8x",
            b"\xFF\xFE\x00\xD8\x00\xDC",
            b"\xFF\xFE\x00\xD8\x00\xDCx",
            b"\xFF\xFE\x00\xDC\x00\xD8",
            b"\xFF\xFE\x00\xD8\x00\xD8\x00\xDC",
            b"\xFF\xFE\x00\xD8a\x00",
            b"\xFE\xFF\xD8\x00",
            b"\xFE\xFF\xD8\x00\xDC\x00x",
            b"\xFE\xFF\x00a\x00",
            b"\xFE",
            b"\xFF",
        ];
        for bytes in cases {
            assert_eq!(decode(bytes), reference(bytes), "{bytes:?}");
        }
    }

    proptest! {
        #[test]
        fn as_the_encoding_standard_decodes(
            bom in prop::sample::select(vec![&b""[..], b"\xEF\xBB\xBF", b"\xFF\xFE", b"\xFE\xFF"]),
            body in prop::collection::vec(
                prop_oneof![any::<u8>(), Just(0xD8u8), Just(0xDCu8), Just(0x00u8)],
                0..64,
            ),
        ) {
            let bytes = [bom, &body[..]].concat();
            prop_assert_eq!(decode(&bytes), reference(&bytes));
        }
    }
}
