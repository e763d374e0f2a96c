//! The YAML semantic layer: descriptions, units and scales, named values,
//! bit fields, patterns, error-table references, and the device error
//! tables themselves.

use std::collections::BTreeMap;

use super::{Cx, Kind, Severity, Val, hex, shown};
use crate::r#gen::rust::naming::{Case, sanitize};
use crate::ir::{BitField, Entry, ErrorTable, NamedValue, ValueTable};

/// A source name's Rust spelling decides whether renaming it is breaking.
fn rename_severity(old: &str, new: &str, case: Case) -> Severity {
    if sanitize(old, case) == sanitize(new, case) {
        Severity::Compatible
    } else {
        Severity::Breaking
    }
}

fn text(v: &Option<String>) -> Option<Val> {
    v.clone().map(Val::Text)
}

fn real(v: Option<f64>) -> Option<Val> {
    v.map(Val::Real)
}

fn same_real(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => a == b || a.to_bits() == b.to_bits(),
        (None, None) => true,
        _ => false,
    }
}

fn range(low: i128, high: i128) -> String {
    if low == high {
        hex(low)
    } else {
        format!("{}..={}", hex(low), hex(high))
    }
}

/// The semantic layer of one entry that is in both devices.
pub(super) fn entry(
    cx: &mut Cx,
    index: u16,
    sub: u8,
    path: &Option<String>,
    old: &Entry,
    new: &Entry,
) {
    let (o, n) = (&old.semantics, &new.semantics);
    let mut push = |kind, severity, old: Option<Val>, new: Option<Val>, message: String| {
        cx.push(
            index,
            Some(sub),
            kind,
            severity,
            path.clone(),
            old,
            new,
            message,
        );
    };
    if o.description != n.description {
        push(
            Kind::DescriptionChanged,
            Severity::Compatible,
            text(&o.description),
            text(&n.description),
            "description changed".into(),
        );
    }
    if o.unit != n.unit {
        let (ov, nv) = (text(&o.unit), text(&n.unit));
        let message = format!("unit {} → {}", shown(&ov), shown(&nv));
        push(Kind::UnitChanged, Severity::Compatible, ov, nv, message);
    }
    if !same_real(o.scale, n.scale) {
        let (ov, nv) = (real(o.scale), real(n.scale));
        let message = format!("scale {} → {}", shown(&ov), shown(&nv));
        push(Kind::ScaleChanged, Severity::Compatible, ov, nv, message);
    }
    if !same_real(o.offset, n.offset) {
        let (ov, nv) = (real(o.offset), real(n.offset));
        let message = format!("offset {} → {}", shown(&ov), shown(&nv));
        push(Kind::OffsetChanged, Severity::Compatible, ov, nv, message);
    }
    if o.error_table != n.error_table {
        let (ov, nv) = (text(&o.error_table), text(&n.error_table));
        let severity = if o.error_table.is_some() {
            Severity::Breaking
        } else {
            Severity::Additive
        };
        let message = format!(
            "reports codes of error table {} → {}",
            shown(&ov),
            shown(&nv)
        );
        push(Kind::ErrorTableRefChanged, severity, ov, nv, message);
    }
    value_table(&mut push, "", o.values.as_ref(), n.values.as_ref());
    bit_fields(&mut push, &o.bits, &n.bits);
    let old_patterns: BTreeMap<&str, _> = o.patterns.iter().map(|p| (p.name.as_str(), p)).collect();
    let new_patterns: BTreeMap<&str, _> = n.patterns.iter().map(|p| (p.name.as_str(), p)).collect();
    for (name, p) in &old_patterns {
        let shape = |p: &crate::ir::Pattern| format!("mask 0x{:X} = 0x{:X}", p.mask, p.value);
        match new_patterns.get(name) {
            None => push(
                Kind::PatternRemoved,
                Severity::Breaking,
                Some(Val::Text(name.to_string())),
                None,
                format!("state pattern {} removed", crate::text::code_span(name)),
            ),
            Some(q) if p.mask != q.mask || p.value != q.value || p.text != q.text => push(
                Kind::PatternChanged,
                Severity::Compatible,
                Some(Val::Text(shape(p))),
                Some(Val::Text(shape(q))),
                format!(
                    "state pattern {}: {} → {}",
                    crate::text::code_span(name),
                    shape(p),
                    shape(q)
                ),
            ),
            Some(_) => {}
        }
    }
    for name in new_patterns
        .keys()
        .filter(|n| !old_patterns.contains_key(*n))
    {
        push(
            Kind::PatternAdded,
            Severity::Additive,
            None,
            Some(Val::Text(name.to_string())),
            format!("state pattern {} added", crate::text::code_span(name)),
        );
    }
}

type Push<'a> = dyn FnMut(Kind, Severity, Option<Val>, Option<Val>, String) + 'a;

