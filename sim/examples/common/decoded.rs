//! What the seed examples' tests share to decode the trace an example
//! recorded with its seed table (`eds2rust-decode`) and find the records
//! that carry the values the example printed.

#![allow(dead_code)]

use std::sync::Arc;

use eds2rust_decode::{Decoder, render};
use serde_json::Value as Json;

/// The IR of `eds/<name>.yaml`.
pub fn seed(name: &str) -> Arc<eds2rust::ir::Device> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../eds/{name}.yaml"));
    let loaded = eds2rust::input::read_device(&path, &eds2rust::input::Options::default());
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}",
        loaded.diagnostics.render()
    );
    Arc::new(loaded.device.expect("a device"))
}

/// A decoder that knows the nodes `nodes` by `eds/<name>.yaml`.
pub fn seed_decoder(name: &str, nodes: &[u8]) -> Decoder {
    let device = seed(name);
    let mut decoder = Decoder::new();
    for node in nodes {
        decoder.add_node(*node, device.clone());
    }
    decoder
}

/// Every record of `trace` (one frame a line) as JSON.
pub fn decode(decoder: &mut Decoder, trace: &[String]) -> Vec<Json> {
    let text = trace.join("\n");
    let mut records = Vec::new();
    let read = eds2rust_decode::decode_trace(decoder, text.as_bytes(), |r| {
        records.push(render::json(r));
        Ok(())
    })
    .expect("an in-memory trace");
    assert_eq!(
        (read.frames, read.bad_lines, read.skipped),
        (trace.len(), 0, 0)
    );
    records
}

/// Every record of `trace` decoded with `eds/<name>.yaml` at `nodes`,
/// each a valid frame ([`assert_every_frame_decodes`]).
pub fn decode_seed(name: &str, nodes: &[u8], trace: &[String]) -> Vec<Json> {
    let records = decode(&mut seed_decoder(name, nodes), trace);
    assert_every_frame_decodes(&records);
    records
}

/// Every frame is a valid CANopen frame of a known kind, every PDO has
/// its mapping and every SDO transfer names a table entry and its value.
/// (The trace has no frame the decoder could not know: the master's and
/// the drive's boot-up are heartbeats, its PDOs are the table's TPDO1-3.)
pub fn assert_every_frame_decodes(records: &[Json]) {
    for r in records {
        match r.get("event") {
            Some(event) => {
                assert_eq!(event, "sdo-transfer", "{r}");
                assert_eq!(r["result"], "ok", "{r}");
                assert!(r["name"].is_string() && !r["value"].is_null(), "{r}");
            }
            None => {
                assert_ne!(r["protocol"], "unknown", "{r}");
                let text = r["text"].as_str().expect("text");
                assert!(!text.contains("invalid frame"), "{r}");
                if r["protocol"] == "pdo" {
                    assert!(r["fields"].as_array().is_some_and(|f| !f.is_empty()), "{r}");
                    assert!(r.get("problem").is_none(), "{r}");
                }
                if r["protocol"] == "sdo" {
                    assert!(r["name"].is_string(), "{r}");
                }
            }
        }
    }
}

/// The texts of the records from `from` on, for failure messages.
pub fn texts(records: &[Json], from: usize) -> String {
    let rest = records.get(from..).unwrap_or_default();
    let lines: Vec<String> = rest
        .iter()
        .enumerate()
        .map(|(i, r)| format!("{:4} {}", from + i, r["text"].as_str().unwrap_or("?")))
        .collect();
    lines.join("\n")
}

/// The first record from `from` on that `accept` takes.
pub fn find(records: &[Json], from: usize, what: &str, accept: impl Fn(&Json) -> bool) -> usize {
    let found = records
        .get(from..)
        .and_then(|rest| rest.iter().position(accept));
    match found {
        Some(i) => from + i,
        None => panic!(
            "no record from {from} on is {what}:\n{}",
            texts(records, from)
        ),
    }
}

/// The PDO field `name` of `record`.
pub fn field<'a>(record: &'a Json, name: &str) -> &'a Json {
    record["fields"]
        .as_array()
        .and_then(|fields| fields.iter().find(|f| f["name"] == name))
        .unwrap_or_else(|| panic!("no field {name} in {record}"))
}

/// The physical value and unit of a transfer (`...: 50 (0x32) = 50 mm/s`).
pub fn physical(record: &Json) -> (f64, String) {
    let text = record["text"].as_str().expect("text");
    let method = format!("({}): ", record["method"].as_str().expect("method"));
    let shown = text.split_once(&method).map_or(text, |(_, v)| v);
    let (_, value) = shown
        .split_once(" = ")
        .unwrap_or_else(|| panic!("no physical value in {record}"));
    let value = value.split(';').next().unwrap_or(value);
    let (number, unit) = value.split_once(' ').unwrap_or((value, ""));
    let number = number
        .parse()
        .unwrap_or_else(|_| panic!("{number} is no number in {record}"));
    (number, unit.to_string())
}

/// `text` (a decoded statusword or controlword) names CiA 402 state or
/// command `name` as the example printed it.
pub fn names_state(text: &str, name: &str) -> bool {
    text.contains(&format!("state \"{}\"", name.to_lowercase()))
}
