//! A recorded CANopen session of python-canopen with a seed-device
//! simulator: the candump `-l` log of every frame on the bus, and what
//! python-canopen says it sent and received. The input of the trace
//! decoder's tests.
//!
//! The simulator of the Interroll RollerDrive EC5000 BI (`eds2rust-sim`,
//! node 127, its table `eds/interroll_ec5000bi.yaml`) runs in a thread on a
//! [`PyPeer`] port; a recording wrapper around that port logs every frame
//! the simulator receives (all python-canopen sends) and sends, in the
//! order the simulator sees them, with the time since the session began.
//! python-canopen, through its own API, then (see [`python_session_with`]):
//!
//! 1. hears the simulator's boot-up (a `RemoteNode` with the device's EDS,
//!    exported by eds2rust, with a heartbeat callback);
//! 2. uploads 0x1000 and 0x1018 sub 1 (expedited), downloads 0x1017 = 150
//!    ms (expedited), waits for a heartbeat (pre-operational), sets 0x1017
//!    back to 0;
//! 3. uploads 0x1008 "EC5000" (segmented), downloads a 19-byte string to
//!    0x6403 and uploads it back (segmented);
//! 4. block-downloads 1000 bytes to 0x6403 (two blocks: the server takes
//!    127 segments a block), block-uploads them back, block-uploads 0x6404
//!    "Interroll" (two segments);
//! 5. makes TPDO1 and TPDO2 synchronous (type 1), TPDO3 every second SYNC
//!    (type 2), disables TPDO4, reads every TPDO's configuration over SDO
//!    (`tpdo.read(from_od=False)`: 24 expedited uploads);
//! 6. starts the node (NMT), waits for its heartbeat (operational), sends
//!    two SYNCs and decodes the five TPDOs they bring (PdoMap callbacks);
//!    then NMT enter pre-operational;
//! 7. a `LocalNode` (node 0x20) boots (boot-up), sends one heartbeat in
//!    pre-operational and one in operational, then two EMCYs.
//!
//! Every SDO transfer python-canopen made (the PDO reads included) is
//! logged by `peer.py` with its protocol. Frames are stamped with the
//! session's real elapsed time from [`TRACE_EPOCH`], made strictly
//! increasing; timing decides nothing else: the same frames in the same
//! order in every run, but for the values the model computes (temperature,
//! torque) and, on a badly stalled machine, an extra heartbeat.

use std::io;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant as StdInstant};

use eds2rust_runtime::trace::candump::{Format, Writer};
use eds2rust_runtime::transport::Bus;
use eds2rust_runtime::{Frame, Instant, Service};
use serde_json::{Value, json};

use crate::peer::{PeerPort, PyPeer, hex, unhex};
use crate::seed_sim::export_eds;
use crate::served::Served;

/// The seed device the session simulates.
pub const DEVICE: &str = "interroll_ec5000bi";
/// The python-canopen `LocalNode`'s id.
pub const LOCAL_NODE: u8 = 0x20;
/// The interface name of the trace's lines.
pub const INTERFACE: &str = "vcan0";
/// The time of the session's start in the trace (2023-11-14 22:13:20 UTC).
pub const TRACE_EPOCH: Duration = Duration::from_secs(1_700_000_000);
/// The simulator's heartbeat period while python-canopen waits for one.
const HEARTBEAT_MS: u16 = 150;
/// How long the session waits for a frame to reach the recorder.
const FRAME_TIMEOUT: Duration = Duration::from_secs(3);

/// A recorded session.
#[derive(Debug, Clone, PartialEq)]
pub struct Session {
    /// The candump `-l` log of every frame, one per line.
    pub trace: String,
    /// The seed device simulated; its table is `eds/<device>.yaml`.
    pub device: &'static str,
    /// The simulated node's id.
    pub node: u8,
    /// The python-canopen `LocalNode`'s id.
    pub local_node: u8,
    /// Every SDO transfer python-canopen's client made, in order.
    pub sdo: Vec<SdoOp>,
    /// Every TPDO frame python-canopen decoded, in order.
    pub pdos: Vec<PdoSeen>,
    /// The EMCYs the `LocalNode` sent.
    pub emcy: Vec<EmcySent>,
    /// The EMCYs python-canopen received from the simulated node.
    pub emcy_received: Vec<EmcySent>,
    /// Every heartbeat and boot-up message (state 0), in order: those
    /// python-canopen received from the simulated node, then those the
    /// `LocalNode` sent. They equal the trace's 0x701..=0x77F frames.
    pub heartbeats: Vec<(u8, u8)>,
}