/// Named values (keyed by their raw range) and the table's numeric range
/// and fallback name; `what` prefixes messages (a bit field's name).
fn value_table(push: &mut Push, what: &str, old: Option<&ValueTable>, new: Option<&ValueTable>) {
    let empty = Vec::new();
    let named = |t: Option<&ValueTable>| -> BTreeMap<(i128, i128), NamedValue> {
        t.map_or(&empty, |t| &t.named)
            .iter()
            .map(|v| ((v.low, v.high), v.clone()))
            .collect()
    };
    let (o, n) = (named(old), named(new));
    for (key, v) in &o {
        let at = range(key.0, key.1);
        match n.get(key) {
            None => push(
                Kind::NamedValueRemoved,
                Severity::Breaking,
                Some(Val::Text(v.name.clone())),
                None,
                format!(
                    "{what}named value {at} {} removed",
                    crate::text::code_span(&v.name)
                ),
            ),
            Some(w) if w.name != v.name => push(
                Kind::NamedValueChanged,
                rename_severity(&v.name, &w.name, Case::UpperCamel),
                Some(Val::Text(v.name.clone())),
                Some(Val::Text(w.name.clone())),
                format!(
                    "{what}named value {at}: {} → {}",
                    crate::text::code_span(&v.name),
                    crate::text::code_span(&w.name)
                ),
            ),
            Some(w) if w.text != v.text => push(
                Kind::NamedValueChanged,
                Severity::Compatible,
                text(&v.text),
                text(&w.text),
                format!(
                    "{what}named value {at} {}: text changed",
                    crate::text::code_span(&w.name)
                ),
            ),
            Some(_) => {}
        }
    }
    for (key, v) in n.iter().filter(|(k, _)| !o.contains_key(k)) {
        push(
            Kind::NamedValueAdded,
            Severity::Additive,
            None,
            Some(Val::Text(v.name.clone())),
            format!(
                "{what}named value {} {} added",
                range(key.0, key.1),
                crate::text::code_span(&v.name)
            ),
        );
    }
    let numeric = |t: Option<&ValueTable>| t.and_then(|t| t.numeric);
    if let (Some(ot), Some(nt)) = (old, new) {
        if ot.numeric != nt.numeric {
            let show = |r: Option<(i128, i128)>| r.map(|(l, h)| Val::Text(range(l, h)));
            let (ov, nv) = (show(numeric(old)), show(numeric(new)));
            let severity = if ot.numeric.is_some() && nt.numeric.is_none() {
                Severity::Breaking
            } else {
                Severity::Compatible
            };
            let message = format!("{what}numeric range {} → {}", shown(&ov), shown(&nv));
            push(Kind::ValueTableChanged, severity, ov, nv, message);
        }
        if ot.other != nt.other {
            push(
                Kind::ValueTableChanged,
                rename_severity(&ot.other, &nt.other, Case::UpperCamel),
                Some(Val::Text(ot.other.clone())),
                Some(Val::Text(nt.other.clone())),
                format!(
                    "{what}fallback name {} → {}",
                    crate::text::code_span(&ot.other),
                    crate::text::code_span(&nt.other)
                ),
            );
        }
    }
}

/// Bit fields keyed by their Rust name (the getter).
fn bit_fields(push: &mut Push, old: &[BitField], new: &[BitField]) {
    let by_name = |fields: &[BitField]| -> BTreeMap<String, BitField> {
        fields
            .iter()
            .map(|f| (sanitize(&f.name, Case::Snake), f.clone()))
            .collect()
    };
    let (o, n) = (by_name(old), by_name(new));
    let bits = |f: &BitField| {
        if f.width == 1 {
            format!("bit {}", f.lsb)
        } else {
            format!("bits {}..={}", f.lsb, f.lsb + f.width - 1)
        }
    };
    for (key, f) in &o {
        let Some(g) = n.get(key) else {
            push(
                Kind::BitFieldRemoved,
                Severity::Breaking,
                Some(Val::Text(f.name.clone())),
                None,
                format!(
                    "bit field {} ({}) removed",
                    crate::text::code_span(&f.name),
                    bits(f)
                ),
            );
            continue;
        };
        if f.lsb != g.lsb || f.width != g.width {
            push(
                Kind::BitFieldChanged,
                Severity::Breaking,
                Some(Val::Text(bits(f))),
                Some(Val::Text(bits(g))),
                format!(
                    "bit field {} moved: {} → {}",
                    crate::text::code_span(&g.name),
                    bits(f),
                    bits(g)
                ),
            );
        }
        if f.text != g.text || f.unit != g.unit || !same_real(f.scale, g.scale) || f.name != g.name
        {
            push(
                Kind::BitFieldChanged,
                Severity::Compatible,
                Some(Val::Text(f.name.clone())),
                Some(Val::Text(g.name.clone())),
                format!(
                    "bit field {}: name, text, unit or scale changed",
                    crate::text::code_span(&g.name)
                ),
            );
        }
        let prefix = format!("bit field {}: ", crate::text::code_span(&g.name));
        value_table(push, &prefix, f.values.as_ref(), g.values.as_ref());
    }
    for (key, g) in n.iter().filter(|(k, _)| !o.contains_key(*k)) {
        let _ = key;
        push(
            Kind::BitFieldAdded,
            Severity::Additive,
            None,
            Some(Val::Text(g.name.clone())),
            format!(
                "bit field {} ({}) added",
                crate::text::code_span(&g.name),
                bits(g)
            ),
        );
    }
}

