//! The `dump --format json` schema: one object with the file, the device
//! identity, every value-carrying entry sorted by index then subindex, and the
//! diagnostics. Type definitions (DEFTYPE/DEFSTRUCT) are not entries.

use serde::ser::{Serialize, SerializeMap, SerializeSeq, Serializer};
use serde_json::{Map, Value as Json, json};

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::{Device, Entry, Literal, Object, ObjectKind, Value, node_value_problems};

/// Builds the JSON document. `node_id` resolves `$NODEID` formulas.
pub fn to_json(
    file: &str,
    device: Option<&Device>,
    diagnostics: &Diagnostics,
    node_id: Option<u8>,
) -> Json {
    let entries: Vec<Json> = entries(device, node_id).collect();
    json!({
        "file": file,
        "device": device_json(device),
        "entries": entries,
        "diagnostics": diagnostics_json(diagnostics),
    })
}

/// The text of [`to_json`] pretty-printed (`serde_json::to_string_pretty`),
/// written an entry at a time: the memory is that of the text, not of a
/// JSON tree of the whole device (several times larger).
pub fn to_json_pretty(
    file: &str,
    device: Option<&Device>,
    diagnostics: &Diagnostics,
    node_id: Option<u8>,
) -> String {
    let document = Document {
        file,
        device,
        diagnostics,
        node_id,
    };
    let bytes = serde_json::to_vec_pretty(&document).unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_default()
}

/// [`to_json`] as something to serialize without building it.
struct Document<'a> {
    file: &'a str,
    device: Option<&'a Device>,
    diagnostics: &'a Diagnostics,
    node_id: Option<u8>,
}

/// The entries as a sequence serialized one at a time.
struct Entries<'a>(Option<&'a Device>, Option<u8>);

impl Serialize for Entries<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut seq = serializer.serialize_seq(None)?;
        for entry in entries(self.0, self.1) {
            seq.serialize_element(&entry)?;
        }
        seq.end()
    }
}

impl Serialize for Document<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        // The keys in the order a JSON object of `to_json` has them.
        let order = json!({"file": 0, "device": 0, "entries": 0, "diagnostics": 0});
        let mut map = serializer.serialize_map(Some(4))?;
        for key in order.as_object().into_iter().flat_map(|o| o.keys()) {
            match key.as_str() {
                "file" => map.serialize_entry(key, self.file)?,
                "device" => map.serialize_entry(key, &device_json(self.device))?,
                "entries" => map.serialize_entry(key, &Entries(self.device, self.node_id))?,
                _ => map.serialize_entry(key, &diagnostics_json(self.diagnostics))?,
            }
        }
        map.end()
    }
}

fn diagnostics_json(diagnostics: &Diagnostics) -> Vec<Json> {
    diagnostics
        .iter()
        .map(|d| json!({"severity": d.severity.as_str(), "line": d.location.line, "message": d.headline()}))
        .collect()
}

/// Every value-carrying entry, as JSON, in index and subindex order.
fn entries(device: Option<&Device>, node_id: Option<u8>) -> impl Iterator<Item = Json> + '_ {
    device
        .into_iter()
        .flat_map(|device| device.objects.values())
        .filter_map(|object| {
            let object_type = match object.kind {
                ObjectKind::Var => "VAR",
                ObjectKind::Domain => "DOMAIN",
                ObjectKind::Array => "ARRAY",
                ObjectKind::Record => "RECORD",
                ObjectKind::DefType | ObjectKind::DefStruct => return None,
            };
            Some((object, object_type))
        })
        .flat_map(move |(object, object_type)| {
            object
                .entries
                .values()
                .map(move |entry| entry_json(object, object_type, entry, node_id))
        })
}

fn device_json(device: Option<&Device>) -> Json {
    let identity = device.map(|d| &d.identity);
    json!({
        "vendor_name": identity.and_then(|i| i.vendor_name.clone()),
        "vendor_number": identity.and_then(|i| i.vendor_number),
        "product_name": identity.and_then(|i| i.product_name.clone()),
        "product_number": identity.and_then(|i| i.product_number),
        "revision_number": identity.and_then(|i| i.revision_number),
    })
}

/// An error for every value of `device` that leaves its type once
/// `$NODEID` is `node_id` (its JSON value is then null, never a number the
/// node cannot hold).
pub fn node_id_diagnostics(device: &Device, node_id: u8) -> Diagnostics {
    let mut diags = Diagnostics::new();
    for object in device.objects.values() {
        for entry in object.entries.values() {
            for (key, why) in node_value_problems(entry, node_id) {
                let file = &entry.origin.file;
                let is_table = file.ends_with(".yaml") || file.ends_with(".yml");
                diags.push(Diagnostic {
                    severity: Severity::Error,
                    code: if is_table {
                        "table::value-out-of-range"
                    } else {
                        "eds::value-out-of-range"
                    },
                    file: file.clone(),
                    location: Location {
                        line: (entry.origin.line > 0).then_some(entry.origin.line),
                        section: Some(format!("0x{:04X} sub {}", object.index, entry.subindex)),
                        key: Some(key.into()),
                        ..Location::default()
                    },
                    message: why,
                    notes: Vec::new(),
                });
            }
        }
    }
    diags
}

fn entry_json(object: &Object, object_type: &str, entry: &Entry, node_id: Option<u8>) -> Json {
    let is_var = matches!(object.kind, ObjectKind::Var | ObjectKind::Domain);
    let value = |l: &Option<Literal>| {
        let value = match (l, node_id) {
            (None, _) => return Json::Null,
            (Some(l), Some(n)) => l.resolve_checked(n, entry.data_type),
            (Some(l), None) => Ok(l.resolve(None)),
        };
        value.map_or(Json::Null, |v| value_json(&v))
    };
    let mut m = Map::new();
    m.insert("index".into(), object.index.into());
    m.insert("subindex".into(), entry.subindex.into());
    m.insert("object_type".into(), object_type.into());
    m.insert(
        "parent_name".into(),
        if is_var {
            Json::Null
        } else {
            object.name.clone().into()
        },
    );
    m.insert("name".into(), entry.name.clone().into());
    m.insert("data_type".into(), entry.data_type.code().into());
    m.insert("access".into(), entry.access.as_str().into());
    m.insert("pdo_mappable".into(), entry.pdo_mappable.into());
    m.insert("default".into(), value(&entry.default));
    m.insert("low_limit".into(), value(&entry.low_limit));
    m.insert("high_limit".into(), value(&entry.high_limit));
    m.insert("parameter_value".into(), value(&entry.parameter_value));
    m.insert("node_relative".into(), entry.node_relative().into());
    Json::Object(m)
}

/// One value: integers as JSON integers, reals as numbers (NaN and infinities,
/// which JSON cannot hold, as null), text as strings, bytes as `{"hex": …}`.
pub fn value_json(value: &Value) -> Json {
    match value {
        Value::Integer(v) => match (i64::try_from(*v), u64::try_from(*v)) {
            (Ok(v), _) => v.into(),
            (_, Ok(v)) => v.into(),
            _ => Json::Null,
        },
        Value::Real(v) => serde_json::Number::from_f64(*v).map_or(Json::Null, Json::Number),
        Value::Text(s) => s.clone().into(),
        Value::Bytes(b) => json!({"hex": b.iter().map(|x| format!("{x:02x}")).collect::<String>()}),
    }
}
