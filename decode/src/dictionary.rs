//! What the decoder knows about one node: its object dictionary (the IR of
//! the file given for it, read at run time), the names of its entries, its
//! error tables and its PDO configuration as the file defines it.

use std::sync::Arc;

use eds2rust::ir::{self, DataType, Device, ErrorTableKind, PdoDirection, Semantics, Value};

/// One entry of a node's dictionary, as the decoder names and types it.
#[derive(Debug, Clone)]
pub struct EntryInfo {
    /// python-canopen's spelling: the object's name for a VAR, `Object.Entry`
    /// for a sub of an ARRAY or RECORD.
    pub name: Arc<str>,
    pub data_type: DataType,
    pub semantics: Arc<Semantics>,
}

/// A node with a file.
#[derive(Debug, Clone)]
pub struct Dictionary {
    pub node: u8,
    device: Arc<Device>,
}

impl Dictionary {
    pub fn new(node: u8, device: Arc<Device>) -> Dictionary {
        Dictionary { node, device }
    }

    pub fn device(&self) -> &Device {
        &self.device
    }

    /// The name of object `index` (without a sub).
    pub fn object_name(&self, index: u16) -> Option<&str> {
        self.device.objects.get(&index).map(|o| o.name.as_str())
    }

    /// Entry `index` sub `sub`, when the file has it.
    pub fn entry(&self, index: u16, sub: u8) -> Option<EntryInfo> {
        let object = self.device.objects.get(&index)?;
        let entry = object.entries.get(&sub)?;
        let name = match object.kind {
            ir::ObjectKind::Var | ir::ObjectKind::Domain if sub == 0 => object.name.clone(),
            // The elements of an ARRAY are often named as the array is.
            _ if entry.name == object.name => format!("{}[{sub}]", object.name),
            _ => format!("{}.{}", object.name, entry.name),
        };
        Some(EntryInfo {
            name: name.into(),
            data_type: entry.data_type,
            semantics: Arc::new(self.with_error_names(&entry.semantics)),
        })
    }

    /// `semantics`, with the codes of its error table (YAML `error_table:`)
    /// as its named values when it has no value table of its own: an
    /// entry that reports error code 1 then reads as that code's name.
    fn with_error_names(&self, semantics: &Semantics) -> Semantics {
        let mut semantics = semantics.clone();
        let Some(table) = semantics.error_table.as_ref() else {
            return semantics;
        };
        let Some(table) = self.device.error_tables.iter().find(|t| &t.name == table) else {
            return semantics;
        };
        if semantics.values.is_none() {
            let named = table.codes.iter().map(|c| ir::NamedValue {
                low: i128::from(c.code),
                high: i128::from(c.code),
                name: c.name.clone(),
                text: c.text.clone(),
                rust_name: None,
                origin: c.origin.clone(),
            });
            semantics.values = Some(ir::ValueTable {
                numeric: None,
                named: named.collect(),
                other: format!("a code {} does not list", table.name),
            });
        }
        semantics
    }

    /// The best name for `index` sub `sub`: the entry's, else the object's.
    pub fn name(&self, index: u16, sub: u8) -> Option<Arc<str>> {
        match self.entry(index, sub) {
            Some(e) => Some(e.name),
            None => self.object_name(index).map(Arc::from),
        }
    }

    /// The text of an EMCY error code from the file's EMCY error tables.
    pub fn emcy_text(&self, code: u16) -> Option<String> {
        self.error_text(ErrorTableKind::Emcy, u32::from(code))
    }

    /// The text of an SDO abort code from the file's abort-code tables (for
    /// codes CiA 301 does not define).
    pub fn abort_text(&self, code: u32) -> Option<String> {
        self.error_text(ErrorTableKind::SdoAbort, code)
    }

    fn error_text(&self, kind: ErrorTableKind, code: u32) -> Option<String> {
        let table = self.device.error_tables.iter().filter(|t| t.kind == kind);
        let found = table.flat_map(|t| &t.codes).find(|c| c.code == code)?;
        Some(match &found.text {
            Some(text) => format!("{}: {text}", found.name),
            None => found.name.clone(),
        })
    }

    /// The label of a default PDO (YAML `pdo_labels`).
    pub fn pdo_label(&self, direction: PdoDirection, number: u16) -> Option<Arc<str>> {
        let labels = &self.device.pdo_labels;
        let label = labels
            .iter()
            .find(|l| l.direction == direction && l.number == number)?;
        Some(Arc::from(label.name.as_str()))
    }

    /// The value the file gives entry `index` sub `sub` for this node: the
    /// DCF's parameter value, else the default, with `$NODEID` resolved.
    pub fn initial_u32(&self, index: u16, sub: u8) -> Option<u32> {
        let entry = self.device.objects.get(&index)?.entries.get(&sub)?;
        let literal = entry.parameter_value.as_ref().or(entry.default.as_ref())?;
        match literal.resolve(Some(self.node)) {
            Value::Integer(v) => u32::try_from(v).ok(),
            _ => None,
        }
    }

    /// The PDOs the file defines: `(direction, number)` of every
    /// communication parameter object 0x1400–0x15FF and 0x1800–0x19FF.
    pub fn pdo_numbers(&self) -> Vec<(PdoDirection, u16)> {
        let comm = |index: u16| match index {
            0x1400..=0x15FF => Some((PdoDirection::Rpdo, index - 0x1400 + 1)),
            0x1800..=0x19FF => Some((PdoDirection::Tpdo, index - 0x1800 + 1)),
            _ => None,
        };
        self.device
            .objects
            .keys()
            .filter_map(|&i| comm(i))
            .collect()
    }
}

/// The communication parameter object of a PDO.
pub fn comm_index(direction: PdoDirection, number: u16) -> u16 {
    match direction {
        PdoDirection::Rpdo => 0x1400 + number - 1,
        PdoDirection::Tpdo => 0x1800 + number - 1,
    }
}

/// The mapping parameter object of a PDO.
pub fn mapping_index(direction: PdoDirection, number: u16) -> u16 {
    comm_index(direction, number) + 0x200
}

/// The PDO whose communication (`false`) or mapping (`true`) parameter
/// object `index` is.
pub fn pdo_of_parameter(index: u16) -> Option<(PdoDirection, u16, bool)> {
    match index {
        0x1400..=0x15FF => Some((PdoDirection::Rpdo, index - 0x1400 + 1, false)),
        0x1600..=0x17FF => Some((PdoDirection::Rpdo, index - 0x1600 + 1, true)),
        0x1800..=0x19FF => Some((PdoDirection::Tpdo, index - 0x1800 + 1, false)),
        0x1A00..=0x1BFF => Some((PdoDirection::Tpdo, index - 0x1A00 + 1, true)),
        _ => None,
    }
}
