//! Stage 6, PDO defaults: `pdos` writes communication values and mapping
//! entries into 0x1400+/0x1600+/0x1800+/0x1A00+, creating the objects when
//! the table does not define them; then every mapping of the device is
//! checked (existence, mappability, length, direction, at most 64 bits).

use std::collections::{BTreeMap, BTreeSet};

use serde_saphyr::Spanned;

use super::schema::{MapDef, PdoDef};
use super::{At, Ctx, place};
use crate::ir::pdo::{self, MappedObject};
use crate::ir::{
    Access, DataType, Device, Entry, Literal, Object, ObjectKind, Origin, PdoDirection, PdoLabel,
    Value,
};

pub(super) fn apply(ctx: &mut Ctx, device: &mut Device, pdos: &[Spanned<PdoDef>]) {
    let mut seen: BTreeMap<(PdoDirection, u16), u32> = BTreeMap::new();
    for def in pdos {
        let d = &def.value;
        let (direction, number) = (d.direction.value, d.number.value);
        let at = At::of(def);
        let here = label(direction, number);
        if !(1..=512).contains(&number) {
            ctx.error(
                "table::pdo-number",
                At::of(&d.number),
                &here,
                "number",
                format!("PDO numbers run from 1 to 512, not {number}"),
            );
            continue;
        }
        if let Some(first) = seen.insert((direction, number), at.line) {
            ctx.error(
                "table::duplicate-pdo",
                at,
                &here,
                "number",
                format!("{here} is already described at line {first}"),
            );
            continue;
        }
        if let Some(name) = &d.name {
            device.pdo_labels.push(PdoLabel {
                direction,
                number,
                name: name.value.clone(),
                description: d.description.as_ref().map(|t| t.value.clone()),
                origin: ctx.origin(at),
            });
        }
        communication(ctx, device, def, &here);
        mapping(ctx, device, def, &here);
    }
    device.pdo_labels.sort_by_key(|l| (l.direction, l.number));
}

fn label(direction: PdoDirection, number: u16) -> String {
    match direction {
        PdoDirection::Rpdo => format!("RPDO{number}"),
        PdoDirection::Tpdo => format!("TPDO{number}"),
    }
}

fn int_literal(value: i128, plus_node_id: bool) -> Literal {
    let text = if plus_node_id {
        format!("$NODEID+0x{value:X}")
    } else {
        value.to_string()
    };
    Literal {
        value: Value::Integer(value),
        plus_node_id,
        text,
    }
}

fn new_entry(sub: u8, name: &str, data_type: DataType, default: Literal, origin: &Origin) -> Entry {
    Entry {
        subindex: sub,
        name: name.into(),
        data_type,
        access: Access::Rw,
        pdo_mappable: false,
        default: Some(default),
        low_limit: None,
        high_limit: None,
        parameter_value: None,
        obj_flags: None,
        denotation: None,
        semantics: Default::default(),
        rust_name: None,
        origin: origin.clone(),
    }
}

