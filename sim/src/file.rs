//! The object table of a simulated device read from a file at run time
//! (feature `files`): an EDS or DCF (CiA 306) or a YAML object table, read
//! with the reader of the `eds2rust` crate (its diagnostics name file,
//! line and key), turned into the [`ObjectInfo`] entries a generated
//! `od::OBJECTS` would have.
//!
//! ```no_run
//! # use eds2rust_runtime::{Instant, od::NodeId};
//! # use eds2rust_sim::{Device, DeviceConfig, file};
//! let table = file::load("drive.eds")?;
//! let node = table.node.or(NodeId::new(5)).expect("node id");
//! let device = Device::new(table.objects, DeviceConfig::node(node), (), Instant::ZERO);
//! # Ok::<(), file::LoadError>(())
//! ```
//!
//! Why the table is leaked: [`Device::new`](crate::Device::new) takes
//! `&'static [ObjectInfo]`, the type of a generated table, whose names and
//! byte defaults are `&'static` too. [`load`] builds the entries once and
//! leaks them (`Box::leak`) so they fit that type unchanged: no second
//! device type, no lifetime on every simulator. The cost is the table's
//! memory (some kilobytes for a real EDS) for the rest of the process; a
//! program loads a file once per simulated device, not in a loop.

use std::fmt;
use std::path::{Path, PathBuf};

use eds2rust::build::load_device;
use eds2rust::diag::{Diagnostics, Severity};
use eds2rust::input::Options;
use eds2rust::ir::{self, Access, Device, Literal, ObjectKind, Value};
use eds2rust_runtime::cia402::object::{CONTROLWORD, STATUSWORD};
use eds2rust_runtime::od::{AccessRight, DataType, DefaultValue, NodeId, Number, ObjectInfo};

/// Object 0x1000, device type (CiA 301).
const DEVICE_TYPE: u16 = 0x1000;

/// A device table read from a file.
#[derive(Debug, Clone)]
pub struct LoadedTable {
    /// The file read.
    pub path: PathBuf,
    /// Every entry, sorted by index and subindex (leaked: see the module
    /// documentation).
    pub objects: &'static [ObjectInfo],
    /// The value of 0x1000 (DCF parameter value, else default), if the
    /// file has one.
    pub device_type: Option<u32>,
    /// Whether it is a CiA 402 drive: 0x1000's low 16 bits are 402, or
    /// 0x6040 and 0x6041 are present.
    pub cia402: bool,
    /// The node id the file gives (DCF `[DeviceComissioning] NodeID`,
    /// YAML `network: node_id`), if any.
    pub node: Option<NodeId>,
    /// The product name (`[DeviceInfo] ProductName`), if any.
    pub product: Option<String>,
    /// The reader's warnings and what the conversion dropped, one line each
    /// (`file:line: warning: ...`).
    pub warnings: Vec<String>,
}

impl LoadedTable {
    /// The entry (index, sub), if the file has it.
    pub fn entry(&self, index: u16, sub: u8) -> Option<&'static ObjectInfo> {
        let objects: &'static [ObjectInfo] = self.objects;
        objects
            .binary_search_by_key(&(index, sub), |o| (o.index, o.subindex))
            .ok()
            .and_then(|i| objects.get(i))
    }

    /// Whether the file has any entry of `index`.
    pub fn has(&self, index: u16) -> bool {
        self.objects.iter().any(|o| o.index == index)
    }

    /// The CiA 402 objects every drive needs (0x6040 Controlword, 0x6041
    /// Statusword) that the file lacks.
    pub fn cia402_lacks(&self) -> Vec<(u16, &'static str)> {
        [(CONTROLWORD, "Controlword"), (STATUSWORD, "Statusword")]
            .into_iter()
            .filter(|(index, _)| self.entry(*index, 0).is_none())
            .collect()
    }
}

/// A file that could not be read into a table: the reader's errors, each
/// naming file and line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadError {
    /// The file.
    pub path: PathBuf,
    /// One line per error: `file:line: error: [section] key: message`.
    pub errors: Vec<String>,
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.errors.as_slice() {
            [] => write!(f, "{}: cannot be read", self.path.display()),
            [one] => f.write_str(one),
            [first, rest @ ..] => write!(f, "{first} (and {} more errors)", rest.len()),
        }
    }
}

