//! Lowers an INI [`Document`] of CiA 306 into an [`ir::Device`].
//!
//! Policy: problems that leave the object's structure intact (a value that is
//! not a number, a limit out of range, an object missing from the object
//! lists) are warnings and the value is dropped or normalised; problems that
//! leave an object without meaning (unknown ObjectType, missing DataType,
//! unknown AccessType) are errors.

use std::collections::BTreeMap;

use super::ini::{Document, Property, Section};
use super::number;
use super::sections::{SectionKind, classify};
use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::{
    Access, Capabilities, Commissioning, DataType, Device, Entry, FileInfo, Identity, Literal,
    Object, ObjectKind, Origin, Value,
};

pub(super) struct Lowering<'a> {
    pub doc: &'a Document,
    pub diags: &'a mut Diagnostics,
}

impl<'a> Lowering<'a> {
    pub fn report(
        &mut self,
        severity: Severity,
        code: &'static str,
        section: &Section,
        prop: Option<&Property>,
        message: String,
    ) {
        let location = match prop {
            Some(p) => Location {
                line: Some(p.line),
                span: Some(p.value_span.clone()),
                section: Some(section.name.clone()),
                key: Some(p.key.clone()),
            },
            None => Location {
                line: Some(section.line),
                span: Some(section.header_span.clone()),
                section: Some(section.name.clone()),
                key: None,
            },
        };
        self.diags.push(Diagnostic {
            severity,
            code,
            file: self.doc.file.clone(),
            location,
            message,
            notes: Vec::new(),
        });
    }

    fn warn(
        &mut self,
        code: &'static str,
        section: &Section,
        prop: Option<&Property>,
        message: String,
    ) {
        self.report(Severity::Warning, code, section, prop, message);
    }

    fn error(
        &mut self,
        code: &'static str,
        section: &Section,
        prop: Option<&Property>,
        message: String,
    ) {
        self.report(Severity::Error, code, section, prop, message);
    }

    fn origin(&self, line: u32) -> Origin {
        Origin {
            file: self.doc.file.clone(),
            line,
        }
    }

    /// A non-empty text value.
    fn text(section: Option<&Section>, key: &str) -> Option<String> {
        section?
            .get(key)
            .map(|p| p.value.clone())
            .filter(|v| !v.is_empty())
    }

    /// An integer value; a bad number is a warning and gives `None`.
    fn int(&mut self, section: Option<&Section>, key: &str) -> Option<i128> {
        let section = section?;
        let prop = section.get(key)?;
        if prop.value.is_empty() {
            return None;
        }
        match number::parse_int(&prop.value) {
            Ok(v) => Some(v),
            Err(e) => {
                self.warn(
                    "eds::bad-number",
                    section,
                    Some(prop),
                    format!("{}; the key is ignored", e.0),
                );
                None
            }
        }
    }

    fn uint<T: TryFrom<i128>>(&mut self, section: Option<&Section>, key: &str) -> Option<T> {
        let v = self.int(section, key)?;
        match T::try_from(v) {
            Ok(v) => Some(v),
            Err(_) => {
                let (s, p) = (section?, section?.get(key)?);
                self.warn(
                    "eds::bad-number",
                    s,
                    Some(p),
                    format!("{v} is out of range for this key; the key is ignored"),
                );
                None
            }
        }
    }

    fn flag(&mut self, section: Option<&Section>, key: &str) -> Option<bool> {
        self.int(section, key).map(|v| v != 0)
    }

