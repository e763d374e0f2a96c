//! The object-dictionary intermediate representation.
//!
//! Plain data, serde-serialisable (feature `serde`), with no knowledge of Rust syntax and none of
//! EDS syntax either: the EDS reader and the YAML table reader lower into it,
//! the generators read from it. Every item carries its [`Origin`].

mod datatype;
pub mod pdo;
mod semantics;
mod value;

use std::collections::BTreeMap;

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

pub use datatype::{DataType, ValueKind};
pub use semantics::{
    BitField, EntryOverride, ErrorCode, ErrorTable, ErrorTableKind, Lss, LssService, NamedValue,
    Network, Pattern, PdoDirection, PdoLabel, Semantics, ValueTable, Variant,
};
pub use value::{
    Literal, NODE_IDS, Value, fitting_node_ids, node_formula_problem, node_value_problems,
};

/// Whether a device takes the built-in meanings of CiA 301 and its device
/// profile (bit fields, states, named values, units of the standard
/// objects) where its sources say nothing.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum ProfileChoice {
    /// The built-in meanings apply (the default).
    #[default]
    Builtin,
    /// Only what the sources say (YAML `profiles: none`).
    None,
}

impl ProfileChoice {
    pub fn is_builtin(&self) -> bool {
        *self == ProfileChoice::Builtin
    }
}

/// Where an item came from: a file and a 1-based line.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Origin {
    pub file: String,
    pub line: u32,
}

/// One device's object dictionary.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Device {
    /// Path of the main input file.
    pub source: String,
    pub file_info: FileInfo,
    pub identity: Identity,
    pub capabilities: Capabilities,
    /// DCF `[DeviceComissioning]`, when present.
    pub commissioning: Option<Commissioning>,
    /// Data types the device accepts as dummy entries in PDO mappings.
    pub dummy_usage: Vec<DataType>,
    /// Objects keyed by index, including DEFTYPE/DEFSTRUCT type definitions.
    pub objects: BTreeMap<u16, Object>,
    /// Free text of the `[Comments]` section, line by line (YAML: `notes`).
    pub comments: Vec<String>,
    /// Network defaults and LSS facts (YAML only; a DCF's are in `commissioning`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub network: Network,
    /// Names of default PDOs (YAML only), sorted by direction and number.
    #[cfg_attr(feature = "serde", serde(default))]
    pub pdo_labels: Vec<PdoLabel>,
    /// Device error tables (YAML only), sorted by name.
    #[cfg_attr(feature = "serde", serde(default))]
    pub error_tables: Vec<ErrorTable>,
    /// Product variants (YAML only), in source order.
    #[cfg_attr(feature = "serde", serde(default))]
    pub variants: Vec<Variant>,
    /// Whether the built-in meanings of the standard objects apply (a
    /// table's `profiles:` key).
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "ProfileChoice::is_builtin")
    )]
    pub profiles: ProfileChoice,
}

impl Device {
    /// Where the identity lacks vendor, product or revision numbers, takes
    /// them from object 0x1018 (its DCF value, else its default).
    pub fn fill_identity_from_1018(&mut self) {
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
        if self.identity.vendor_number.is_none() {
            self.identity.vendor_number = from_1018(self, 1);
        }
        if self.identity.product_number.is_none() {
            self.identity.product_number = from_1018(self, 2);
        }
        if self.identity.revision_number.is_none() {
            self.identity.revision_number = from_1018(self, 3);
        }
    }
}

/// File metadata (`[FileInfo]`), kept as written.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct FileInfo {
    pub file_name: Option<String>,
    pub file_version: Option<String>,
    pub file_revision: Option<String>,
    pub format_version: Option<String>,
    pub description: Option<String>,
    pub created_by: Option<String>,
    pub creation_date: Option<String>,
    pub creation_time: Option<String>,
    pub modified_by: Option<String>,
    pub modification_date: Option<String>,
    pub modification_time: Option<String>,
}

