//! The decoder: frames in, records out. A frame is classified by its
//! identifier (a PDO COB-ID a node's file or the trace's own SDO writes
//! configured, else the predefined connection set: the runtime's
//! `frame::cob::classify`), then read with the runtime's parser for its
//! protocol.

use std::collections::BTreeMap;
use std::sync::Arc;

use eds2rust::ir::{Device, PdoDirection};
use eds2rust_runtime::emcy::Emcy;
use eds2rust_runtime::frame::cob::{self, Function};
use eds2rust_runtime::lss::proto as lss;
use eds2rust_runtime::sdo::proto::{Request, Response};
use eds2rust_runtime::time_stamp::TimeOfDay;
use eds2rust_runtime::{CanId, Frame, heartbeat, nmt, sync};

use crate::dictionary::{Dictionary, pdo_of_parameter};
use crate::pdo::{self, PdoTable};
use crate::record::{FrameRecord, Kind, LssFrame, Protocol, Record, TransferRecord, TransferValue};
use crate::sdo::{Direction, Role, SdoChannel, SdoFrame, Transfer};
use crate::value;

/// Decodes the frames of one bus, in order.
#[derive(Debug, Default)]
pub struct Decoder {
    dicts: BTreeMap<u8, Dictionary>,
    pdos: PdoTable,
    sdo: BTreeMap<u8, SdoChannel>,
    /// Nodes a guarding request was seen for: their error-control frames
    /// are guarding replies, not heartbeats.
    guarded: std::collections::BTreeSet<u8>,
}

impl Decoder {
    pub fn new() -> Decoder {
        Decoder::default()
    }

    /// Decodes node `node`'s frames with `device` (its file's IR): entry
    /// names and types, error tables, default PDO mappings.
    pub fn add_node(&mut self, node: u8, device: Arc<Device>) {
        let dict = Dictionary::new(node, device);
        self.pdos.add_node(&dict);
        self.dicts.insert(node, dict);
    }

    /// The dictionary of `node`, when it has a file.
    pub fn dictionary(&self, node: u8) -> Option<&Dictionary> {
        self.dicts.get(&node)
    }

    /// Decodes one frame of trace line `line`: its record first, then the
    /// record of the SDO transfer it ended, if any.
    pub fn frame(&mut self, line: usize, time: Option<f64>, frame: &Frame, out: &mut Vec<Record>) {
        let (id, extended) = match frame.id() {
            CanId::Standard(id) => (u32::from(id), false),
            CanId::Extended(id) => (id, true),
        };
        let mut rec = FrameRecord {
            line,
            time,
            id,
            extended,
            remote: frame.is_remote(),
            data: *frame.data_padded(),
            len: frame.len() as u8,
            node: None,
            index: None,
            subindex: None,
            name: None,
            kind: Kind::Unknown,
        };
        let mut ended = None;
        if let Some(layout) = self.pdos.lookup(&self.dicts, id, extended) {
            rec.node = Some(layout.node);
            rec.kind = pdo_kind(layout.direction, layout.number, Some(layout), frame);
        } else if !extended {
            ended = self.classified(&mut rec, frame);
        }
        out.push(Record::Frame(rec));
        if let Some(t) = ended {
            out.push(Record::Transfer(t));
        }
    }

    /// A frame on a standard identifier without a configured PDO.
    fn classified(&mut self, rec: &mut FrameRecord, frame: &Frame) -> Option<TransferRecord> {
        let data = frame.data();
        let invalid = |protocol, reason: &str| Kind::Invalid {
            protocol,
            reason: reason.into(),
        };
        match cob::classify(rec.id as u16) {
            Function::Nmt => {
                rec.kind = match nmt::parse_command(frame) {
                    Some((command, target)) => {
                        rec.node = match target {
                            nmt::NmtTarget::Node(n) => Some(n.get()),
                            nmt::NmtTarget::All => None,
                        };
                        Kind::Nmt {
                            command,
                            target: rec.node,
                        }
                    }
                    None => invalid(
                        Protocol::Nmt,
                        "not an NMT command (2 bytes: command, node id)",
                    ),
                };
            }
            Function::Sync => {
                rec.kind = match sync::parse_sync(frame) {
                    Some(counter) => Kind::Sync { counter },
                    None => invalid(Protocol::Sync, "SYNC has no data or a 1-byte counter"),
                };
            }
            Function::Time => {
                rec.kind = match frame.is_remote() {
                    true => invalid(Protocol::Time, "a remote frame"),
                    false => Kind::Time(TimeOfDay::decode(data)),
                };
            }
            Function::Emcy(node) => {
                rec.node = Some(node.get());
                rec.kind = match Emcy::parse(data) {
                    Ok(emcy) if !frame.is_remote() => {
                        let text = self
                            .dicts
                            .get(&node.get())
                            .and_then(|d| d.emcy_text(emcy.code));
                        Kind::Emcy { emcy, text }
                    }
                    Ok(_) => invalid(Protocol::Emcy, "a remote frame"),
                    Err(e) => invalid(Protocol::Emcy, &e.to_string()),
                };
            }
            Function::Tpdo(n, node) | Function::Rpdo(n, node) => {
                rec.node = Some(node.get());
                let direction = match cob::classify(rec.id as u16) {
                    Function::Tpdo(..) => PdoDirection::Tpdo,
                    _ => PdoDirection::Rpdo,
                };
                rec.kind = pdo_kind(direction, u16::from(n), None, frame);
            }
            Function::SdoTx(node) | Function::SdoRx(node) => {
                let role = match cob::classify(rec.id as u16) {
                    Function::SdoRx(_) => Role::Client,
                    _ => Role::Server,
                };
                rec.node = Some(node.get());
                return self.sdo_frame(rec, node.get(), role, frame);
            }
            Function::ErrorControl(node) => {
                let n = node.get();
                rec.node = Some(n);
                rec.kind = if frame.is_remote() {
                    self.guarded.insert(n);
                    Kind::GuardRequest
                } else {
                    match heartbeat::parse_error_control(frame) {
                        Some((_, byte)) if self.guarded.contains(&n) => Kind::GuardReply {
                            toggle: byte & 0x80 != 0,
                            state: byte & 0x7F,
                        },
                        Some((_, state)) => Kind::Heartbeat { state },
                        None => {
                            invalid(Protocol::Heartbeat, "error control frames have 1 data byte")
                        }
                    }
                };
            }
            Function::LssMaster => {
                rec.kind = match lss::Request::parse(data) {
                    Some(r) if data.len() == 8 => Kind::Lss(LssFrame::Request(r)),
                    _ => invalid(Protocol::Lss, "not an LSS request"),
                };
            }
            Function::LssSlave => {
                rec.kind = match lss::Response::parse(data) {
                    Some(r) if data.len() == 8 => Kind::Lss(LssFrame::Response(r)),
                    _ => invalid(Protocol::Lss, "not an LSS response"),
                };
            }
            Function::Other => {}
        }
        None
    }

