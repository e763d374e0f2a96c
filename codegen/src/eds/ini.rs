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
}

/// One `[section]` with its properties.
#[derive(Debug, Clone)]
pub struct Section<'a> {
    /// The name as written, without brackets.
    pub name: &'a str,
    pub line: u32,
    pub header_span: Range<usize>,
    pub properties: Vec<Property<'a>>,
    /// Lowercase key → position in `properties`, once the section has more
    /// than [`SCAN_LIMIT`] keys: lookups stay constant time in sections of
    /// any size (a list of 200,000 objects), and small sections (every
    /// object section) pay no allocation per key.
    index: Option<HashMap<String, usize>>,
}

/// Sections with at most this many keys are searched by a scan.
const SCAN_LIMIT: usize = 16;

impl<'a> Section<'a> {
    fn new(name: &'a str, line: u32, header_span: Range<usize>) -> Section<'a> {
        Section {
            name,
            line,
            header_span,
            properties: Vec::new(),
            index: None,
        }
    }

    /// The position in `properties` of the key `key`, without regard to case.
    fn position(&self, key: &str) -> Option<usize> {
        match &self.index {
            Some(index) => index.get(&key.to_ascii_lowercase()).copied(),
            None => self
                .properties
                .iter()
                .position(|p| p.key.eq_ignore_ascii_case(key)),
        }
    }

    /// Adds a property whose key is not in the section yet.
    fn push(&mut self, property: Property<'a>) {
        let position = self.properties.len();
        if let Some(index) = &mut self.index {
            index.insert(property.key.to_ascii_lowercase(), position);
        } else if position == SCAN_LIMIT {
            let index = self
                .properties
                .iter()
                .chain([&property])
                .enumerate()
                .map(|(i, p)| (p.key.to_ascii_lowercase(), i))
                .collect();
            self.index = Some(index);
        }
        self.properties.push(property);
    }

    /// The property whose key matches `key` without regard to case.
    pub fn get(&self, key: &str) -> Option<&Property<'a>> {
        self.position(key).map(|i| &self.properties[i])
    }
}

/// A parsed INI document.
#[derive(Debug, Clone)]
pub struct Document<'a> {
    pub file: String,
    pub text: &'a str,
    pub sections: Vec<Section<'a>>,
    by_name: HashMap<String, usize>,
}

impl<'a> Document<'a> {
    /// The section whose header is on `line` (sections are in file order).
    pub fn section_at_line(&self, line: u32) -> Option<&Section<'a>> {
        let i = self.sections.partition_point(|s| s.line < line);
        self.sections.get(i).filter(|s| s.line == line)
    }

    /// The section whose name matches `name` without regard to case.
    pub fn section(&self, name: &str) -> Option<&Section<'a>> {
        self.by_name
            .get(&name.to_ascii_lowercase())
            .map(|&i| &self.sections[i])
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
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = match std::str::from_utf8(bytes) {
        Ok(text) => text.to_string(),
        Err(err) => {
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
    diags.push(Diagnostic {
        severity: Severity::Warning,
        code,
        file: file.to_string(),
        location: Location {
            line: Some(line),
            span: Some(start..end.max(start)),
            ..Location::default()
        },
        message,
        notes: vec![note.to_string()],
    });
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
    let mut sections: Vec<Section<'a>> = Vec::new();
    let mut by_name: HashMap<String, usize> = HashMap::new();
    // Index into `sections` of the section that receives properties now.
    let mut current: Option<usize> = None;
    let warn = |diags: &mut Diagnostics,
                code,
                line,
                span: Range<usize>,
                section: Option<&str>,
                key: Option<&str>,
                message: String| {
        diags.push(Diagnostic {
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
        })
    };

    let mut offset = 0usize;
    for (n, raw_line) in text.split('\n').enumerate() {
        let line_no = n as u32 + 1;
        let line_offset = offset;
        offset += raw_line.len() + 1;
        let content = raw_line.strip_suffix('\r').unwrap_or(raw_line);
        let lead = content.len() - content.trim_start().len();
        let trimmed = content.trim();
        let line_span = line_offset + lead..line_offset + lead + trimmed.len();
        if trimmed.is_empty() || trimmed.starts_with(';') || trimmed.starts_with('#') {
            continue;
        }
        if let Some(rest) = trimmed.strip_prefix('[') {
            let Some(close) = rest.find(']') else {
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
            let name = rest[..close].trim();
            let after = rest[close + 1..].trim();
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
            let key = name.to_ascii_lowercase();
            if let Some(&existing) = by_name.get(&key) {
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
            } else {
                by_name.insert(key, sections.len());
                current = Some(sections.len());
                sections.push(Section::new(name, line_no, line_span));
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
        let Some(eq) = trimmed.find('=') else {
            warn(
                diags,
                "eds::not-key-value",
                line_no,
                line_span,
                Some(sections[section_index].name),
                None,
                "a line without `=` is ignored".to_string(),
            );
            continue;
        };
        let key = trimmed[..eq].trim();
        if key.is_empty() {
            warn(
                diags,
                "eds::not-key-value",
                line_no,
                line_span,
                Some(sections[section_index].name),
                None,
                "a line with an empty key is ignored".to_string(),
            );
            continue;
        }
        let raw_value = &trimmed[eq + 1..];
        let value_lead = raw_value.len() - raw_value.trim_start().len();
        let mut value = raw_value.trim();
        if !is_free_text_key(key) {
            value = strip_inline_comment(value);
        }
        let value_start = line_span.start + eq + 1 + value_lead;
        let value_span = if value.is_empty() {
            line_span.start..line_span.start + eq
        } else {
            value_start..value_start + value.len()
        };
        let property = Property {
            key,
            value,
            line: line_no,
            value_span,
            line_span: line_span.clone(),
        };
        let section = &mut sections[section_index];
        if let Some(pos) = section.position(key) {
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