fn communication(ctx: &mut Ctx, device: &mut Device, def: &Spanned<PdoDef>, here: &str) {
    let d = &def.value;
    let (direction, number) = (d.direction.value, d.number.value);
    let index = direction.communication_index(number);
    let origin = ctx.origin(At::of(def));
    let cob_id = match &d.cob_id {
        Some(text) => super::entry::literal(
            ctx,
            &text.value,
            At::of(text),
            DataType::Unsigned32,
            here,
            "cob_id",
        ),
        None => None,
    };
    let mut given: Vec<(u8, &str, DataType, Literal, At)> = Vec::new();
    if let (Some(lit), Some(t)) = (cob_id, &d.cob_id) {
        given.push((1, "COB-ID", DataType::Unsigned32, lit, At::of(t)));
    }
    let small = |v: &Option<Spanned<u16>>| v.as_ref().map(|s| (i128::from(s.value), At::of(s)));
    let byte = |v: &Option<Spanned<u8>>| v.as_ref().map(|s| (i128::from(s.value), At::of(s)));
    for (sub, name, data_type, value) in [
        (
            2u8,
            "Transmission type",
            DataType::Unsigned8,
            byte(&d.transmission),
        ),
        (
            3,
            "Inhibit time",
            DataType::Unsigned16,
            small(&d.inhibit_time),
        ),
        (
            5,
            "Event timer",
            DataType::Unsigned16,
            small(&d.event_timer),
        ),
        (
            6,
            "SYNC start value",
            DataType::Unsigned8,
            byte(&d.sync_start),
        ),
    ] {
        if let Some((v, at)) = value {
            given.push((sub, name, data_type, int_literal(v, false), at));
        }
    }
    if direction == PdoDirection::Rpdo
        && let Some((_, name, _, _, at)) = given.iter().find(|g| g.0 == 3 || g.0 == 6)
    {
        ctx.error(
            "table::pdo-parameter",
            *at,
            here,
            "",
            format!("an RPDO has no {}", name.to_lowercase()),
        );
    }
    match device.objects.get_mut(&index) {
        Some(object) => {
            for (sub, name, _, lit, at) in given {
                match object.entries.get_mut(&sub) {
                    Some(entry) => entry.default = Some(lit),
                    None => ctx.error(
                        "table::missing-entry",
                        at,
                        &place(index, Some(sub)),
                        "",
                        format!(
                            "{here}: object 0x{index:04X} has no sub-index {sub} for the {}",
                            name.to_lowercase()
                        ),
                    ),
                }
            }
        }
        None => {
            // The predefined connection set gives PDOs 1–4 their COB-IDs.
            let standard_cob_id = match (direction, number) {
                (PdoDirection::Tpdo, 1..=4) => {
                    int_literal(0x180 + 0x100 * i128::from(number - 1), true)
                }
                (PdoDirection::Rpdo, 1..=4) => {
                    int_literal(0x200 + 0x100 * i128::from(number - 1), true)
                }
                _ => int_literal(0x8000_0000, false),
            };
            let mut entries = BTreeMap::new();
            entries.insert(
                1,
                new_entry(1, "COB-ID", DataType::Unsigned32, standard_cob_id, &origin),
            );
            entries.insert(
                2,
                new_entry(
                    2,
                    "Transmission type",
                    DataType::Unsigned8,
                    int_literal(255, false),
                    &origin,
                ),
            );
            if direction == PdoDirection::Tpdo {
                entries.insert(
                    3,
                    new_entry(
                        3,
                        "Inhibit time",
                        DataType::Unsigned16,
                        int_literal(0, false),
                        &origin,
                    ),
                );
                entries.insert(
                    5,
                    new_entry(
                        5,
                        "Event timer",
                        DataType::Unsigned16,
                        int_literal(0, false),
                        &origin,
                    ),
                );
            }
            for (sub, name, data_type, lit, _) in given {
                if direction == PdoDirection::Rpdo && (sub == 3 || sub == 6) {
                    continue;
                }
                entries.insert(sub, new_entry(sub, name, data_type, lit, &origin));
            }
            let highest = entries.keys().next_back().copied().unwrap_or(0);
            entries.insert(0, Entry::highest_subindex(highest, origin.clone()));
            let name = format!("{} communication parameter", label(direction, number));
            device
                .objects
                .insert(index, record(index, name, entries, origin));
        }
    }
}

fn record(index: u16, name: String, entries: BTreeMap<u8, Entry>, origin: Origin) -> Object {
    Object {
        index,
        name,
        kind: ObjectKind::Record,
        entries: Object::boxed_entries(entries),
        obj_flags: None,
        denotation: None,
        compact_sub_obj: None,
        rust_name: None,
        origin,
    }
}