/// One SDO transfer of python-canopen's client.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SdoOp {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub subindex: u8,
    /// An upload (read from the node); otherwise a download.
    pub upload: bool,
    /// A block transfer.
    pub block: bool,
    /// A standard transfer that was segmented, not expedited (false for
    /// block transfers).
    pub segmented: bool,
    /// The bytes transferred as python-canopen saw them (empty when
    /// aborted).
    pub data: Vec<u8>,
    /// The abort code, when the transfer was aborted.
    pub abort: Option<u32>,
}

/// One TPDO frame python-canopen received and decoded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PdoSeen {
    /// python-canopen's number of the TPDO (1 = 0x1800/0x1A00).
    pub tpdo: u16,
    /// The COB-ID.
    pub cob_id: u32,
    /// The frame's data.
    pub data: Vec<u8>,
    /// Each mapped variable: python-canopen's name, index, sub-index, raw
    /// value.
    pub fields: Vec<(String, u16, u8, i64)>,
}

/// One EMCY message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EmcySent {
    /// The producer's node id.
    pub node: u8,
    /// The error code.
    pub code: u16,
    /// The error register.
    pub register: u8,
    /// The manufacturer-specific bytes (as given to python-canopen's
    /// `emcy.send`, which pads them with zeros to 5 on the bus; as received
    /// for [`Session::emcy_received`]).
    pub data: Vec<u8>,
}

/// The frames the simulator saw, with the times they were seen (µs since
/// the session began, strictly increasing).
struct Tap {
    start: StdInstant,
    frames: Mutex<Vec<(u64, Frame)>>,
    changed: Condvar,
}

impl Tap {
    fn lock(&self) -> MutexGuard<'_, Vec<(u64, Frame)>> {
        match self.frames.lock() {
            Ok(guard) => guard,
            Err(poisoned) => poisoned.into_inner(),
        }
    }

    fn push(&self, frame: Frame) {
        let now = u64::try_from(self.start.elapsed().as_micros()).unwrap_or(u64::MAX);
        let mut frames = self.lock();
        let at = match frames.last() {
            Some(&(last, _)) if now <= last => last + 1,
            _ => now,
        };
        frames.push((at, frame));
        self.changed.notify_all();
    }

    /// Waits until at least `count` recorded frames satisfy `pick`.
    fn wait(&self, what: &str, count: usize, pick: impl Fn(&Frame) -> bool) -> Result<(), String> {
        let deadline = StdInstant::now() + FRAME_TIMEOUT;
        let mut frames = self.lock();
        loop {
            if frames.iter().filter(|(_, f)| pick(f)).count() >= count {
                return Ok(());
            }
            let now = StdInstant::now();
            if now >= deadline {
                return Err(format!("{what}: not on the bus within {FRAME_TIMEOUT:?}"));
            }
            frames = match self.changed.wait_timeout(frames, deadline - now) {
                Ok((guard, _)) => guard,
                Err(poisoned) => poisoned.into_inner().0,
            };
        }
    }
}

/// A port that records every frame through it.
struct Recorder {
    port: PeerPort,
    tap: Arc<Tap>,
}

impl Bus for Recorder {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        self.tap.push(*frame);
        self.port.send(frame)
    }
    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        let frame = self.port.recv(timeout)?;
        if let Some(frame) = frame {
            self.tap.push(frame);
        }
        Ok(frame)
    }
}

