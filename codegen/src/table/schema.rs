//! The YAML object table as serde reads it: shapes and scalar types only.
//! Everything that depends on more than one key (which keys may appear
//! together, ranges, references) is checked by the lowering, which collects
//! every problem instead of stopping at the first.
//!
//! Numbers that belong to an entry's data type (defaults, limits, named
//! values, masks) are read as their source text, so that `0xFB00` keeps its
//! spelling and `$NODEID+0x180` is possible; the lowering parses them.

use serde::Deserialize;
use serde_saphyr::Spanned;

use crate::ir::{ErrorTableKind, LssService, PdoDirection};

/// A scalar kept as written in the YAML source.
pub type Text = Spanned<String>;

/// A whole file. See `docs/yaml-tables.md`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Table {
    /// The format version; only `1` exists.
    pub format: Spanned<u32>,
    /// An EDS/DCF file this table is an overlay on, relative to the table.
    pub base: Option<Text>,
    pub device: Option<Spanned<DeviceDef>>,
    pub network: Option<Spanned<NetworkDef>>,
    #[serde(default)]
    pub notes: Vec<Text>,
    #[serde(default)]
    pub delete: Vec<Spanned<EntryDef>>,
    #[serde(default)]
    pub modify: Vec<Spanned<EntryDef>>,
    #[serde(default)]
    pub objects: Vec<Spanned<EntryDef>>,
    #[serde(default)]
    pub semantics: Vec<Spanned<EntryDef>>,
    #[serde(default)]
    pub pdos: Vec<Spanned<PdoDef>>,
    #[serde(default)]
    pub errors: Vec<Spanned<ErrorTableDef>>,
    #[serde(default)]
    pub variants: Vec<Spanned<VariantDef>>,
    /// Rule levels for this device: `allow:` and `deny:` lists of rule codes.
    pub diagnostics: Option<Spanned<DiagnosticsDef>>,
    /// `none`: no built-in meanings of the standard objects (CiA 301 and
    /// the device profile); `builtin` (the default): they apply where the
    /// sources say nothing.
    pub profiles: Option<Text>,
}

/// The `diagnostics:` section: which rules to allow (their warnings are
/// dropped) and which to deny (their warnings are errors), for this device.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiagnosticsDef {
    #[serde(default)]
    pub allow: Vec<Text>,
    #[serde(default)]
    pub deny: Vec<Text>,
}

/// Identity and description of the device.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceDef {
    pub vendor_name: Option<Text>,
    pub vendor_number: Option<Spanned<u32>>,
    pub product_name: Option<Text>,
    pub product_number: Option<Spanned<u32>>,
    pub revision_number: Option<Spanned<u32>>,
    pub order_code: Option<Text>,
    pub description: Option<Text>,
}

/// Network defaults and facts.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetworkDef {
    pub node_id: Option<Spanned<u8>>,
    /// kbit/s.
    pub bit_rate: Option<Spanned<u32>>,
    /// Supported bit rates, kbit/s.
    #[serde(default)]
    pub bit_rates: Vec<Spanned<u32>>,
    pub auto_bit_rate: Option<bool>,
    pub lss: Option<Spanned<LssDef>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LssDef {
    #[serde(default)]
    pub services: Vec<Spanned<LssService>>,
    pub unconfigured_node_id: Option<Spanned<u8>>,
    #[serde(default)]
    pub bit_timing: Vec<Spanned<BitTimingDef>>,
}

/// One row of a CiA 305 bit timing table.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BitTimingDef {
    pub index: Spanned<u8>,
    /// kbit/s.
    pub bit_rate: Spanned<u32>,
}

/// The object kinds a table can declare.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum KindDef {
    Var,
    Array,
    Record,
    Domain,
}

