//! Objects and entries of a table: the `objects` (add), `delete` and
//! `modify` stages, data types, access rights and literals.

use std::collections::BTreeMap;

use serde_saphyr::Spanned;

use super::item::{
    SEMANTIC_KEYS, VALUE_KEYS, entry_reference, find_entry, has_leading_zero, only_pin, pin_object,
    reject_keys, required_index, rust_name,
};
use super::schema::{EntryDef, KindDef, Text};
use super::{At, Ctx, place};
use crate::diag::Severity;
use crate::eds::number;
use crate::r#gen::rust::naming::Case;
use crate::ir::{Access, DataType, Device, Entry, LimitProblem, Literal, Object, ObjectKind};

/// Stage 4: adds one object of `objects`.
pub(super) fn add(ctx: &mut Ctx, device: &mut Device, def: &Spanned<EntryDef>) {
    let Some(index) = required_index(ctx, def, "an object") else {
        return;
    };
    let here = place(index, None);
    if let Some(existing) = device.objects.get(&index) {
        let first = if existing.origin.file == ctx.file {
            format!("line {}", existing.origin.line)
        } else {
            format!("{}:{}", existing.origin.file, existing.origin.line)
        };
        ctx.error(
            "table::duplicate-index",
            At::of(def),
            &here,
            "index",
            format!("object 0x{index:04X} is already defined ({first}); an overlay changes existing objects with `modify`"),
        );
        return;
    }
    let kind = def.value.kind.as_ref().map_or(KindDef::Var, |k| k.value);
    let name = required_name(ctx, def, &here, format!("Object 0x{index:04X}"));
    let mut entries = BTreeMap::new();
    let object_kind = match kind {
        KindDef::Var | KindDef::Domain => {
            let object_kind = if kind == KindDef::Var {
                ObjectKind::Var
            } else {
                ObjectKind::Domain
            };
            reject_keys(
                ctx,
                def,
                &[
                    &["index", "name", "kind", "description", "rust_name"],
                    VALUE_KEYS,
                    SEMANTIC_KEYS,
                ],
                "on a var or domain object (sub-entries belong to `kind: array` or `record`)",
                &here,
            );
            if let Some(entry) = build_entry(ctx, index, 0, def, object_kind, &here) {
                entries.insert(0, entry);
            }
            object_kind
        }
        KindDef::Array | KindDef::Record => {
            reject_keys(
                ctx,
                def,
                &[&["index", "name", "kind", "description", "subs", "rust_name"]],
                "on an array or record object (give it on its sub-entries)",
                &here,
            );
            let object_kind = if kind == KindDef::Array {
                ObjectKind::Array
            } else {
                ObjectKind::Record
            };
            entries = build_subs(ctx, index, def, object_kind);
            object_kind
        }
    };
    let object_rust_name = match object_kind {
        ObjectKind::Array | ObjectKind::Record => {
            rust_name(ctx, &def.value.rust_name, Case::Snake, &here)
        }
        _ => None,
    };
    device.objects.insert(
        index,
        Object {
            index,
            name,
            kind: object_kind,
            entries: Object::boxed_entries(entries),
            obj_flags: None,
            denotation: None,
            compact_sub_obj: None,
            rust_name: object_rust_name,
            origin: ctx.origin(At::of(def)),
        },
    );
}

fn required_name(ctx: &mut Ctx, def: &Spanned<EntryDef>, here: &str, fallback: String) -> String {
    match &def.value.name {
        Some(name) if !name.value.trim().is_empty() => name.value.clone(),
        other => {
            let at = other.as_ref().map_or(At::of(def), At::of);
            ctx.error(
                "table::missing-key",
                at,
                here,
                "name",
                "every object and sub-entry needs a non-empty `name`".into(),
            );
            fallback
        }
    }
}