/// The session with the Interroll EC5000 BI simulator; `simulator` is
/// `eds2rust_sim::models::interroll_ec5000bi::simulator` (eds2rust-sim is
/// a dev-dependency of this crate, so the caller passes it in).
pub fn python_session_with<S>(simulator: impl FnOnce(Instant) -> S) -> Result<Session, String>
where
    S: Service + Send + 'static,
{
    let (eds, node) = export_eds(DEVICE, "recording")?;
    let py = PyPeer::spawn()?;
    let tap = Arc::new(Tap {
        start: StdInstant::now(),
        frames: Mutex::new(Vec::new()),
        changed: Condvar::new(),
    });
    let run = Run {
        py: &py,
        tap: &tap,
        node,
    };
    run.ok(json!({"op": "remote_node_eds", "node": node, "eds": eds}))?;
    run.ok(json!({"op": "sdo_log_start", "node": node}))?;
    run.ok(json!({"op": "local_node", "node": LOCAL_NODE}))?;
    let sim = Served::start(
        Recorder {
            port: py.port(),
            tap: Arc::clone(&tap),
        },
        simulator,
    );
    let result = run.script();
    let stopped = sim.finish();
    let mut session = result.map_err(|e| py.failure(&e))?;
    stopped?;
    session.trace = trace(&tap.lock())?;
    Ok(session)
}

/// The candump `-l` log of `frames`.
fn trace(frames: &[(u64, Frame)]) -> Result<String, String> {
    let mut writer = Writer::new(Vec::new(), Format::Log);
    for (micros, frame) in frames {
        let at = TRACE_EPOCH + Duration::from_micros(*micros);
        writer
            .write_frame(Some(at), INTERFACE, frame)
            .map_err(|e| format!("writing the trace: {e}"))?;
    }
    String::from_utf8(writer.into_inner()).map_err(|e| format!("the trace is not UTF-8: {e}"))
}

/// The python-canopen side of the session.
struct Run<'a> {
    py: &'a PyPeer,
    tap: &'a Tap,
    node: u8,
}