/// Device error tables (index 0): tables by name, codes by code.
pub(super) fn error_tables(cx: &mut Cx) {
    let by_name = |tables: &[ErrorTable]| -> BTreeMap<String, ErrorTable> {
        tables.iter().map(|t| (t.name.clone(), t.clone())).collect()
    };
    let (o, n) = (by_name(&cx.old.error_tables), by_name(&cx.new.error_tables));
    for (name, t) in &o {
        let old_path = cx.old_names.error_tables.get(name).cloned();
        let Some(u) = n.get(name) else {
            cx.push(
                0,
                None,
                Kind::ErrorTableRemoved,
                Severity::Breaking,
                old_path,
                Some(Val::Text(name.clone())),
                None,
                format!(
                    "error table {} removed (codes: {})",
                    crate::text::code_span(name),
                    t.codes.len()
                ),
            );
            continue;
        };
        let path = cx.new_names.error_tables.get(name).cloned();
        if t.kind != u.kind {
            cx.push(
                0,
                None,
                Kind::ErrorTableChanged,
                Severity::Breaking,
                path.clone(),
                Some(Val::Text(format!("{:?}", t.kind).to_lowercase())),
                Some(Val::Text(format!("{:?}", u.kind).to_lowercase())),
                format!(
                    "error table {}: kind {:?} → {:?}",
                    crate::text::code_span(name),
                    t.kind,
                    u.kind
                ),
            );
        }
        if t.description != u.description {
            cx.push(
                0,
                None,
                Kind::ErrorTableChanged,
                Severity::Compatible,
                path.clone(),
                text(&t.description),
                text(&u.description),
                format!(
                    "error table {}: description changed",
                    crate::text::code_span(name)
                ),
            );
        }
        error_codes(cx, name, &path, t, u);
    }
    for (name, u) in n.iter().filter(|(k, _)| !o.contains_key(*k)) {
        let path = cx.new_names.error_tables.get(name).cloned();
        cx.push(
            0,
            None,
            Kind::ErrorTableAdded,
            Severity::Additive,
            path,
            None,
            Some(Val::Text(name.clone())),
            format!(
                "error table {} added (codes: {})",
                crate::text::code_span(name),
                u.codes.len()
            ),
        );
    }
}

fn error_codes(
    cx: &mut Cx,
    table: &str,
    path: &Option<String>,
    old: &ErrorTable,
    new: &ErrorTable,
) {
    let by_code = |t: &ErrorTable| -> BTreeMap<u32, crate::ir::ErrorCode> {
        t.codes.iter().map(|c| (c.code, c.clone())).collect()
    };
    let (o, n) = (by_code(old), by_code(new));
    for (code, c) in &o {
        let Some(d) = n.get(code) else {
            cx.push(
                0,
                None,
                Kind::ErrorCodeRemoved,
                Severity::Breaking,
                path.clone(),
                Some(Val::Int((*code).into())),
                None,
                format!(
                    "error table {}: code 0x{code:X} {} removed",
                    crate::text::code_span(table),
                    crate::text::code_span(&c.name)
                ),
            );
            continue;
        };
        if c.name != d.name {
            cx.push(
                0,
                None,
                Kind::ErrorCodeChanged,
                rename_severity(&c.name, &d.name, Case::UpperCamel),
                path.clone(),
                Some(Val::Text(c.name.clone())),
                Some(Val::Text(d.name.clone())),
                format!(
                    "error table {}: code 0x{code:X} {} → {}",
                    crate::text::code_span(table),
                    crate::text::code_span(&c.name),
                    crate::text::code_span(&d.name)
                ),
            );
        }
        if c.text != d.text
            || c.reaction != d.reaction
            || c.remedy != d.remedy
            || c.configurable != d.configurable
        {
            cx.push(
                0,
                None,
                Kind::ErrorCodeChanged,
                Severity::Compatible,
                path.clone(),
                text(&c.text),
                text(&d.text),
                format!(
                    "error table {}: code 0x{code:X} {}: text, reaction or remedy changed",
                    crate::text::code_span(table),
                    crate::text::code_span(&d.name)
                ),
            );
        }
    }
    for (code, d) in n.iter().filter(|(k, _)| !o.contains_key(*k)) {
        cx.push(
            0,
            None,
            Kind::ErrorCodeAdded,
            Severity::Additive,
            path.clone(),
            None,
            Some(Val::Int((*code).into())),
            format!(
                "error table {}: code 0x{code:X} {} added",
                crate::text::code_span(table),
                crate::text::code_span(&d.name)
            ),
        );
    }
}
