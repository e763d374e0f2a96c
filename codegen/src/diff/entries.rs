//! Objects and their entries: added, removed, and every property of an entry
//! that is in both devices.

use super::{Cx, Kind, Severity, Val, hex, literal_val, same_literal, shown};
use crate::ir::{Access, Entry, Literal, Object, ObjectKind, pdo::is_mapping_object};

/// Objects that generate items (not DEFTYPE/DEFSTRUCT, not empty).
fn generates(object: &Object) -> bool {
    !matches!(object.kind, ObjectKind::DefType | ObjectKind::DefStruct)
        && !object.entries.is_empty()
}

fn is_var(object: &Object) -> bool {
    matches!(object.kind, ObjectKind::Var | ObjectKind::Domain)
}

fn is_communication_object(index: u16) -> bool {
    (0x1400..=0x15FF).contains(&index) || (0x1800..=0x19FF).contains(&index)
}

fn kind_name(kind: ObjectKind) -> &'static str {
    match kind {
        ObjectKind::DefType => "DEFTYPE",
        ObjectKind::DefStruct => "DEFSTRUCT",
        ObjectKind::Var => "VAR",
        ObjectKind::Array => "ARRAY",
        ObjectKind::Record => "RECORD",
        ObjectKind::Domain => "DOMAIN",
    }
}

/// The path of an object's own item: a VAR's type, an ARRAY/RECORD's module.
fn object_path(
    names: &crate::r#gen::rust::od_plan::DeviceNames,
    object: &Object,
) -> Option<String> {
    if is_var(object) {
        let sub = *object.entries.keys().next()?;
        names.entries.get(&(object.index, sub)).map(|p| p.0.clone())
    } else {
        names.modules.get(&object.index).cloned()
    }
}

/// Every object of either device, in index order.
pub(super) fn objects(cx: &mut Cx) {
    let mut indices: Vec<u16> = cx
        .old
        .objects
        .keys()
        .chain(cx.new.objects.keys())
        .copied()
        .collect();
    indices.sort_unstable();
    indices.dedup();
    for index in indices {
        match (cx.old.objects.get(&index), cx.new.objects.get(&index)) {
            (Some(old), None) => {
                let path = object_path(&cx.old_names, old);
                let severity = if generates(old) {
                    Severity::Breaking
                } else {
                    Severity::Compatible
                };
                cx.push(
                    index,
                    None,
                    Kind::ObjectRemoved,
                    severity,
                    path,
                    Some(Val::Text(old.name.clone())),
                    None,
                    format!(
                        "{} {} removed",
                        kind_name(old.kind),
                        crate::text::code_span(&old.name)
                    ),
                );
            }
            (None, Some(new)) => {
                let path = object_path(&cx.new_names, new);
                let severity = if generates(new) {
                    Severity::Additive
                } else {
                    Severity::Compatible
                };
                cx.push(
                    index,
                    None,
                    Kind::ObjectAdded,
                    severity,
                    path,
                    None,
                    Some(Val::Text(new.name.clone())),
                    format!(
                        "{} {} added",
                        kind_name(new.kind),
                        crate::text::code_span(&new.name)
                    ),
                );
            }
            (Some(old), Some(new)) => object(cx, old, new),
            (None, None) => {}
        }
    }
}

