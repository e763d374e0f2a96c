//! What every item of a table shares, whatever its stage: the keys it
//! gives and those its place allows, the entry it names, integers outside
//! an entry's own values, and `rust_name:` pins.

use serde_saphyr::Spanned;

use super::schema::{EntryDef, Text};
use super::{At, Ctx, place};
use crate::eds::number;
use crate::r#gen::rust::naming::{Case, sanitize};
use crate::ir::{Device, Entry, ObjectKind};

/// Semantic keys, allowed wherever an entry's meaning may be given.
pub(super) const SEMANTIC_KEYS: &[&str] = &[
    "unit",
    "scale",
    "offset",
    "values",
    "bits",
    "patterns",
    "error_table",
];
pub(super) const VALUE_KEYS: &[&str] = &["type", "access", "pdo", "default", "min", "max"];

/// The keys an [`EntryDef`] gives, with where each is.
pub(super) fn present_keys(def: &Spanned<EntryDef>) -> Vec<(&'static str, At)> {
    let d = &def.value;
    let mut keys = Vec::new();
    let mut put = |key, at: Option<At>| {
        if let Some(at) = at {
            keys.push((key, at));
        }
    };
    let whole = At::of(def);
    put("index", d.index.as_ref().map(At::of));
    put("sub", d.sub.as_ref().map(At::of));
    put("name", d.name.as_ref().map(At::of));
    put("kind", d.kind.as_ref().map(At::of));
    put("description", d.description.as_ref().map(At::of));
    put("type", d.data_type.as_ref().map(At::of));
    put("access", d.access.as_ref().map(At::of));
    put("pdo", d.pdo.as_ref().map(At::of));
    put("default", d.default.as_ref().map(At::of));
    put("min", d.min.as_ref().map(At::of));
    put("max", d.max.as_ref().map(At::of));
    put("subs", d.subs.as_ref().map(|_| whole));
    put("unit", d.unit.as_ref().map(At::of));
    put("scale", d.scale.as_ref().map(At::of));
    put("offset", d.offset.as_ref().map(At::of));
    put("values", d.values.as_ref().map(At::of));
    put("bits", d.bits.as_ref().map(|_| whole));
    put("patterns", d.patterns.as_ref().map(|_| whole));
    put("error_table", d.error_table.as_ref().map(At::of));
    put("rust_name", d.rust_name.as_ref().map(At::of));
    keys
}

/// Reports every key of `def` that `allowed` does not hold; `what` names the context.
pub(super) fn reject_keys(
    ctx: &mut Ctx,
    def: &Spanned<EntryDef>,
    allowed: &[&[&str]],
    what: &str,
    place: &str,
) {
    for (key, at) in present_keys(def) {
        if !allowed.iter().any(|set| set.contains(&key)) {
            ctx.error(
                "table::misplaced-key",
                at,
                place,
                key,
                format!("`{key}` is not allowed {what}"),
            );
        }
    }
}

/// The `index` of a reference, reported when missing.
pub(super) fn required_index(ctx: &mut Ctx, def: &Spanned<EntryDef>, what: &str) -> Option<u16> {
    match &def.value.index {
        Some(index) if index.value == 0 => {
            ctx.error(
                "table::bad-index",
                At::of(index),
                "",
                "index",
                "index 0x0000 is not an object index".into(),
            );
            None
        }
        Some(index) => Some(index.value),
        None => {
            ctx.error(
                "table::missing-key",
                At::of(def),
                "",
                "index",
                format!("{what} needs `index`"),
            );
            None
        }
    }
}

/// The entry an item names (`index`, `sub` defaulting to 0) and how
/// diagnostics name it, after reporting every key `allowed` does not hold.
pub(super) fn entry_reference(
    ctx: &mut Ctx,
    def: &Spanned<EntryDef>,
    what: &str,
    allowed: &[&[&str]],
    context: &str,
) -> Option<(u16, u8, String)> {
    let index = required_index(ctx, def, what)?;
    let sub = def.value.sub.as_ref().map_or(0, |s| s.value);
    let here = place(index, Some(sub));
    reject_keys(ctx, def, allowed, context, &here);
    Some((index, sub, here))
}

