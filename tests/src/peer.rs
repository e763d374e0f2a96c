//! A python-canopen peer on the other end of a CAN bus: the process
//! `tests/python/peer.py`, run with the oracle's interpreter.
//!
//! Frames travel as candump compact lines (`F 123#1122`): [`PyPeer`] and its
//! [`PeerPort`]s implement [`Bus`], so the runtime's protocol cores talk to
//! python-canopen as they would to a device. Commands (`C {json}`) make
//! python-canopen act (create a LocalNode, run an SDO transfer, send NMT or
//! EMCY) and are answered with `R {json}` when done; see `peer.py` for the
//! operations.
//!
//! Every failure of the harness itself (the process died, a reply did not
//! come) is an `Err` that carries Python's stderr.

use std::collections::{HashMap, VecDeque};
use std::io::{self, BufRead, BufReader, Read, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, OnceLock, mpsc};
use std::thread;
use std::time::{Duration, Instant};

use eds2rust_runtime::trace::candump::parse_frame;
use eds2rust_runtime::transport::Bus;
use eds2rust_runtime::{CanId, Frame};
use serde_json::Value;

use crate::python::{python, scripts_dir};

mod reply;
mod step;

pub use reply::{Outcome, hex, unhex};
pub use step::{flush, run_until, step};

/// How long [`PyPeer::command`] waits for a reply.
pub const COMMAND_TIMEOUT: Duration = Duration::from_secs(10);
/// How long [`PyPeer::spawn`] waits for the peer to report that it is ready.
pub const STARTUP_TIMEOUT: Duration = Duration::from_secs(30);
/// The part of Python's stderr kept for error messages (its last bytes).
const STDERR_KEPT: usize = 32 * 1024;
/// The identifier of the marker frames of [`PyPeer::settle`] and
/// [`PyPeer::barrier`]: one CANopen does not use.
pub const MARKER_ID: u16 = 0x7FF;
/// The number of exchanged lines kept for failure messages.
const TRACE_KEPT: usize = 60;

/// A running `peer.py`. Dropping it quits and kills the process.
pub struct PyPeer {
    link: Arc<Link>,
    port: Mutex<PeerPort>,
    child: Mutex<Child>,
}

/// One receiver of the frames python-canopen sends (every port gets every
/// frame sent after it was opened), and a sender of frames to it.
pub struct PeerPort {
    link: Arc<Link>,
    frames: mpsc::Receiver<Frame>,
}

/// What the reader threads share with the peer's handles.
struct Link {
    stdin: Mutex<Option<ChildStdin>>,
    state: Mutex<LinkState>,
    changed: Condvar,
    next_id: AtomicU64,
}

#[derive(Default)]
struct LinkState {
    replies: HashMap<u64, Value>,
    ports: Vec<mpsc::Sender<Frame>>,
    stdout_closed: bool,
    stderr_closed: bool,
    stderr: String,
    /// stdout lines that are neither frames nor replies.
    stray: Vec<String>,
    /// The last lines exchanged, both ways, for failure messages.
    trace: VecDeque<String>,
}

