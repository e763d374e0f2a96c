//! Lowers an INI [`Document`] of CiA 306 into an [`ir::Device`].
//!
//! Policy: problems that leave the object's structure intact (a value that is
//! not a number, a limit out of range, an object missing from the object
//! lists, an AccessType CiA 306 does not define) are warnings and the value
//! is dropped or normalised; problems that leave an object without meaning
//! (unknown ObjectType, missing DataType) are errors.

use std::collections::BTreeMap;

use super::ini::{Document, Property, Section};
use super::number;
use super::sections::{SectionKind, classify, decimal_subs, hex_sub};
use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::{
    Capabilities, Commissioning, DataType, Device, FileInfo, Identity, Object, Origin,
};

pub(super) struct Lowering<'a> {
    pub doc: &'a Document<'a>,
    pub diags: &'a mut Diagnostics,
}

impl<'a> Lowering<'a> {
    pub(super) fn report(
        &mut self,
        severity: Severity,
        code: &'static str,
        section: &Section,
        prop: Option<&Property>,
        message: String,
    ) {
        self.report_with_notes(severity, code, section, prop, message, Vec::new());
    }

    /// [`Self::report`] with notes (what was done, what to write instead).
    pub(super) fn report_with_notes(
        &mut self,
        severity: Severity,
        code: &'static str,
        section: &Section,
        prop: Option<&Property>,
        message: String,
        notes: Vec<String>,
    ) {
        let location = match prop {
            Some(p) => Location {
                line: Some(p.line),
                span: Some(p.value_span.clone()),
                section: Some(section.name.to_string()),
                key: Some(p.key.to_string()),
            },
            None => Location {
                line: Some(section.line),
                span: Some(section.header_span.clone()),
                section: Some(section.name.to_string()),
                key: None,
            },
        };
        self.diags.push(Diagnostic {
            severity,
            code,
            file: self.doc.file.clone(),
            location,
            message,
            notes,
        });
    }

    pub(super) fn warn(
        &mut self,
        code: &'static str,
        section: &Section,
        prop: Option<&Property>,
        message: String,
    ) {
        self.report(Severity::Warning, code, section, prop, message);
    }

    pub(super) fn origin(&self, line: u32) -> Origin {
        Origin {
            file: self.doc.file.clone(),
            line,
        }
    }

    /// A non-empty text value.
    pub(super) fn text(section: Option<&Section>, key: &str) -> Option<String> {
        section?
            .get(key)
            .map(|p| p.value.to_string())
            .filter(|v| !v.is_empty())
    }

