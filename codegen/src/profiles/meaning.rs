//! The built-in meaning of standard objects: bit fields, state patterns,
//! named values and units that CiA 301 and the device profiles fix, applied
//! to every device that has the objects (a plain vendor EDS included), so
//! that no overlay has to transcribe the standard.
//!
//! The facts sit next to the canonical names, one table per profile
//! (`MEANINGS` in `cia301.rs`, `cia402.rs`). [`apply`] fills in, per entry
//! and per kind, only what the device does not say itself: a YAML table's
//! own `patterns:`, `values:` or `unit:` always wins, and its bit fields
//! win over the standard's on the same bits (the standard's other bits
//! stay). A table's `profiles: none` switches it off
//! ([`ProfileChoice::None`]); [`apply`] then removes what an earlier read
//! filled in.

use super::std_meaning::{RuntimeType, StdBit, StdMeaning};
use super::{Canonical, Profile};
use crate::ir::{
    BitField, DataType, Device, Entry, NamedValue, Origin, Pattern, ProfileChoice, ValueKind,
    ValueTable,
};

/// Where the meanings of `profile` come from, as rustdoc and diagnostics
/// show it.
fn origin(profile: Option<Profile>) -> Origin {
    let file = match profile {
        None => "CiA 301",
        Some(Profile::Cia401) => "CiA 401",
        Some(Profile::Cia402) => "CiA 402",
        Some(Profile::Cia406) => "CiA 406",
    };
    Origin {
        file: file.to_string(),
        line: 0,
    }
}

/// Whether an item came from a built-in table.
fn built_in(origin: &Origin) -> bool {
    origin.line == 0 && origin.file.starts_with("CiA ")
}

impl Canonical {
    /// The built-in meaning of entry `index`/`sub` (its profile's first,
    /// then CiA 301's).
    pub(crate) fn meaning(self, index: u16, sub: u8) -> Option<(&'static StdMeaning, Origin)> {
        let profile = match self.profile {
            Some(Profile::Cia402) => super::cia402::MEANINGS,
            _ => &[],
        };
        if let Some(m) = profile.iter().find(|m| m.covers(index, sub)) {
            return Some((m, origin(self.profile)));
        }
        super::cia301::MEANINGS
            .iter()
            .find(|m| m.covers(index, sub))
            .map(|m| (m, origin(None)))
    }

    /// The runtime type entry `index`/`sub` of this device converts to and
    /// from, when the standard fixes one (whatever bits or values the
    /// device gives it: the raw value means the same).
    pub(crate) fn runtime_type(self, index: u16, sub: u8) -> Option<RuntimeType> {
        self.meaning(index, sub)?.0.runtime.filter(|t| !t.value)
    }

    /// The runtime type that is entry `index`/`sub`'s value type: when the
    /// standard gives one and the entry has exactly the standard's meaning
    /// (nothing of its own, and not PDO-mappable: a PDO struct's fields
    /// are generated types or primitives).
    pub(crate) fn runtime_value(self, index: u16, entry: &Entry) -> Option<RuntimeType> {
        let (m, origin) = self.meaning(index, entry.subindex)?;
        let ty = m.runtime.filter(|t| t.value)?;
        let mut standard = entry.clone();
        *standard.semantics = Default::default();
        if fits(m, entry.data_type) {
            fill(&mut standard, m, &origin);
        }
        let s = &entry.semantics;
        let same = standard.semantics == *s;
        (same && !entry.pdo_mappable && !s.is_empty()).then_some(ty)
    }
}

/// Fills in the built-in meanings of `device`'s standard entries (see the
/// module documentation), or with `profiles: none` removes those filled in
/// before.
pub(crate) fn apply(device: &mut Device) {
    let canonical = Canonical::of(device);
    let off = device.profiles == ProfileChoice::None;
    for object in device.objects.values_mut() {
        let index = object.index;
        for entry in object.entries.values_mut() {
            let Some((m, origin)) = canonical.meaning(index, entry.subindex) else {
                continue;
            };
            if off {
                remove(entry, m);
            } else if fits(m, entry.data_type) {
                fill(entry, m, &origin);
            }
        }
    }
}

