//! The INI layer of CiA 306: bytes → decoded text → sections of `key=value`.
//!
//! Rules (documented in docs/eds-reader.md):
//! - The file is UTF-8 (a BOM is dropped); if it is not, it is decoded as
//!   Windows-1252 (a superset of Latin-1's printable range) with a warning.
//! - Lines end in LF or CRLF. Leading and trailing white space is ignored.
//! - A line whose first non-blank character is `;` or `#` is a comment.
//! - Section names and keys are matched without regard to case.
//! - In values, a `;` preceded by white space starts a comment (as
//!   python-canopen's INI parser does), except in free-text keys (names,
//!   descriptions), where the whole rest of the line is the value. A `;` or `#`
//!   not preceded by white space is always part of the value.
//! - A repeated key in one section: the later one wins (warning). A repeated
//!   section: its keys are merged into the first one, later keys winning
//!   (warning).

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::hash::{Hash, Hasher};
use std::ops::Range;

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};

/// A `key=value` line.
#[derive(Debug, Clone)]
pub struct Property<'a> {
    /// The key as written.
    pub key: &'a str,
    /// The value, trimmed, with any inline comment removed.
    pub value: &'a str,
    pub line: u32,
    /// Byte range of the value in the decoded text (of the key when the value is empty).
    pub value_span: Range<usize>,
    /// Byte range of the whole line without its end-of-line.
    pub line_span: Range<usize>,
    /// [`fold`] of the key: a key is compared in full only where this matches.
    fold: u64,
}

/// One `[section]` with its properties.
#[derive(Debug, Clone)]
pub struct Section<'a> {
    /// The name as written, without brackets.
    pub name: &'a str,
    pub line: u32,
    pub header_span: Range<usize>,
    pub properties: Vec<Property<'a>>,
    /// Key (any case) → position in `properties`, once the section has more
    /// than [`SCAN_LIMIT`] keys: lookups stay constant time in sections of
    /// any size (a list of 200,000 objects), and small sections (every
    /// object section) are scanned by [`Property::fold`].
    index: Option<HashMap<NoCase<'a>, usize>>,
}

/// Sections with at most this many keys are searched by a scan.
const SCAN_LIMIT: usize = 16;

/// A name compared and hashed without regard to ASCII case, borrowed from
/// the text (no lowercase copy).
#[derive(Debug, Clone, Copy)]
struct NoCase<'a>(&'a str);

impl PartialEq for NoCase<'_> {
    fn eq(&self, other: &Self) -> bool {
        same_key(self.0, other.0)
    }
}

impl Eq for NoCase<'_> {}

impl Hash for NoCase<'_> {
    fn hash<H: Hasher>(&self, state: &mut H) {
        let mut buf = [0u8; 32];
        for chunk in self.0.as_bytes().chunks(buf.len()) {
            let lower = &mut buf[..chunk.len()];
            lower.copy_from_slice(chunk);
            lower.make_ascii_lowercase();
            state.write(lower);
        }
        state.write_u8(0xFF);
    }
}

/// Whether two keys are equal without regard to ASCII case (most files
/// write a key as CiA 306 does: compared byte for byte first).
fn same_key(a: &str, b: &str) -> bool {
    a == b || a.eq_ignore_ascii_case(b)
}

/// A summary of a key, equal for keys equal without regard to ASCII case
/// (a filter: keys of equal summaries are compared in full): its length
/// and its first seven bytes with the ASCII case bit (0x20) set.
#[inline(always)]
fn fold(key: &str) -> u64 {
    let bytes = key.as_bytes();
    let mut word = (bytes.len() as u64) << 56;
    for (i, &b) in bytes.iter().take(7).enumerate() {
        word |= u64::from(b | 0x20) << (8 * i);
    }
    word
}

