//! Records as JSON Lines objects: the keys of docs/decode.md, serialized
//! straight from the records.

use serde::Serialize;
use serde_json::{Value as Json, json};

use super::{frame_text_with, hex, pdo_name, sdo_command, state_text, transfer_text};
use crate::pdo::Raw;
use crate::record::{FieldValue, FrameRecord, Kind, Record, TransferRecord};
use crate::sdo::{Role, SdoFrame};
use crate::value::Decoded;
use eds2rust_runtime::sdo::proto::{Request, Response};

/// A decoded value as JSON: integers as numbers (as strings when beyond
/// 64 bits), reals as numbers, text as a string, bytes as hex.
pub fn value_json(v: &Decoded) -> Json {
    match v {
        Decoded::Int(i) => int_json(*i),
        Decoded::Real(r) => json!(r),
        Decoded::Text(s) => json!(s),
        Decoded::Bytes(b) => json!(hex(b)),
    }
}

fn int_json(i: i128) -> Json {
    if let Ok(v) = i64::try_from(i) {
        json!(v)
    } else if let Ok(v) = u64::try_from(i) {
        json!(v)
    } else {
        json!(i.to_string())
    }
}

/// A decoded field as JSON: `value` is the named value, else the physical
/// value, else the raw value.
#[derive(Serialize)]
struct FieldJson<'a> {
    name: &'a str,
    index: u16,
    subindex: u8,
    value: Json,
    unit: Option<&'a str>,
    raw: Json,
    text: &'a str,
}

fn field_json(f: &FieldValue) -> FieldJson<'_> {
    let raw = match f.raw {
        Raw::Int(i) => int_json(i),
        Raw::Real(r) => json!(r),
    };
    let value = match (&f.named, f.number) {
        (Some(name), _) => json!(name),
        (None, Some(n)) => json!(n),
        (None, None) => raw.clone(),
    };
    FieldJson {
        name: &f.name,
        index: f.index,
        subindex: f.subindex,
        value,
        unit: f.unit.as_deref(),
        raw,
        text: &f.text,
    }
}

/// A frame record as JSON: the keys every frame has, then those of its
/// protocol (absent keys are not written; `Some(None)` is `null`).
#[derive(Serialize, Default)]
struct FrameJson<'a> {
    line: usize,
    time: Option<f64>,
    id: u32,
    #[serde(skip_serializing_if = "is_false")]
    extended: bool,
    #[serde(skip_serializing_if = "is_false")]
    remote: bool,
    data: String,
    protocol: &'static str,
    node: Option<u8>,
    index: Option<u16>,
    subindex: Option<u8>,
    name: Option<&'a str>,
    text: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    command: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    target: Option<Option<u8>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    counter: Option<Option<u8>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    timestamp: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    code: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    register: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    manufacturer: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    class: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<Option<&'a str>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    state: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    role: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    abort: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pdo: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    fields: Option<Vec<FieldJson<'a>>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    problem: Option<&'a str>,
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// An SDO transfer record as JSON.
#[derive(Serialize)]
struct TransferJson<'a> {
    event: &'static str,
    line: usize,
    time: Option<f64>,
    node: u8,
    index: u16,
    subindex: u8,
    direction: &'static str,
    method: &'static str,
    data: String,
    value: Json,
    name: Option<&'a str>,
    result: String,
    text: String,
}

/// A trace line that could not be read, as JSON.
#[derive(Serialize)]
struct DiagnosticJson<'a> {
    event: &'static str,
    line: usize,
    message: &'a str,
}

/// Writes a record as one JSON object (no line end), without building a
/// [`Json`] value first.
pub fn write_json(out: &mut impl std::io::Write, record: &Record) -> serde_json::Result<()> {
    match record {
        Record::Frame(r) => {
            let fields = r.kind.pdo_fields();
            serde_json::to_writer(out, &frame_json(r, &fields))
        }
        Record::Transfer(t) => serde_json::to_writer(out, &transfer_json(t)),
        Record::Diagnostic { line, message } => serde_json::to_writer(
            out,
            &DiagnosticJson {
                event: "diagnostic",
                line: *line,
                message,
            },
        ),
    }
}

/// A record as one JSON object (docs/decode.md lists the keys).
pub fn json(record: &Record) -> Json {
    let value = match record {
        Record::Frame(r) => {
            let fields = r.kind.pdo_fields();
            serde_json::to_value(frame_json(r, &fields))
        }
        Record::Transfer(t) => serde_json::to_value(transfer_json(t)),
        Record::Diagnostic { line, message } => serde_json::to_value(DiagnosticJson {
            event: "diagnostic",
            line: *line,
            message,
        }),
    };
    value.unwrap_or_else(|e| json!({"event": "diagnostic", "message": e.to_string()}))
}

fn transfer_json(t: &TransferRecord) -> TransferJson<'_> {
    let tr = &t.transfer;
    let result = match tr.abort {
        Some(code) => format!("abort {:#010x}", code.code()),
        None => "ok".into(),
    };
    let value = match t.value.as_ref().map(|v| &v.value) {
        Some(Ok(d)) => value_json(d),
        _ => Json::Null,
    };
    TransferJson {
        event: "sdo-transfer",
        line: t.line,
        time: t.time,
        node: t.node,
        index: tr.index,
        subindex: tr.subindex,
        direction: tr.direction.as_str(),
        method: tr.method,
        data: hex(&tr.data),
        value,
        name: t.name.as_deref(),
        result,
        text: transfer_text(t),
    }
}

fn frame_json<'a>(r: &'a FrameRecord, fields: &'a [FieldValue]) -> FrameJson<'a> {
    let mut j = FrameJson {
        line: r.line,
        time: r.time,
        id: r.id,
        extended: r.extended,
        remote: r.remote,
        data: hex(r.data()),
        protocol: r.protocol().as_str(),
        node: r.node,
        index: r.index,
        subindex: r.subindex,
        name: r.name.as_deref(),
        text: frame_text_with(r, fields),
        ..FrameJson::default()
    };
    match &r.kind {
        Kind::Nmt { command, target } => {
            j.command = Some(command.to_string());
            j.target = Some(*target);
        }
        Kind::Sync { counter } => j.counter = Some(*counter),
        Kind::Time(Ok(t)) => j.timestamp = Some(t.to_string()),
        Kind::Emcy { emcy, text } => {
            j.code = Some(emcy.code);
            j.register = Some(emcy.register);
            j.manufacturer = Some(hex(&emcy.manufacturer));
            j.class = Some(emcy.class());
            j.error = Some(text.as_deref());
        }
        Kind::Heartbeat { state } | Kind::GuardReply { state, .. } => {
            j.state = Some(state_text(*state))
        }
        Kind::Sdo { role, frame, .. } => {
            j.role = Some(match role {
                Role::Client => "client",
                Role::Server => "server",
            });
            j.command = Some(sdo_command(frame).to_string());
            if let SdoFrame::Request(Request::Abort { code, .. })
            | SdoFrame::Response(Response::Abort { code, .. }) = frame
            {
                j.abort = Some(code.code());
            }
        }
        Kind::Pdo {
            direction,
            number,
            problem,
            ..
        } => {
            j.pdo = Some(pdo_name(*direction, *number).to_lowercase());
            j.fields = Some(fields.iter().map(field_json).collect());
            j.problem = problem.as_deref();
        }
        _ => {}
    }
    j
}