    fn sdo_frame(
        &mut self,
        rec: &mut FrameRecord,
        node: u8,
        role: Role,
        frame: &Frame,
    ) -> Option<TransferRecord> {
        if frame.is_remote() {
            rec.kind = Kind::Invalid {
                protocol: Protocol::Sdo,
                reason: "a remote frame".into(),
            };
            return None;
        }
        let step = self.sdo.entry(node).or_default().frame(role, frame.data());
        let dict = self.dicts.get(&node);
        if let Some((index, sub)) = step.target {
            rec.index = Some(index);
            rec.subindex = Some(sub);
            rec.name = dict.and_then(|d| d.name(index, sub));
        }
        rec.kind = match (step.frame, step.error) {
            (Some(sdo), _) => {
                let abort_text =
                    abort_code(&sdo).and_then(|code| dict.and_then(|d| d.abort_text(code)));
                Kind::Sdo {
                    role,
                    frame: sdo,
                    note: step.note,
                    abort_text,
                }
            }
            (None, reason) => Kind::Invalid {
                protocol: Protocol::Sdo,
                reason: reason.unwrap_or_default(),
            },
        };
        let transfer = step.ended?;
        if transfer.direction == Direction::Download && transfer.abort.is_none() {
            self.apply_download(node, &transfer);
        }
        let (name, value) = match self.dicts.get(&node) {
            Some(d) => transfer_value(d, &transfer),
            None => (None, None),
        };
        Some(TransferRecord {
            line: rec.line,
            time: rec.time,
            node,
            transfer,
            name,
            value,
        })
    }

    /// A completed download to a PDO parameter changes the PDO.
    fn apply_download(&mut self, node: u8, t: &Transfer) {
        let Some(pdo) = pdo_of_parameter(t.index) else {
            return;
        };
        if t.data.is_empty() || t.data.len() > 4 {
            return;
        }
        let mut bytes = [0u8; 4];
        bytes[..t.data.len()].copy_from_slice(&t.data);
        self.pdos
            .write(node, pdo, t.subindex, u32::from_le_bytes(bytes));
    }
}

fn abort_code(frame: &SdoFrame) -> Option<u32> {
    match frame {
        SdoFrame::Request(Request::Abort { code, .. })
        | SdoFrame::Response(Response::Abort { code, .. }) => {
            code.description().is_none().then_some(code.code())
        }
        _ => None,
    }
}

fn transfer_value(d: &Dictionary, t: &Transfer) -> (Option<Arc<str>>, Option<TransferValue>) {
    let Some(entry) = d.entry(t.index, t.subindex) else {
        return (d.name(t.index, t.subindex), None);
    };
    let value = if t.abort.is_some() {
        None
    } else {
        let decoded = value::decode(entry.data_type, &t.data).map(|(v, _)| v);
        Some(TransferValue {
            data_type: entry.data_type,
            semantics: entry.semantics.clone(),
            value: decoded,
        })
    };
    (Some(entry.name), value)
}

/// A PDO frame: with a layout, every field's raw value.
fn pdo_kind(
    direction: PdoDirection,
    number: u16,
    layout: Option<Arc<pdo::PdoLayout>>,
    frame: &Frame,
) -> Kind {
    let data = frame.data();
    let mut fields = Vec::new();
    let mut problem = None;
    if frame.is_remote() {
        problem = Some("a remote frame (a request for the PDO)".to_string());
    } else if let Some(l) = &layout {
        if data.len() < l.len() {
            problem = Some(format!(
                "{} data bytes; the mapping has {} bits ({} bytes)",
                data.len(),
                l.bits,
                l.len()
            ));
        } else {
            let word = eds2rust_runtime::pdo::layout::word_of(data);
            fields.extend(l.fields.iter().map(|f| pdo::read_field(f, word)));
            if data.len() > l.len() {
                problem = Some(format!(
                    "{} data bytes; the mapping has {} bits ({} bytes)",
                    data.len(),
                    l.bits,
                    l.len()
                ));
            }
        }
    }
    Kind::Pdo {
        direction,
        number,
        layout,
        fields,
        problem,
    }
}