impl PyPeer {
    /// Starts `peer.py` (creating the oracle's venv if needed) and waits
    /// until it is ready.
    pub fn spawn() -> Result<PyPeer, String> {
        let interpreter = python()?;
        let script = scripts_dir().join("peer.py");
        let mut child = Command::new(&interpreter)
            .arg(&script)
            .env("PYTHONUNBUFFERED", "1")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("cannot start {}: {e}", script.display()))?;
        let (Some(stdin), Some(stdout), Some(stderr)) =
            (child.stdin.take(), child.stdout.take(), child.stderr.take())
        else {
            let _ = child.kill();
            return Err("peer.py started without its pipes".to_string());
        };
        let link = Arc::new(Link {
            stdin: Mutex::new(Some(stdin)),
            state: Mutex::new(LinkState::default()),
            changed: Condvar::new(),
            // Id 0 is the ready message.
            next_id: AtomicU64::new(1),
        });
        let port = link.port();
        let out_link = Arc::clone(&link);
        thread::spawn(move || out_link.read_stdout(stdout));
        let err_link = Arc::clone(&link);
        thread::spawn(move || err_link.read_stderr(stderr));
        let peer = PyPeer {
            link,
            port: Mutex::new(port),
            child: Mutex::new(child),
        };
        peer.reply(0, STARTUP_TIMEOUT)
            .map_err(|e| format!("peer.py did not start: {e}"))?;
        Ok(peer)
    }

    /// A new receiver of every frame python-canopen sends from now on.
    pub fn port(&self) -> PeerPort {
        self.link.port()
    }

    /// Sends a command without waiting; returns its id for [`PyPeer::reply`].
    /// `command` is a JSON object with an `"op"`; its `"id"` is set here.
    pub fn start(&self, command: Value) -> Result<u64, String> {
        let Value::Object(mut fields) = command else {
            return Err(format!("a command is a JSON object, not {command}"));
        };
        let id = self.link.next_id.fetch_add(1, Ordering::Relaxed);
        fields.insert("id".to_string(), Value::from(id));
        self.link
            .send_line(&format!("C {}", Value::Object(fields)))?;
        Ok(id)
    }

    /// Waits up to `timeout` for the reply to command `id`.
    pub fn reply(&self, id: u64, timeout: Duration) -> Result<Value, String> {
        let deadline = Instant::now() + timeout;
        let mut state = self.link.lock();
        loop {
            if let Some(reply) = state.replies.remove(&id) {
                return Ok(reply);
            }
            if state.stdout_closed {
                drop(state);
                return Err(self.link.exited(&format!("waiting for reply {id}")));
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(format!(
                    "no reply to command {id} within {timeout:?}{}",
                    tail("stderr", &state.stderr)
                ));
            }
            state = match self.link.changed.wait_timeout(state, deadline - now) {
                Ok((guard, _)) => guard,
                Err(poisoned) => poisoned.into_inner().0,
            };
        }
    }

    /// The reply to command `id` when it has come (and removes it).
    pub fn try_reply(&self, id: u64) -> Result<Option<Value>, String> {
        let mut state = self.link.lock();
        if let Some(reply) = state.replies.remove(&id) {
            return Ok(Some(reply));
        }
        if state.stdout_closed {
            drop(state);
            return Err(self.link.exited(&format!("waiting for reply {id}")));
        }
        Ok(None)
    }

    /// Runs a command and waits for its reply (up to [`COMMAND_TIMEOUT`]).
    /// The reply holds `"ok": true` and the results, `"abort"` (an SDO abort
    /// code) or `"error"` (any other Python exception).
    pub fn command(&self, command: Value) -> Result<Value, String> {
        let id = self.start(command)?;
        self.reply(id, COMMAND_TIMEOUT)
    }

    /// Runs a command that must succeed; any other reply is an `Err` with
    /// the reply and Python's stderr.
    pub fn command_ok(&self, command: Value) -> Result<Value, String> {
        let text = command.to_string();
        let reply = self.command(command)?;
        if reply.get("ok") == Some(&Value::Bool(true)) {
            Ok(reply)
        } else {
            Err(self.failure(&format!("{text} answered {reply}")))
        }
    }

    /// Waits until every frame python-canopen sent before this call has
    /// reached `port`, and returns those frames (they are taken off the
    /// port). Works by sending a marker frame (id 0x7FF, which CANopen does
    /// not use) from python-canopen and reading up to it; markers of other
    /// calls are skipped.
    pub fn settle(&self, port: &mut PeerPort) -> Result<Vec<Frame>, String> {
        let token = self.link.next_id.fetch_add(1, Ordering::Relaxed);
        let marker = Frame::new(CanId::Standard(MARKER_ID), &token.to_le_bytes())
            .map_err(|e| e.to_string())?;
        self.command_ok(serde_json::json!({"op": "send", "frame": marker.to_string()}))?;
        let deadline = Instant::now() + COMMAND_TIMEOUT;
        let mut before = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match port.recv(left) {
                Ok(Some(frame)) if frame == marker => return Ok(before),
                Ok(Some(frame)) if frame.standard_id() == Some(MARKER_ID) => {}
                Ok(Some(frame)) => before.push(frame),
                Ok(None) => return Err(self.failure("the marker frame did not come back")),
                Err(e) => return Err(e.to_string()),
            }
        }
    }

    /// Waits until python-canopen has handled every frame sent to it before
    /// this call (through any port). Works by sending a marker frame (id
    /// 0x7FF) and waiting for python-canopen to receive it.
    pub fn barrier(&self) -> Result<(), String> {
        let token = self.link.next_id.fetch_add(1, Ordering::Relaxed);
        let marker = Frame::new(CanId::Standard(MARKER_ID), &token.to_le_bytes())
            .map_err(|e| e.to_string())?;
        self.link.send_frame(&marker).map_err(|e| e.to_string())?;
        let token = hex(&token.to_le_bytes());
        self.command_ok(serde_json::json!({"op": "barrier", "token": token}))
            .map(drop)
    }

    /// Everything Python wrote to stderr so far (its last 32 KiB).
    pub fn stderr(&self) -> String {
        self.link.lock().stderr.clone()
    }

    /// Waits up to `timeout` until Python's stderr contains `needle`
    /// (stderr is read by its own thread, so it may lag behind replies).
    pub fn stderr_contains(&self, needle: &str, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        let mut state = self.link.lock();
        loop {
            if state.stderr.contains(needle) {
                return true;
            }
            let now = Instant::now();
            if now >= deadline || state.stderr_closed {
                return false;
            }
            state = match self.link.changed.wait_timeout(state, deadline - now) {
                Ok((guard, _)) => guard,
                Err(poisoned) => poisoned.into_inner().0,
            };
        }
    }

    /// `what`, followed by the last lines exchanged with the peer (all
    /// ports, `->` to Python) and Python's stderr: for failure messages.
    pub fn failure(&self, what: &str) -> String {
        let state = self.link.lock();
        let trace: Vec<&str> = state.trace.iter().map(String::as_str).collect();
        format!(
            "{what}{}{}",
            tail("last lines exchanged", &trace.join("\n")),
            tail("python stderr", &state.stderr)
        )
    }
}

