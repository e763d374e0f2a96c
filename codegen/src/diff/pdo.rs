//! Default PDOs, compared as PDOs: the active entries of each mapping object
//! (0x1600–0x17FF, 0x1A00–0x1BFF), the default COB-ID of each communication
//! object (0x1400–0x15FF, 0x1800–0x19FF, sub 1) and the YAML labels that
//! name the generated PDO structs.

use super::{Cx, Kind, Severity, Val, literal_val, same_literal, shown};
use crate::r#gen::rust::naming::{Case, sanitize};
use crate::ir::pdo::{MappedObject, is_mapping_object, raw_mapping};
use crate::ir::{Device, PdoDirection, PdoLabel};

/// `TPDO1` for mapping or communication index `index`.
fn pdo_name(index: u16) -> (PdoDirection, u16, String) {
    let (direction, number) = match index {
        0x1400..=0x15FF => (PdoDirection::Rpdo, index - 0x1400 + 1),
        0x1600..=0x17FF => (PdoDirection::Rpdo, index - 0x1600 + 1),
        0x1800..=0x19FF => (PdoDirection::Tpdo, index - 0x1800 + 1),
        _ => (PdoDirection::Tpdo, index - 0x1A00 + 1),
    };
    let prefix = match direction {
        PdoDirection::Rpdo => "RPDO",
        PdoDirection::Tpdo => "TPDO",
    };
    (direction, number, format!("{prefix}{number}"))
}

/// The active mapping entries (subs 1 to the default of sub 0), without
/// zero entries; `None` when the device has no such mapping object.
fn active(device: &Device, index: u16) -> Option<Vec<u32>> {
    let object = device.objects.get(&index)?;
    let count = object
        .entries
        .get(&0)
        .map(Box::as_ref)
        .and_then(raw_mapping)
        .unwrap_or(u32::MAX);
    Some(
        object
            .entries
            .values()
            .map(Box::as_ref)
            .filter(|e| e.subindex >= 1 && u32::from(e.subindex) <= count)
            .filter_map(raw_mapping)
            .filter(|&raw| raw != 0)
            .collect(),
    )
}

pub(crate) fn describe(raw: u32) -> String {
    let m = MappedObject::from_raw(raw);
    if m.is_dummy() {
        format!("dummy 0x{:04X} ({} bits)", m.index, m.bits)
    } else {
        format!("0x{:04X} sub {} ({} bits)", m.index, m.subindex, m.bits)
    }
}

pub(crate) fn listed(mapping: &[u32]) -> Vec<String> {
    mapping.iter().map(|&raw| describe(raw)).collect()
}

pub(super) fn pdos(cx: &mut Cx) {
    let mut indices: Vec<u16> = cx
        .old
        .objects
        .keys()
        .chain(cx.new.objects.keys())
        .copied()
        .filter(|&i| is_mapping_object(i))
        .collect();
    indices.sort_unstable();
    indices.dedup();
    for index in indices {
        let (_, _, name) = pdo_name(index);
        let old = active(cx.old, index).unwrap_or_default();
        let new = active(cx.new, index).unwrap_or_default();
        if old == new {
            continue;
        }
        let (ov, nv) = (Val::List(listed(&old)), Val::List(listed(&new)));
        let (kind, severity, message) = if old.is_empty() {
            (
                Kind::PdoAdded,
                Severity::Additive,
                format!("{name} default mapping added: {nv}"),
            )
        } else if new.is_empty() {
            (
                Kind::PdoRemoved,
                Severity::Breaking,
                format!("{name} default mapping removed: was {ov}"),
            )
        } else {
            (
                Kind::PdoMappingChanged,
                Severity::Breaking,
                format!("{name} mapping changed: {ov} → {nv}"),
            )
        };
        cx.push(
            index,
            None,
            kind,
            severity,
            None,
            Some(ov),
            Some(nv),
            message,
        );
    }
    cob_ids(cx);
    labels(cx);
}