/// Whether the meaning fits the entry's type: an integer wide enough for
/// every bit field and pattern, whose range holds every named value.
fn fits(m: &StdMeaning, data_type: DataType) -> bool {
    let Some(ValueKind::Integer { signed, bits }) = data_type.value_kind() else {
        return false;
    };
    if data_type == DataType::Boolean {
        return false;
    }
    let width_ok = m.bits.iter().all(|b| b.lsb + b.width <= bits)
        && m.patterns
            .iter()
            .all(|p| bits >= 64 || (p.mask | p.value) >> bits == 0);
    let (low, high) = if signed {
        (-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1)
    } else {
        (0, (1i128 << bits) - 1)
    };
    let values_ok = m.values.is_none_or(|v| {
        v.named.iter().all(|&(l, h, _)| low <= l && h <= high)
            && v.numeric.is_none_or(|(l, h)| low <= l && h <= high)
    });
    width_ok && values_ok
}

fn fill(entry: &mut Entry, m: &StdMeaning, origin: &Origin) {
    let s = &mut entry.semantics;
    // The standard's bit fields where the device defines none of its own
    // over the same bits: a table's bit 14 adds to the standard's, its
    // bit 13 replaces the standard's bit 13.
    let own = |b: &StdBit| {
        s.bits
            .iter()
            .any(|f| f.lsb < b.lsb + b.width && b.lsb < f.lsb + f.width)
    };
    let added: Vec<BitField> = m
        .bits
        .iter()
        .filter(|b| !own(b))
        .map(|b| BitField {
            name: b.name.to_string(),
            lsb: b.lsb,
            width: b.width,
            text: b.text.map(str::to_string),
            unit: b.unit.map(str::to_string),
            scale: None,
            values: None,
            rust_name: None,
            origin: origin.clone(),
        })
        .collect();
    if !added.is_empty() {
        s.bits.extend(added);
        s.bits.sort_by_key(|f| f.lsb);
    }
    if s.patterns.is_empty() {
        s.patterns = m
            .patterns
            .iter()
            .map(|p| Pattern {
                name: p.name.to_string(),
                mask: p.mask,
                value: p.value,
                text: None,
                origin: origin.clone(),
            })
            .collect();
    }
    if s.values.is_none()
        && s.bits.is_empty()
        && let Some(v) = m.values
    {
        s.values = Some(ValueTable {
            numeric: v.numeric,
            named: v
                .named
                .iter()
                .map(|&(low, high, name)| NamedValue {
                    low,
                    high,
                    name: name.to_string(),
                    text: None,
                    rust_name: None,
                    origin: origin.clone(),
                })
                .collect(),
            other: v.other.to_string(),
        });
    }
    // A unit only where the entry says nothing of its own physical value
    // (a scale without a unit would take this unit's meaning).
    if s.unit.is_none()
        && s.scale.is_none()
        && s.offset.is_none()
        && s.values.as_ref().is_none_or(|v| v.numeric.is_some())
        && let Some(unit) = m.unit
    {
        s.unit = Some(unit.to_string());
        s.scale = m.scale;
    }
}

/// Removes what [`fill`] put in (items of a built-in origin; the unit when
/// it is the built-in one).
fn remove(entry: &mut Entry, m: &StdMeaning) {
    let s = &mut entry.semantics;
    s.bits.retain(|b| !built_in(&b.origin));
    s.patterns.retain(|p| !built_in(&p.origin));
    if s.values
        .as_ref()
        .is_some_and(|v| !v.named.is_empty() && v.named.iter().all(|n| built_in(&n.origin)))
    {
        s.values = None;
    }
    if m.unit.is_some() && s.unit.as_deref() == m.unit && s.scale == m.scale {
        s.unit = None;
        s.scale = None;
    }
}
