//! The semantic layer: what an EDS cannot say about an entry or a device
//! (units and scale, named values, bit fields, error tables, variants,
//! network defaults). Filled from YAML object tables; empty for a plain EDS.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use super::{Access, Identity, Literal, Origin};

/// Meaning of one entry's raw value.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Semantics {
    /// Free text from the source (manual wording, translated).
    pub description: Option<String>,
    /// Physical unit of `raw × scale + offset`, e.g. `mm`.
    pub unit: Option<String>,
    /// Physical value of one raw step (`0.1` for 0.1 mm/bit).
    pub scale: Option<f64>,
    /// Physical value of raw 0 (`-40` for "1 °C/bit − 40 °C").
    pub offset: Option<f64>,
    /// Named raw values, reserved ranges and the numeric range.
    pub values: Option<ValueTable>,
    /// Bit fields of the raw value, by ascending least significant bit.
    pub bits: Vec<BitField>,
    /// Masked patterns of the raw value that name a state (CiA 402 statusword).
    pub patterns: Vec<Pattern>,
    /// The raw value is a code of this device error table.
    pub error_table: Option<String>,
}

impl Semantics {
    pub fn is_empty(&self) -> bool {
        *self == Semantics::default()
    }
}

/// How raw values map to meanings: an enumeration when `numeric` is absent,
/// a number with special values when it is present.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct ValueTable {
    /// The inclusive raw range that carries a (scaled) number.
    pub numeric: Option<(i128, i128)>,
    /// Named single values and ranges, sorted by their low end.
    pub named: Vec<NamedValue>,
    /// The name of every raw value that neither `numeric` nor `named` covers.
    pub other: String,
}

/// A named raw value, or a named inclusive range of raw values.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct NamedValue {
    pub low: i128,
    pub high: i128,
    pub name: String,
    pub text: Option<String>,
    /// The enum variant name pinned for this value (YAML `rust_name:`),
    /// UpperCamelCase.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub rust_name: Option<String>,
    pub origin: Origin,
}

impl NamedValue {
    pub fn is_range(&self) -> bool {
        self.low != self.high
    }
}

/// A field of `width` bits starting at bit `lsb` of the raw value.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct BitField {
    pub name: String,
    pub lsb: u32,
    pub width: u32,
    pub text: Option<String>,
    pub unit: Option<String>,
    pub scale: Option<f64>,
    pub values: Option<ValueTable>,
    /// The getter name pinned for this field (YAML `rust_name:`), snake_case.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub rust_name: Option<String>,
    pub origin: Origin,
}

/// `raw & mask == value` names a state.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Pattern {
    pub name: String,
    pub mask: u64,
    pub value: u64,
    pub text: Option<String>,
    pub origin: Origin,
}

/// What the codes of an error table are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum ErrorTableKind {
    /// The 16-bit error code of an EMCY frame (and of 0x1003).
    Emcy,
    /// A manufacturer code reported in an object or PDO.
    Device,
    /// 32-bit SDO abort codes.
    SdoAbort,
}

/// A table of error codes with their texts.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct ErrorTable {
    /// The table's identifier, referenced by [`Semantics::error_table`].
    pub name: String,
    pub kind: ErrorTableKind,
    pub description: Option<String>,
    /// Sorted by code.
    pub codes: Vec<ErrorCode>,
    pub origin: Origin,
}

#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct ErrorCode {
    pub code: u32,
    pub name: String,
    pub text: Option<String>,
    /// What the device does (severity, reaction), as the source says it.
    pub reaction: Option<String>,
    /// Whether the reaction can be configured.
    pub configurable: Option<bool>,
    /// What to do about it.
    pub remedy: Option<String>,
    pub origin: Origin,
}

/// Network defaults and facts of a device.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Network {
    /// Node id as delivered.
    pub node_id: Option<u8>,
    /// Bit rate as delivered, kbit/s.
    pub bit_rate: Option<u32>,
    /// The device detects the bus bit rate by itself.
    pub auto_bit_rate: bool,
    /// Layer setting services (CiA 305), when the device supports them.
    pub lss: Option<Lss>,
}

/// What a device supports of CiA 305.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Lss {
    /// Sorted and without duplicates.
    pub services: Vec<LssService>,
    /// The node id that means "not configured" on this device, if it has one.
    pub unconfigured_node_id: Option<u8>,
    /// CiA 305 bit timing table indices the device accepts with their bit
    /// rates in kbit/s, when the source gives them.
    pub bit_timing: Vec<(u8, u32)>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum LssService {
    SwitchGlobal,
    SwitchSelective,
    ConfigureNodeId,
    ConfigureBitTiming,
    ActivateBitTiming,
    StoreConfiguration,
    InquireIdentity,
    InquireNodeId,
    Identify,
    Fastscan,
}

/// A product variant: the same dictionary with other identity, defaults or
/// rated values.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Variant {
    pub name: String,
    pub description: Option<String>,
    /// Identity fields that differ (absent fields are the device's).
    pub identity: Identity,
    /// Network defaults that differ (absent fields are the device's).
    pub node_id: Option<u8>,
    pub bit_rate: Option<u32>,
    /// Entry values that differ, sorted by index and subindex.
    pub overrides: Vec<EntryOverride>,
    pub origin: Origin,
}

/// Values of one entry that a variant changes.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct EntryOverride {
    pub index: u16,
    pub subindex: u8,
    pub default: Option<Literal>,
    pub low_limit: Option<Literal>,
    pub high_limit: Option<Literal>,
    pub origin: Origin,
}

/// Whether a PDO is received or transmitted by the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum PdoDirection {
    /// Received by the device (0x1400/0x1600 + n − 1).
    Rpdo,
    /// Transmitted by the device (0x1800/0x1A00 + n − 1).
    Tpdo,
}

impl PdoDirection {
    /// The communication parameter index of PDO number `n` (1-based).
    pub fn communication_index(self, n: u16) -> u16 {
        match self {
            PdoDirection::Rpdo => 0x1400 + n - 1,
            PdoDirection::Tpdo => 0x1800 + n - 1,
        }
    }

    /// The mapping parameter index of PDO number `n` (1-based).
    pub fn mapping_index(self, n: u16) -> u16 {
        self.communication_index(n) + 0x200
    }

    /// Whether a PDO of this direction may map an entry of `access`: an
    /// RPDO writes its entries (they must be writable), a TPDO reads them
    /// (they must be readable).
    pub fn allows(self, access: Access) -> bool {
        match self {
            PdoDirection::Rpdo => access.is_writable(),
            PdoDirection::Tpdo => access.is_readable(),
        }
    }
}

/// A name for a default PDO (its layout lives in the mapping object).
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct PdoLabel {
    pub direction: PdoDirection,
    /// 1-based PDO number (RPDO1 = 1).
    pub number: u16,
    pub name: String,
    pub description: Option<String>,
    pub origin: Origin,
}