/// Device identity (`[DeviceInfo]` and object 0x1018).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Identity {
    pub vendor_name: Option<String>,
    pub vendor_number: Option<u32>,
    pub product_name: Option<String>,
    pub product_number: Option<u32>,
    pub revision_number: Option<u32>,
    pub order_code: Option<String>,
}

/// What the device says it supports (`[DeviceInfo]`).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Capabilities {
    /// Supported bit rates in kbit/s, ascending.
    pub baud_rates: Vec<u32>,
    pub simple_boot_up_master: Option<bool>,
    pub simple_boot_up_slave: Option<bool>,
    pub granularity: Option<u8>,
    pub dynamic_channels_supported: Option<u8>,
    pub group_messaging: Option<bool>,
    pub nr_of_rx_pdo: Option<u16>,
    pub nr_of_tx_pdo: Option<u16>,
    pub lss_supported: Option<bool>,
}

/// DCF commissioning data (`[DeviceComissioning]`, CiA 306 spelling).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Commissioning {
    pub node_id: Option<u8>,
    pub node_name: Option<String>,
    /// Bit rate in kbit/s.
    pub baud_rate: Option<u32>,
    pub net_number: Option<u32>,
    pub network_name: Option<String>,
    pub canopen_manager: Option<bool>,
    pub lss_serial_number: Option<u32>,
}

/// The CiA 301 object code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "SCREAMING_SNAKE_CASE"))]
pub enum ObjectKind {
    /// 0x5: a data type definition.
    DefType,
    /// 0x6: a record type definition.
    DefStruct,
    /// 0x7: a single value.
    Var,
    /// 0x8: sub-entries of one type.
    Array,
    /// 0x9: sub-entries of different types.
    Record,
    /// 0x2: a large block of data (a VAR of type DOMAIN is also common).
    Domain,
}

impl ObjectKind {
    pub fn code(self) -> u8 {
        match self {
            ObjectKind::Domain => 0x2,
            ObjectKind::DefType => 0x5,
            ObjectKind::DefStruct => 0x6,
            ObjectKind::Var => 0x7,
            ObjectKind::Array => 0x8,
            ObjectKind::Record => 0x9,
        }
    }
}

/// One object of the dictionary.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Object {
    pub index: u16,
    pub name: String,
    pub kind: ObjectKind,
    /// For a VAR or DOMAIN the single entry has subindex 0.
    ///
    /// Boxed: a map reserves room for several values in each of its nodes,
    /// and most objects hold one entry (a VAR), so that an object costs the
    /// size of its entries, not of a node of unboxed entries.
    pub entries: BTreeMap<u8, Box<Entry>>,
    pub obj_flags: Option<u32>,
    pub denotation: Option<String>,
    /// Set when the sub-entries were expanded from `CompactSubObj`.
    pub compact_sub_obj: Option<u8>,
    /// The Rust module name pinned for an ARRAY/RECORD object (YAML
    /// `rust_name:`), snake_case; it wins over the canonical and the source
    /// name. A VAR object's pin is its entry's [`Entry::rust_name`].
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub rust_name: Option<String>,
    pub origin: Origin,
}

/// Access right of an entry (CiA 306 AccessType).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Access {
    Ro,
    Wo,
    Rw,
    /// Read/write, mapped into a TPDO (read on process input).
    Rwr,
    /// Read/write, mapped into an RPDO (write on process output).
    Rww,
    Const,
}

impl Access {
    pub fn as_str(self) -> &'static str {
        match self {
            Access::Ro => "ro",
            Access::Wo => "wo",
            Access::Rw => "rw",
            Access::Rwr => "rwr",
            Access::Rww => "rww",
            Access::Const => "const",
        }
    }

    pub fn is_readable(self) -> bool {
        !matches!(self, Access::Wo)
    }

    pub fn is_writable(self) -> bool {
        matches!(self, Access::Wo | Access::Rw | Access::Rwr | Access::Rww)
    }
}