impl<'a> Section<'a> {
    /// A section without properties, room made for `keys` of them.
    fn new(name: &'a str, line: u32, header_span: Range<usize>, keys: usize) -> Section<'a> {
        Section {
            name,
            line,
            header_span,
            properties: Vec::with_capacity(keys),
            index: None,
        }
    }

    /// The position in `properties` of the key `key` (whose [`fold`] is
    /// `folded`), without regard to case.
    fn position(&self, key: &str, folded: u64) -> Option<usize> {
        match &self.index {
            Some(index) => index.get(&NoCase(key)).copied(),
            None => self
                .properties
                .iter()
                .position(|p| p.fold == folded && same_key(p.key, key)),
        }
    }

    /// Adds a property whose key is not in the section yet.
    fn push(&mut self, property: Property<'a>) {
        let position = self.properties.len();
        if let Some(index) = &mut self.index {
            index.insert(NoCase(property.key), position);
        } else if position == SCAN_LIMIT {
            let index = self
                .properties
                .iter()
                .chain([&property])
                .enumerate()
                .map(|(i, p)| (NoCase(p.key), i))
                .collect();
            self.index = Some(index);
        }
        self.properties.push(property);
    }

    /// The property whose key matches `key` without regard to case.
    #[inline(always)]
    pub fn get(&self, key: &str) -> Option<&Property<'a>> {
        // Inlined, so that the fold of a constant key is a constant.
        self.position(key, fold(key)).map(|i| &self.properties[i])
    }
}

/// A parsed INI document.
#[derive(Debug, Clone)]
pub struct Document<'a> {
    pub file: String,
    pub text: &'a str,
    pub sections: Vec<Section<'a>>,
    by_name: HashMap<NoCase<'a>, usize>,
}

impl<'a> Document<'a> {
    /// The section whose header is on `line` (sections are in file order).
    pub fn section_at_line(&self, line: u32) -> Option<&Section<'a>> {
        let i = self.sections.partition_point(|s| s.line < line);
        self.sections.get(i).filter(|s| s.line == line)
    }

    /// The section whose name matches `name` without regard to case.
    pub fn section(&self, name: &str) -> Option<&Section<'a>> {
        self.by_name.get(&NoCase(name)).map(|&i| &self.sections[i])
    }
}

/// Keys whose values are free text: no inline comments are stripped there.
fn is_free_text_key(key: &str) -> bool {
    const KEYS: &[&str] = &[
        "parametername",
        "denotation",
        "description",
        "vendorname",
        "productname",
        "ordercode",
        "createdby",
        "modifiedby",
        "filename",
        "nodename",
        "networkname",
    ];
    KEYS.iter().any(|k| k.eq_ignore_ascii_case(key))
        || key.get(..4).is_some_and(|p| p.eq_ignore_ascii_case("line"))
}

/// Decodes the bytes of a file: UTF-8, else UTF-16 when a byte-order mark
/// says so, else Windows-1252, with a warning saying what it was read as.
/// CR line endings alone (old Mac OS) become line breaks, as in
/// python-canopen's reader (Python's universal newlines), with a warning.
pub fn decode(file: &str, bytes: &[u8], diags: &mut Diagnostics) -> String {
    decode_owned(file, bytes.to_vec(), diags)
}

/// [`decode`] of bytes the caller hands over: UTF-8 text keeps them (no copy).
pub(super) fn decode_owned(file: &str, mut bytes: Vec<u8>, diags: &mut Diagnostics) -> String {
    const BOM: &[u8] = b"\xEF\xBB\xBF";
    if bytes.starts_with(BOM) {
        bytes.drain(..BOM.len());
    }
    let text = match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(err) => {
            let (bytes, err) = (err.as_bytes(), err.utf8_error());
            // `decode` follows a UTF-16 byte-order mark, else reads Windows-1252.
            let (text, encoding) = super::legacy::decode(bytes);
            let (line, message) = if encoding == super::legacy::Encoding::Windows1252 {
                let offset = err.valid_up_to();
                let line = bytes[..offset].iter().filter(|&&b| b == b'\n').count() as u32 + 1;
                let message = format!(
                    "the file is not valid UTF-8 (byte 0x{:02X} at line {line}); read as Windows-1252 (Latin-1)",
                    bytes[offset]
                );
                (line, message)
            } else {
                let name = encoding.name();
                let message = format!(
                    "the file is {name}, not UTF-8 (it starts with a {name} byte-order mark); read as {name}"
                );
                (1, message)
            };
            let note = "save the file as UTF-8 to silence this warning";
            warn_whole_line(file, &text, line, "eds::not-utf8", message, note, diags);
            text
        }
    };
    lone_cr_as_line_breaks(file, text, diags)
}