fn build_subs(
    ctx: &mut Ctx,
    index: u16,
    def: &Spanned<EntryDef>,
    kind: ObjectKind,
) -> BTreeMap<u8, Entry> {
    let mut entries: BTreeMap<u8, Entry> = BTreeMap::new();
    let mut seen: BTreeMap<u8, u32> = BTreeMap::new();
    let subs = def.value.subs.as_deref().unwrap_or_default();
    if subs.is_empty() {
        ctx.error(
            "table::missing-key",
            At::of(def),
            &place(index, None),
            "subs",
            "an array or record needs `subs:` with at least one sub-entry".into(),
        );
        return entries;
    }
    for sub_def in subs {
        let Some(sub) = &sub_def.value.sub else {
            ctx.error(
                "table::missing-key",
                At::of(sub_def),
                &place(index, None),
                "sub",
                "every item of `subs` needs `sub`".into(),
            );
            continue;
        };
        let here = place(index, Some(sub.value));
        reject_keys(
            ctx,
            sub_def,
            &[
                &["sub", "name", "description", "rust_name"],
                VALUE_KEYS,
                SEMANTIC_KEYS,
            ],
            "on a sub-entry",
            &here,
        );
        if let Some(first) = seen.insert(sub.value, At::of(sub).line) {
            ctx.error(
                "table::duplicate-sub",
                At::of(sub),
                &here,
                "sub",
                format!("sub-index {} is already defined at line {first}", sub.value),
            );
            continue;
        }
        if let Some(entry) = build_entry(ctx, index, sub.value, sub_def, ObjectKind::Var, &here) {
            entries.insert(sub.value, entry);
        }
    }
    if kind == ObjectKind::Array {
        let mut types = entries.values().filter(|e| e.subindex > 0);
        if let Some(first) = types.next() {
            let first_type = first.data_type;
            for other in types.filter(|e| e.data_type != first_type) {
                let at = At::line(other.origin.line);
                ctx.error(
                    "table::array-type",
                    at,
                    &place(index, Some(other.subindex)),
                    "type",
                    format!(
                        "sub-entries of an array share one type: sub {} is {}, sub {} is {}",
                        first.subindex,
                        first_type.name(),
                        other.subindex,
                        other.data_type.name()
                    ),
                );
            }
        }
    }
    if !seen.contains_key(&0)
        && let Some(&highest) = seen.keys().next_back()
    {
        entries.insert(0, Entry::highest_subindex(highest, ctx.origin(At::of(def))));
    }
    entries
}

/// Builds one value-carrying entry from a var object or a sub-entry.
fn build_entry(
    ctx: &mut Ctx,
    index: u16,
    sub: u8,
    def: &Spanned<EntryDef>,
    kind: ObjectKind,
    here: &str,
) -> Option<Entry> {
    let d = &def.value;
    let name = required_name(ctx, def, here, format!("Sub-index {sub}"));
    let data_type = match (&d.data_type, kind) {
        (Some(t), _) => data_type(ctx, t, here)?,
        (None, ObjectKind::Domain) => DataType::Domain,
        (None, _) => {
            ctx.error(
                "table::missing-key",
                At::of(def),
                here,
                "type",
                "a value needs `type` (a CiA 301 name such as UNSIGNED16)".into(),
            );
            return None;
        }
    };
    let access = match &d.access {
        Some(a) => access(ctx, a, here).unwrap_or(Access::Ro),
        None => {
            ctx.error(
                "table::missing-key",
                At::of(def),
                here,
                "access",
                "a value needs `access` (ro, wo, rw, rwr, rww or const)".into(),
            );
            Access::Ro
        }
    };
    let value = |ctx: &mut Ctx, key: &str, t: &Option<Text>| {
        t.as_ref()
            .and_then(|t| literal(ctx, &t.value, At::of(t), data_type, here, key))
    };
    let mut entry = Entry {
        subindex: sub,
        name,
        data_type,
        access,
        pdo_mappable: d.pdo.as_ref().is_some_and(|p| p.value),
        default: value(ctx, "default", &d.default),
        low_limit: value(ctx, "min", &d.min),
        high_limit: value(ctx, "max", &d.max),
        parameter_value: None,
        obj_flags: None,
        denotation: None,
        semantics: Default::default(),
        rust_name: rust_name(ctx, &d.rust_name, Case::UpperCamel, here),
        origin: ctx.origin(At::of(def)),
    };
    check_limits(ctx, &entry, def, here);
    entry.semantics = super::meaning::semantics(ctx, def, &entry, here);
    let _ = index;
    Some(entry)
}