impl Bus for PyPeer {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        self.link.send_frame(frame)
    }
    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        match self.port.get_mut() {
            Ok(port) => port.recv(timeout),
            Err(poisoned) => poisoned.into_inner().recv(timeout),
        }
    }
}

impl Drop for PyPeer {
    fn drop(&mut self) {
        let _ = self.link.send_line("Q");
        if let Ok(mut stdin) = self.link.stdin.lock() {
            stdin.take();
        }
        let child = match self.child.get_mut() {
            Ok(child) => child,
            Err(poisoned) => poisoned.into_inner(),
        };
        let _ = child.kill();
        let _ = child.wait();
    }
}

impl PeerPort {
    /// Drops every frame received so far.
    pub fn clear(&mut self) {
        while self.frames.try_recv().is_ok() {}
    }
}

impl Bus for PeerPort {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        self.link.send_frame(frame)
    }
    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        match self.frames.recv_timeout(timeout) {
            Ok(frame) => Ok(Some(frame)),
            Err(mpsc::RecvTimeoutError::Timeout) => Ok(None),
            Err(mpsc::RecvTimeoutError::Disconnected) => Err(io::Error::new(
                io::ErrorKind::BrokenPipe,
                self.link.exited("receiving a frame"),
            )),
        }
    }
}

