//! Records as text (one line each, for a person) and as JSON (one object
//! each, JSON Lines: docs/decode.md lists the keys; the `json` module).

mod json;

pub use json::{json, value_json, write_json};

use std::fmt::Write as _;

use eds2rust::ir::PdoDirection;
use eds2rust_runtime::sdo::AbortCode;
use eds2rust_runtime::sdo::proto::{Initiate, Request, Response};

use crate::record::{FieldValue, FrameRecord, Kind, LssFrame, Record, TransferRecord};
use crate::sdo::{Role, SdoFrame};
use crate::value;

/// Data bytes as compact hex (`1A0006`), as JSON carries them.
pub fn hex(data: &[u8]) -> String {
    data.iter()
        .fold(String::with_capacity(data.len() * 2), |mut s, b| {
            let _ = write!(s, "{b:02X}");
            s
        })
}

fn index_text(index: u16, sub: u8) -> String {
    format!("0x{index:04X}.{sub}")
}

fn pdo_name(direction: PdoDirection, number: u16) -> String {
    match direction {
        PdoDirection::Tpdo => format!("TPDO{number}"),
        PdoDirection::Rpdo => format!("RPDO{number}"),
    }
}

fn abort_text(code: AbortCode, vendor: Option<&String>) -> String {
    match (code.description(), vendor) {
        (None, Some(text)) => format!("abort {:#010X} ({text})", code.code()),
        _ => format!("abort {code}"),
    }
}

/// What an SDO frame says, without its index (the record names it).
fn sdo_text(frame: &SdoFrame) -> String {
    let init = |what: &str, data: &Initiate| match data {
        Initiate::Expedited { data, len } => {
            let n = usize::from(len.unwrap_or(4));
            format!("{what} (expedited): {}", value::hex_bytes(&data[..n]))
        }
        Initiate::Segmented { size: Some(size) } => format!("{what} (segmented, {size} bytes)"),
        Initiate::Segmented { size: None } => format!("{what} (segmented, size not indicated)"),
    };
    let last = |last: bool| if last { ", last" } else { "" };
    match frame {
        SdoFrame::Request(r) => match r {
            Request::DownloadInitiate { data, .. } => init("download request", data),
            Request::DownloadSegment {
                toggle,
                last: l,
                data,
                len,
            } => format!(
                "download segment (toggle {}{}): {}",
                u8::from(*toggle),
                last(*l),
                value::hex_bytes(&data[..usize::from(*len)])
            ),
            Request::UploadInitiate { .. } => "upload request".into(),
            Request::UploadSegment { toggle } => {
                format!("upload segment request (toggle {})", u8::from(*toggle))
            }
            Request::BlockDownloadInitiate { size, crc, .. } => match size {
                Some(size) => format!(
                    "block download request ({size} bytes{})",
                    if *crc { ", CRC" } else { "" }
                ),
                None => "block download request (size not indicated)".into(),
            },
            Request::BlockDownloadEnd { unused, crc } => {
                format!(
                    "block download end ({unused} unused bytes in the last segment, CRC {crc:#06X})"
                )
            }
            Request::BlockUploadInitiate {
                block_size, pst, ..
            } => {
                format!(
                    "block upload request (block size {block_size}, protocol switch threshold {pst})"
                )
            }
            Request::BlockUploadStart => "block upload start".into(),
            Request::BlockUploadAck {
                ack_seq,
                block_size,
            } => {
                format!(
                    "block upload acknowledged up to segment {ack_seq} (next block size {block_size})"
                )
            }
            Request::BlockUploadEnd => "block upload end confirmed".into(),
            Request::Abort { code, .. } => abort_text(*code, None),
        },
        SdoFrame::Response(r) => match r {
            Response::DownloadInitiate { .. } => "download confirmed".into(),
            Response::DownloadSegment { toggle } => {
                format!("download segment confirmed (toggle {})", u8::from(*toggle))
            }
            Response::UploadInitiate { data, .. } => init("upload response", data),
            Response::UploadSegment {
                toggle,
                last: l,
                data,
                len,
            } => format!(
                "upload segment (toggle {}{}): {}",
                u8::from(*toggle),
                last(*l),
                value::hex_bytes(&data[..usize::from(*len)])
            ),
            Response::BlockDownloadInitiate { block_size, .. } => {
                format!("block download accepted (block size {block_size})")
            }
            Response::BlockDownloadAck {
                ack_seq,
                block_size,
            } => {
                format!(
                    "block download acknowledged up to segment {ack_seq} (next block size {block_size})"
                )
            }
            Response::BlockDownloadEnd => "block download end confirmed".into(),
            Response::BlockUploadInitiate { size, .. } => match size {
                Some(size) => format!("block upload response ({size} bytes)"),
                None => "block upload response (size not indicated)".into(),
            },
            Response::BlockUploadEnd { unused, crc } => {
                format!(
                    "block upload end ({unused} unused bytes in the last segment, CRC {crc:#06X})"
                )
            }
            Response::Abort { code, .. } => abort_text(*code, None),
        },
        SdoFrame::BlockSegment(s) => format!(
            "block segment {}{}: {}",
            s.seq,
            last(s.last),
            value::hex_bytes(&s.data)
        ),
    }
}