    pub fn lower(mut self) -> Device {
        let doc = self.doc;
        let file_info_section = doc.section("FileInfo");
        let fi = file_info_section;
        let file_info = FileInfo {
            file_name: Self::text(fi, "FileName"),
            file_version: Self::text(fi, "FileVersion"),
            file_revision: Self::text(fi, "FileRevision"),
            format_version: Self::text(fi, "EDSVersion"),
            description: Self::text(fi, "Description"),
            created_by: Self::text(fi, "CreatedBy"),
            creation_date: Self::text(fi, "CreationDate"),
            creation_time: Self::text(fi, "CreationTime"),
            modified_by: Self::text(fi, "ModifiedBy"),
            modification_date: Self::text(fi, "ModificationDate"),
            modification_time: Self::text(fi, "ModificationTime"),
        };
        let di = doc.section("DeviceInfo");
        let identity = Identity {
            vendor_name: Self::text(di, "VendorName"),
            vendor_number: self.uint(di, "VendorNumber"),
            product_name: Self::text(di, "ProductName"),
            product_number: self.uint(di, "ProductNumber"),
            revision_number: self.uint(di, "RevisionNumber"),
            order_code: Self::text(di, "OrderCode"),
        };
        let mut baud_rates = Vec::new();
        for rate in [10u32, 20, 50, 125, 250, 500, 800, 1000] {
            if self.flag(di, &format!("BaudRate_{rate}")) == Some(true) {
                baud_rates.push(rate);
            }
        }
        let capabilities = Capabilities {
            baud_rates,
            simple_boot_up_master: self.flag(di, "SimpleBootUpMaster"),
            simple_boot_up_slave: self.flag(di, "SimpleBootUpSlave"),
            granularity: self.uint(di, "Granularity"),
            dynamic_channels_supported: self.uint(di, "DynamicChannelsSupported"),
            group_messaging: self.flag(di, "GroupMessaging"),
            nr_of_rx_pdo: self.uint(di, "NrOfRXPDO"),
            nr_of_tx_pdo: self.uint(di, "NrOfTXPDO"),
            lss_supported: self.flag(di, "LSS_Supported"),
        };
        let commissioning = doc
            .section("DeviceComissioning")
            .or_else(|| doc.section("DeviceCommissioning"))
            .map(|s| {
                let s = Some(s);
                Commissioning {
                    node_id: self.uint(s, "NodeID"),
                    node_name: Self::text(s, "NodeName"),
                    baud_rate: self.uint(s, "Baudrate"),
                    net_number: self.uint(s, "NetNumber"),
                    network_name: Self::text(s, "NetworkName"),
                    canopen_manager: self.flag(s, "CANopenManager"),
                    lss_serial_number: self.uint(s, "LSS_SerialNumber"),
                }
            });
        let mut dummy_usage = Vec::new();
        let du = doc.section("DummyUsage");
        for code in 1u16..=0x1B {
            if self.flag(du, &format!("Dummy{code:04X}")) == Some(true) {
                dummy_usage.push(DataType::from_code(code));
            }
        }
        let comments = match doc.section("Comments") {
            Some(s) => s
                .properties
                .iter()
                .filter(|p| p.key.to_ascii_lowercase().starts_with("line"))
                .map(|p| p.value.clone())
                .collect(),
            None => Vec::new(),
        };
        let objects = self.objects();
        let mut device = Device {
            source: doc.file.clone(),
            file_info,
            identity,
            capabilities,
            commissioning,
            dummy_usage,
            objects,
            comments,
        };
        fill_identity_from_1018(&mut device);
        device
    }

    /// Reads the object lists: index → (list section, property).
    fn object_lists(&mut self) -> BTreeMap<u16, (&'a Section, &'a Property)> {
        let doc = self.doc;
        let mut listed = BTreeMap::new();
        for list in ["MandatoryObjects", "OptionalObjects", "ManufacturerObjects"] {
            let Some(section) = doc.section(list) else {
                continue;
            };
            let declared: Option<usize> = self.uint(Some(section), "SupportedObjects");
            let mut count = 0usize;
            for prop in &section.properties {
                if prop.key.eq_ignore_ascii_case("SupportedObjects") {
                    continue;
                }
                if number::parse_int(&prop.key).is_err() {
                    self.warn(
                        "eds::object-list",
                        section,
                        Some(prop),
                        "a key of an object list must be a number; the line is ignored".into(),
                    );
                    continue;
                }
                count += 1;
                match number::parse_int(&prop.value)
                    .ok()
                    .and_then(|v| u16::try_from(v).ok())
                {
                    Some(index) => {
                        if let Some((other, _)) = listed.insert(index, (section, prop)) {
                            if other.name != section.name {
                                self.warn(
                                    "eds::object-list",
                                    section,
                                    Some(prop),
                                    format!(
                                        "object 0x{index:04X} is also listed in [{}]",
                                        other.name
                                    ),
                                );
                            }
                        }
                    }
                    None => self.warn(
                        "eds::object-list",
                        section,
                        Some(prop),
                        format!(
                            "`{}` is not an object index; the line is ignored",
                            prop.value
                        ),
                    ),
                }
            }
            if let Some(declared) = declared {
                if declared != count {
                    let p = section.get("SupportedObjects");
                    self.warn(
                        "eds::object-list",
                        section,
                        p,
                        format!("SupportedObjects says {declared} but the section lists {count}"),
                    );
                }
            }
        }
        listed
    }

