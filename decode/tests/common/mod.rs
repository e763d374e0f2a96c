//! What the decode tests share: seed devices read from eds/, traces
//! decoded into records and their JSON.

#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::Arc;

use eds2rust_decode::{Decoder, Record, render};
use serde_json::Value as Json;

pub fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The IR of `eds/<name>.yaml`.
pub fn seed(name: &str) -> Arc<eds2rust::ir::Device> {
    let path = workspace().join(format!("eds/{name}.yaml"));
    let loaded = eds2rust::input::read_device(&path, &eds2rust::input::Options::default());
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}",
        loaded.diagnostics.render()
    );
    Arc::new(loaded.device.expect("a device"))
}

/// Every record of `trace`, as JSON.
pub fn decode(decoder: &mut Decoder, trace: &str) -> Vec<Json> {
    let mut out = Vec::new();
    eds2rust_decode::decode_trace(decoder, trace.as_bytes(), |r: &Record| {
        out.push(render::json(r));
        Ok(())
    })
    .expect("in-memory trace");
    out
}

/// The records of `trace` that are frames.
pub fn frames(records: &[Json]) -> Vec<&Json> {
    records
        .iter()
        .filter(|r| r.get("event").is_none())
        .collect()
}

/// The records of `trace` that are SDO transfers.
pub fn transfers(records: &[Json]) -> Vec<&Json> {
    records
        .iter()
        .filter(|r| r["event"] == "sdo-transfer")
        .collect()
}

/// The field named `name` of a PDO record.
pub fn field<'a>(record: &'a Json, name: &str) -> &'a Json {
    let fields = record["fields"].as_array().expect("a PDO record");
    fields
        .iter()
        .find(|f| f["name"] == name)
        .unwrap_or_else(|| panic!("no field {name} in {record}"))
}