/// A file without LF whose lines end with CR alone (old Mac OS): every CR
/// becomes LF, which keeps byte offsets and gives the line numbers an editor
/// shows. A lone CR in a file of LF or CR LF lines stays as it is.
fn lone_cr_as_line_breaks(file: &str, text: String, diags: &mut Diagnostics) -> String {
    if text.contains('\n') || !text.contains('\r') {
        return text;
    }
    let text = text.replace('\r', "\n");
    let message =
        "the lines end with CR alone (old Mac OS line endings); each CR is read as a line break";
    let note = "save the file with LF or CR LF line endings to silence this warning";
    warn_whole_line(
        file,
        &text,
        1,
        "eds::line-endings",
        message.into(),
        note,
        diags,
    );
    text
}

/// A warning about a whole line of the decoded text.
fn warn_whole_line(
    file: &str,
    text: &str,
    line: u32,
    code: &'static str,
    message: String,
    note: &str,
    diags: &mut Diagnostics,
) {
    let start = line_start(text, line);
    let end = text[start..].find('\n').map_or(text.len(), |n| start + n);
    let mut warning = warning(file, code, line, start..end.max(start), None, None, message);
    warning.notes.push(note.to_string());
    diags.push(warning);
}

/// A warning of the INI layer at `line` (`span` of the text), in `section`
/// at `key` where those are known.
fn warning(
    file: &str,
    code: &'static str,
    line: u32,
    span: Range<usize>,
    section: Option<&str>,
    key: Option<&str>,
    message: String,
) -> Diagnostic {
    Diagnostic {
        severity: Severity::Warning,
        code,
        file: file.to_string(),
        location: Location {
            line: Some(line),
            span: Some(span),
            section: section.map(str::to_string),
            key: key.map(str::to_string),
        },
        message,
        notes: Vec::new(),
    }
}

fn line_start(text: &str, line: u32) -> usize {
    if line <= 1 {
        return 0;
    }
    text.match_indices('\n')
        .nth(line as usize - 2)
        .map_or(text.len(), |(i, _)| i + 1)
}