fn cob_ids(cx: &mut Cx) {
    let is_comm = |i: u16| (0x1400..=0x15FF).contains(&i) || (0x1800..=0x19FF).contains(&i);
    let mut indices: Vec<u16> = cx
        .old
        .objects
        .keys()
        .chain(cx.new.objects.keys())
        .copied()
        .filter(|&i| is_comm(i))
        .collect();
    indices.sort_unstable();
    indices.dedup();
    for index in indices {
        let cob = |d: &Device| {
            let entry = d.objects.get(&index)?.entries.get(&1)?;
            entry.parameter_value.clone().or(entry.default.clone())
        };
        let (old, new) = (cob(cx.old), cob(cx.new));
        // A COB-ID that appears or disappears is a sub or object added or
        // removed, reported as such.
        let (Some(o), Some(n)) = (&old, &new) else {
            continue;
        };
        if same_literal(o, n) {
            continue;
        }
        let (_, _, name) = pdo_name(index);
        let show = |l: &Option<crate::ir::Literal>| {
            l.as_ref().map(|l| match literal_val(l) {
                Val::Int(v) => Val::Text(super::hex(v)),
                other => other,
            })
        };
        let (ov, nv) = (show(&old), show(&new));
        let path = cx.new_names.entries.get(&(index, 1)).map(|p| p.0.clone());
        let message = format!("{name} default COB-ID {} → {}", shown(&ov), shown(&nv));
        cx.push(
            index,
            Some(1),
            Kind::PdoCobIdChanged,
            Severity::Breaking,
            path,
            ov,
            nv,
            message,
        );
    }
}

/// Labels name the PDO structs (`pdo::Tpdo1Feedback`): a label whose Rust
/// spelling changes renames the struct.
fn labels(cx: &mut Cx) {
    let key = |l: &PdoLabel| (l.direction, l.number);
    let mut keys: Vec<(PdoDirection, u16)> = cx
        .old
        .pdo_labels
        .iter()
        .chain(cx.new.pdo_labels.iter())
        .map(key)
        .collect();
    keys.sort_unstable();
    keys.dedup();
    for k in keys {
        let find = |d: &Device| d.pdo_labels.iter().find(|l| key(l) == k).cloned();
        let (old, new) = (find(cx.old), find(cx.new));
        let index = k.0.mapping_index(k.1);
        // The label of a PDO added or removed is part of that change.
        let exists = |d: &Device| active(d, index).is_some_and(|m| !m.is_empty());
        if !exists(cx.old) || !exists(cx.new) {
            continue;
        }
        let (_, _, name) = pdo_name(index);
        let old_name = old.as_ref().map(|l| l.name.clone());
        let new_name = new.as_ref().map(|l| l.name.clone());
        let spelled = |n: &Option<String>| {
            sanitize(
                &format!("{name} {}", n.as_deref().unwrap_or("")),
                Case::UpperCamel,
            )
        };
        if old_name != new_name {
            let severity = if spelled(&old_name) == spelled(&new_name) {
                Severity::Compatible
            } else {
                Severity::Breaking
            };
            let (ov, nv) = (old_name.map(Val::Text), new_name.map(Val::Text));
            let message = format!(
                "{name} label {} → {} (struct pdo::{} → pdo::{})",
                shown(&ov),
                shown(&nv),
                spelled(&old.as_ref().map(|l| l.name.clone())),
                spelled(&new.as_ref().map(|l| l.name.clone()))
            );
            cx.push(
                index,
                None,
                Kind::PdoLabelChanged,
                severity,
                None,
                ov,
                nv,
                message,
            );
        } else if let (Some(o), Some(n)) = (&old, &new)
            && o.description != n.description
        {
            cx.push(
                index,
                None,
                Kind::PdoLabelChanged,
                Severity::Compatible,
                None,
                o.description.clone().map(Val::Text),
                n.description.clone().map(Val::Text),
                format!(
                    "{name} label {}: description changed",
                    crate::text::code_span(&n.name)
                ),
            );
        }
    }
}