impl Link {
    fn lock(&self) -> MutexGuard<'_, LinkState> {
        match self.state.lock() {
            Ok(guard) => guard,
            Err(poisoned) => poisoned.into_inner(),
        }
    }

    fn port(self: &Arc<Self>) -> PeerPort {
        let (sender, frames) = mpsc::channel();
        self.lock().ports.push(sender);
        PeerPort {
            link: Arc::clone(self),
            frames,
        }
    }

    fn send_frame(&self, frame: &Frame) -> io::Result<()> {
        self.send_line(&format!("F {frame}"))
            .map_err(|e| io::Error::new(io::ErrorKind::BrokenPipe, e))
    }

    fn send_line(&self, line: &str) -> Result<(), String> {
        let mut stdin = match self.stdin.lock() {
            Ok(guard) => guard,
            Err(poisoned) => poisoned.into_inner(),
        };
        let Some(pipe) = stdin.as_mut() else {
            return Err("the python peer was closed".to_string());
        };
        self.lock().record(format!("-> {line}"));
        let written = pipe
            .write_all(line.as_bytes())
            .and_then(|()| pipe.write_all(b"\n"))
            .and_then(|()| pipe.flush());
        drop(stdin);
        written.map_err(|e| self.exited(&format!("writing to it ({e})")))
    }

    /// The message for a peer that is gone: what we were doing and its
    /// stderr, once the stderr reader has seen the end (waits up to 2 s).
    fn exited(&self, doing: &str) -> String {
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut state = self.lock();
        while !state.stderr_closed {
            let now = Instant::now();
            if now >= deadline {
                break;
            }
            state = match self.changed.wait_timeout(state, deadline - now) {
                Ok((guard, _)) => guard,
                Err(poisoned) => poisoned.into_inner().0,
            };
        }
        let stray = if state.stray.is_empty() {
            String::new()
        } else {
            format!("\nunexpected stdout lines: {:?}", state.stray)
        };
        format!(
            "the python peer exited ({doing}){stray}{}",
            tail("python stderr", &state.stderr)
        )
    }

    fn read_stdout(&self, stdout: impl Read) {
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            let mut state = self.lock();
            state.record(format!("<- {line}"));
            if let Some(text) = line.strip_prefix("F ") {
                match parse_frame(text) {
                    Ok(frame) => state.ports.retain(|port| port.send(frame).is_ok()),
                    Err(_) => keep_stray(&mut state.stray, line),
                }
            } else if let Some(text) = line.strip_prefix("R ") {
                let reply: Option<Value> = serde_json::from_str(text).ok();
                match reply
                    .as_ref()
                    .and_then(|r| r.get("id"))
                    .and_then(Value::as_u64)
                {
                    Some(id) => {
                        if let Some(reply) = reply {
                            state.replies.insert(id, reply);
                        }
                        self.changed.notify_all();
                    }
                    None => keep_stray(&mut state.stray, line),
                }
            } else {
                keep_stray(&mut state.stray, line);
            }
        }
        let mut state = self.lock();
        state.stdout_closed = true;
        // Ports see the end as a disconnected channel.
        state.ports.clear();
        self.changed.notify_all();
    }

    fn read_stderr(&self, stderr: impl Read) {
        let mut reader = BufReader::new(stderr);
        let mut buf = [0u8; 4096];
        loop {
            match reader.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => {
                    let mut state = self.lock();
                    state
                        .stderr
                        .push_str(&String::from_utf8_lossy(buf.get(..n).unwrap_or(&[])));
                    if state.stderr.len() > STDERR_KEPT {
                        let mut cut = state.stderr.len() - STDERR_KEPT;
                        while !state.stderr.is_char_boundary(cut) {
                            cut += 1;
                        }
                        state.stderr.drain(..cut);
                    }
                    self.changed.notify_all();
                }
            }
        }
        self.lock().stderr_closed = true;
        self.changed.notify_all();
    }
}

impl LinkState {
    fn record(&mut self, line: String) {
        if self.trace.len() >= TRACE_KEPT {
            self.trace.pop_front();
        }
        self.trace.push_back(line);
    }
}

fn keep_stray(stray: &mut Vec<String>, line: String) {
    if stray.len() < 100 {
        stray.push(line);
    }
}

fn tail(name: &str, text: &str) -> String {
    if text.trim().is_empty() {
        String::new()
    } else {
        format!("\n--- {name} ---\n{}", text.trim_end())
    }
}

/// A peer shared by the tests of one test binary, started on first use
/// (the process ends with the binary, when its stdin closes).
pub fn shared(cell: &'static OnceLock<PyPeer>) -> &'static PyPeer {
    cell.get_or_init(|| PyPeer::spawn().unwrap_or_else(|e| panic!("{e}")))
}
