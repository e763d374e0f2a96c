//! Reading the values of a bus file's tree as dcfgen reads them (Python's
//! `int()`, `float()`, `bool()` and `str()` on what PyYAML gives), each
//! problem reported with file, line and key path.

use std::collections::HashMap;

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::table::At;

use super::model::{At as Valued, Spot};
use super::yaml::{Node, Value};

/// The reporting context of one bus file.
pub(crate) struct Ctx<'a> {
    pub file: &'a str,
    pub text: &'a str,
    pub diags: &'a mut Diagnostics,
}

/// One key of a map and its value; `path` is the key's dotted path
/// (`prbt_joint_1.tpdo`).
#[derive(Debug, Clone)]
pub(crate) struct Entry<'n> {
    pub key: String,
    pub key_node: &'n Node,
    pub value: &'n Node,
    pub path: String,
}

impl Entry<'_> {
    /// Where the key was written, for the model.
    pub fn spot(&self) -> Spot {
        Spot {
            line: self.key_node.at.line,
            key: self.path.clone(),
        }
    }
}

impl Ctx<'_> {
    pub fn report(
        &mut self,
        severity: Severity,
        code: &'static str,
        at: At,
        key: &str,
        message: String,
    ) {
        self.diags.push(Diagnostic {
            severity,
            code,
            file: self.file.to_string(),
            location: Location {
                line: (at.line > 0).then_some(at.line),
                span: (at.line > 0).then(|| at.span(self.text)),
                section: None,
                key: (!key.is_empty()).then(|| key.to_string()),
            },
            message,
            notes: Vec::new(),
        });
    }

    pub fn error(&mut self, code: &'static str, at: At, key: &str, message: String) {
        self.report(Severity::Error, code, at, key, message);
    }

    pub fn warn(&mut self, code: &'static str, at: At, key: &str, message: String) {
        self.report(Severity::Warning, code, at, key, message);
    }

    /// Adds a note to the diagnostic reported last.
    pub fn note(&mut self, note: String) {
        self.diags.add_note_to_last(note);
    }

    /// The entries of a map as dcfgen sees them: a key given twice keeps
    /// its later value (as PyYAML does), with a warning; a key that is not
    /// a scalar is an error and skipped. `path` is the map's own path
    /// (empty at the top). `None` (with an error) when `node` is not a map;
    /// an empty value (`key:` alone) is an empty map.
    pub fn entries<'n>(&mut self, node: &'n Node, path: &str) -> Option<Vec<Entry<'n>>> {
        let pairs = match &node.value {
            Value::Map(pairs) => pairs,
            Value::Null => return Some(Vec::new()),
            other => {
                self.error(
                    "net::bad-value",
                    node.at,
                    path,
                    format!("a map of keys is needed here, not {}", other.kind()),
                );
                return None;
            }
        };
        let mut out: Vec<Entry<'n>> = Vec::with_capacity(pairs.len());
        let mut seen: HashMap<String, usize> = HashMap::with_capacity(pairs.len());
        for (key_node, value) in pairs {
            let Some(key) = key_node.key_text() else {
                self.error(
                    "net::bad-value",
                    key_node.at,
                    path,
                    format!(
                        "a key must be a name or a number, not {}",
                        key_node.value.kind()
                    ),
                );
                continue;
            };
            let entry = Entry {
                path: join(path, &key),
                key,
                key_node,
                value,
            };
            match seen.get(&entry.key) {
                // As in a Python dict: the first place, the later value.
                Some(&pos) => {
                    self.warn(
                        "net::duplicate-key",
                        key_node.at,
                        &entry.path,
                        format!(
                            "key given again (first at line {}); this later value wins, as in \
                             dcfgen",
                            out[pos].key_node.at.line
                        ),
                    );
                    out[pos] = entry;
                }
                None => {
                    seen.insert(entry.key.clone(), out.len());
                    out.push(entry);
                }
            }
        }
        Some(out)
    }

    /// An integer as Python's `int()` reads it: a YAML integer, a decimal
    /// number in quotes, a boolean (1 or 0), a decimal fraction (cut, with
    /// a warning).
    pub fn integer(&mut self, node: &Node, key: &str) -> Option<i128> {
        match &node.value {
            Value::Int(i) => Some(*i),
            Value::Bool(b) => Some(i128::from(*b)),
            Value::Float(f) if f.is_finite() && f.abs() < 1e30 => {
                let cut = f.trunc();
                if cut != *f {
                    self.warn(
                        "net::truncated",
                        node.at,
                        key,
                        format!("an integer is needed; dcfgen cuts {f} to {cut}, and so does this reader"),
                    );
                }
                // In range: |cut| < 1e30 < i128::MAX.
                Some(cut as i128)
            }
            Value::Str(s) => match python_int(s) {
                Some(i) => Some(i),
                None => {
                    self.error(
                        "net::bad-value",
                        node.at,
                        key,
                        format!("an integer is needed here, not the text {s:?}"),
                    );
                    if looks_numeric(s) {
                        self.note(
                            "dcfgen reads quoted text with Python's int(), which takes decimal \
                             digits only: write the number without quotes (0x1A is a number)"
                                .into(),
                        );
                    }
                    None
                }
            },
            other => {
                self.error(
                    "net::bad-value",
                    node.at,
                    key,
                    format!("an integer is needed here, not {}", other.kind()),
                );
                None
            }
        }
    }

    /// An integer in `lo..=hi`, of type `T`; a value outside is an error
    /// of rule `code`.
    pub fn ranged<T: TryFrom<i128>>(
        &mut self,
        node: &Node,
        key: &str,
        lo: i128,
        hi: i128,
        code: &'static str,
    ) -> Option<T> {
        let value = self.integer(node, key)?;
        if value < lo || value > hi {
            self.error(
                code,
                node.at,
                key,
                format!(
                    "{value} is out of range: {key_name} takes {lo}..={hi}",
                    key_name = last(key)
                ),
            );
            return None;
        }
        T::try_from(value).ok()
    }

    /// An unsigned integer that fits `T` (`u8`, `u16`, `u32`).
    pub fn unsigned<T: TryFrom<i128> + Into<u64> + Bounded>(
        &mut self,
        node: &Node,
        key: &str,
    ) -> Option<T> {
        self.ranged(node, key, 0, i128::from(T::MAX.into()), "net::bad-value")
    }

    /// A boolean as Python's `bool()` reads it: `true`/`false` (and YAML
    /// 1.1's `yes`/`no`/`on`/`off`), a number (0 is false), nothing
    /// (false); any non-empty text is true, with a warning when it reads
    /// like false.
    pub fn truthy(&mut self, node: &Node, key: &str) -> Option<bool> {
        match &node.value {
            Value::Bool(b) => Some(*b),
            Value::Int(i) => Some(*i != 0),
            Value::Float(f) => Some(*f != 0.0),
            Value::Null => Some(false),
            Value::Str(s) => {
                let lower = s.trim().to_ascii_lowercase();
                if ["false", "no", "off", "0", "n"].contains(&lower.as_str()) {
                    self.warn(
                        "net::truthy-text",
                        node.at,
                        key,
                        format!(
                            "the text {s:?} is true for dcfgen (Python's bool() of any non-empty \
                             text), and so for this reader"
                        ),
                    );
                    self.note("write false without quotes".into());
                }
                Some(!s.is_empty())
            }
            other => {
                self.error(
                    "net::bad-value",
                    node.at,
                    key,
                    format!("true or false is needed here, not {}", other.kind()),
                );
                None
            }
        }
    }

    /// A flag dcfgen reads with `int()` (the master's `start` keys):
    /// `true`/`false` or an integer (0 is false).
    pub fn int_flag(&mut self, node: &Node, key: &str) -> Option<bool> {
        self.integer(node, key).map(|i| i != 0)
    }

    /// A decimal number as Python's `float()` reads it, finite and not
    /// negative.
    pub fn float(&mut self, node: &Node, key: &str) -> Option<f64> {
        let value = match &node.value {
            Value::Int(i) => Some(*i as f64),
            Value::Float(f) => Some(*f),
            Value::Str(s) => s.trim().parse::<f64>().ok(),
            _ => None,
        };
        match value {
            Some(f) if f.is_finite() && f >= 0.0 => Some(f),
            Some(f) => {
                self.error(
                    "net::bad-value",
                    node.at,
                    key,
                    format!("{f} is out of range: a finite number, 0 or more, is needed"),
                );
                None
            }
            None => {
                self.error(
                    "net::bad-value",
                    node.at,
                    key,
                    format!("a number is needed here, not {}", node.value.kind()),
                );
                None
            }
        }
    }

    /// Text as Python's `str()` gives it for a scalar (a number is written
    /// as its digits).
    pub fn text(&mut self, node: &Node, key: &str) -> Option<String> {
        match &node.value {
            Value::Str(s) => Some(s.clone()),
            Value::Int(i) => Some(i.to_string()),
            Value::Float(f) => Some(f.to_string()),
            Value::Bool(b) => Some(if *b { "True" } else { "False" }.into()),
            other => {
                self.error(
                    "net::bad-value",
                    node.at,
                    key,
                    format!("text is needed here, not {}", other.kind()),
                );
                None
            }
        }
    }
}

