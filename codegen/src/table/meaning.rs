//! The semantic layer of a table: unit and scale, named values, bit fields,
//! patterns and error-table references, with their checks against the
//! entry's data type.

use std::collections::BTreeMap;

use serde_saphyr::Spanned;

use super::item::{
    SEMANTIC_KEYS, entry_reference, find_entry, integer, only_pin, pin_object, rust_name,
};
use super::schema::{BitDef, EntryDef, PatternDef, Text, ValuesDef};
use super::{At, Ctx, place};
use crate::r#gen::rust::naming::Case;
use crate::ir::{
    BitField, DataType, Device, Entry, NamedValue, Pattern, Semantics, ValueKind, ValueTable,
};

/// The semantic keys of `def` for `entry` (whose type is already known).
pub(super) fn semantics(
    ctx: &mut Ctx,
    def: &Spanned<EntryDef>,
    entry: &Entry,
    here: &str,
) -> Box<Semantics> {
    let mut out = entry.semantics.clone();
    merge(ctx, &mut out, def, entry.data_type, here);
    out
}

/// Writes the semantic keys `def` gives into `out` (a key given replaces).
fn merge(
    ctx: &mut Ctx,
    out: &mut Semantics,
    def: &Spanned<EntryDef>,
    data_type: DataType,
    here: &str,
) {
    let d = &def.value;
    let kind = data_type.value_kind();
    let numeric = matches!(
        kind,
        Some(ValueKind::Integer { .. } | ValueKind::Real { .. })
    );
    let range = integer_range(data_type);
    if let Some(description) = &d.description {
        out.description = Some(description.value.clone());
    }
    if let Some(unit) = &d.unit {
        need(ctx, numeric, At::of(unit), here, "unit", data_type);
        out.unit = Some(unit.value.clone());
    }
    if let Some(scale) = &d.scale {
        need(ctx, numeric, At::of(scale), here, "scale", data_type);
        if scale.value == 0.0 || !scale.value.is_finite() {
            ctx.error(
                "table::bad-scale",
                At::of(scale),
                here,
                "scale",
                "`scale` must be a finite number other than 0".into(),
            );
        } else {
            out.scale = Some(scale.value);
        }
    }
    if let Some(offset) = &d.offset {
        need(ctx, numeric, At::of(offset), here, "offset", data_type);
        if offset.value.is_finite() {
            out.offset = Some(offset.value);
        } else {
            ctx.error(
                "table::bad-scale",
                At::of(offset),
                here,
                "offset",
                "`offset` must be a finite number".into(),
            );
        }
    }
    if let Some(values) = &d.values {
        match range {
            Some(range) => out.values = value_table(ctx, values, range, here, "values"),
            None => need(ctx, false, At::of(values), here, "values", data_type),
        }
    }
    if let Some(bits) = &d.bits {
        match kind {
            Some(ValueKind::Integer { bits: width, .. }) => {
                out.bits = bit_fields(ctx, bits, width, here);
            }
            _ => need(ctx, false, At::of(def), here, "bits", data_type),
        }
    }
    if let Some(patterns) = &d.patterns {
        match kind {
            Some(ValueKind::Integer { bits: width, .. }) => {
                out.patterns = patterns
                    .iter()
                    .filter_map(|p| pattern(ctx, p, width, here))
                    .collect();
            }
            _ => need(ctx, false, At::of(def), here, "patterns", data_type),
        }
    }
    if let Some(table) = &d.error_table {
        need(
            ctx,
            range.is_some(),
            At::of(table),
            here,
            "error_table",
            data_type,
        );
        out.error_table = Some(table.value.clone());
    }
}

fn need(ctx: &mut Ctx, ok: bool, at: At, here: &str, key: &str, data_type: DataType) {
    if !ok {
        ctx.error(
            "table::semantics-type",
            at,
            here,
            key,
            format!(
                "`{key}` does not apply to a value of type {}",
                data_type.name()
            ),
        );
    }
}

/// The raw range of an integer type (BOOLEAN included).
fn integer_range(data_type: DataType) -> Option<(i128, i128)> {
    data_type.integer_range()
}

/// Reads `[low, high]` of integers.
fn pair(ctx: &mut Ctx, list: &Spanned<Vec<Text>>, here: &str, key: &str) -> Option<(i128, i128)> {
    if list.value.len() != 2 {
        ctx.error(
            "table::bad-range",
            At::of(list),
            here,
            key,
            format!("a range is `[low, high]`, not {} numbers", list.value.len()),
        );
        return None;
    }
    let low = integer(ctx, &list.value[0], here, key)?;
    let high = integer(ctx, &list.value[1], here, key)?;
    if low > high {
        ctx.error(
            "table::bad-range",
            At::of(list),
            here,
            key,
            format!("range [{low}, {high}] runs backwards"),
        );
        return None;
    }
    Some((low, high))
}