/// The SDO command as a JSON key (`upload-request`, `block-segment`, ...).
fn sdo_command(frame: &SdoFrame) -> &'static str {
    match frame {
        SdoFrame::Request(r) => match r {
            Request::DownloadInitiate { .. } => "download-request",
            Request::DownloadSegment { .. } => "download-segment",
            Request::UploadInitiate { .. } => "upload-request",
            Request::UploadSegment { .. } => "upload-segment-request",
            Request::BlockDownloadInitiate { .. } => "block-download-request",
            Request::BlockDownloadEnd { .. } => "block-download-end",
            Request::BlockUploadInitiate { .. } => "block-upload-request",
            Request::BlockUploadStart => "block-upload-start",
            Request::BlockUploadAck { .. } => "block-upload-ack",
            Request::BlockUploadEnd => "block-upload-end",
            Request::Abort { .. } => "abort",
        },
        SdoFrame::Response(r) => match r {
            Response::DownloadInitiate { .. } => "download-response",
            Response::DownloadSegment { .. } => "download-segment-response",
            Response::UploadInitiate { .. } => "upload-response",
            Response::UploadSegment { .. } => "upload-segment",
            Response::BlockDownloadInitiate { .. } => "block-download-response",
            Response::BlockDownloadAck { .. } => "block-download-ack",
            Response::BlockDownloadEnd => "block-download-end-response",
            Response::BlockUploadInitiate { .. } => "block-upload-response",
            Response::BlockUploadEnd { .. } => "block-upload-end",
            Response::Abort { .. } => "abort",
        },
        SdoFrame::BlockSegment(_) => "block-segment",
    }
}

fn node_text(node: Option<u8>) -> String {
    node.map_or_else(String::new, |n| format!(" node {n}"))
}

/// What a frame is, for a person.
pub fn frame_text(r: &FrameRecord) -> String {
    frame_text_with(r, &r.kind.pdo_fields())
}

