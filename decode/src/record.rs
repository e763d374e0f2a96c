//! What the decoder says: one record per frame, one per SDO transfer that
//! ended, one per trace line that could not be read. Records hold the
//! decoded values; their text and JSON forms are made on demand.

use std::sync::Arc;

use eds2rust::ir::{DataType, PdoDirection, Semantics};
use eds2rust_runtime::emcy::Emcy;
use eds2rust_runtime::lss::proto as lss;
use eds2rust_runtime::nmt::NmtCommand;
use eds2rust_runtime::time_stamp::{TimeError, TimeOfDay};

use crate::error::ValueError;
use crate::pdo::{PdoLayout, Raw};
use crate::sdo::{Role, SdoFrame, Transfer};
use crate::value::Decoded;

/// The protocol of a frame (CiA 301, CiA 305).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Protocol {
    Nmt,
    Sync,
    Time,
    Emcy,
    Heartbeat,
    Guarding,
    Lss,
    Sdo,
    Pdo,
    Unknown,
}

impl Protocol {
    /// The name used in JSON (`"nmt"`, `"sdo"`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            Protocol::Nmt => "nmt",
            Protocol::Sync => "sync",
            Protocol::Time => "time",
            Protocol::Emcy => "emcy",
            Protocol::Heartbeat => "heartbeat",
            Protocol::Guarding => "guarding",
            Protocol::Lss => "lss",
            Protocol::Sdo => "sdo",
            Protocol::Pdo => "pdo",
            Protocol::Unknown => "unknown",
        }
    }
}

/// An LSS frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LssFrame {
    Request(lss::Request),
    Response(lss::Response),
}

/// What a frame is, with its decoded content.
#[derive(Debug, Clone)]
pub enum Kind {
    Nmt {
        command: NmtCommand,
        /// `None`: all nodes.
        target: Option<u8>,
    },
    Sync {
        counter: Option<u8>,
    },
    Time(Result<TimeOfDay, TimeError>),
    Emcy {
        emcy: Emcy,
        /// The device's text for the code, from its file's error tables.
        text: Option<String>,
    },
    /// Heartbeat or boot-up (state byte 0).
    Heartbeat {
        state: u8,
    },
    GuardRequest,
    GuardReply {
        toggle: bool,
        state: u8,
    },
    Lss(LssFrame),
    Sdo {
        role: Role,
        frame: SdoFrame,
        note: Option<&'static str>,
        /// The device's text for a vendor abort code.
        abort_text: Option<String>,
    },
    Pdo {
        direction: PdoDirection,
        number: u16,
        /// The PDO's mapping, when the node has a file.
        layout: Option<Arc<PdoLayout>>,
        /// The raw value of every field of `layout`, in its order.
        fields: Vec<Raw>,
        /// Why the data does not fit the mapping.
        problem: Option<String>,
    },
    /// A frame on a known identifier whose content is not valid for it.
    Invalid {
        protocol: Protocol,
        reason: String,
    },
    Unknown,
}

/// One frame of the trace.
#[derive(Debug, Clone)]
pub struct FrameRecord {
    /// The trace line (1-based).
    pub line: usize,
    /// Seconds, as the trace gives them.
    pub time: Option<f64>,
    pub id: u32,
    pub extended: bool,
    pub remote: bool,
    pub data: [u8; 8],
    pub len: u8,
    pub node: Option<u8>,
    pub index: Option<u16>,
    pub subindex: Option<u8>,
    pub name: Option<Arc<str>>,
    pub kind: Kind,
}

impl FrameRecord {
    pub fn data(&self) -> &[u8] {
        &self.data[..usize::from(self.len)]
    }

    pub fn protocol(&self) -> Protocol {
        match &self.kind {
            Kind::Nmt { .. } => Protocol::Nmt,
            Kind::Sync { .. } => Protocol::Sync,
            Kind::Time(_) => Protocol::Time,
            Kind::Emcy { .. } => Protocol::Emcy,
            Kind::Heartbeat { .. } => Protocol::Heartbeat,
            Kind::GuardRequest | Kind::GuardReply { .. } => Protocol::Guarding,
            Kind::Lss(_) => Protocol::Lss,
            Kind::Sdo { .. } => Protocol::Sdo,
            Kind::Pdo { .. } => Protocol::Pdo,
            Kind::Invalid { protocol, .. } => *protocol,
            Kind::Unknown => Protocol::Unknown,
        }
    }
}

/// The value of an SDO transfer's data, decoded by the entry's type.
#[derive(Debug, Clone)]
pub struct TransferValue {
    pub data_type: DataType,
    pub semantics: Arc<Semantics>,
    /// The value, or why the data is no value of the type.
    pub value: Result<Decoded, ValueError>,
}

/// An SDO transfer that ended (done or aborted).
#[derive(Debug, Clone)]
pub struct TransferRecord {
    /// The line of the frame that ended it.
    pub line: usize,
    pub time: Option<f64>,
    pub node: u8,
    pub transfer: Transfer,
    pub name: Option<Arc<str>>,
    /// `None` when the node has no file or the file lacks the entry.
    pub value: Option<TransferValue>,
}

/// Everything the decoder reports.
#[derive(Debug, Clone)]
pub enum Record {
    Frame(FrameRecord),
    Transfer(TransferRecord),
    /// A trace line that could not be read.
    Diagnostic {
        line: usize,
        message: String,
    },
}

/// One decoded PDO field, as it is shown.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldValue {
    pub name: Arc<str>,
    /// The mapped entry.
    pub index: u16,
    pub subindex: u8,
    pub raw: Raw,
    /// The named value, if the entry's table names this raw value.
    pub named: Option<String>,
    /// The physical value (scale, offset) or the REAL's number.
    pub number: Option<f64>,
    pub unit: Option<String>,
    /// The value for a person (as `eds2rust sdo read` prints it).
    pub text: String,
}

impl Kind {
    /// The fields of a PDO with their meaning; empty for other frames.
    pub fn pdo_fields(&self) -> Vec<FieldValue> {
        let Kind::Pdo {
            layout: Some(layout),
            fields,
            ..
        } = self
        else {
            return Vec::new();
        };
        layout
            .fields
            .iter()
            .zip(fields)
            .map(|(f, &raw)| FieldValue {
                index: f.index,
                subindex: f.subindex,
                ..field_value(&f.name, f.data_type, &f.semantics, raw)
            })
            .collect()
    }
}

fn field_value(name: &Arc<str>, t: Option<DataType>, sem: &Semantics, raw: Raw) -> FieldValue {
    use crate::value;
    let (named, number, decoded) = match raw {
        Raw::Int(v) => (
            value::named_value(sem, v),
            value::physical_value(sem, v),
            Decoded::Int(v),
        ),
        Raw::Real(v) => (None, Some(v), Decoded::Real(v)),
    };
    let text = match t {
        Some(t) => value::describe(t, sem, &decoded),
        None => value::plain(&decoded),
    };
    FieldValue {
        name: name.clone(),
        index: 0,
        subindex: 0,
        raw,
        named,
        number,
        unit: sem.unit.clone(),
        text,
    }
}