    /// An integer value; a bad number is a warning and gives `None`.
    pub(super) fn int(&mut self, section: Option<&Section>, key: &str) -> Option<i128> {
        let section = section?;
        let prop = section.get(key)?;
        if prop.value.is_empty() {
            return None;
        }
        match number::parse_int(prop.value) {
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

    pub(super) fn uint<T: TryFrom<i128>>(
        &mut self,
        section: Option<&Section>,
        key: &str,
    ) -> Option<T> {
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

    /// `[DeviceComissioning] NodeID`: the configured node's id, 1..=127.
    fn node_id(&mut self, section: Option<&Section>) -> Option<u8> {
        let id: u8 = self.uint(section, "NodeID")?;
        if crate::ir::NODE_IDS.contains(&id) {
            return Some(id);
        }
        let (s, p) = (section?, section?.get("NodeID")?);
        let mut notes =
            vec!["write the id this DCF configures the node with, 1 to 127".to_string()];
        if id == 255 {
            notes.push(
                "255 is how LSS (CiA 305) marks a node whose id is not configured yet; \
                 a DCF describes one configured node"
                    .into(),
            );
        }
        self.report_with_notes(
            Severity::Warning,
            "eds::bad-number",
            s,
            Some(p),
            format!("{id} is not a node id (1..=127); the key is ignored"),
            notes,
        );
        None
    }

    pub(super) fn flag(&mut self, section: Option<&Section>, key: &str) -> Option<bool> {
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
                    node_id: self.node_id(s),
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
                // `Line1`…`LineN`; `Lines=N` is the count, not a comment.
                .filter(|p| {
                    let key = p.key.to_ascii_lowercase();
                    key.starts_with("line") && key[4..].bytes().all(|b| b.is_ascii_digit())
                })
                .map(|p| p.value.to_string())
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
            ..Device::default()
        };
        device.fill_identity_from_1018();
        device
    }

    /// Reads the object lists: index → (list section, property).
    fn object_lists(&mut self) -> BTreeMap<u16, (&'a Section<'a>, &'a Property<'a>)> {
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
                if number::parse_int(prop.key).is_err() {
                    self.warn(
                        "eds::object-list",
                        section,
                        Some(prop),
                        "a key of an object list must be a number; the line is ignored".into(),
                    );
                    continue;
                }
                count += 1;
                match number::parse_int(prop.value)
                    .ok()
                    .and_then(|v| u16::try_from(v).ok())
                {
                    Some(index) => {
                        if let Some((other, _)) = listed.insert(index, (section, prop))
                            && other.name != section.name
                        {
                            self.warn(
                                "eds::object-list",
                                section,
                                Some(prop),
                                format!("object 0x{index:04X} is also listed in [{}]", other.name),
                            );
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
            if let Some(declared) = declared
                && declared != count
            {
                let p = section.get("SupportedObjects");
                self.warn(
                    "eds::object-list",
                    section,
                    p,
                    format!("SupportedObjects says {declared} but the section lists {count}"),
                );
            }
        }
        listed
    }

    fn unknown_section(&mut self, section: &Section) {
        self.warn(
            "eds::unknown-section",
            section,
            None,
            "not a CiA 306 section name (objects are 4 hex digits, sub-objects `XXXXsubY`); the section is ignored".into(),
        );
    }

    /// The sub-index of each sub-section of object `index` (`written`: sub
    /// numbers as written, in section order): hex (CiA 306), or decimal for
    /// the whole object when [`decimal_subs`] says the names are decimal,
    /// with one warning. A name that is no hex sub-index is an unknown
    /// section.
    fn sub_indices<'s>(
        &mut self,
        index: u16,
        object: Option<&Section>,
        written: &[(&str, &'s Section<'s>)],
    ) -> Vec<(u8, &'s Section<'s>)> {
        let digits: Vec<&str> = written.iter().map(|&(d, _)| d).collect();
        let sub_number = object
            .and_then(|o| o.get("SubNumber"))
            .and_then(|p| number::parse_int(p.value).ok());
        let decimal = object.and_then(|_| decimal_subs(&digits, sub_number));
        let Some(decimal) = decimal else {
            let mut subs = Vec::new();
            for &(digits, section) in written {
                match hex_sub(digits) {
                    Some(sub) => subs.push((sub, section)),
                    None => self.unknown_section(section),
                }
            }
            return subs;
        };
        // The first name that is not a hex sub-index shows the rule.
        let (shown, (digits, section)) = written
            .iter()
            .enumerate()
            .find(|(_, (d, _))| hex_sub(d).is_none())
            .map_or((0, written[0]), |(i, &w)| (i, w));
        let sub = decimal[shown];
        let name = section.name.trim();
        let prefix = name
            .get(..name.len().saturating_sub(digits.len()))
            .unwrap_or(name);
        let as_hex = format!("{prefix}{sub:X}");
        let count = written.len();
        self.report_with_notes(
            Severity::Warning,
            "eds::decimal-subindex",
            section,
            None,
            format!(
                "the sub-section names of object 0x{index:04X} are decimal (this is sub-index {sub} = 0x{sub:X}): all {count} are read as decimal"
            ),
            vec![
                format!(
                    "read as decimal because `{digits}` read as hex (CiA 306) is above 0xFF, no name of the object has a hex letter (a-f), and the {count} names are {count} distinct sub-indices, as SubNumber says"
                ),
                format!(
                    "write the sub-index in hex: [{as_hex}] instead of [{name}], and so on for every name from sub10 up"
                ),
            ],
        );
        decimal
            .into_iter()
            .zip(written.iter().map(|&(_, s)| s))
            .collect()
    }

    fn objects(&mut self) -> BTreeMap<u16, Object> {
        let doc = self.doc;
        let listed = self.object_lists();
        let mut object_sections: BTreeMap<u16, &Section> = BTreeMap::new();
        let mut written_subs: BTreeMap<u16, Vec<(&str, &Section)>> = BTreeMap::new();
        let mut names: BTreeMap<u16, &Section> = BTreeMap::new();
        let mut values: BTreeMap<u16, &Section> = BTreeMap::new();
        for section in &doc.sections {
            match classify(section.name) {
                SectionKind::Object(i) => {
                    object_sections.insert(i, section);
                }
                SectionKind::Sub(i, digits) => {
                    written_subs.entry(i).or_default().push((digits, section));
                }
                SectionKind::CompactNames(i) => {
                    names.insert(i, section);
                }
                SectionKind::CompactValues(i) => {
                    values.insert(i, section);
                }
                SectionKind::Known => {}
                SectionKind::Unknown => self.unknown_section(section),
            }
        }
        let mut subs: BTreeMap<u16, BTreeMap<u8, &Section>> = BTreeMap::new();
        for (index, written) in written_subs {
            let object = object_sections.get(&index).copied();
            let subs = subs.entry(index).or_default();
            for (sub, section) in self.sub_indices(index, object, &written) {
                subs.insert(sub, section);
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
}