fn object(cx: &mut Cx, old: &Object, new: &Object) {
    let index = old.index;
    let old_path = object_path(&cx.old_names, old);
    let new_path = object_path(&cx.new_names, new);
    let moved = old_path != new_path;
    if old.kind != new.kind {
        let severity = if moved || is_var(old) != is_var(new) {
            Severity::Breaking
        } else {
            Severity::Compatible
        };
        cx.push(
            index,
            None,
            Kind::ObjectKindChanged,
            severity,
            new_path.clone(),
            Some(Val::Text(kind_name(old.kind).into())),
            Some(Val::Text(kind_name(new.kind).into())),
            if moved {
                format!(
                    "object kind {} → {} (`{}` → `{}`)",
                    kind_name(old.kind),
                    kind_name(new.kind),
                    shown_path(&old_path),
                    shown_path(&new_path)
                )
            } else {
                format!(
                    "object kind {} → {}",
                    kind_name(old.kind),
                    kind_name(new.kind)
                )
            },
        );
    }
    let object_renamed = old.name != new.name;
    // A VAR that becomes an ARRAY/RECORD (or back) has nothing in common
    // with its former self but the index: only subs added and removed.
    let reshaped = is_var(old) != is_var(new);
    if object_renamed {
        push_rename(
            cx,
            index,
            None,
            (&old.name, &new.name),
            (&old_path, &new_path),
        );
    }
    let mut subs: Vec<u8> = old
        .entries
        .keys()
        .chain(new.entries.keys())
        .copied()
        .collect();
    subs.sort_unstable();
    subs.dedup();
    for sub in subs {
        match (old.entries.get(&sub), new.entries.get(&sub)) {
            (Some(o), None) => {
                let path = cx.old_names.entries.get(&(index, sub)).map(|p| p.0.clone());
                cx.push(
                    index,
                    Some(sub),
                    Kind::SubRemoved,
                    Severity::Breaking,
                    path,
                    Some(Val::Text(o.name.clone())),
                    None,
                    format!("sub {sub} {} removed", crate::text::code_span(&o.name)),
                );
            }
            (None, Some(n)) => {
                let path = cx.new_names.entries.get(&(index, sub)).map(|p| p.0.clone());
                cx.push(
                    index,
                    Some(sub),
                    Kind::SubAdded,
                    Severity::Additive,
                    path,
                    None,
                    Some(Val::Text(n.name.clone())),
                    format!("sub {sub} {} added", crate::text::code_span(&n.name)),
                );
            }
            (Some(o), Some(n)) if !reshaped => entry(cx, old, o, n, object_renamed),
            (Some(_), Some(_)) => {}
            (None, None) => {}
        }
    }
}

/// A source name changed: breaking when its Rust path moved with it,
/// compatible when the path stayed.
fn push_rename(
    cx: &mut Cx,
    index: u16,
    sub: Option<u8>,
    (old_name, new_name): (&str, &str),
    (old_path, new_path): (&Option<String>, &Option<String>),
) {
    let moved = old_path != new_path;
    let (severity, how) = if moved {
        (
            Severity::Breaking,
            format!(" (`{}` → `{}`)", shown_path(old_path), shown_path(new_path)),
        )
    } else {
        (Severity::Compatible, String::new())
    };
    cx.push(
        index,
        sub,
        Kind::NameChanged,
        severity,
        new_path.clone(),
        Some(Val::Text(old_name.to_string())),
        Some(Val::Text(new_name.to_string())),
        format!(
            "name {} → {}{how}",
            crate::text::code_span(old_name),
            crate::text::code_span(new_name)
        ),
    );
}

fn shown_path(path: &Option<String>) -> &str {
    path.as_deref().unwrap_or("not generated")
}

