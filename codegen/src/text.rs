//! Text from an input on its way out: the one place that decides which
//! characters of a name, description or unit may reach a terminal, a
//! generated Rust file or a Markdown code span.
//!
//! Hazards are control characters (C0, DEL, C1: escape sequences, NUL,
//! carriage returns) and the invisible characters that reorder or hide text
//! (bidirectional embeddings, overrides and isolates, the directional marks;
//! rustc rejects them in comments and literals, see CVE-2021-42574).

use std::borrow::Cow;

/// Where an input stops being UTF-8.
#[cfg(feature = "yaml")]
pub(crate) struct NotUtf8 {
    /// The 0-based offset of the first byte that is not UTF-8.
    pub byte: usize,
    /// Its 1-based line.
    pub line: u32,
}

/// An input's bytes as UTF-8 text without a leading byte-order mark.
#[cfg(feature = "yaml")]
pub(crate) fn decode_utf8(bytes: &[u8]) -> Result<&str, NotUtf8> {
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok(text.strip_prefix('\u{feff}').unwrap_or(text)),
        Err(err) => {
            let byte = err.valid_up_to();
            let lines = bytes[..byte].iter().filter(|&&b| b == b'\n').count();
            let line = u32::try_from(lines).unwrap_or(u32::MAX).saturating_add(1);
            Err(NotUtf8 { byte, line })
        }
    }
}

/// Whether `c` is a bidirectional-text control: U+202A–U+202E
/// (embeddings, overrides), U+2066–U+2069 (isolates), U+200E/U+200F (marks)
/// and U+061C (Arabic letter mark).
pub fn is_bidi(c: char) -> bool {
    matches!(c, '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}' | '\u{200E}' | '\u{200F}' | '\u{061C}')
}

/// Whether `c` must not reach a terminal or a generated file as it is: a
/// control character other than a line feed or a tab, or a bidi control.
pub fn is_hazard(c: char) -> bool {
    (c.is_control() && !matches!(c, '\n' | '\t')) || is_bidi(c)
}

/// Whether `text` holds a character that [`is_hazard`] (line feeds count
/// too: a name or unit is one line).
pub fn has_hazard(text: &str) -> bool {
    text.chars().any(|c| c == '\n' || is_hazard(c))
}

/// Text for a terminal: every hazard, and carriage returns, becomes `?`,
/// one per byte, so that byte offsets into the text stay valid (the
/// diagnostics renderer underlines by offset). Line feeds and tabs stay.
pub fn terminal(text: &str) -> Cow<'_, str> {
    if !text.chars().any(|c| is_hazard(c) && c != '\r') {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if is_hazard(c) && c != '\r' {
            out.extend(std::iter::repeat_n('?', c.len_utf8()));
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// One line for a terminal: [`terminal`], with line breaks and carriage
/// returns as `?` too (a name must not start a line of its own).
pub fn terminal_line(text: &str) -> Cow<'_, str> {
    if !has_hazard(text) {
        return Cow::Borrowed(text);
    }
    Cow::Owned(
        text.chars()
            .map(|c| if c == '\n' || is_hazard(c) { '?' } else { c })
            .collect(),
    )
}

/// Text for generated source (Rust, and every other file the generator
/// writes): each hazard becomes its escape as Rust writes it (`\u{202E}`,
/// `\u{1B}`), which is what a reader of a doc comment should see and what a
/// string literal means. Line feeds stay (they separate lines of code).
pub fn code(text: &str) -> Cow<'_, str> {
    if !text.chars().any(is_hazard) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if is_hazard(c) {
            out.push_str(&format!("\\u{{{:X}}}", u32::from(c)));
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// A Markdown code span of `text` (CommonMark 6.1): fenced by one backtick
/// more than the longest run of backticks in it, padded with spaces when it
/// starts or ends with a backtick; line breaks and hazards as `?`.
pub fn code_span(text: &str) -> String {
    let text = terminal_line(text);
    let mut longest = 0;
    let mut run = 0;
    for c in text.chars() {
        run = if c == '`' { run + 1 } else { 0 };
        longest = longest.max(run);
    }
    let fence = "`".repeat(longest + 1);
    let pad = if text.starts_with('`') || text.ends_with('`') {
        " "
    } else {
        ""
    };
    format!("{fence}{pad}{text}{pad}{fence}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terminal_keeps_offsets() {
        let s = "a\u{1b}[2Jb\u{85}c\u{202E}d\n\te\r";
        let t = terminal(s);
        assert_eq!(t.len(), s.len());
        assert_eq!(t, "a?[2Jb??c???d\n\te\r");
        assert!(matches!(terminal("plain µs"), Cow::Borrowed(_)));
        assert_eq!(terminal_line("a\nb\r"), "a?b?");
    }

    #[test]
    fn code_escapes_hazards() {
        assert_eq!(
            code("x\u{202E}y\u{0}\u{2066}\r"),
            "x\\u{202E}y\\u{0}\\u{2066}\\u{D}"
        );
        assert_eq!(code("Größe\n°C"), "Größe\n°C");
    }

    #[test]
    fn code_spans_outgrow_backticks() {
        assert_eq!(code_span("abc"), "`abc`");
        assert_eq!(code_span("a`b"), "``a`b``");
        assert_eq!(code_span("`a``"), "``` `a`` ```");
        assert_eq!(code_span("a\nb"), "`a?b`");
    }
}