/// A CiA 301 data type name.
pub(super) fn data_type(ctx: &mut Ctx, text: &Text, here: &str) -> Option<DataType> {
    let name = text.value.trim();
    let found = (1u16..=0x1B)
        .map(DataType::from_code)
        .find(|t| !matches!(t, DataType::Other(_)) && t.name().eq_ignore_ascii_case(name));
    if found.is_none() {
        ctx.error(
            "table::bad-type",
            At::of(text),
            here,
            "type",
            format!("`{name}` is not a CiA 301 data type; write e.g. UNSIGNED16, INTEGER32, REAL32, VISIBLE_STRING (see docs/yaml-tables.md)"),
        );
    }
    found
}

fn access(ctx: &mut Ctx, text: &Text, here: &str) -> Option<Access> {
    let access = match text.value.trim() {
        "ro" => Access::Ro,
        "wo" => Access::Wo,
        "rw" => Access::Rw,
        "rwr" => Access::Rwr,
        "rww" => Access::Rww,
        "const" => Access::Const,
        other => {
            ctx.error(
                "table::bad-access",
                At::of(text),
                here,
                "access",
                format!("`{other}` is not an access right (ro, wo, rw, rwr, rww, const)"),
            );
            return None;
        }
    };
    Some(access)
}

/// Reads `text` as a value of `data_type`; an error when it is not one.
pub(super) fn literal(
    ctx: &mut Ctx,
    text: &str,
    at: At,
    data_type: DataType,
    here: &str,
    key: &str,
) -> Option<Literal> {
    let t = text.trim();
    let is_integer = matches!(
        data_type.value_kind(),
        Some(crate::ir::ValueKind::Integer { .. })
    );
    if is_integer && has_leading_zero(t) {
        ctx.error(
            "table::leading-zero",
            at,
            here,
            key,
            format!("`{t}` has a leading zero: YAML reads it as decimal, EDS as octal; write it without the zero or as 0x hex"),
        );
        return None;
    }
    match number::parse_value(t, data_type) {
        Some(Ok(parsed)) => match parsed.warning {
            None => Some(parsed.literal),
            // A formula that fits some node ids is kept: the node id decides.
            Some(warning) if parsed.fits_some_node_ids => {
                let code = "table::value-out-of-range";
                ctx.report(Severity::Warning, code, at, here, Some(key), warning);
                Some(parsed.literal)
            }
            Some(warning) => {
                ctx.error("table::value-out-of-range", at, here, key, warning);
                None
            }
        },
        Some(Err(e)) => {
            ctx.error(
                "table::bad-value",
                at,
                here,
                key,
                format!("{} for {}", e.0, data_type.name()),
            );
            None
        }
        None => None,
    }
}
/// `min` above `max`, or a default outside them; reported at the key that
/// `def` gives (else at `def`).
fn check_limits(ctx: &mut Ctx, entry: &Entry, def: &Spanned<EntryDef>, here: &str) {
    let text = |l: &Option<Literal>| l.as_ref().map_or(String::new(), |l| l.text.clone());
    let at_key = |t: &Option<Text>| t.as_ref().map_or(At::of(def), At::of);
    let (key, message) = match entry.limit_problem() {
        None => return,
        Some(LimitProblem::LowAboveHigh) => (
            "min",
            format!(
                "min {} is above max {}",
                text(&entry.low_limit),
                text(&entry.high_limit)
            ),
        ),
        Some(LimitProblem::DefaultBelowLow | LimitProblem::DefaultAboveHigh) => {
            let bound = |l: &Option<Literal>| match l {
                Some(l) => l.text.clone(),
                None => "…".into(),
            };
            let message = format!(
                "default {} is outside min..max ({}..{})",
                text(&entry.default),
                bound(&entry.low_limit),
                bound(&entry.high_limit)
            );
            ("default", message)
        }
    };
    let at = match key {
        "min" => at_key(&def.value.min),
        _ => at_key(&def.value.default),
    };
    ctx.error("table::limits", at, here, key, message);
}