/// One value-carrying entry (a VAR, or a sub-entry of an ARRAY/RECORD).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Entry {
    pub subindex: u8,
    pub name: String,
    pub data_type: DataType,
    pub access: Access,
    pub pdo_mappable: bool,
    pub default: Option<Literal>,
    pub low_limit: Option<Literal>,
    pub high_limit: Option<Literal>,
    /// DCF `ParameterValue`: the value configured for this node.
    pub parameter_value: Option<Literal>,
    pub obj_flags: Option<u32>,
    pub denotation: Option<String>,
    /// What the raw value means (YAML only).
    ///
    /// Boxed: most entries of a real file have none, and an entry stays
    /// small (a file of a million sub-entries holds a million of these).
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "semantics_is_empty")
    )]
    pub semantics: Box<Semantics>,
    /// The Rust type name pinned for this entry (YAML `rust_name:`),
    /// UpperCamelCase; it wins over the canonical and the source name.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub rust_name: Option<String>,
    pub origin: Origin,
}

/// Serde's test for an entry's boxed [`Semantics`].
#[cfg(feature = "serde")]
fn semantics_is_empty(semantics: &Semantics) -> bool {
    semantics.is_empty()
}

/// How an entry's limits and default disagree (both readers report it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimitProblem {
    /// The low limit is above the high limit.
    LowAboveHigh,
    /// The default is below the low limit.
    DefaultBelowLow,
    /// The default is above the high limit.
    DefaultAboveHigh,
}

impl Entry {
    /// The low limit above the high limit, else the default outside them;
    /// only numbers are compared (not `$NODEID` formulas, not text).
    pub fn limit_problem(&self) -> Option<LimitProblem> {
        let num = |l: &Option<Literal>| match l.as_ref().map(|l| (&l.value, l.plus_node_id)) {
            Some((Value::Integer(v), false)) => Some(*v as f64),
            Some((Value::Real(v), false)) => Some(*v),
            _ => None,
        };
        let (low, high) = (num(&self.low_limit), num(&self.high_limit));
        if let (Some(lo), Some(hi)) = (low, high)
            && lo > hi
        {
            return Some(LimitProblem::LowAboveHigh);
        }
        let default = num(&self.default)?;
        if low.is_some_and(|lo| default < lo) {
            Some(LimitProblem::DefaultBelowLow)
        } else if high.is_some_and(|hi| default > hi) {
            Some(LimitProblem::DefaultAboveHigh)
        } else {
            None
        }
    }
}

impl Object {
    /// Entries by sub-index, each boxed as [`Object::entries`] holds them.
    pub fn boxed_entries(entries: BTreeMap<u8, Entry>) -> BTreeMap<u8, Box<Entry>> {
        entries
            .into_iter()
            .map(|(sub, entry)| (sub, Box::new(entry)))
            .collect()
    }
}

impl Entry {
    /// Sub-index 0 of an ARRAY or RECORD: "Highest sub-index supported",
    /// UNSIGNED8, read-only, with `highest` as its default.
    pub fn highest_subindex(highest: u8, origin: Origin) -> Entry {
        Entry {
            subindex: 0,
            name: "Highest sub-index supported".into(),
            data_type: DataType::Unsigned8,
            access: Access::Ro,
            pdo_mappable: false,
            default: Some(Literal {
                value: Value::Integer(highest.into()),
                plus_node_id: false,
                text: highest.to_string(),
            }),
            low_limit: None,
            high_limit: None,
            parameter_value: None,
            obj_flags: None,
            denotation: None,
            semantics: Box::default(),
            rust_name: None,
            origin,
        }
    }

    /// True when the default value is a `$NODEID` formula.
    pub fn node_relative(&self) -> bool {
        self.default.as_ref().is_some_and(|l| l.plus_node_id)
    }
}
