//! A semantic diff of two object dictionaries: what changed between two
//! versions of a device, each change classified by what it does to a user of
//! the generated Rust and to the bus.
//!
//! ```
//! # use eds2rust::{diff, ir::Device};
//! let old = Device::default();
//! let new = Device::default();
//! let changes = diff::diff(&old, &new);
//! assert!(changes.is_empty());
//! ```
//!
//! Changes are plain data ([`Change`]), in a deterministic order: by index,
//! then subindex (object-level changes first), then in the order the
//! comparisons run. [`render`] formats them as text, Markdown or JSON
//! (hand-written: the library's default build has no JSON dependency).
//!
//! Severities ([`Severity`]):
//! - `breaking`: a generated item disappears or changes its path or value
//!   type, an access right loses read or write, a default PDO's layout or
//!   COB-ID changes;
//! - `additive`: new items only (objects, subs, named values, bit fields,
//!   error codes, a widened access right, a sub that becomes PDO-mappable);
//! - `compatible`: defaults, limits, descriptions, units and scales, names
//!   whose Rust path stays the same: the API and the wire stay as they are.
//!
//! The rules for every kind are in `docs/diff.md`.

mod entries;
pub(crate) mod pdo;
pub mod render;
mod semantics;

use serde::Serialize;

use crate::r#gen::rust::od_plan::{DeviceNames, device_names};
use crate::ir::{Device, Literal, Value};

/// What a change does to a user.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// The API and the wire stay as they are.
    Compatible,
    /// New items only: existing code keeps compiling and working.
    Additive,
    /// Existing code may stop compiling or working.
    Breaking,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Compatible => "compatible",
            Severity::Additive => "additive",
            Severity::Breaking => "breaking",
        }
    }
}

/// The kinds of change; [`Kind::as_str`] is the stable kebab-case name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Kind {
    ObjectAdded,
    ObjectRemoved,
    ObjectKindChanged,
    SubAdded,
    SubRemoved,
    NameChanged,
    RustPathChanged,
    DataTypeChanged,
    ValueTypeChanged,
    AccessChanged,
    PdoMappableChanged,
    DefaultChanged,
    LowLimitChanged,
    HighLimitChanged,
    ParameterValueChanged,
    DescriptionChanged,
    UnitChanged,
    ScaleChanged,
    OffsetChanged,
    NamedValueAdded,
    NamedValueRemoved,
    NamedValueChanged,
    ValueTableChanged,
    BitFieldAdded,
    BitFieldRemoved,
    BitFieldChanged,
    PatternAdded,
    PatternRemoved,
    PatternChanged,
    ErrorTableRefChanged,
    ErrorTableAdded,
    ErrorTableRemoved,
    ErrorTableChanged,
    ErrorCodeAdded,
    ErrorCodeRemoved,
    ErrorCodeChanged,
    PdoAdded,
    PdoRemoved,
    PdoMappingChanged,
    PdoCobIdChanged,
    PdoLabelChanged,
}