/// Splits decoded text into sections. Problems of the INI layer are pushed to `diags`.
pub fn parse<'a>(file: &str, text: &'a str, diags: &mut Diagnostics) -> Document<'a> {
    // Room for the sections of a typical file of this size (a section
    // of a real file is 140 bytes on average), up to a bound.
    let headers = (text.len() / 128).min(1 << 16);
    let mut sections: Vec<Section<'a>> = Vec::with_capacity(headers);
    let mut by_name: HashMap<NoCase<'a>, usize> = HashMap::with_capacity(headers);
    // Index into `sections` of the section that receives properties now.
    let mut current: Option<usize> = None;
    let warn = |diags: &mut Diagnostics,
                code,
                line,
                span: Range<usize>,
                section: Option<&str>,
                key: Option<&str>,
                message: String| {
        diags.push(warning(file, code, line, span, section, key, message))
    };

    for (n, (line_offset, raw_line)) in lines(text).enumerate() {
        let line_no = n as u32 + 1;
        let content = raw_line.strip_suffix('\r').unwrap_or(raw_line);
        let trimmed = trim_start(content);
        let lead = content.len() - trimmed.len();
        let trimmed = trim_end(trimmed);
        let line_span = line_offset + lead..line_offset + lead + trimmed.len();
        if trimmed.is_empty() || trimmed.starts_with(';') || trimmed.starts_with('#') {
            continue;
        }
        if let Some(rest) = trimmed.strip_prefix('[') {
            let Some(close) = rest.bytes().position(|b| b == b']') else {
                warn(
                    diags,
                    "eds::bad-section-header",
                    line_no,
                    line_span,
                    None,
                    None,
                    format!("section header `{trimmed}` has no closing `]`; the line is ignored"),
                );
                current = None;
                continue;
            };
            let name = trim(&rest[..close]);
            let after = trim(&rest[close + 1..]);
            if !after.is_empty() && !after.starts_with(';') && !after.starts_with('#') {
                warn(
                    diags,
                    "eds::bad-section-header",
                    line_no,
                    line_span.clone(),
                    Some(name),
                    None,
                    format!("text after the section header is ignored: `{after}`"),
                );
            }
            match by_name.entry(NoCase(name)) {
                Entry::Occupied(first) => {
                    let existing = *first.get();
                    let first_line = sections[existing].line;
                    warn(
                        diags,
                        "eds::duplicate-section",
                        line_no,
                        line_span,
                        Some(name),
                        None,
                        format!(
                            "section [{name}] appears again (first at line {first_line}); its keys are merged into the first, later keys win"
                        ),
                    );
                    current = Some(existing);
                }
                Entry::Vacant(vacant) => {
                    vacant.insert(sections.len());
                    current = Some(sections.len());
                    // Sections of a file are alike: room for as many keys
                    // as the one before had.
                    let keys = sections.last().map_or(0, |s| s.properties.len().min(32));
                    sections.push(Section::new(name, line_no, line_span, keys));
                }
            }
            continue;
        }
        let Some(section_index) = current else {
            warn(
                diags,
                "eds::outside-section",
                line_no,
                line_span,
                None,
                None,
                "a line outside any section (before the first header or after a broken one) is ignored".to_string(),
            );
            continue;
        };
        let eq = trimmed.bytes().position(|b| b == b'=');
        let (eq, key) = match eq.map(|eq| (eq, trim(&trimmed[..eq]))) {
            Some((eq, key)) if !key.is_empty() => (eq, key),
            other => {
                let message = match other {
                    None => "a line without `=` is ignored",
                    Some(_) => "a line with an empty key is ignored",
                };
                warn(
                    diags,
                    "eds::not-key-value",
                    line_no,
                    line_span,
                    Some(sections[section_index].name),
                    None,
                    message.to_string(),
                );
                continue;
            }
        };
        let raw_value = &trimmed[eq + 1..];
        let mut value = trim_start(raw_value);
        let value_lead = raw_value.len() - value.len();
        value = trim_end(value);
        if !is_free_text_key(key) {
            value = strip_inline_comment(value);
        }
        let value_start = line_span.start + eq + 1 + value_lead;
        let value_span = if value.is_empty() {
            line_span.start..line_span.start + eq
        } else {
            value_start..value_start + value.len()
        };
        let folded = fold(key);
        let property = Property {
            key,
            value,
            line: line_no,
            value_span,
            line_span: line_span.clone(),
            fold: folded,
        };
        let section = &mut sections[section_index];
        if let Some(pos) = section.position(key, folded) {
            let first_line = section.properties[pos].line;
            section.properties[pos] = property;
            warn(
                diags,
                "eds::duplicate-key",
                line_no,
                line_span,
                Some(section.name),
                Some(key),
                format!("key repeated (first at line {first_line}); this later value wins"),
            );
        } else {
            section.push(property);
        }
    }
    Document {
        file: file.to_string(),
        text,
        sections,
        by_name,
    }
}

/// The lines of `text` (split at LF, as `str::split`) with the byte offset
/// each starts at.
fn lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let mut start = Some(0);
    std::iter::from_fn(move || {
        let from = start?;
        let rest = &text[from..];
        let len = rest.bytes().position(|b| b == b'\n');
        start = len.map(|len| from + len + 1);
        Some((from, &rest[..len.unwrap_or(rest.len())]))
    })
}

/// Whether `b` is ASCII white space as [`char::is_whitespace`] has it
/// (tab, LF, vertical tab, form feed, CR, space).
fn is_ascii_space(b: u8) -> bool {
    matches!(b, b'\t'..=b'\r' | b' ')
}