fn mapping(ctx: &mut Ctx, device: &mut Device, def: &Spanned<PdoDef>, here: &str) {
    let d = &def.value;
    let (direction, number) = (d.direction.value, d.number.value);
    let index = direction.mapping_index(number);
    let origin = ctx.origin(At::of(def));
    let mut items: Vec<(MappedObject, At)> = Vec::new();
    for item in &d.mapping {
        if let Some(mapped) = map_item(ctx, device, item, direction, here) {
            items.push((mapped, At::of(item)));
        }
    }
    let total: u32 = items.iter().map(|(m, _)| u32::from(m.bits)).sum();
    if total > 64 {
        ctx.error(
            "table::pdo-too-long",
            At::of(def),
            here,
            "mapping",
            format!("the mapping totals {total} bits; a PDO carries at most 64"),
        );
    }
    if d.mapping.is_empty() {
        return;
    }
    // CiA 301: mapping sub-indices 1 to 0x40.
    if d.mapping.len() > 64 {
        ctx.error(
            "table::pdo-too-long",
            At::of(def),
            here,
            "mapping",
            format!(
                "the mapping has {} entries; a PDO maps at most 64",
                d.mapping.len()
            ),
        );
        return;
    }
    let count = items.len();
    let object = device.objects.entry(index).or_insert_with(|| {
        let mut entries = BTreeMap::new();
        for sub in 1..=count.max(8) as u8 {
            let name = format!("Mapped object {sub}");
            entries.insert(
                sub,
                new_entry(
                    sub,
                    &name,
                    DataType::Unsigned32,
                    int_literal(0, false),
                    &origin,
                ),
            );
        }
        let mut sub0 = Entry::highest_subindex(count as u8, origin.clone());
        sub0.access = Access::Rw;
        entries.insert(0, sub0);
        let name = format!("{} mapping parameter", label(direction, number));
        record(index, name, entries, origin.clone())
    });
    if let Some(sub0) = object.entries.get_mut(&0) {
        sub0.default = Some(int_literal(count as i128, false));
    }
    let subs: Vec<u8> = object.entries.keys().copied().filter(|&s| s >= 1).collect();
    for sub in subs {
        if let Some(entry) = object.entries.get_mut(&sub) {
            let raw = items.get(usize::from(sub) - 1).map_or(0, |(m, _)| m.raw());
            entry.default = Some(Literal {
                value: Value::Integer(raw.into()),
                plus_node_id: false,
                text: format!("0x{raw:08X}"),
            });
        }
    }
    for (i, (_, at)) in items.iter().enumerate() {
        let sub = i + 1;
        if !object.entries.contains_key(&(sub as u8)) {
            ctx.error(
                "table::missing-entry",
                *at,
                &place(index, Some(sub as u8)),
                "mapping",
                format!(
                    "{here} maps {count} entries, but object 0x{index:04X} has no sub-index {sub}"
                ),
            );
        }
    }
}

/// One `mapping` item: a gap or an entry of the device, checked.
fn map_item(
    ctx: &mut Ctx,
    device: &Device,
    item: &Spanned<MapDef>,
    direction: PdoDirection,
    here: &str,
) -> Option<MappedObject> {
    let m = &item.value;
    let at = At::of(item);
    match (&m.dummy, &m.index) {
        (Some(dummy), None) => {
            let data_type = super::entry::data_type(ctx, dummy, here)?;
            let code = data_type.code();
            let bits = pdo::mappable_bits(data_type).map(|b| b[b.len() - 1]);
            match bits {
                Some(bits) if (1..=7).contains(&code) => Some(MappedObject {
                    index: code,
                    subindex: 0,
                    bits: if data_type == DataType::Boolean {
                        1
                    } else {
                        bits
                    },
                }),
                _ => {
                    ctx.error(
                        "table::pdo-dummy",
                        At::of(dummy),
                        here,
                        "dummy",
                        format!(
                            "a dummy entry is BOOLEAN … UNSIGNED32 (codes 0x1–0x7), not {}",
                            data_type.name()
                        ),
                    );
                    None
                }
            }
        }
        (None, Some(index)) => {
            let index = index.value;
            let sub = m.sub.as_ref().map_or(0, |s| s.value);
            let entry = super::item::find_entry(ctx, device, index, sub, at)?;
            let widths = pdo::mappable_bits(entry.data_type);
            let bits = match (&m.bits, widths) {
                (Some(b), _) => b.value,
                (None, Some(w)) => w[w.len() - 1],
                (None, None) => {
                    ctx.error(
                        "table::pdo-mapping",
                        at,
                        here,
                        "mapping",
                        format!(
                            "0x{index:04X} sub {sub} is a {} and has no fixed length to map",
                            entry.data_type.name()
                        ),
                    );
                    return None;
                }
            };
            let mapped = MappedObject {
                index,
                subindex: sub,
                bits,
            };
            for problem in pdo::check_entry(device, mapped.raw()) {
                ctx.error(
                    "table::pdo-mapping",
                    at,
                    here,
                    "mapping",
                    problem.to_string(),
                );
            }
            if !direction.allows(entry.access) {
                let (verb, way) = match direction {
                    PdoDirection::Rpdo => ("writes", "writable"),
                    PdoDirection::Tpdo => ("reads", "readable"),
                };
                ctx.error(
                    "table::pdo-direction",
                    at,
                    here,
                    "mapping",
                    format!(
                        "{here} {verb} 0x{index:04X} sub {sub}, which is `{}`, not {way}",
                        entry.access.as_str()
                    ),
                );
            }
            Some(mapped)
        }
        _ => {
            ctx.error(
                "table::pdo-mapping",
                at,
                here,
                "mapping",
                "a mapping item has `index` (with optional `sub`, `bits`) or `dummy: TYPE`, not both".into(),
            );
            None
        }
    }
}

