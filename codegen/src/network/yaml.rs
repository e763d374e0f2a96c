//! A bus file as a generic YAML tree: maps, lists and scalars, each with
//! where it was written. A bus file is read as PyYAML reads it for dcfgen
//! (YAML 1.1 scalars: `0x` hex, `0`-octal, `yes`/`no` booleans; repeated
//! keys kept, the reader decides), so that its keys can be checked one by
//! one with their lines, which a derived struct cannot do for the open key
//! set of a slave section.

use std::fmt;

use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_saphyr::Spanned;

use crate::table::At;

/// One YAML node and where it was written.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Node {
    pub at: At,
    pub value: Value,
}

/// A YAML value. Integers are kept wide (a bus file may write numbers that
/// no field takes; the reader says which).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    Null,
    Bool(bool),
    Int(i128),
    Float(f64),
    Str(String),
    Seq(Vec<Node>),
    /// Entries in file order, repeated keys included.
    Map(Vec<(Node, Node)>),
}

impl Value {
    /// How a message names the kind of value: `a list`, `text`.
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Null => "nothing",
            Value::Bool(_) => "a boolean",
            Value::Int(_) => "an integer",
            Value::Float(_) => "a decimal number",
            Value::Str(_) => "text",
            Value::Seq(_) => "a list",
            Value::Map(_) => "a map",
        }
    }
}

impl Node {
    /// The key as text, when it is a scalar (`1`, `tpdo`, `true`).
    pub fn key_text(&self) -> Option<String> {
        match &self.value {
            Value::Str(s) => Some(s.clone()),
            Value::Int(i) => Some(i.to_string()),
            Value::Bool(b) => Some(b.to_string()),
            Value::Float(f) => Some(f.to_string()),
            Value::Null => Some("null".into()),
            Value::Seq(_) | Value::Map(_) => None,
        }
    }

    /// The number of nodes in this tree (this one included), counted up
    /// to `limit` (the count stops there).
    pub fn size(&self, limit: usize) -> usize {
        let mut count = 1;
        let mut stack = vec![self];
        while let Some(node) = stack.pop() {
            if count >= limit {
                return limit;
            }
            match &node.value {
                Value::Seq(items) => {
                    count += items.len();
                    stack.extend(items);
                }
                Value::Map(entries) => {
                    count += 2 * entries.len();
                    for (k, v) in entries {
                        stack.push(k);
                        stack.push(v);
                    }
                }
                _ => {}
            }
        }
        count.min(limit)
    }

    /// The value as short YAML-ish text (`"ros2_canopen::MasterDriver"`,
    /// `10`, `[1, 2]`, `{a: 1}`), cut after about `max` characters.
    pub fn brief(&self, max: usize) -> String {
        let mut out = String::new();
        write_brief(self, &mut out, max);
        if out.len() > max {
            let mut cut = max;
            while !out.is_char_boundary(cut) {
                cut -= 1;
            }
            out.truncate(cut);
            out.push('…');
        }
        out
    }
}

fn write_brief(node: &Node, out: &mut String, max: usize) {
    if out.len() > max {
        return;
    }
    match &node.value {
        Value::Null => out.push_str("null"),
        Value::Bool(b) => out.push_str(if *b { "true" } else { "false" }),
        Value::Int(i) => out.push_str(&i.to_string()),
        Value::Float(f) => out.push_str(&f.to_string()),
        Value::Str(s) => out.push_str(&format!("{s:?}")),
        Value::Seq(items) => {
            out.push('[');
            for (n, item) in items.iter().enumerate() {
                if out.len() > max {
                    break;
                }
                if n > 0 {
                    out.push_str(", ");
                }
                write_brief(item, out, max);
            }
            out.push(']');
        }
        Value::Map(entries) => {
            out.push('{');
            for (n, (k, v)) in entries.iter().enumerate() {
                if out.len() > max {
                    break;
                }
                if n > 0 {
                    out.push_str(", ");
                }
                write_brief(k, out, max);
                out.push_str(": ");
                write_brief(v, out, max);
            }
            out.push('}');
        }
    }
}