impl Kind {
    /// Every kind, in declaration order.
    pub const ALL: &'static [Kind] = &[
        Kind::ObjectAdded,
        Kind::ObjectRemoved,
        Kind::ObjectKindChanged,
        Kind::SubAdded,
        Kind::SubRemoved,
        Kind::NameChanged,
        Kind::RustPathChanged,
        Kind::DataTypeChanged,
        Kind::ValueTypeChanged,
        Kind::AccessChanged,
        Kind::PdoMappableChanged,
        Kind::DefaultChanged,
        Kind::LowLimitChanged,
        Kind::HighLimitChanged,
        Kind::ParameterValueChanged,
        Kind::DescriptionChanged,
        Kind::UnitChanged,
        Kind::ScaleChanged,
        Kind::OffsetChanged,
        Kind::NamedValueAdded,
        Kind::NamedValueRemoved,
        Kind::NamedValueChanged,
        Kind::ValueTableChanged,
        Kind::BitFieldAdded,
        Kind::BitFieldRemoved,
        Kind::BitFieldChanged,
        Kind::PatternAdded,
        Kind::PatternRemoved,
        Kind::PatternChanged,
        Kind::ErrorTableRefChanged,
        Kind::ErrorTableAdded,
        Kind::ErrorTableRemoved,
        Kind::ErrorTableChanged,
        Kind::ErrorCodeAdded,
        Kind::ErrorCodeRemoved,
        Kind::ErrorCodeChanged,
        Kind::PdoAdded,
        Kind::PdoRemoved,
        Kind::PdoMappingChanged,
        Kind::PdoCobIdChanged,
        Kind::PdoLabelChanged,
    ];

    /// The stable kebab-case name (`access-changed`).
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::ObjectAdded => "object-added",
            Kind::ObjectRemoved => "object-removed",
            Kind::ObjectKindChanged => "object-kind-changed",
            Kind::SubAdded => "sub-added",
            Kind::SubRemoved => "sub-removed",
            Kind::NameChanged => "name-changed",
            Kind::RustPathChanged => "rust-path-changed",
            Kind::DataTypeChanged => "data-type-changed",
            Kind::ValueTypeChanged => "value-type-changed",
            Kind::AccessChanged => "access-changed",
            Kind::PdoMappableChanged => "pdo-mappable-changed",
            Kind::DefaultChanged => "default-changed",
            Kind::LowLimitChanged => "low-limit-changed",
            Kind::HighLimitChanged => "high-limit-changed",
            Kind::ParameterValueChanged => "parameter-value-changed",
            Kind::DescriptionChanged => "description-changed",
            Kind::UnitChanged => "unit-changed",
            Kind::ScaleChanged => "scale-changed",
            Kind::OffsetChanged => "offset-changed",
            Kind::NamedValueAdded => "named-value-added",
            Kind::NamedValueRemoved => "named-value-removed",
            Kind::NamedValueChanged => "named-value-changed",
            Kind::ValueTableChanged => "value-table-changed",
            Kind::BitFieldAdded => "bit-field-added",
            Kind::BitFieldRemoved => "bit-field-removed",
            Kind::BitFieldChanged => "bit-field-changed",
            Kind::PatternAdded => "pattern-added",
            Kind::PatternRemoved => "pattern-removed",
            Kind::PatternChanged => "pattern-changed",
            Kind::ErrorTableRefChanged => "error-table-ref-changed",
            Kind::ErrorTableAdded => "error-table-added",
            Kind::ErrorTableRemoved => "error-table-removed",
            Kind::ErrorTableChanged => "error-table-changed",
            Kind::ErrorCodeAdded => "error-code-added",
            Kind::ErrorCodeRemoved => "error-code-removed",
            Kind::ErrorCodeChanged => "error-code-changed",
            Kind::PdoAdded => "pdo-added",
            Kind::PdoRemoved => "pdo-removed",
            Kind::PdoMappingChanged => "pdo-mapping-changed",
            Kind::PdoCobIdChanged => "pdo-cob-id-changed",
            Kind::PdoLabelChanged => "pdo-label-changed",
        }
    }
}

/// A value before or after a change.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Val {
    Bool(bool),
    Int(i128),
    Real(f64),
    Text(String),
    List(Vec<String>),
}

impl std::fmt::Display for Val {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Val::Bool(b) => write!(f, "{b}"),
            Val::Int(v) => write!(f, "{v}"),
            Val::Real(v) => write!(f, "{v}"),
            Val::Text(t) => write!(f, "{t}"),
            Val::List(items) if items.is_empty() => write!(f, "(empty)"),
            Val::List(items) => write!(f, "{}", items.join(", ")),
        }
    }
}

/// One change between the old and the new device.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Change {
    /// The object's index; 0 for device-level changes (error tables).
    pub index: u16,
    /// The sub-entry, `None` for object-level and PDO-level changes.
    pub subindex: Option<u8>,
    pub kind: Kind,
    pub severity: Severity,
    /// The Rust path inside the device module (`od::Statusword`), from the
    /// old device's naming for removals and the new one's otherwise.
    pub rust_path: Option<String>,
    pub old: Option<Val>,
    pub new: Option<Val>,
    /// One line for a reviewer.
    pub message: String,
}

/// How to compare.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Options {
    /// Compare without the YAML-only layer (an EDS cannot say it): entry
    /// semantics (description, unit, scale, offset, named values, bit
    /// fields, patterns, error-table references), device error tables and
    /// PDO labels are dropped from both sides first, so an EDS and the YAML
    /// table it was exported from diff as equal.
    pub ignore_semantics: bool,
}