impl Run<'_> {
    fn ok(&self, command: Value) -> Result<Value, String> {
        self.py.command_ok(command)
    }

    fn upload(&self, index: u16, sub: u8, block: bool) -> Result<Vec<u8>, String> {
        let reply = self.ok(
            json!({"op": "sdo_transfer", "node": self.node, "index": index,
                                   "sub": sub, "upload": true, "block": block}),
        )?;
        unhex(reply["value"].as_str().unwrap_or_default())
    }

    fn download(&self, index: u16, sub: u8, data: &[u8], block: bool) -> Result<(), String> {
        self.ok(
            json!({"op": "sdo_transfer", "node": self.node, "index": index, "sub": sub,
                       "upload": false, "block": block, "value": hex(data)}),
        )
        .map(drop)
    }

    /// A download, then an upload of the same object that must give it back.
    fn round_trip(&self, index: u16, data: &[u8], block: bool) -> Result<(), String> {
        self.download(index, 0, data, block)?;
        let back = self.upload(index, 0, block)?;
        if back != data {
            return Err(format!(
                "{index:#06X} read back {} bytes, not the {} written",
                back.len(),
                data.len()
            ));
        }
        Ok(())
    }

    fn heartbeat_time(&self, ms: u16) -> Result<(), String> {
        self.download(0x1017, 0, &ms.to_le_bytes(), false)
    }

    /// Turns the simulator's heartbeat on, waits for one in NMT state
    /// `state` (python-canopen's name), turns it off.
    fn one_heartbeat(&self, state: &str) -> Result<(), String> {
        self.heartbeat_time(HEARTBEAT_MS)?;
        let reply = self.ok(json!({"op": "wait_heartbeat", "node": self.node, "timeout": 2.0}))?;
        self.heartbeat_time(0)?;
        if reply["state"] != state {
            return Err(format!(
                "heartbeat in state {}, not {state}",
                reply["state"]
            ));
        }
        Ok(())
    }

    /// Waits until the recorder has seen `count` frames of `id` with `data`.
    fn on_bus(&self, what: &str, count: usize, id: u16, data: &[u8]) -> Result<(), String> {
        self.tap.wait(what, count, |f| {
            f.standard_id() == Some(id) && f.data() == data
        })
    }

    fn script(&self) -> Result<Session, String> {
        let node = self.node;
        // 1. Boot-up, heard by python-canopen.
        self.on_bus("the simulator's boot-up", 1, 0x700 + u16::from(node), &[0])?;
        let deadline = StdInstant::now() + FRAME_TIMEOUT;
        while self.heard()?.is_empty() {
            if StdInstant::now() >= deadline {
                return Err("python-canopen did not hear the boot-up".to_string());
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        // 2. Expedited transfers and a heartbeat.
        self.upload(0x1000, 0, false)?;
        self.upload(0x1018, 1, false)?;
        self.one_heartbeat("PRE-OPERATIONAL")?;
        // 3. Segmented transfers.
        self.upload(0x1008, 0, false)?;
        self.round_trip(0x6403, b"RD-EC5000BI-24V-50W", false)?;
        // 4. Block transfers.
        self.round_trip(0x6403, &catalogue_text(1000), true)?;
        self.upload(0x6404, 0, true)?;
        // 5. PDO configuration, read back by python-canopen.
        self.download(0x1800, 2, &[1], false)?;
        self.download(0x1801, 2, &[1], false)?;
        self.download(0x1802, 2, &[2], false)?;
        let tpdo4 = 0x8000_0480u32 + u32::from(node);
        self.download(0x1803, 1, &tpdo4.to_le_bytes(), false)?;
        self.ok(json!({"op": "tpdo_read", "node": node, "timeout": 1.0}))?;
        self.ok(json!({"op": "pdo_listen", "node": node}))?;
        // 6. Operational: heartbeat, two SYNCs, five TPDOs.
        self.ok(json!({"op": "nmt_command", "node": node, "command": 1}))?;
        self.one_heartbeat("OPERATIONAL")?;
        self.ok(json!({"op": "sync"}))?;
        self.ok(json!({"op": "pdo_log", "node": node, "count": 2}))?;
        self.ok(json!({"op": "sync"}))?;
        let pdos = self.ok(json!({"op": "pdo_log", "node": node, "count": 5}))?;
        self.ok(json!({"op": "nmt_command", "node": node, "command": 0x80}))?;
        // 7. The LocalNode: boot-up, two heartbeats, two EMCYs.
        let local = LOCAL_NODE;
        let heartbeat = 0x700 + u16::from(local);
        let mut sent_heartbeats = Vec::new();
        self.ok(json!({"op": "local_nmt", "node": local, "state": "INITIALISING"}))?;
        self.on_bus("the LocalNode's boot-up", 1, heartbeat, &[0])?;
        sent_heartbeats.push((local, 0));
        for state in ["PRE-OPERATIONAL", "OPERATIONAL"] {
            self.ok(json!({"op": "local_nmt", "node": local, "state": state}))?;
            let code = self.local_state()?;
            // The first heartbeat goes out at once; the next would be 1 s later.
            self.ok(json!({"op": "heartbeat_start", "node": local, "period_ms": 1000}))?;
            self.on_bus("the LocalNode's heartbeat", 1, heartbeat, &[code])?;
            self.ok(json!({"op": "heartbeat_stop", "node": local}))?;
            sent_heartbeats.push((local, code));
        }
        let emcy = vec![
            EmcySent {
                node: local,
                code: 0x3210,
                register: 0x05,
                data: vec![1, 2, 3, 4, 5],
            },
            EmcySent {
                node: local,
                code: 0x0000,
                register: 0x00,
                data: Vec::new(),
            },
        ];
        for (sent, count) in emcy.iter().zip(1..) {
            self.ok(json!({"op": "emcy", "node": local, "code": sent.code,
                           "register": sent.register, "data": hex(&sent.data)}))?;
            self.tap.wait("the LocalNode's EMCY", count, |f| {
                f.standard_id() == Some(0x80 + u16::from(local))
            })?;
        }
        // What python-canopen logged.
        let mut heartbeats: Vec<(u8, u8)> = self.heard()?.into_iter().map(|s| (node, s)).collect();
        heartbeats.extend(sent_heartbeats);
        let emcy_log = self.ok(json!({"op": "emcy_log", "node": node}))?;
        Ok(Session {
            trace: String::new(),
            device: DEVICE,
            node,
            local_node: local,
            sdo: sdo_ops(&self.ok(json!({"op": "sdo_log", "node": node}))?)?,
            pdos: pdos_seen(&pdos)?,
            emcy,
            emcy_received: emcy_received(&emcy_log, node)?,
            heartbeats,
        })
    }

    /// The state bytes of every heartbeat python-canopen heard from the node.
    fn heard(&self) -> Result<Vec<u8>, String> {
        let reply = self.ok(json!({"op": "remote_state", "node": self.node}))?;
        list(&reply, "heard")?
            .iter()
            .map(|s| int(s, "heard"))
            .collect()
    }

    fn local_state(&self) -> Result<u8, String> {
        let reply = self.ok(json!({"op": "local_state", "node": LOCAL_NODE}))?;
        int(&reply["code"], "code")
    }
}

/// `len` bytes of ASCII text for the block transfers.
fn catalogue_text(len: usize) -> Vec<u8> {
    let mut text = String::new();
    let mut line = 0;
    while text.len() < len {
        text.push_str(&format!("EC5000 BI catalogue line {line:03}; "));
        line += 1;
    }
    text.truncate(len);
    text.into_bytes()
}

fn list<'v>(reply: &'v Value, key: &str) -> Result<&'v Vec<Value>, String> {
    reply[key]
        .as_array()
        .ok_or_else(|| format!("no list {key:?} in {reply}"))
}