fn entry(cx: &mut Cx, old_object: &Object, old: &Entry, new: &Entry, object_renamed: bool) {
    let index = old_object.index;
    let sub = old.subindex;
    let key = (index, sub);
    let (old_path, old_value) = cx.old_names.entries.get(&key).cloned().unzip();
    let (new_path, new_value) = cx.new_names.entries.get(&key).cloned().unzip();
    let path = new_path.clone();
    let moved = old_path != new_path;
    // A VAR's Rust name comes from its object's name (compared with the
    // object); its entry's own name is compared here too.
    let renamed = old.name != new.name && !(is_var(old_object) && object_renamed);
    if renamed {
        push_rename(
            cx,
            index,
            Some(sub),
            (&old.name, &new.name),
            (&old_path, &new_path),
        );
    } else if moved && !object_renamed {
        cx.push(
            index,
            Some(sub),
            Kind::RustPathChanged,
            Severity::Breaking,
            path.clone(),
            old_path.clone().map(Val::Text),
            new_path.clone().map(Val::Text),
            format!(
                "Rust path `{}` → `{}` (names around it changed)",
                shown_path(&old_path),
                shown_path(&new_path)
            ),
        );
    }
    if old.data_type != new.data_type {
        let value = if old_value != new_value {
            format!(
                " (value type {} → {})",
                old_value.as_deref().unwrap_or("none"),
                new_value.as_deref().unwrap_or("none")
            )
        } else {
            String::new()
        };
        cx.push(
            index,
            Some(sub),
            Kind::DataTypeChanged,
            Severity::Breaking,
            path.clone(),
            Some(Val::Text(old.data_type.name().to_string())),
            Some(Val::Text(new.data_type.name().to_string())),
            format!(
                "data type {} → {}{value}",
                old.data_type.name(),
                new.data_type.name()
            ),
        );
    } else if old_value != new_value {
        cx.push(
            index,
            Some(sub),
            Kind::ValueTypeChanged,
            Severity::Breaking,
            path.clone(),
            old_value.clone().map(Val::Text),
            new_value.clone().map(Val::Text),
            format!(
                "value type {} → {}",
                old_value.as_deref().unwrap_or("none"),
                new_value.as_deref().unwrap_or("none")
            ),
        );
    }
    if old.access != new.access {
        let (severity, why) = access_change(old.access, new.access);
        cx.push(
            index,
            Some(sub),
            Kind::AccessChanged,
            severity,
            path.clone(),
            Some(Val::Text(old.access.as_str().into())),
            Some(Val::Text(new.access.as_str().into())),
            format!(
                "access {} → {}{why}",
                old.access.as_str(),
                new.access.as_str()
            ),
        );
    }
    if old.pdo_mappable != new.pdo_mappable {
        let (severity, what) = if new.pdo_mappable {
            (Severity::Additive, "becomes PDO-mappable")
        } else {
            (Severity::Breaking, "is no longer PDO-mappable")
        };
        cx.push(
            index,
            Some(sub),
            Kind::PdoMappableChanged,
            severity,
            path.clone(),
            Some(Val::Bool(old.pdo_mappable)),
            Some(Val::Bool(new.pdo_mappable)),
            what.to_string(),
        );
    }
    // A default PDO's mapping and COB-ID are reported per PDO.
    let pdo_level = is_mapping_object(index) || (is_communication_object(index) && sub == 1);
    if !pdo_level {
        default(cx, index, sub, &path, &old.default, &new.default);
    }
    let literal_kinds = [
        (
            Kind::LowLimitChanged,
            "low limit",
            &old.low_limit,
            &new.low_limit,
        ),
        (
            Kind::HighLimitChanged,
            "high limit",
            &old.high_limit,
            &new.high_limit,
        ),
        (
            Kind::ParameterValueChanged,
            "DCF parameter value",
            &old.parameter_value,
            &new.parameter_value,
        ),
    ];
    for (kind, what, o, n) in literal_kinds {
        if kind == Kind::ParameterValueChanged && pdo_level {
            continue;
        }
        if !same_option(o, n) {
            let (ov, nv) = (o.as_ref().map(literal_val), n.as_ref().map(literal_val));
            cx.push(
                index,
                Some(sub),
                kind,
                Severity::Compatible,
                path.clone(),
                ov.clone(),
                nv.clone(),
                format!("{what} {} → {}", shown(&ov), shown(&nv)),
            );
        }
    }
    super::semantics::entry(cx, index, sub, &path, old, new);
}

fn same_option(a: &Option<Literal>, b: &Option<Literal>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => same_literal(a, b),
        (None, None) => true,
        _ => false,
    }
}

/// A default: changed values are compatible; a default that appears adds
/// `DEFAULT`, one that disappears or switches between a plain value and a
/// `$NODEID` formula removes `DEFAULT` or `default_for`.
fn default(
    cx: &mut Cx,
    index: u16,
    sub: u8,
    path: &Option<String>,
    old: &Option<Literal>,
    new: &Option<Literal>,
) {
    if same_option(old, new) {
        return;
    }
    let severity = match (old, new) {
        (None, Some(_)) => Severity::Additive,
        (Some(_), None) => Severity::Breaking,
        (Some(o), Some(n)) if o.plus_node_id != n.plus_node_id => Severity::Breaking,
        _ => Severity::Compatible,
    };
    let (ov, nv) = (old.as_ref().map(literal_val), new.as_ref().map(literal_val));
    let show = |v: &Option<Val>| match v {
        Some(Val::Int(i)) if !(-9..=9).contains(i) => format!("{i} ({})", hex(*i)),
        other => shown(other),
    };
    cx.push(
        index,
        Some(sub),
        Kind::DefaultChanged,
        severity,
        path.clone(),
        ov.clone(),
        nv.clone(),
        format!("default {} → {}", show(&ov), show(&nv)),
    );
}

/// Losing read or write breaks; gaining one without losing is additive;
/// the rest (rw → rwr, ro → const) is compatible.
fn access_change(old: Access, new: Access) -> (Severity, &'static str) {
    let lost_read = old.is_readable() && !new.is_readable();
    let lost_write = old.is_writable() && !new.is_writable();
    let gained =
        (!old.is_readable() && new.is_readable()) || (!old.is_writable() && new.is_writable());
    match (lost_read, lost_write, gained) {
        (true, true, _) => (Severity::Breaking, ": loses read and write"),
        (true, false, _) => (Severity::Breaking, ": loses read"),
        (false, true, _) => (Severity::Breaking, ": loses write"),
        (false, false, true) => (Severity::Additive, ": widened"),
        (false, false, false) => (Severity::Compatible, ""),
    }
}