    fn objects(&mut self) -> BTreeMap<u16, Object> {
        let doc = self.doc;
        let listed = self.object_lists();
        let mut object_sections: BTreeMap<u16, &Section> = BTreeMap::new();
        let mut subs: BTreeMap<u16, BTreeMap<u8, &Section>> = BTreeMap::new();
        let mut names: BTreeMap<u16, &Section> = BTreeMap::new();
        let mut values: BTreeMap<u16, &Section> = BTreeMap::new();
        for section in &doc.sections {
            match classify(&section.name) {
                SectionKind::Object(i) => {
                    object_sections.insert(i, section);
                }
                SectionKind::Sub(i, s) => {
                    subs.entry(i).or_default().insert(s, section);
                }
                SectionKind::CompactNames(i) => {
                    names.insert(i, section);
                }
                SectionKind::CompactValues(i) => {
                    values.insert(i, section);
                }
                SectionKind::Known => {}
                SectionKind::Unknown => self.warn(
                    "eds::unknown-section",
                    section,
                    None,
                    "not a CiA 306 section name (objects are 4 hex digits, sub-objects `XXXXsubY`); the section is ignored".into(),
                ),
            }
        }
        for (&index, &(list, prop)) in &listed {
            if !object_sections.contains_key(&index) {
                self.warn("eds::missing-object-section", list, Some(prop), format!("object 0x{index:04X} is listed but has no section [{index:04X}]; it is left out"));
            }
        }
        let mut objects = BTreeMap::new();
        for (&index, &section) in &object_sections {
            if index == 0 {
                self.warn(
                    "eds::bad-index",
                    section,
                    None,
                    "index 0x0000 is not a valid object index; the section is ignored".into(),
                );
                continue;
            }
            if !listed.contains_key(&index) && index >= 0x1000 {
                self.warn("eds::unlisted-object", section, None, format!("object 0x{index:04X} is not listed in [MandatoryObjects], [OptionalObjects] or [ManufacturerObjects]; it is read anyway"));
            }
            let object = self.object(
                index,
                section,
                subs.remove(&index).unwrap_or_default(),
                names.remove(&index),
                values.remove(&index),
            );
            if let Some(object) = object {
                objects.insert(index, object);
            }
        }
        for (index, orphans) in subs {
            for (_, section) in orphans {
                self.warn(
                    "eds::orphan-sub",
                    section,
                    None,
                    format!(
                        "sub-object section without an object section [{index:04X}]; it is ignored"
                    ),
                );
            }
        }
        for (index, section) in names.into_iter().chain(values) {
            self.warn(
                "eds::orphan-sub",
                section,
                None,
                format!(
                    "[{}] belongs to no CompactSubObj object 0x{index:04X}; it is ignored",
                    section.name
                ),
            );
        }
        objects
    }

