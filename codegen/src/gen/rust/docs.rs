//! Rustdoc for generated items. Text from the source (names, descriptions,
//! units) only ever reaches the output inside a doc string, with Markdown
//! and HTML specials escaped and control characters replaced, so that no
//! input can change the code around it or the rendered page's structure.

use proc_macro2::TokenStream;
use quote::quote;

use super::naming;
use crate::ir::{Access, Entry, Origin, Semantics};

/// Source text made safe for Markdown: line breaks and tabs become spaces and
/// Markdown/HTML specials are backslash-escaped. Other control and bidi
/// characters are left to [`crate::text::code`], which escapes them in the
/// whole generated file.
pub(crate) fn text(source: &str) -> String {
    let mut out = String::with_capacity(source.len());
    for c in source.chars() {
        match c {
            '\\' | '`' | '*' | '_' | '[' | ']' | '<' | '>' | '#' | '|' | '~' | '&' => {
                out.push('\\');
                out.push(c);
            }
            // Line breaks would end the doc line; clippy warns on tabs.
            '\n' | '\r' | '\t' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// Lines of rustdoc, built paragraph by paragraph.
#[derive(Default)]
pub(crate) struct Doc {
    lines: Vec<String>,
}

impl Doc {
    pub(crate) fn new() -> Doc {
        Doc::default()
    }

    /// Starts a paragraph with Markdown written by the generator.
    pub(crate) fn para(&mut self, markdown: impl Into<String>) -> &mut Doc {
        if !self.lines.is_empty() {
            self.lines.push(String::new());
        }
        self.lines.push(markdown.into());
        self
    }

    /// Adds a line to the current paragraph (or table).
    pub(crate) fn line(&mut self, markdown: impl Into<String>) -> &mut Doc {
        self.lines.push(markdown.into());
        self
    }

    /// A paragraph of source text (escaped); multi-line text keeps its lines.
    pub(crate) fn source_para(&mut self, source: &str) -> &mut Doc {
        let mut first = true;
        for line in source.lines() {
            if first {
                self.para(text(line.trim()));
                first = false;
            } else {
                self.line(text(line.trim()));
            }
        }
        self
    }

    /// "Unit: mm, 0.1 per raw step, offset -40." of an entry with a unit or
    /// scale.
    pub(crate) fn unit(&mut self, s: &Semantics) -> &mut Doc {
        if s.unit.is_none() && s.scale.is_none() {
            return self;
        }
        let mut line = String::from("Unit:");
        if let Some(unit) = &s.unit {
            line.push_str(&format!(" {}", text(unit)));
        }
        if let Some(scale) = s.scale {
            line.push_str(&format!(", {scale} per raw step"));
        }
        if let Some(offset) = s.offset {
            line.push_str(&format!(", offset {offset}"));
        }
        self.para(line)
    }

    /// "Defined at file:line." as its own paragraph.
    pub(crate) fn origin(&mut self, origin: &Origin) -> &mut Doc {
        self.facts_and_origin(&[], origin)
    }

    /// Facts (sentences of generated Markdown: "Default: 254") and "Defined
    /// at file:line." as one closing paragraph.
    pub(crate) fn facts_and_origin(&mut self, facts: &[String], origin: &Origin) -> &mut Doc {
        let mut sentences: Vec<String> = facts.iter().map(|f| format!("{f}.")).collect();
        if !origin.file.is_empty() {
            let at = if origin.line > 0 {
                format!("{}:{}", origin.file, origin.line)
            } else {
                origin.file.clone()
            };
            sentences.push(format!("Defined at {}.", text(&at)));
        }
        if sentences.is_empty() {
            return self;
        }
        self.para(sentences.join(" "))
    }

    /// The `#[doc = "..."]` attributes (prettyplease prints them as `///`),
    /// plus `#[doc(alias)]` for `source` when it differs from `ident`.
    pub(crate) fn tokens_with_alias(&self, source: &str, ident: &str) -> TokenStream {
        let mut tokens = self.tokens();
        if naming::alias_allowed(source, ident) {
            tokens.extend(quote!(#[doc(alias = #source)]));
        }
        tokens
    }

    pub(crate) fn tokens(&self) -> TokenStream {
        let lines = self.lines.iter().map(|l| {
            if l.is_empty() {
                String::new()
            } else {
                format!(" {l}")
            }
        });
        quote!(#(#[doc = #lines])*)
    }
}

/// "0x2000 sub 1" (or "0x2000" for sub 0 of a VAR).
pub(crate) fn address(index: u16, subindex: u8, var: bool) -> String {
    if var {
        format!("0x{index:04X}")
    } else {
        format!("0x{index:04X} sub {subindex}")
    }
}

/// The facts line of an entry: address, type, access, mappability.
pub(crate) fn entry_facts(index: u16, entry: &Entry, var: bool) -> String {
    format!(
        "{}, {}, {}{}",
        address(index, entry.subindex, var),
        entry.data_type.name(),
        access_words(entry.access),
        if entry.pdo_mappable {
            ", PDO-mappable"
        } else {
            ""
        }
    )
}

pub(crate) fn access_words(access: Access) -> &'static str {
    match access {
        Access::Ro => "read-only",
        Access::Wo => "write-only",
        Access::Rw => "read/write",
        Access::Rwr => "read/write (TPDO)",
        Access::Rww => "read/write (RPDO)",
        Access::Const => "constant",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes() {
        assert_eq!(text("a*b [x] <y> `z`"), "a\\*b \\[x\\] \\<y\\> \\`z\\`");
        assert_eq!(text("line\u{1b}[31m\r\n\t"), "line\u{1b}\\[31m   ");
        assert_eq!(text("\"]; } */"), "\"\\]; } \\*/");
    }
}