/// The largest value of an unsigned field type.
pub(crate) trait Bounded: Sized {
    const MAX: Self;
}
impl Bounded for u8 {
    const MAX: u8 = u8::MAX;
}
impl Bounded for u16 {
    const MAX: u16 = u16::MAX;
}
impl Bounded for u32 {
    const MAX: u32 = u32::MAX;
}

/// A value with the spot of its entry.
pub(crate) fn at<T>(value: T, entry: &Entry) -> Valued<T> {
    Valued::new(value, entry.spot())
}

/// `path.key`, or `key` at the top.
pub(crate) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// The last component of a dotted key path.
fn last(path: &str) -> &str {
    path.rsplit('.').next().unwrap_or(path)
}

/// Python's `int()` of text: blanks around, an optional sign, decimal
/// digits with single underscores between them.
pub(crate) fn python_int(text: &str) -> Option<i128> {
    let t = text.trim();
    let (negative, digits) = match t.as_bytes().first()? {
        b'-' => (true, &t[1..]),
        b'+' => (false, &t[1..]),
        _ => (false, t),
    };
    if digits.is_empty()
        || digits.starts_with('_')
        || digits.ends_with('_')
        || digits.contains("__")
        || !digits.bytes().all(|b| b.is_ascii_digit() || b == b'_')
    {
        return None;
    }
    let clean: String = digits.chars().filter(|&c| c != '_').collect();
    let value: i128 = clean.parse().ok()?;
    Some(if negative { -value } else { value })
}

/// Text that a user meant as a number (`"0x1A"`, `"12 "`).
fn looks_numeric(text: &str) -> bool {
    let t = text.trim();
    t.strip_prefix("0x")
        .or_else(|| t.strip_prefix("0X"))
        .is_some_and(|h| !h.is_empty() && h.bytes().all(|b| b.is_ascii_hexdigit()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn python_int_of_text() {
        assert_eq!(python_int(" 12 "), Some(12));
        assert_eq!(python_int("-1_000"), Some(-1000));
        assert_eq!(python_int("+7"), Some(7));
        for bad in ["", "0x10", "1__0", "_1", "1_", "1.5", "-", "１"] {
            assert_eq!(python_int(bad), None, "{bad}");
        }
    }
}