/// [`frame_text`] with the PDO fields already made.
fn frame_text_with(r: &FrameRecord, fields: &[FieldValue]) -> String {
    let node = node_text(r.node);
    let named = |r: &FrameRecord| match (r.index, r.subindex) {
        (Some(i), Some(s)) => match &r.name {
            Some(name) => format!(" {} {name}", index_text(i, s)),
            None => format!(" {}", index_text(i, s)),
        },
        _ => String::new(),
    };
    match &r.kind {
        Kind::Nmt { command, target } => match target {
            Some(n) => format!("NMT {command} → node {n}"),
            None => format!("NMT {command} → all nodes"),
        },
        Kind::Sync { counter: Some(c) } => format!("SYNC counter {c}"),
        Kind::Sync { counter: None } => "SYNC".into(),
        Kind::Time(Ok(t)) => format!("TIME {t}"),
        Kind::Time(Err(e)) => format!("TIME (invalid: {e})"),
        Kind::Emcy { emcy, text } => {
            let mut s = if emcy.is_reset() {
                format!(
                    "EMCY{node}: error reset, error register {:#04X}",
                    emcy.register
                )
            } else {
                format!("EMCY{node}: {emcy}")
            };
            if emcy.manufacturer != [0; 5] {
                let _ = write!(
                    s,
                    ", manufacturer bytes {}",
                    value::hex_bytes(&emcy.manufacturer)
                );
            }
            if let Some(text) = text {
                let _ = write!(s, "; {text}");
            }
            s
        }
        Kind::Heartbeat { state: 0 } => format!("boot-up{node}"),
        Kind::Heartbeat { state } => format!("heartbeat{node}: {}", state_text(*state)),
        Kind::GuardRequest => format!("node guarding request{node}"),
        Kind::GuardReply { toggle, state } => {
            format!(
                "node guarding reply{node}: {}, toggle {}",
                state_text(*state),
                u8::from(*toggle)
            )
        }
        Kind::Lss(LssFrame::Request(q)) => format!("LSS request: {q:?}"),
        Kind::Lss(LssFrame::Response(q)) => format!("LSS response: {q:?}"),
        Kind::Sdo {
            role,
            frame,
            note,
            abort_text: vendor,
        } => {
            let who = match role {
                Role::Client => format!("SDO client →{node}"),
                Role::Server => format!("SDO{node} → client"),
            };
            let mut what = match (frame, vendor) {
                (SdoFrame::Request(Request::Abort { code, .. }), Some(_))
                | (SdoFrame::Response(Response::Abort { code, .. }), Some(_)) => {
                    abort_text(*code, vendor.as_ref())
                }
                _ => sdo_text(frame),
            };
            if let Some(note) = note {
                let _ = write!(what, " ({note})");
            }
            format!("{who}:{} {what}", named(r))
        }
        Kind::Pdo {
            direction,
            number,
            layout,
            problem,
            ..
        } => {
            let mut s = format!("{}{node}", pdo_name(*direction, *number));
            if let Some(label) = layout.as_ref().and_then(|l| l.label.as_ref()) {
                let _ = write!(s, " ({label})");
            }
            if !fields.is_empty() {
                let list: Vec<String> = fields
                    .iter()
                    .map(|f| format!("{}={}", f.name, f.text))
                    .collect();
                let _ = write!(s, ": {}", list.join(", "));
            } else if layout.is_none() {
                s.push_str(": no mapping known for it");
            }
            if let Some(p) = problem {
                let _ = write!(s, " ({p})");
            }
            s
        }
        Kind::Invalid { protocol, reason } => format!(
            "{}{node}: invalid frame: {reason}",
            protocol.as_str().to_uppercase()
        ),
        Kind::Unknown => "not a CANopen frame of the predefined connection set".into(),
    }
}

fn state_text(state: u8) -> String {
    match eds2rust_runtime::nmt::NmtState::from_byte(state) {
        Some(s) => s.to_string(),
        None => format!("state {state:#04X} (no CiA 301 state)"),
    }
}

/// The value of a transfer, for a person.
pub fn transfer_text(t: &TransferRecord) -> String {
    let tr = &t.transfer;
    let name = t
        .name
        .as_ref()
        .map_or_else(String::new, |n| format!(" {n}"));
    let head = format!(
        "SDO {} {}{name}, node {} ({})",
        tr.direction.as_str(),
        index_text(tr.index, tr.subindex),
        t.node,
        tr.method
    );
    if let Some(code) = tr.abort {
        return format!("{head}: {}", abort_text(code, None));
    }
    let shown = match &t.value {
        Some(v) => match &v.value {
            Ok(d) => value::describe(v.data_type, &v.semantics, d),
            Err(why) => format!("{} ({why})", value::hex_bytes(&tr.data)),
        },
        None => value::hex_bytes(&tr.data),
    };
    format!("{head}: {shown}")
}

/// A record as one line of text.
pub fn text(record: &Record) -> String {
    match record {
        Record::Frame(r) => {
            let time = r
                .time
                .map_or_else(|| "-".to_string(), |t| format!("{t:.6}"));
            let id = if r.extended {
                format!("{:08X}", r.id)
            } else {
                format!("{:03X}", r.id)
            };
            let data = if r.remote {
                format!("[{}] remote request", r.len)
            } else {
                format!("[{}] {}", r.len, spaced(r.data()))
            };
            format!(
                "{:>6} {time:>17} {id:>8} {data:<28} {}",
                r.line,
                frame_text(r)
            )
        }
        Record::Transfer(t) => format!(
            "{:>6} {:>17} {:>8} {:<28} {}",
            t.line,
            "",
            "",
            "",
            transfer_text(t)
        ),
        Record::Diagnostic { line, message } => format!("{line:>6} error: {message}"),
    }
}

fn spaced(data: &[u8]) -> String {
    let mut s = String::with_capacity(data.len() * 3);
    for (i, b) in data.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{b:02X}");
    }
    s
}