/// [`str::trim_start`], skipping ASCII white space byte by byte (the
/// Unicode rule decides only where a non-ASCII character follows).
fn trim_start(s: &str) -> &str {
    let skip = s.bytes().take_while(|&b| is_ascii_space(b)).count();
    let rest = &s[skip..];
    if rest.as_bytes().first().is_some_and(|b| !b.is_ascii()) {
        rest.trim_start()
    } else {
        rest
    }
}

/// [`str::trim_end`], ASCII white space byte by byte as [`trim_start`].
fn trim_end(s: &str) -> &str {
    let skip = s.bytes().rev().take_while(|&b| is_ascii_space(b)).count();
    let rest = &s[..s.len() - skip];
    if rest.as_bytes().last().is_some_and(|b| !b.is_ascii()) {
        rest.trim_end()
    } else {
        rest
    }
}

/// [`str::trim`], ASCII white space byte by byte as [`trim_start`].
fn trim(s: &str) -> &str {
    trim_end(trim_start(s))
}

/// Cuts a value at the first `;` that follows white space.
fn strip_inline_comment(value: &str) -> &str {
    let bytes = value.as_bytes();
    for i in 1..bytes.len() {
        if bytes[i] == b';' && bytes[i - 1].is_ascii_whitespace() {
            return value[..i].trim_end();
        }
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc(text: &str) -> (Document<'_>, Diagnostics) {
        let mut d = Diagnostics::new();
        let doc = parse("t.eds", text, &mut d);
        (doc, d)
    }

    #[test]
    fn comments_case_and_crlf() {
        let (doc, d) =
            doc("; head\r\n[fileINFO]\r\nFileName = a;b #c\r\nDefaultValue=0x10 ; note\r\n");
        assert!(d.is_empty());
        let s = doc.section("FileInfo").unwrap();
        assert_eq!(s.get("filename").unwrap().value, "a;b #c");
        assert_eq!(s.get("DEFAULTVALUE").unwrap().value, "0x10");
        let p = s.get("defaultvalue").unwrap();
        assert_eq!(&doc.text[p.value_span.clone()], "0x10");
        assert_eq!(p.line, 4);
    }

    #[test]
    fn duplicates_later_wins() {
        let (doc, d) = doc("[1000]\na=1\nA=2\n[1000]\nb=3\n");
        assert_eq!(d.len(), 2);
        let s = doc.section("1000").unwrap();
        assert_eq!(s.get("a").unwrap().value, "2");
        assert_eq!(s.get("b").unwrap().value, "3");
    }

    #[test]
    fn duplicates_in_a_large_section_are_found_by_the_index() {
        // Past SCAN_LIMIT keys the section is searched by its index: the
        // same rules (any case, later value wins, the warning names the line
        // of the value it replaces).
        let mut text = String::from("[MandatoryObjects]\n");
        for i in 0..100 {
            text.push_str(&format!("Key{i}={i}\n"));
        }
        text.push_str("KEY7=late\nkey99=later\nKey7=last\n");
        let (doc, d) = doc(&text);
        let s = doc.section("mandatoryobjects").unwrap();
        assert_eq!(s.properties.len(), 100);
        assert_eq!(s.get("key7").unwrap().value, "last");
        assert_eq!(s.get("KEY99").unwrap().value, "later");
        assert_eq!(s.get("Key0").unwrap().line, 2);
        assert!(s.get("Key100").is_none());
        let lines: Vec<(Option<u32>, &str)> = d
            .iter()
            .map(|d| (d.location.line, d.message.as_str()))
            .collect();
        assert_eq!(
            lines,
            [
                (
                    Some(102),
                    "key repeated (first at line 9); this later value wins"
                ),
                (
                    Some(103),
                    "key repeated (first at line 101); this later value wins"
                ),
                (
                    Some(104),
                    "key repeated (first at line 102); this later value wins"
                ),
            ]
        );
    }

    #[test]
    fn latin1_fallback() {
        let mut d = Diagnostics::new();
        let text = decode("t.eds", b"[Comments]\nLine1=Gr\xf6\xdfe\n", &mut d);
        assert_eq!(text, "[Comments]\nLine1=Größe\n");
        assert_eq!(d.len(), 1);
        assert_eq!(d.iter().next().unwrap().location.line, Some(2));
    }
}