impl std::error::Error for LoadError {}

/// Reads the EDS/DCF (any extension but `.yaml`/`.yml`) or YAML table at
/// `path` leniently (warnings stay warnings, as `eds2rust check` without
/// `--strict`) and builds its object table.
pub fn load(path: impl AsRef<Path>) -> Result<LoadedTable, LoadError> {
    load_with_overlays(path, &[])
}

/// [`load`] with the YAML `overlays` (tables without `base:`, as
/// `eds2rust generate --overlay`) applied on the file in order: names,
/// defaults, limits, added and deleted objects of the simulated device
/// come from them. Their diagnostics name the overlay's own file and line.
pub fn load_with_overlays(
    path: impl AsRef<Path>,
    overlays: &[PathBuf],
) -> Result<LoadedTable, LoadError> {
    let path = path.as_ref();
    let loaded = load_device(path, overlays, &Options::lenient());
    let (device, warnings) = accept(path, loaded.device, &loaded.diagnostics)?;
    Ok(from_device(path, &device, warnings))
}

/// What a reader made of `path` (`value`) with the warnings of
/// `diagnostics`, or, when they have an error, every error.
pub(crate) fn accept<T>(
    path: &Path,
    value: Option<T>,
    diagnostics: &Diagnostics,
) -> Result<(T, Vec<String>), LoadError> {
    let lines = |severity: Severity| -> Vec<String> {
        diagnostics
            .iter()
            .filter(|d| d.severity == severity)
            .map(ToString::to_string)
            .collect()
    };
    let errors = lines(Severity::Error);
    match value {
        Some(value) if errors.is_empty() => Ok((value, lines(Severity::Warning))),
        _ => Err(LoadError {
            path: path.to_path_buf(),
            errors,
        }),
    }
}

/// The table of `device`, already read from `path` (by a bus file's
/// reader, for example), with the reader's `warnings` (what the
/// conversion drops is added to them).
pub fn from_device(path: &Path, device: &Device, mut warnings: Vec<String>) -> LoadedTable {
    let objects = convert(device, &mut warnings);
    let device_type = objects
        .iter()
        .find(|o| (o.index, o.subindex) == (DEVICE_TYPE, 0))
        .and_then(|o| match o.default {
            Some(DefaultValue::Number(Number::Int(v))) => u32::try_from(v).ok(),
            _ => None,
        });
    let cia402 = eds2rust::profiles::is_cia402(device);
    let node = device
        .commissioning
        .as_ref()
        .and_then(|c| c.node_id)
        .or(device.network.node_id)
        .and_then(NodeId::new);
    LoadedTable {
        path: path.to_path_buf(),
        objects: Box::leak(objects.into_boxed_slice()),
        device_type,
        cia402,
        node,
        product: device.identity.product_name.clone(),
        warnings,
    }
}

/// Every value-carrying entry of `device` (type definitions left out), in
/// index and subindex order.
fn convert(device: &Device, warnings: &mut Vec<String>) -> Vec<ObjectInfo> {
    let mut out = Vec::new();
    for object in device.objects.values() {
        if matches!(object.kind, ObjectKind::DefType | ObjectKind::DefStruct) {
            continue;
        }
        for entry in object.entries.values() {
            let name = if matches!(object.kind, ObjectKind::Var | ObjectKind::Domain) {
                &object.name
            } else {
                &entry.name
            };
            let data_type = data_type(entry.data_type);
            let mut info = ObjectInfo::new(
                object.index,
                entry.subindex,
                Box::leak(name.clone().into_boxed_str()),
                data_type,
                access(entry.access),
                entry.pdo_mappable,
            );
            // A DCF's ParameterValue is the value configured for the node.
            if let Some(literal) = entry.parameter_value.as_ref().or(entry.default.as_ref()) {
                match default(literal, data_type) {
                    Some(value) => info = info.with_default(value),
                    None => warnings.push(format!(
                        "{}:{}: warning: {:#06X} sub {}: value `{}` does not fit {:?}; \
                         the simulated entry starts at 0",
                        entry.origin.file,
                        entry.origin.line,
                        object.index,
                        entry.subindex,
                        literal.text,
                        data_type
                    )),
                }
            }
            let limit = |l: &Option<Literal>| l.as_ref().and_then(|l| number(&l.value, data_type));
            info = info.with_limits(limit(&entry.low_limit), limit(&entry.high_limit));
            out.push(info);
        }
    }
    out.sort_by_key(|o| (o.index, o.subindex));
    out
}