/// A `values:` table checked against the raw range of its type.
fn value_table(
    ctx: &mut Ctx,
    def: &Spanned<ValuesDef>,
    (lo, hi): (i128, i128),
    here: &str,
    key: &str,
) -> Option<ValueTable> {
    let d = &def.value;
    let fits = |ctx: &mut Ctx, (a, b): (i128, i128), at: At, what: &str| {
        let ok = a >= lo && b <= hi;
        if !ok {
            ctx.error(
                "table::value-out-of-range",
                at,
                here,
                key,
                if a == b {
                    format!("{what} {a} does not fit the type's range {lo}..={hi}")
                } else {
                    format!("{what} [{a}, {b}] does not fit the type's range {lo}..={hi}")
                },
            );
        }
        ok
    };
    let numeric = match &d.numeric {
        Some(list) => pair(ctx, list, here, "numeric")
            .filter(|&r| fits(ctx, r, At::of(list), "the numeric range")),
        None => None,
    };
    let mut named: Vec<NamedValue> = Vec::new();
    let mut names: BTreeMap<String, u32> = BTreeMap::new();
    for item in &d.named {
        let n = &item.value;
        let at = At::of(item);
        let range = match (&n.value, &n.range) {
            (Some(v), None) => integer(ctx, v, here, "value").map(|v| (v, v)),
            (None, Some(r)) => pair(ctx, r, here, "range"),
            _ => {
                ctx.error(
                    "table::named-value",
                    at,
                    here,
                    "named",
                    "a named value has exactly one of `value: N` or `range: [low, high]`".into(),
                );
                None
            }
        };
        let Some(range) = range else { continue };
        if !fits(ctx, range, at, &format!("`{}`", n.name.value)) {
            continue;
        }
        if let Some(first) = names.insert(n.name.value.clone(), at.line) {
            ctx.error(
                "table::duplicate-name",
                At::of(&n.name),
                here,
                "name",
                format!("`{}` is already named at line {first}", n.name.value),
            );
        }
        named.push(NamedValue {
            low: range.0,
            high: range.1,
            name: n.name.value.clone(),
            text: n.text.as_ref().map(|t| t.value.clone()),
            rust_name: rust_name(ctx, &n.rust_name, Case::UpperCamel, here),
            origin: ctx.origin(at),
        });
    }
    named.sort_by_key(|n| (n.low, n.high));
    for pair in named.windows(2) {
        if pair[1].low <= pair[0].high {
            let at = At::line(pair[1].origin.line);
            ctx.error(
                "table::overlap",
                at,
                here,
                key,
                format!(
                    "`{}` overlaps `{}` (line {})",
                    pair[1].name, pair[0].name, pair[0].origin.line
                ),
            );
        }
    }
    if let Some((a, b)) = numeric {
        for n in named.iter().filter(|n| n.low <= b && a <= n.high) {
            let at = At::line(n.origin.line);
            ctx.error(
                "table::overlap",
                at,
                here,
                key,
                format!("`{}` overlaps the numeric range [{a}, {b}]", n.name),
            );
        }
    }
    let Some(other) = &d.other else {
        ctx.error(
            "table::missing-key",
            At::of(def),
            here,
            "other",
            "`values` needs `other:`, the name of every raw value nothing else covers".into(),
        );
        return None;
    };
    Some(ValueTable {
        numeric,
        named,
        other: other.value.clone(),
    })
}

fn bit_fields(ctx: &mut Ctx, defs: &[Spanned<BitDef>], width: u32, here: &str) -> Vec<BitField> {
    let mut fields: Vec<BitField> = Vec::new();
    for def in defs {
        let d = &def.value;
        let at = At::of(def);
        let (lsb, msb) = match (&d.bit, &d.bits) {
            (Some(b), None) => (b.value, b.value),
            (None, Some(bits)) if bits.value.len() == 2 && bits.value[0] <= bits.value[1] => {
                (bits.value[0], bits.value[1])
            }
            (None, Some(bits)) => {
                ctx.error(
                    "table::bad-range",
                    At::of(bits),
                    here,
                    "bits",
                    "`bits` is `[low, high]` with low ≤ high".into(),
                );
                continue;
            }
            _ => {
                ctx.error(
                    "table::bit-field",
                    at,
                    here,
                    "bits",
                    "a bit field has exactly one of `bit: N` or `bits: [low, high]`".into(),
                );
                continue;
            }
        };
        if msb >= width {
            ctx.error(
                "table::bit-field",
                at,
                here,
                "bits",
                format!(
                    "`{}` uses bit {msb}, but the value has {width} bits",
                    d.name.value
                ),
            );
            continue;
        }
        let field_width = msb - lsb + 1;
        let field_range = (0, (1i128 << field_width) - 1);
        let values = d
            .values
            .as_ref()
            .and_then(|v| value_table(ctx, v, field_range, here, "values"));
        fields.push(BitField {
            name: d.name.value.clone(),
            lsb,
            width: field_width,
            text: d.text.as_ref().map(|t| t.value.clone()),
            unit: d.unit.as_ref().map(|t| t.value.clone()),
            scale: d.scale.as_ref().map(|s| s.value),
            values,
            rust_name: rust_name(ctx, &d.rust_name, Case::Snake, here),
            origin: ctx.origin(at),
        });
    }
    fields.sort_by_key(|f| f.lsb);
    for pair in fields.windows(2) {
        if pair[1].lsb < pair[0].lsb + pair[0].width {
            let at = At::line(pair[1].origin.line);
            ctx.error(
                "table::overlap",
                at,
                here,
                "bits",
                format!(
                    "bit field `{}` overlaps `{}` (line {})",
                    pair[1].name, pair[0].name, pair[0].origin.line
                ),
            );
        }
    }
    let mut names = BTreeMap::new();
    for f in &fields {
        if let Some(first) = names.insert(f.name.clone(), f.origin.line) {
            let at = At::line(f.origin.line);
            ctx.error(
                "table::duplicate-name",
                at,
                here,
                "bits",
                format!("bit field `{}` is already named at line {first}", f.name),
            );
        }
    }
    fields
}