pub(super) fn has_leading_zero(t: &str) -> bool {
    let digits = t.trim_start_matches(['-', '+']);
    digits.len() > 1 && digits.starts_with('0') && digits.bytes().all(|b| b.is_ascii_digit())
}

/// An integer written in a table outside an entry's own values (named
/// values, ranges, masks): decimal or 0x hex, up to 64 bits.
pub(super) fn integer(ctx: &mut Ctx, text: &Text, here: &str, key: &str) -> Option<i128> {
    let t = text.value.trim();
    if has_leading_zero(t) {
        ctx.error(
            "table::leading-zero",
            At::of(text),
            here,
            key,
            format!("`{t}` has a leading zero; write it without the zero or as 0x hex"),
        );
        return None;
    }
    match number::parse_int(t) {
        Ok(v) => Some(v),
        Err(e) => {
            ctx.error("table::bad-value", At::of(text), here, key, e.0);
            None
        }
    }
}

/// The entry `index`/`sub`, or an error naming what is missing.
pub(super) fn find_entry<'d>(
    ctx: &mut Ctx,
    device: &'d Device,
    index: u16,
    sub: u8,
    at: At,
) -> Option<&'d Entry> {
    let here = place(index, Some(sub));
    match device.objects.get(&index) {
        None => {
            ctx.error(
                "table::missing-entry",
                at,
                &here,
                "index",
                format!("there is no object 0x{index:04X}"),
            );
            None
        }
        Some(object) => {
            let entry = object.entries.get(&sub).map(Box::as_ref);
            if entry.is_none() {
                ctx.error(
                    "table::missing-entry",
                    at,
                    &here,
                    "sub",
                    format!("object 0x{index:04X} has no sub-index {sub}"),
                );
            }
            entry
        }
    }
}

/// A `rust_name:` pin, checked to be an identifier of `case` already: a
/// `table::rust-name` error suggesting the converted form when it is not.
pub(super) fn rust_name(
    ctx: &mut Ctx,
    text: &Option<Text>,
    case: Case,
    here: &str,
) -> Option<String> {
    let text = text.as_ref()?;
    let pin = text.value.as_str();
    let converted = sanitize(pin, case);
    if converted == pin {
        return Some(pin.to_string());
    }
    let (case_name, what) = match case {
        Case::UpperCamel => ("UpperCamelCase", "a type or enum variant"),
        Case::Snake => ("snake_case", "a module or method"),
        Case::ShoutySnake => ("SHOUTY_SNAKE_CASE", "a constant"),
    };
    let suggestion = if converted.is_empty() {
        "it has nothing usable as an identifier".to_string()
    } else {
        format!("write `{converted}`")
    };
    ctx.error(
        "table::rust-name",
        At::of(text),
        here,
        "rust_name",
        format!(
            "`rust_name: {pin}` is not a valid {case_name} Rust identifier, which {what} needs; {suggestion}"
        ),
    );
    None
}

/// A `rust_name:` of a `modify:` or `semantics:` item without `sub` that
/// names an ARRAY or RECORD object pins the object's module name; true when
/// the item did that (its other keys still apply to sub 0).
pub(super) fn pin_object(
    ctx: &mut Ctx,
    device: &mut Device,
    def: &Spanned<EntryDef>,
    index: u16,
) -> bool {
    let d = &def.value;
    if d.rust_name.is_none() || d.sub.is_some() {
        return false;
    }
    let Some(object) = device.objects.get(&index) else {
        return false;
    };
    if !matches!(object.kind, ObjectKind::Array | ObjectKind::Record) {
        return false;
    }
    let pin = rust_name(ctx, &d.rust_name, Case::Snake, &place(index, None));
    if let Some(object) = device.objects.get_mut(&index) {
        object.rust_name = pin;
    }
    true
}

/// Whether an item gives nothing but `index` and `rust_name`.
pub(super) fn only_pin(def: &Spanned<EntryDef>) -> bool {
    present_keys(def)
        .iter()
        .all(|(key, _)| matches!(*key, "index" | "rust_name"))
}
