//! Decoding of CANopen traffic into named, typed values, from object
//! dictionaries read at run time (EDS/DCF files and YAML tables lowered to
//! the IR of the `eds2rust` crate): no generated code is needed.
//!
//! A [`Decoder`] takes the frames of one bus in order and gives
//! [`Record`]s: what every frame is per CiA 301 and CiA 305 (NMT, SYNC,
//! TIME, EMCY, heartbeat and boot-up, node guarding, LSS, SDO, PDO), the
//! mapped fields of PDOs of nodes with a file (default mappings, changed by
//! the SDO writes the traffic itself makes to 0x1400–0x1BFF), and SDO
//! transfers reassembled into one value. Frames are classified with the
//! runtime's predefined-connection-set classifier and read with the
//! runtime's own frame parsers; PDO fields with its PDO codec.
//!
//! `eds2rust decode` (recorded traces) and `eds2rust monitor` (a live bus)
//! are this crate behind a command line; docs/decode.md describes both.

mod decoded;
pub mod decoder;
pub mod dictionary;
pub mod error;
pub mod pdo;
pub mod record;
pub mod render;
pub mod sdo;
pub mod value;

pub use decoder::Decoder;
pub use error::{TraceDecodeError, UnknownType, ValueError};
pub use record::{FrameRecord, Kind, Protocol, Record, TransferRecord};

use std::io::{self, BufRead};

use eds2rust_runtime::trace::{ErrorKind, Reader};

/// What [`decode_trace`] read.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Summary {
    /// Frames decoded.
    pub frames: usize,
    /// Lines that could not be read (each gave a [`Record::Diagnostic`]).
    pub bad_lines: usize,
    /// Messages of a `.trc` file that are no classic CAN frames (error
    /// frames, status, CAN FD); each gave a [`Record::Diagnostic`] too.
    pub skipped: usize,
}

/// Decodes a recorded trace in any form the runtime's trace reader knows
/// (candump log, text and compact lines; PCAN-View `.trc` files), handing
/// every record to `sink` in order. Bad lines become diagnostics and
/// decoding goes on; only a failure to read `input`
/// ([`TraceDecodeError::Read`]) or an error of `sink`
/// ([`TraceDecodeError::Sink`]) ends it.
pub fn decode_trace<R: BufRead>(
    decoder: &mut Decoder,
    input: R,
    mut sink: impl FnMut(&Record) -> io::Result<()>,
) -> Result<Summary, TraceDecodeError> {
    let mut summary = Summary::default();
    let mut records = Vec::new();
    for item in Reader::new(input) {
        match item {
            Ok(line) => {
                summary.frames += 1;
                let time = line.time.map(|t| t.as_secs_f64());
                decoder.frame(line.line, time, &line.frame, &mut records);
                for r in records.drain(..) {
                    sink(&r).map_err(TraceDecodeError::Sink)?;
                }
            }
            Err(e) if e.kind == ErrorKind::Io => return Err(TraceDecodeError::Read(e)),
            Err(e) => {
                match e.kind {
                    ErrorKind::Skipped => summary.skipped += 1,
                    _ => summary.bad_lines += 1,
                }
                sink(&Record::Diagnostic {
                    line: e.line,
                    message: e.message,
                })
                .map_err(TraceDecodeError::Sink)?;
            }
        }
    }
    Ok(summary)
}