    fn object(
        &mut self,
        index: u16,
        section: &Section,
        subs: BTreeMap<u8, &Section>,
        names: Option<&Section>,
        values: Option<&Section>,
    ) -> Option<Object> {
        let name = self.name(section, format!("Object 0x{index:04X}"));
        let kind = match section.get("ObjectType") {
            None => ObjectKind::Var,
            Some(p) => match number::parse_int(&p.value) {
                Ok(0x2) => ObjectKind::Domain,
                Ok(0x5) => ObjectKind::DefType,
                Ok(0x6) => ObjectKind::DefStruct,
                Ok(0x7) => ObjectKind::Var,
                Ok(0x8) => ObjectKind::Array,
                Ok(0x9) => ObjectKind::Record,
                Ok(other) => {
                    self.error("eds::bad-object-type", section, Some(p), format!("object type {other:#x} is not one of 0x2 DOMAIN, 0x5 DEFTYPE, 0x6 DEFSTRUCT, 0x7 VAR, 0x8 ARRAY, 0x9 RECORD; the object is left out"));
                    return None;
                }
                Err(e) => {
                    self.error(
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
            for (_, sub) in &subs {
                self.warn("eds::orphan-sub", sub, None, format!("object 0x{index:04X} is a {kind:?}, which has no sub-objects; the section is ignored"));
            }
            if let Some(entry) = self.entry(index, 0, section, kind) {
                entries.insert(0, entry);
            }
        } else {
            if let Some(n) = compact {
                if let Some(p) = section
                    .get("SubNumber")
                    .filter(|p| number::parse_int(&p.value).is_ok_and(|v| v != 0))
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
                if let Some(declared) = declared {
                    if usize::from(declared) != subs.len() {
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
                    entries.insert(sub, entry);
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
            origin: self.origin(section.line),
        })
    }

    fn name(&mut self, section: &Section, fallback: String) -> String {
        match Self::text(Some(section), "ParameterName") {
            Some(name) => name,
            None => {
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
    fn expand_compact(
        &mut self,
        index: u16,
        name: &str,
        section: &Section,
        n: u8,
        names: Option<&Section>,
        values: Option<&Section>,
    ) -> BTreeMap<u8, Entry> {
        let mut entries = BTreeMap::new();
        let origin = self.origin(section.line);
        entries.insert(
            0,
            Entry {
                subindex: 0,
                name: "Highest sub-index supported".into(),
                data_type: DataType::Unsigned8,
                access: Access::Ro,
                pdo_mappable: false,
                default: Some(Literal {
                    value: Value::Integer(n.into()),
                    plus_node_id: false,
                    text: n.to_string(),
                }),
                low_limit: None,
                high_limit: None,
                parameter_value: None,
                obj_flags: None,
                denotation: None,
                origin,
            },
        );
        let Some(template) = self.entry(index, 1, section, ObjectKind::Var) else {
            return entries;
        };
        let name_of = |sub: u8| {
            names
                .and_then(|s| s.get(&sub.to_string()))
                .filter(|p| !p.value.is_empty())
        };
        for sub in 1..=n {
            let mut entry = template.clone();
            entry.subindex = sub;
            entry.name = match name_of(sub) {
                Some(p) => p.value.clone(),
                None => format!("{name}{sub}"),
            };
            if let Some(p) = name_of(sub) {
                entry.origin = self.origin(p.line);
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
    fn compact_table_checks(&mut self, index: u16, n: u8, table: Option<&Section>) {
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

/// Where [DeviceInfo] lacks identity numbers, takes them from object 0x1018's defaults.
fn fill_identity_from_1018(device: &mut Device) {
    let from_1018 = |device: &Device, sub: u8| -> Option<u32> {
        let entry = device.objects.get(&0x1018)?.entries.get(&sub)?;
        match entry
            .parameter_value
            .as_ref()
            .or(entry.default.as_ref())?
            .value
        {
            Value::Integer(v) => u32::try_from(v).ok(),
            _ => None,
        }
    };
    if device.identity.vendor_number.is_none() {
        device.identity.vendor_number = from_1018(device, 1);
    }
    if device.identity.product_number.is_none() {
        device.identity.product_number = from_1018(device, 2);
    }
    if device.identity.revision_number.is_none() {
        device.identity.revision_number = from_1018(device, 3);
    }
}