/// Stage 2: removes an object or one sub-entry of the base.
pub(super) fn delete(ctx: &mut Ctx, device: &mut Device, def: &Spanned<EntryDef>) {
    let Some(index) = required_index(ctx, def, "a `delete` item") else {
        return;
    };
    let sub = def.value.sub.as_ref().map(|s| s.value);
    let here = place(index, sub);
    reject_keys(ctx, def, &[&["index", "sub"]], "in `delete`", &here);
    let Some(object) = device.objects.get_mut(&index) else {
        ctx.error(
            "table::missing-entry",
            At::of(def),
            &here,
            "index",
            format!("object 0x{index:04X} is not in the base; nothing to delete"),
        );
        return;
    };
    match sub {
        None => {
            device.objects.remove(&index);
        }
        Some(sub) => {
            if object.entries.remove(&sub).is_none() {
                ctx.error(
                    "table::missing-entry",
                    At::of(def),
                    &here,
                    "sub",
                    format!("object 0x{index:04X} has no sub-index {sub}; nothing to delete"),
                );
            }
        }
    }
}

/// Stage 3: changes the EDS-level keys of an existing entry.
pub(super) fn modify(ctx: &mut Ctx, device: &mut Device, def: &Spanned<EntryDef>) {
    let Some((index, sub, here)) = entry_reference(
        ctx,
        def,
        "a `modify` item",
        &[
            &["index", "sub", "name", "description", "rust_name"],
            VALUE_KEYS,
        ],
        "in `modify` (meaning goes to `semantics`)",
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
    let mut entry = entry.clone();
    let d = &def.value;
    if d.rust_name.is_some() && !object_pinned {
        entry.rust_name = rust_name(ctx, &d.rust_name, Case::UpperCamel, &here);
    }
    if let Some(name) = &d.name {
        entry.name = name.value.clone();
    }
    if let Some(description) = &d.description {
        entry.semantics.description = Some(description.value.clone());
    }
    if let Some(a) = &d.access
        && let Some(a) = access(ctx, a, &here)
    {
        entry.access = a;
    }
    if let Some(p) = &d.pdo {
        entry.pdo_mappable = p.value;
    }
    if let Some(t) = &d.data_type
        && let Some(t) = data_type(ctx, t, &here)
    {
        entry.data_type = t;
    }
    let at = At::of(def);
    let slots: [(&str, &Option<Text>, &mut Option<Literal>); 3] = [
        ("default", &d.default, &mut entry.default),
        ("min", &d.min, &mut entry.low_limit),
        ("max", &d.max, &mut entry.high_limit),
    ];
    for (key, given, slot) in slots {
        // A new value is read with the (new) type; an old one is read again.
        let (text, at) = match given {
            Some(t) => (t.value.clone(), At::of(t)),
            None => match slot.as_ref() {
                Some(old) => (old.text.clone(), at),
                None => continue,
            },
        };
        *slot = literal(ctx, &text, at, entry.data_type, &here, key);
    }
    check_limits(ctx, &entry, def, &here);
    if let Some(object) = device.objects.get_mut(&index) {
        // A variable is its one entry: renaming it renames the object (the
        // name `od::OBJECTS`, the decoder and the CLI show).
        if matches!(object.kind, ObjectKind::Var | ObjectKind::Domain) && d.name.is_some() {
            object.name = entry.name.clone();
        }
        object.entries.insert(sub, Box::new(entry));
    }
}