/// Checks the mappings that `pdos` did not write (those given as plain
/// objects, or kept from the base EDS of an overlay).
/// The problems of every default mapping entry of `device` that `pdos`
/// does not write, as (mapping index, sub, problem): taken of the base
/// device before an overlay's stages, so that only what the overlay
/// introduces is reported after them.
pub(super) type MappingProblems = BTreeSet<(u16, u8, String)>;

pub(super) fn mapping_problems(device: &Device) -> MappingProblems {
    let mut out = BTreeSet::new();
    for (&index, object) in &device.objects {
        if !pdo::is_mapping_object(index) {
            continue;
        }
        for entry in object.entries.values().filter(|e| e.subindex >= 1) {
            if let Some(raw) = pdo::raw_mapping(entry) {
                for problem in pdo::check_entry(device, raw) {
                    out.insert((index, entry.subindex, problem.to_string()));
                }
            }
        }
    }
    out
}

/// Checks every default mapping that `written` (the table's `pdos`) does
/// not write; those are checked where they are written. `before` holds the
/// problems the base device had already (reported, with their own
/// severity, by the reader of the base file): they are not reported again.
/// A new problem of a mapping entry that the table wrote is an error at
/// that entry; one of a base mapping entry that the table's changes to the
/// mapped object broke is an error at that change, naming the base entry.
pub(super) fn check_mappings(
    ctx: &mut Ctx,
    device: &Device,
    written: &BTreeSet<u16>,
    before: &MappingProblems,
    changes: &BTreeMap<u16, At>,
) {
    for (&index, object) in &device.objects {
        if !pdo::is_mapping_object(index) || written.contains(&index) {
            continue;
        }
        for entry in object.entries.values().filter(|e| e.subindex >= 1) {
            let Some(raw) = pdo::raw_mapping(entry) else {
                continue;
            };
            for problem in pdo::check_entry(device, raw) {
                let text = problem.to_string();
                if before.contains(&(index, entry.subindex, text.clone())) {
                    continue;
                }
                let here = place(index, Some(entry.subindex));
                let target = MappedObject::from_raw(raw).index;
                let (at, message) = if entry.origin.file == ctx.file {
                    (At::line(entry.origin.line), text)
                } else {
                    // The entry is the base file's; this table changed what it maps.
                    let at = changes.get(&target).copied().unwrap_or(At::line(0));
                    let message = format!(
                        "after this table's change to 0x{target:04X}, the mapping entry at {}:{} {text}",
                        entry.origin.file, entry.origin.line
                    );
                    (at, message)
                };
                ctx.error("table::pdo-mapping", at, &here, "default", message);
                if let Some(fix) = problem.fix(index, entry.subindex) {
                    ctx.note(fix);
                }
            }
        }
        let total = pdo::total_bits(device, index);
        if total > 64 && !before.iter().any(|(i, _, _)| *i == index) {
            ctx.error(
                "table::pdo-too-long",
                At::line(object.origin.line),
                &place(index, None),
                "",
                format!("the mapping totals {total} bits; a PDO carries at most 64"),
            );
        }
    }
}

/// The mapping objects `pdos` writes.
pub(super) fn written_mappings(pdos: &[Spanned<PdoDef>]) -> BTreeSet<u16> {
    pdos.iter()
        .filter(|p| !p.value.mapping.is_empty() && (1..=512).contains(&p.value.number.value))
        .map(|p| p.value.direction.value.mapping_index(p.value.number.value))
        .collect()
}