/// Counts of changes by severity.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Summary {
    pub breaking: usize,
    pub additive: usize,
    pub compatible: usize,
}

impl Summary {
    pub fn of(changes: &[Change]) -> Summary {
        Summary::of_severities(changes.iter().map(|c| c.severity))
    }

    /// Counts of these severities (for lists of other change types, such
    /// as a network's).
    pub fn of_severities(severities: impl IntoIterator<Item = Severity>) -> Summary {
        let mut s = Summary::default();
        for severity in severities {
            match severity {
                Severity::Breaking => s.breaking += 1,
                Severity::Additive => s.additive += 1,
                Severity::Compatible => s.compatible += 1,
            }
        }
        s
    }

    /// The highest severity present.
    pub fn worst(&self) -> Option<Severity> {
        if self.breaking > 0 {
            Some(Severity::Breaking)
        } else if self.additive > 0 {
            Some(Severity::Additive)
        } else if self.compatible > 0 {
            Some(Severity::Compatible)
        } else {
            None
        }
    }
}

/// Every change from `old` to `new`, with the default [`Options`].
pub fn diff(old: &Device, new: &Device) -> Vec<Change> {
    diff_with(old, new, &Options::default())
}

/// Every change from `old` to `new`.
pub fn diff_with(old: &Device, new: &Device, options: &Options) -> Vec<Change> {
    let (old, new) = if options.ignore_semantics {
        (strip_semantics(old), strip_semantics(new))
    } else {
        (old.clone(), new.clone())
    };
    let mut cx = Cx {
        old: &old,
        new: &new,
        old_names: device_names(&old),
        new_names: device_names(&new),
        changes: Vec::new(),
    };
    semantics::error_tables(&mut cx);
    entries::objects(&mut cx);
    pdo::pdos(&mut cx);
    let mut changes = cx.changes;
    // Stable: within one (index, subindex) the comparison order stays.
    changes.sort_by_key(|c| (c.index, c.subindex.map_or(-1, i32::from)));
    changes
}

/// `device` without what only a YAML table can say.
fn strip_semantics(device: &Device) -> Device {
    let mut device = device.clone();
    for object in device.objects.values_mut() {
        for entry in object.entries.values_mut() {
            *entry.semantics = Default::default();
        }
    }
    device.error_tables.clear();
    device.pdo_labels.clear();
    device
}

/// The state of one comparison.
struct Cx<'a> {
    old: &'a Device,
    new: &'a Device,
    old_names: DeviceNames,
    new_names: DeviceNames,
    changes: Vec<Change>,
}

impl Cx<'_> {
    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        index: u16,
        subindex: Option<u8>,
        kind: Kind,
        severity: Severity,
        rust_path: Option<String>,
        old: Option<Val>,
        new: Option<Val>,
        message: String,
    ) {
        self.changes.push(Change {
            index,
            subindex,
            kind,
            severity,
            rust_path,
            old,
            new,
            message,
        });
    }
}

/// A literal as a value: integers and reals as numbers, `$NODEID` formulas
/// and bytes as text.
fn literal_val(literal: &Literal) -> Val {
    match (&literal.value, literal.plus_node_id) {
        (Value::Integer(v), true) => Val::Text(format!("$NODEID+{}", hex(*v))),
        (Value::Integer(v), false) => Val::Int(*v),
        (Value::Real(v), _) => Val::Real(*v),
        (Value::Text(t), _) => Val::Text(t.clone()),
        (Value::Bytes(b), _) => Val::Text(b.iter().map(|b| format!("{b:02X}")).collect()),
    }
}

/// Whether two literals say the same value (the source text aside).
fn same_literal(a: &Literal, b: &Literal) -> bool {
    a.plus_node_id == b.plus_node_id
        && match (&a.value, &b.value) {
            (Value::Real(x), Value::Real(y)) => x.to_bits() == y.to_bits() || x == y,
            (x, y) => x == y,
        }
}

/// `0x1F` for a non-negative integer, `-0x1F` for a negative one.
pub(crate) fn hex(v: i128) -> String {
    if v < 0 {
        format!("-0x{:X}", v.unsigned_abs())
    } else {
        format!("0x{v:X}")
    }
}

/// An optional value for a message: `none` when absent.
fn shown(v: &Option<Val>) -> String {
    v.as_ref()
        .map_or_else(|| "none".to_string(), Val::to_string)
}
