//! The `dump --format json` schema: one object with the file, the device
//! identity, every value-carrying entry sorted by index then subindex, and the
//! diagnostics. Type definitions (DEFTYPE/DEFSTRUCT) are not entries.

use serde_json::{Map, Value as Json, json};

use crate::diag::Diagnostics;
use crate::ir::{Device, Entry, Literal, Object, ObjectKind, Value};

/// Builds the JSON document. `node_id` resolves `$NODEID` formulas.
pub fn to_json(
    file: &str,
    device: Option<&Device>,
    diagnostics: &Diagnostics,
    node_id: Option<u8>,
) -> Json {
    let identity = device.map(|d| &d.identity);
    let device_json = json!({
        "vendor_name": identity.and_then(|i| i.vendor_name.clone()),
        "vendor_number": identity.and_then(|i| i.vendor_number),
        "product_name": identity.and_then(|i| i.product_name.clone()),
        "product_number": identity.and_then(|i| i.product_number),
        "revision_number": identity.and_then(|i| i.revision_number),
    });
    let mut entries = Vec::new();
    if let Some(device) = device {
        for object in device.objects.values() {
            let object_type = match object.kind {
                ObjectKind::Var => "VAR",
                ObjectKind::Domain => "DOMAIN",
                ObjectKind::Array => "ARRAY",
                ObjectKind::Record => "RECORD",
                ObjectKind::DefType | ObjectKind::DefStruct => continue,
            };
            for entry in object.entries.values() {
                entries.push(entry_json(object, object_type, entry, node_id));
            }
        }
    }
    let diagnostics: Vec<Json> = diagnostics
        .iter()
        .map(|d| json!({"severity": d.severity.as_str(), "line": d.location.line, "message": d.headline()}))
        .collect();
    json!({"file": file, "device": device_json, "entries": entries, "diagnostics": diagnostics})
}

fn entry_json(object: &Object, object_type: &str, entry: &Entry, node_id: Option<u8>) -> Json {
    let is_var = matches!(object.kind, ObjectKind::Var | ObjectKind::Domain);
    let value = |l: &Option<Literal>| {
        l.as_ref()
            .map_or(Json::Null, |l| value_json(&l.resolve(node_id)))
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