fn pattern(ctx: &mut Ctx, def: &Spanned<PatternDef>, width: u32, here: &str) -> Option<Pattern> {
    let d = &def.value;
    let mask = integer(ctx, &d.mask, here, "mask")?;
    let value = integer(ctx, &d.value, here, "value")?;
    let limit = (1i128 << width) - 1;
    if !(0..=limit).contains(&mask) || !(0..=limit).contains(&value) {
        ctx.error(
            "table::value-out-of-range",
            At::of(def),
            here,
            "patterns",
            format!(
                "pattern `{}`: mask and value must fit {width} bits",
                d.name.value
            ),
        );
        return None;
    }
    if value & !mask != 0 {
        ctx.error(
            "table::pattern",
            At::of(&d.value),
            here,
            "value",
            format!(
                "pattern `{}`: value 0x{value:X} has bits outside mask 0x{mask:X}",
                d.name.value
            ),
        );
        return None;
    }
    Some(Pattern {
        name: d.name.value.clone(),
        mask: mask as u64,
        value: value as u64,
        text: d.text.as_ref().map(|t| t.value.clone()),
        origin: ctx.origin(At::of(def)),
    })
}

/// Stage 5: one item of the `semantics` list.
pub(super) fn apply_list_item(ctx: &mut Ctx, device: &mut Device, def: &Spanned<EntryDef>) {
    let Some((index, sub, here)) = entry_reference(
        ctx,
        def,
        "a `semantics` item",
        &[&["index", "sub", "description", "rust_name"], SEMANTIC_KEYS],
        "in `semantics` (values and access go to `modify` or `objects`)",
    ) else {
        return;
    };
    let object_pinned = pin_object(ctx, device, def, index);
    if object_pinned && only_pin(def) {
        return;
    }
    let Some(entry) = find_entry(ctx, device, index, sub, At::of(def)) else {
        return;
    };
    let (mut semantics, data_type) = (entry.semantics.clone(), entry.data_type);
    let pin = (def.value.rust_name.is_some() && !object_pinned)
        .then(|| rust_name(ctx, &def.value.rust_name, Case::UpperCamel, &here));
    merge(ctx, &mut semantics, def, data_type, &here);
    if let Some(entry) = device
        .objects
        .get_mut(&index)
        .and_then(|o| o.entries.get_mut(&sub))
    {
        entry.semantics = semantics;
        if let Some(pin) = pin {
            entry.rust_name = pin;
        }
    }
}

/// Every `error_table:` names a table of `errors`, whose codes fit the entry.
pub(super) fn check_error_table_references(ctx: &mut Ctx, device: &Device) {
    for object in device.objects.values() {
        for entry in object.entries.values() {
            let Some(name) = &entry.semantics.error_table else {
                continue;
            };
            let at = At::line(entry.origin.line);
            let here = place(object.index, Some(entry.subindex));
            match device.error_tables.iter().find(|t| &t.name == name) {
                None => ctx.error(
                    "table::dangling-reference",
                    at,
                    &here,
                    "error_table",
                    format!("there is no error table `{name}` in `errors`"),
                ),
                Some(table) => {
                    let Some((lo, hi)) = entry.data_type.integer_range() else {
                        continue;
                    };
                    if let Some(code) = table
                        .codes
                        .iter()
                        .find(|c| !(lo..=hi).contains(&i128::from(c.code)))
                    {
                        ctx.error(
                            "table::value-out-of-range",
                            at,
                            &here,
                            "error_table",
                            format!(
                                "error table `{name}` has code 0x{:X}, which a {} cannot hold",
                                code.code,
                                entry.data_type.name()
                            ),
                        );
                    }
                }
            }
        }
    }
}