/// One object, one sub-entry, or a reference to one (in `delete`, `modify`,
/// `semantics` and variant `values`). Which keys a context allows is checked
/// by the lowering.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EntryDef {
    pub index: Option<Spanned<u16>>,
    pub sub: Option<Spanned<u8>>,
    pub name: Option<Text>,
    pub kind: Option<Spanned<KindDef>>,
    pub description: Option<Text>,
    #[serde(rename = "type")]
    pub data_type: Option<Text>,
    pub access: Option<Text>,
    pub pdo: Option<Spanned<bool>>,
    pub default: Option<Text>,
    pub min: Option<Text>,
    pub max: Option<Text>,
    pub subs: Option<Vec<Spanned<EntryDef>>>,
    // The semantic layer.
    pub unit: Option<Text>,
    pub scale: Option<Spanned<f64>>,
    pub offset: Option<Spanned<f64>>,
    pub values: Option<Spanned<ValuesDef>>,
    pub bits: Option<Vec<Spanned<BitDef>>>,
    pub patterns: Option<Vec<Spanned<PatternDef>>>,
    pub error_table: Option<Text>,
    /// Pins the Rust name of the object (module of an array/record, type of
    /// a var) or sub-entry.
    pub rust_name: Option<Text>,
}

/// Named raw values, reserved ranges and the numeric range of a value.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ValuesDef {
    /// `[low, high]`: the raw range that is a (scaled) number.
    pub numeric: Option<Spanned<Vec<Text>>>,
    #[serde(default)]
    pub named: Vec<Spanned<NamedDef>>,
    /// The name of every raw value nothing else covers.
    pub other: Option<Text>,
}

/// `value: N` or `range: [low, high]`, with a name.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedDef {
    pub value: Option<Text>,
    pub range: Option<Spanned<Vec<Text>>>,
    pub name: Text,
    pub text: Option<Text>,
    /// Pins the Rust name of the enum variant (UpperCamelCase).
    pub rust_name: Option<Text>,
}

/// `bit: N` or `bits: [low, high]`, with a name.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BitDef {
    pub name: Text,
    pub bit: Option<Spanned<u32>>,
    pub bits: Option<Spanned<Vec<u32>>>,
    pub text: Option<Text>,
    pub unit: Option<Text>,
    pub scale: Option<Spanned<f64>>,
    pub values: Option<Spanned<ValuesDef>>,
    /// Pins the Rust name of the getter (snake_case).
    pub rust_name: Option<Text>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PatternDef {
    pub name: Text,
    pub mask: Text,
    pub value: Text,
    pub text: Option<Text>,
}

/// A default PDO: communication values and mapping.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PdoDef {
    pub direction: Spanned<PdoDirection>,
    pub number: Spanned<u16>,
    pub name: Option<Text>,
    pub description: Option<Text>,
    pub cob_id: Option<Text>,
    pub transmission: Option<Spanned<u8>>,
    /// Multiples of 100 µs.
    pub inhibit_time: Option<Spanned<u16>>,
    /// Milliseconds.
    pub event_timer: Option<Spanned<u16>>,
    pub sync_start: Option<Spanned<u8>>,
    #[serde(default)]
    pub mapping: Vec<Spanned<MapDef>>,
}

/// One mapped object (`index`, `sub`, optional `bits`) or a gap (`dummy: TYPE`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapDef {
    pub index: Option<Spanned<u16>>,
    pub sub: Option<Spanned<u8>>,
    pub bits: Option<Spanned<u8>>,
    pub dummy: Option<Text>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErrorTableDef {
    pub name: Text,
    pub kind: Spanned<ErrorTableKind>,
    pub description: Option<Text>,
    pub codes: Vec<Spanned<ErrorCodeDef>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErrorCodeDef {
    pub code: Spanned<u32>,
    pub name: Text,
    pub text: Option<Text>,
    pub reaction: Option<Text>,
    pub configurable: Option<bool>,
    pub remedy: Option<Text>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariantDef {
    pub name: Text,
    pub description: Option<Text>,
    pub device: Option<Spanned<DeviceDef>>,
    pub node_id: Option<Spanned<u8>>,
    pub bit_rate: Option<Spanned<u32>>,
    #[serde(default)]
    pub values: Vec<Spanned<EntryDef>>,
}