fn int<T: TryFrom<i64>>(value: &Value, what: &str) -> Result<T, String> {
    let number = match value {
        Value::Bool(b) => Some(i64::from(*b)),
        other => other.as_i64(),
    };
    number
        .and_then(|n| T::try_from(n).ok())
        .ok_or_else(|| format!("{what}: {value} is not an integer in range"))
}

fn bytes(value: &Value, what: &str) -> Result<Vec<u8>, String> {
    let text = value
        .as_str()
        .ok_or_else(|| format!("{what}: {value} is not hex"))?;
    unhex(text)
}

fn sdo_ops(reply: &Value) -> Result<Vec<SdoOp>, String> {
    list(reply, "log")?
        .iter()
        .map(|e| {
            Ok(SdoOp {
                index: int(&e["index"], "index")?,
                subindex: int(&e["sub"], "sub")?,
                upload: e["upload"] == true,
                block: e["block"] == true,
                segmented: e["segmented"] == true,
                data: bytes(&e["value"], "value")?,
                abort: match e.get("abort") {
                    Some(code) => Some(int(code, "abort")?),
                    None => None,
                },
            })
        })
        .collect()
}

fn pdos_seen(reply: &Value) -> Result<Vec<PdoSeen>, String> {
    list(reply, "log")?
        .iter()
        .map(|e| {
            let fields = list(e, "fields")?
                .iter()
                .map(|f| {
                    let name = f[0]
                        .as_str()
                        .ok_or_else(|| format!("no name in {f}"))?
                        .to_string();
                    Ok((
                        name,
                        int(&f[1], "index")?,
                        int(&f[2], "sub")?,
                        int(&f[3], "raw")?,
                    ))
                })
                .collect::<Result<_, String>>()?;
            Ok(PdoSeen {
                tpdo: int(&e["number"], "number")?,
                cob_id: int(&e["cob_id"], "cob_id")?,
                data: bytes(&e["data"], "data")?,
                fields,
            })
        })
        .collect()
}

fn emcy_received(reply: &Value, node: u8) -> Result<Vec<EmcySent>, String> {
    list(reply, "log")?
        .iter()
        .map(|e| {
            Ok(EmcySent {
                node,
                code: int(&e["code"], "code")?,
                register: int(&e["register"], "register")?,
                data: bytes(&e["data"], "data")?,
            })
        })
        .collect()
}