/// Parses a bus file's text into its tree, within serde-saphyr's default
/// budgets (nodes, depth, aliases); repeated keys are kept.
pub(crate) fn parse(text: &str) -> Result<Node, serde_saphyr::Error> {
    let mut options = serde_saphyr::options! { legacy_octal_numbers: true };
    options.duplicate_keys = serde_saphyr::options::DuplicateKeyPolicy::PassThrough;
    // `.inf` and `1e400` are values (that no key takes), not syntax.
    options.non_finite_float_policy = serde_saphyr::NonFiniteFloatPolicy::PassThrough;
    serde_saphyr::from_str_with_options::<Node>(text, options)
}

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let spanned = Spanned::<Value>::deserialize(deserializer)?;
        Ok(Node {
            at: At::of(&spanned),
            value: spanned.value,
        })
    }
}

impl<'de> Deserialize<'de> for Value {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(ValueVisitor)
    }
}

struct ValueVisitor;

impl<'de> Visitor<'de> for ValueVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a YAML value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::Int(v.into()))
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::Int(v.into()))
    }
    fn visit_i128<E>(self, v: i128) -> Result<Value, E> {
        Ok(Value::Int(v))
    }
    fn visit_u128<E: de::Error>(self, v: u128) -> Result<Value, E> {
        i128::try_from(v)
            .map(Value::Int)
            .map_err(|_| E::custom("an integer too large"))
    }
    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(Value::Float(v))
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::Str(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::Str(v))
    }
    fn visit_bytes<E>(self, v: &[u8]) -> Result<Value, E> {
        Ok(Value::Str(String::from_utf8_lossy(v).into_owned()))
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_some<D: Deserializer<'de>>(self, deserializer: D) -> Result<Value, D::Error> {
        Value::deserialize(deserializer)
    }
    fn visit_newtype_struct<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        Value::deserialize(d)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element::<Node>()? {
            items.push(item);
        }
        Ok(Value::Seq(items))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut entries = Vec::new();
        while let Some(entry) = map.next_entry::<Node, Node>()? {
            entries.push(entry);
        }
        Ok(Value::Map(entries))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(node: &Node) -> &[(Node, Node)] {
        match &node.value {
            Value::Map(entries) => entries,
            other => panic!("not a map: {other:?}"),
        }
    }

    #[test]
    fn scalars_as_pyyaml_reads_them() {
        let text = "a: 0x10\nb: 010\nc: yes\nd: \"12\"\ne: 1.5\nf:\ng: -3\nh: auto\n";
        let root = parse(text).unwrap();
        let values: Vec<Value> = map(&root).iter().map(|(_, v)| v.value.clone()).collect();
        assert_eq!(
            values,
            vec![
                Value::Int(16),
                Value::Int(8),
                Value::Bool(true),
                Value::Str("12".into()),
                Value::Float(1.5),
                Value::Null,
                Value::Int(-3),
                Value::Str("auto".into()),
            ]
        );
    }

    #[test]
    fn lines_of_keys_and_values() {
        let text = "master:\n  node_id: 1\ntpdo:\n  1:\n    mapping:\n      - {index: 0x6041}\n";
        let root = parse(text).unwrap();
        let entries = map(&root);
        assert_eq!(entries[0].0.at.line, 1);
        let (k, v) = &map(&entries[0].1)[0];
        assert_eq!((k.at.line, v.at.line), (2, 2));
        let (one, pdo) = &map(&entries[1].1)[0];
        assert_eq!(one.value, Value::Int(1));
        assert_eq!(one.at.line, 4);
        let (_, mapping) = &map(pdo)[0];
        let Value::Seq(items) = &mapping.value else {
            panic!()
        };
        assert_eq!(items[0].at.line, 6);
    }

    #[test]
    fn repeated_keys_are_kept_and_aliases_expand() {
        let root = parse("a: 1\na: 2\nb: &x [1, 2]\nc: *x\n").unwrap();
        let entries = map(&root);
        assert_eq!(entries.len(), 4);
        assert_eq!(entries[2].1.brief(80), "[1, 2]");
        assert_eq!(entries[3].1.brief(80), "[1, 2]");
        // An alias's values are where the alias is.
        assert_eq!(entries[3].1.at.line, 4);
    }

    #[test]
    fn brief_is_cut() {
        let root = parse("a: [aaaaaaaaaa, bbbbbbbbbb, cccccccccc]\n").unwrap();
        let text = map(&root)[0].1.brief(12);
        assert!(text.ends_with('…') && text.len() <= 16, "{text}");
        assert_eq!(root.size(usize::MAX), 6);
        assert_eq!(root.size(3), 3);
    }
}