fn data_type(t: ir::DataType) -> DataType {
    use ir::DataType as I;
    match t {
        I::Boolean => DataType::Boolean,
        I::Integer8 => DataType::Integer8,
        I::Integer16 => DataType::Integer16,
        I::Integer24 => DataType::Integer24,
        I::Integer32 => DataType::Integer32,
        I::Integer40 => DataType::Integer40,
        I::Integer48 => DataType::Integer48,
        I::Integer56 => DataType::Integer56,
        I::Integer64 => DataType::Integer64,
        I::Unsigned8 => DataType::Unsigned8,
        I::Unsigned16 => DataType::Unsigned16,
        I::Unsigned24 => DataType::Unsigned24,
        I::Unsigned32 => DataType::Unsigned32,
        I::Unsigned40 => DataType::Unsigned40,
        I::Unsigned48 => DataType::Unsigned48,
        I::Unsigned56 => DataType::Unsigned56,
        I::Unsigned64 => DataType::Unsigned64,
        I::Real32 => DataType::Real32,
        I::Real64 => DataType::Real64,
        I::VisibleString => DataType::VisibleString,
        I::OctetString => DataType::OctetString,
        I::UnicodeString => DataType::UnicodeString,
        I::TimeOfDay => DataType::TimeOfDay,
        I::TimeDifference => DataType::TimeDifference,
        I::Domain => DataType::Domain,
        I::Other(code) => DataType::Other(code),
    }
}

fn access(a: Access) -> AccessRight {
    match a {
        Access::Ro => AccessRight::Ro,
        Access::Wo => AccessRight::Wo,
        Access::Rw => AccessRight::Rw,
        Access::Rwr => AccessRight::Rwr,
        Access::Rww => AccessRight::Rww,
        Access::Const => AccessRight::Const,
    }
}

fn is_real(t: DataType) -> bool {
    matches!(t, DataType::Real32 | DataType::Real64)
}

/// A number for an entry of type `t` (integers of a REAL entry as reals).
fn number(value: &Value, t: DataType) -> Option<Number> {
    match value {
        Value::Integer(v) if is_real(t) => Some(Number::Real(*v as f64)),
        Value::Integer(v) => Some(Number::Int(*v)),
        Value::Real(f) if is_real(t) && f.is_finite() => Some(Number::Real(*f)),
        _ => None,
    }
}

/// The default of an entry of type `t`: `$NODEID + n` stays node
/// relative (resolved when the device gets its node id); bytes only for
/// types without a fixed size; `None` for a value the type cannot hold.
fn default(literal: &Literal, t: DataType) -> Option<DefaultValue> {
    let bytes = |b: &[u8]| -> Option<DefaultValue> {
        if t.size().is_some() {
            return None;
        }
        Some(DefaultValue::Bytes(Box::leak(
            b.to_vec().into_boxed_slice(),
        )))
    };
    match &literal.value {
        Value::Integer(v) if literal.plus_node_id && !is_real(t) => {
            Some(DefaultValue::NodeRelative(*v))
        }
        Value::Text(text) => bytes(text.as_bytes()),
        Value::Bytes(b) => bytes(b),
        value => {
            let number = number(value, t)?;
            // A value out of the type's range would start the entry at 0
            // without a word: say so instead.
            let fits = ObjectInfo::new(0, 0, "", t, AccessRight::Ro, false)
                .with_default(DefaultValue::Number(number))
                .encode_default(None, &mut [0; 8])
                .is_some();
            (fits || t.size().is_none()).then_some(DefaultValue::Number(number))
        }
    }
}
