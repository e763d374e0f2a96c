//! Lowering of one object section (VAR, DOMAIN, ARRAY, RECORD, DEFTYPE,
//! DEFSTRUCT) with its sub-object sections and CompactSubObj expansion.

use std::collections::BTreeMap;

use super::ini::Section;
use super::lower::Lowering;
use super::number;
use crate::diag::Severity;
use crate::ir::{Entry, Object, ObjectKind, Origin};

impl Lowering<'_> {
    pub(super) fn object(
        &mut self,
        index: u16,
        section: &Section,
        subs: BTreeMap<u8, &Section>,
        names: Option<&Section>,
        values: Option<&Section>,
    ) -> Option<Object> {
        let name = self.name(section, || format!("Object 0x{index:04X}"));
        let kind = match section.get("ObjectType") {
            None => ObjectKind::Var,
            Some(p) => match number::parse_int(p.value) {
                Ok(0x2) => ObjectKind::Domain,
                Ok(0x5) => ObjectKind::DefType,
                Ok(0x6) => ObjectKind::DefStruct,
                Ok(0x7) => ObjectKind::Var,
                Ok(0x8) => ObjectKind::Array,
                Ok(0x9) => ObjectKind::Record,
                Ok(other) => {
                    self.report(Severity::Error, "eds::bad-object-type", section, Some(p), format!("object type {other:#x} is not one of 0x2 DOMAIN, 0x5 DEFTYPE, 0x6 DEFSTRUCT, 0x7 VAR, 0x8 ARRAY, 0x9 RECORD; the object is left out"));
                    return None;
                }
                Err(e) => {
                    self.report(
                        Severity::Error,
                        "eds::bad-object-type",
                        section,
                        Some(p),
                        format!("{}; the object is left out", e.0),
                    );
                    return None;
                }
            },
        };
        let obj_flags = self.uint(Some(section), "ObjFlags");
        let denotation = Self::text(Some(section), "Denotation");
        let compact: Option<u8> = self
            .uint(Some(section), "CompactSubObj")
            .filter(|&n: &u8| n > 0);
        let mut entries = BTreeMap::new();
        let is_var = matches!(
            kind,
            ObjectKind::Var | ObjectKind::Domain | ObjectKind::DefType
        );
        if is_var {
            if let Some(p) = section.get("CompactSubObj") {
                self.warn(
                    "eds::compact-sub-obj",
                    section,
                    Some(p),
                    "CompactSubObj on an object that has no sub-objects is ignored".into(),
                );
            }
            for sub in subs.values() {
                self.warn("eds::orphan-sub", sub, None, format!("object 0x{index:04X} is a {kind:?}, which has no sub-objects; the section is ignored"));
            }
            if let Some(entry) = self.entry(index, 0, section, kind) {
                entries.insert(0, Box::new(entry));
            }
        } else {
            if let Some(n) = compact {
                if let Some(p) = section
                    .get("SubNumber")
                    .filter(|p| number::parse_int(p.value).is_ok_and(|v| v != 0))
                {
                    self.warn(
                        "eds::compact-sub-obj",
                        section,
                        Some(p),
                        format!("SubNumber together with CompactSubObj={n}: CompactSubObj wins"),
                    );
                }
                entries = self.expand_compact(index, &name, section, n, names, values);
            } else {
                for extra in names.into_iter().chain(values) {
                    self.warn(
                        "eds::compact-sub-obj",
                        extra,
                        None,
                        format!(
                            "object 0x{index:04X} has no CompactSubObj; [{}] is ignored",
                            extra.name
                        ),
                    );
                }
            }
            let declared: Option<u16> = self.uint(Some(section), "SubNumber");
            if compact.is_none() {
                if let Some(declared) = declared
                    && usize::from(declared) != subs.len()
                {
                    let p = section.get("SubNumber");
                    self.warn(
                        "eds::sub-number",
                        section,
                        p,
                        format!(
                            "SubNumber says {declared} but {} sub-object sections were found",
                            subs.len()
                        ),
                    );
                }
                if subs.is_empty() {
                    self.warn(
                        "eds::sub-number",
                        section,
                        None,
                        format!("{kind:?} object 0x{index:04X} has no sub-objects"),
                    );
                }
            } else if !subs.is_empty() {
                self.warn("eds::compact-sub-obj", section, None, "both CompactSubObj and sub-object sections are given; the sub-object sections override the expanded entries".into());
            }
            for (sub, sub_section) in subs {
                if let Some(entry) = self.entry(index, sub, sub_section, ObjectKind::Var) {
                    entries.insert(sub, Box::new(entry));
                }
            }
        }
        Some(Object {
            index,
            name,
            kind,
            entries,
            obj_flags,
            denotation,
            compact_sub_obj: compact,
            rust_name: None,
            origin: self.origin(section.line),
        })
    }

    /// The section's ParameterName; when it has none (or an empty one), a
    /// warning and the name `fallback` gives.
    pub(super) fn name(&mut self, section: &Section, fallback: impl FnOnce() -> String) -> String {
        match Self::text(Some(section), "ParameterName") {
            Some(name) => name,
            None => {
                let fallback = fallback();
                self.warn(
                    "eds::missing-name",
                    section,
                    None,
                    format!("no ParameterName; named `{fallback}`"),
                );
                fallback
            }
        }
    }

    /// Expands `CompactSubObj=n` into sub 0 (number of entries) and subs 1..=n.
    pub(super) fn expand_compact(
        &mut self,
        index: u16,
        name: &str,
        section: &Section,
        n: u8,
        names: Option<&Section>,
        values: Option<&Section>,
    ) -> BTreeMap<u8, Box<Entry>> {
        let mut entries = BTreeMap::new();
        let origin = self.origin(section.line);
        entries.insert(0, Box::new(Entry::highest_subindex(n, origin)));
        let Some(template) = self.entry(index, 1, section, ObjectKind::Var) else {
            return entries;
        };
        let name_of = |sub: u8| {
            names
                .and_then(|s| s.get(&sub.to_string()))
                .filter(|p| !p.value.is_empty())
        };
        for sub in 1..=n {
            let mut entry = Box::new(template.clone());
            entry.subindex = sub;
            match name_of(sub) {
                Some(p) => {
                    entry.name = p.value.to_string();
                    entry.origin = self.origin(p.line);
                }
                None => entry.name = format!("{name}{sub}"),
            }
            entries.insert(sub, entry);
        }
        self.compact_table_checks(index, n, names);
        if let Some(values) = values {
            self.compact_table_checks(index, n, Some(values));
            for prop in &values.properties {
                let Ok(sub) = prop.key.parse::<u8>() else {
                    continue;
                };
                let Some(entry) = entries.get_mut(&sub).filter(|_| sub >= 1) else {
                    continue;
                };
                if let Some(lit) = self.literal(values, prop, entry.data_type) {
                    entry.parameter_value = Some(lit);
                    entry.origin = Origin {
                        file: self.doc.file.clone(),
                        line: prop.line,
                    };
                }
            }
        }
        entries
    }

    /// Checks `[xxxxName]`/`[xxxxValue]`: NrOfEntries and keys within 1..=n.
    pub(super) fn compact_table_checks(&mut self, index: u16, n: u8, table: Option<&Section>) {
        let Some(table) = table else { return };
        let mut count = 0;
        for prop in &table.properties {
            if prop.key.eq_ignore_ascii_case("NrOfEntries") {
                continue;
            }
            count += 1;
            match prop.key.parse::<u8>() {
                Ok(sub) if (1..=n).contains(&sub) => {}
                _ => self.warn(
                    "eds::compact-sub-obj",
                    table,
                    Some(prop),
                    format!(
                        "`{}` is not a sub-index 1..={n} of object 0x{index:04X}; ignored",
                        prop.key
                    ),
                ),
            }
        }
        let declared: Option<usize> = self.uint(Some(table), "NrOfEntries");
        if declared.is_some_and(|d| d != count) {
            let p = table.get("NrOfEntries");
            self.warn(
                "eds::compact-sub-obj",
                table,
                p,
                format!(
                    "NrOfEntries says {} but {count} entries follow",
                    declared.unwrap_or(0)
                ),
            );
        }
    }
}
