//! python-canopen 2.4.1 against our runtime over the kernel's SocketCAN
//! stack: python-can's `socketcan` interface on one side, our
//! [`SocketCanBus`] on the other, each flow on its own vcan interface.
//!
//! Ignored by default: `tests/vm/run.sh` runs them with `--ignored` in a VM
//! whose kernel has vcan, with the host's python venv shared read-only at
//! the same path. `CAN_IFACES` names the interfaces (index per test, as in
//! the runtime's socketcan_vcan tests); `VCAN_PYTHON` overrides the
//! interpreter (default: `target/pyoracle/bin/python3` of the workspace).
#![cfg(target_os = "linux")]

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, ChildStdout, Command};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use eds2rust_runtime::blocking::{self, SdoClient};
use eds2rust_runtime::heartbeat::HeartbeatProducer;
use eds2rust_runtime::nmt::{NmtSlave, NmtSlaveEvent, NmtState};
use eds2rust_runtime::od::standard::EventTimer;
use eds2rust_runtime::od::{AccessRight, NodeId};
use eds2rust_runtime::pdo::{PdoCobId, PdoTransmitter, TransmissionType, TransmitterConfig};
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::client::{ClientConfig, Method};
use eds2rust_runtime::sdo::server::{MemoryStore, SdoServer, ServerConfig};
use eds2rust_runtime::transport::socketcan::SocketCanBus;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{CanId, Frame, Service};
use eds2rust_tests::vcan::{iface, python, spawn_script};
use serde_json::{Value, json};

/// Interface indices in `CAN_IFACES`, one per test (after the four the
/// runtime's socketcan_vcan tests use).
const SDO_CLIENT: usize = 4;
const SDO_SERVER: usize = 5;
const NMT: usize = 6;
const PDO: usize = 7;

/// Waits for frames that must arrive; generous for an emulated VM.
const ARRIVAL: Duration = Duration::from_secs(2);

fn open(name: &str) -> SocketCanBus {
    SocketCanBus::open(name).unwrap_or_else(|e| panic!("opening {name}: {e}"))
}

/// Reads and drops whatever a socket received before its filter was set.
fn drain(bus: &mut SocketCanBus) {
    while bus.recv(Duration::ZERO).unwrap().is_some() {}
}

fn std_frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

/// tests/python/vcan_peer.py running one flow.
struct Peer {
    child: Child,
    stdin: Option<ChildStdin>,
    stdout: BufReader<ChildStdout>,
}

impl Peer {
    fn spawn(command: &Value) -> Peer {
        let mut child = spawn_script("vcan_peer.py", &command.to_string());
        let stdin = child.stdin.take();
        let stdout = BufReader::new(child.stdout.take().unwrap());
        Peer {
            child,
            stdin,
            stdout,
        }
    }

    /// The next JSON line; panics on an `error` reply or the end of output.
    fn read(&mut self) -> Value {
        let mut line = String::new();
        let n = self.stdout.read_line(&mut line).unwrap();
        assert!(
            n > 0,
            "vcan_peer.py ended without a reply (its stderr is above)"
        );
        let value: Value = serde_json::from_str(&line)
            .unwrap_or_else(|e| panic!("vcan_peer.py printed {line:?}: {e}"));
        if let Some(error) = value.get("error") {
            panic!("vcan_peer.py failed: {error}");
        }
        value
    }

    /// Closes stdin (the end of a served flow) and returns the last reply.
    fn finish(mut self) -> Value {
        if let Some(mut stdin) = self.stdin.take() {
            let _ = stdin.flush();
        }
        let value = self.read();
        let status = self.child.wait().unwrap();
        assert!(status.success(), "vcan_peer.py exited with {status}");
        value
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        if std::thread::panicking() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// A service of ours served (`blocking::serve` with the flag it is given)
/// in a thread, until [`Serving::stop`], which gives what the thread
/// returned.
struct Serving<T> {
    stop: Arc<AtomicBool>,
    thread: JoinHandle<std::io::Result<T>>,
}

impl<T: Send + 'static> Serving<T> {
    fn start(serve: impl FnOnce(&AtomicBool) -> std::io::Result<T> + Send + 'static) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = std::thread::spawn(move || serve(&flag));
        Serving { stop, thread }
    }

    /// Stops it; what it returned (a failed bus or a panic fails the test).
    fn stop(self) -> T {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.join().unwrap().unwrap()
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02X}")).collect()
}

#[test]
#[ignore = "needs SocketCAN and python-canopen in a VM: run by tests/vm/run.sh"]
fn our_sdo_client_against_python_local_node() {
    let name = iface(SDO_CLIENT);
    let node = NodeId::new(5).unwrap();
    let channel = Channel::default_for(node);
    let text = b"python-canopen over vcan";
    let mut sniffer = open(&name)
        .set_filters(&[(0x605, 0x7FF), (0x585, 0x7FF)])
        .unwrap();
    drain(&mut sniffer);
    let mut peer = Peer::spawn(&json!({
        "op": "sdo_server", "channel": name, "node": 5,
        "objects": [
            {"index": 0x2000, "sub": 0, "type": "UNSIGNED32", "value": "11223344"},
            {"index": 0x2001, "sub": 0, "type": "VISIBLE_STRING", "value": hex(text)},
            {"index": 0x2002, "sub": 0, "type": "DOMAIN", "value": "00"},
            {"index": 0x2003, "sub": 0, "type": "UNSIGNED16", "value": "0000"},
        ],
    }));
    assert_eq!(peer.read(), json!({"ready": true}));

    let bus = open(&name).set_id_filters(&[channel.response]).unwrap();
    let mut client = SdoClient::new(bus, ClientConfig::new(channel));
    let long: Vec<u8> = (0..100u8).map(|i| i.wrapping_mul(13) ^ 0x5A).collect();
    // Expedited upload and download.
    assert_eq!(client.upload(0x2000, 0).unwrap(), [0x11, 0x22, 0x33, 0x44]);
    client.download(0x2003, 0, &[0xCD, 0xAB]).unwrap();
    // Segmented upload (24 bytes) and download (100 bytes), read back.
    assert_eq!(
        client.upload_with(0x2001, 0, Method::Standard).unwrap(),
        text
    );
    client
        .download_with(0x2002, 0, &long, Method::Segmented)
        .unwrap();
    assert_eq!(
        client.upload_with(0x2002, 0, Method::Standard).unwrap(),
        long
    );

    let values = peer.finish();
    assert_eq!(values["values"]["2003:00"], "CDAB");
    assert_eq!(values["values"]["2002:00"], hex(&long));

    // CiA 301 on the wire: our initiate upload request, python-canopen's
    // expedited response (scs 2, e = s = 1, n = 0: 0x43).
    assert_eq!(
        sniffer.recv(ARRIVAL).unwrap(),
        Some(std_frame(0x605, &[0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0]))
    );
    assert_eq!(
        sniffer.recv(ARRIVAL).unwrap(),
        Some(std_frame(
            0x585,
            &[0x43, 0x00, 0x20, 0x00, 0x11, 0x22, 0x33, 0x44]
        ))
    );
    // Our expedited download (ccs 1, n = 2, e = s = 1: 0x2B), answered
    // with scs 3 (0x60).
    assert_eq!(
        sniffer.recv(ARRIVAL).unwrap(),
        Some(std_frame(
            0x605,
            &[0x2B, 0x03, 0x20, 0x00, 0xCD, 0xAB, 0, 0]
        ))
    );
    assert_eq!(
        sniffer.recv(ARRIVAL).unwrap(),
        Some(std_frame(0x585, &[0x60, 0x03, 0x20, 0x00, 0, 0, 0, 0]))
    );
    // The segmented upload: initiate response with s = 1, size 24 (0x41).
    sniffer.recv(ARRIVAL).unwrap();
    assert_eq!(
        sniffer.recv(ARRIVAL).unwrap(),
        Some(std_frame(0x585, &[0x41, 0x01, 0x20, 0x00, 24, 0, 0, 0]))
    );
}

#[test]
#[ignore = "needs SocketCAN and python-canopen in a VM: run by tests/vm/run.sh"]
fn python_remote_node_against_our_sdo_server() {
    let name = iface(SDO_SERVER);
    let node = NodeId::new(6).unwrap();
    let channel = Channel::default_for(node);
    let long: Vec<u8> = (0..1000u32).map(|i| (i * 7 + 3) as u8).collect();
    let back: Vec<u8> = long.iter().rev().copied().collect();
    let text = b"eds2rust answers python".to_vec();
    let mut store = MemoryStore::new();
    store.insert(0x2000, 1, AccessRight::Rw, &[0x11, 0x22, 0x33, 0x44]);
    store.insert(0x2001, 0, AccessRight::Rw, &text);
    store.insert(0x2002, 0, AccessRight::Rw, &long);
    store.insert(0x2003, 0, AccessRight::Rw, &[0x00]);
    store.insert(0x2004, 0, AccessRight::Rw, &[0x00]);

    let server_bus = open(&name).set_id_filters(&[channel.request]).unwrap();
    let server = Serving::start(move |server_stop| {
        let mut bus = server_bus;
        drain(&mut bus);
        // python-canopen reads block segments one by one in python, which
        // takes longer than the default 500 ms under an emulated CPU.
        let mut config = ServerConfig::new(channel);
        config.timeout = Duration::from_secs(5);
        let mut server = SdoServer::new(config, store);
        let deadline = Instant::now() + Duration::from_secs(120);
        blocking::serve(
            &mut bus,
            &Clock::new(),
            &mut server,
            server_stop,
            Some(deadline),
            |_| {},
        )
        .map(|()| server.into_store())
    });

    let peer = Peer::spawn(&json!({
        "op": "sdo_client", "channel": name, "node": 6,
        "steps": [
            {"do": "upload", "index": 0x2000, "sub": 1},
            {"do": "upload", "index": 0x2001, "sub": 0},
            {"do": "download", "index": 0x2003, "sub": 0, "value": "A1B2"},
            {"do": "download", "index": 0x2004, "sub": 0, "value": hex(b"segmented!"),
             "segmented": true},
            {"do": "upload", "index": 0x2002, "sub": 0, "block": true},
            {"do": "download", "index": 0x2002, "sub": 0, "value": hex(&back), "block": true},
            {"do": "upload", "index": 0x2002, "sub": 0},
        ],
    }));
    let reply = peer.finish();
    let store = server.stop();
    assert_eq!(
        reply["results"],
        json!([
            "11223344",
            hex(&text),
            null,
            null,
            hex(&long),
            null,
            hex(&back)
        ])
    );
    assert_eq!(store.get(0x2003, 0), Some(&[0xA1, 0xB2][..]));
    assert_eq!(store.get(0x2004, 0), Some(&b"segmented!"[..]));
    assert_eq!(store.get(0x2002, 0), Some(&back[..]));
}

/// NMT slave and heartbeat producer as one service: the heartbeat reports
/// the state the NMT commands set.
struct Device {
    nmt: NmtSlave,
    heartbeat: HeartbeatProducer,
}

impl Service for Device {
    type Event = NmtSlaveEvent;

    fn handle_frame(&mut self, now: eds2rust_runtime::Instant, frame: &Frame) {
        self.nmt.handle_frame(now, frame);
        self.heartbeat.set_state(self.nmt.state());
    }

    fn handle_timeout(&mut self, now: eds2rust_runtime::Instant) {
        self.heartbeat.handle_timeout(now);
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        self.heartbeat.poll_transmit()
    }

    fn poll_event(&mut self) -> Option<NmtSlaveEvent> {
        self.nmt.poll_event()
    }

    fn poll_timeout(&self) -> Option<eds2rust_runtime::Instant> {
        self.heartbeat.poll_timeout()
    }
}

#[test]
#[ignore = "needs SocketCAN and python-canopen in a VM: run by tests/vm/run.sh"]
fn python_nmt_master_commands_our_slave() {
    let name = iface(NMT);
    let node = NodeId::new(7).unwrap();
    let mut sniffer = open(&name).set_filters(&[(0x000, 0x7FF)]).unwrap();
    drain(&mut sniffer);
    let mut peer = Peer::spawn(&json!({
        "op": "nmt_master", "channel": name, "node": 7, "timeout": 5.0,
        "states": ["OPERATIONAL", "STOPPED", "PRE-OPERATIONAL"],
    }));
    assert_eq!(peer.read(), json!({"ready": true}));

    let device_bus = open(&name).set_filters(&[(0x000, 0x7FF)]).unwrap();
    let device = Serving::start(move |device_stop| {
        let mut bus = device_bus;
        drain(&mut bus);
        let clock = Clock::new();
        let mut nmt = NmtSlave::new(node);
        nmt.boot_complete();
        while nmt.poll_event().is_some() {}
        let mut heartbeat = HeartbeatProducer::new(node, Some(Duration::from_millis(100)));
        heartbeat.set_state(nmt.state());
        heartbeat.start(clock.now());
        let mut device = Device { nmt, heartbeat };
        let mut events = Vec::new();
        let deadline = Instant::now() + Duration::from_secs(120);
        blocking::serve(
            &mut bus,
            &clock,
            &mut device,
            device_stop,
            Some(deadline),
            |e| events.push(e),
        )
        .map(|()| events)
    });

    let reply = peer.finish();
    let events = device.stop();
    assert_eq!(
        reply["reached"],
        json!([
            "PRE-OPERATIONAL",
            "OPERATIONAL",
            "STOPPED",
            "PRE-OPERATIONAL"
        ]),
        "heartbeats python saw: {}",
        reply["seen"]
    );
    use NmtState::{Operational, PreOperational, Stopped};
    assert_eq!(
        events,
        [
            NmtSlaveEvent::StateChanged {
                from: PreOperational,
                to: Operational
            },
            NmtSlaveEvent::StateChanged {
                from: Operational,
                to: Stopped
            },
            NmtSlaveEvent::StateChanged {
                from: Stopped,
                to: PreOperational
            },
        ]
    );
    // CiA 301 NMT frames on COB-ID 0: start (1), stop (2), enter
    // pre-operational (0x80), each addressed to node 7.
    for command in [0x01, 0x02, 0x80] {
        assert_eq!(
            sniffer.recv(ARRIVAL).unwrap(),
            Some(std_frame(0x000, &[command, 0x07]))
        );
    }
}

#[test]
#[ignore = "needs SocketCAN and python-canopen in a VM: run by tests/vm/run.sh"]
fn environment_is_complete() {
    // Fails loudly when the VM lacks the interfaces or the interpreter,
    // rather than letting a flow time out.
    let _ = iface(NMT);
    let python = python();
    let out = Command::new(&python)
        .args([
            "-c",
            "import canopen, can; print(canopen.__version__, can.__version__)",
        ])
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .unwrap_or_else(|e| panic!("running {}: {e}", python.display()));
    assert!(
        out.status.success(),
        "{} cannot import canopen: {}",
        python.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "2.4.1 4.6.1");
}

#[test]
#[ignore = "needs SocketCAN and python-canopen in a VM: run by tests/vm/run.sh"]
fn our_pdo_transmitter_decoded_by_python_tpdo_map() {
    let name = iface(PDO);
    let mut peer = Peer::spawn(&json!({
        "op": "tpdo", "channel": name, "node": 8, "cob_id": 0x188, "timeout": 5.0,
        "objects": [
            {"index": 0x6041, "type": "UNSIGNED16"},
            {"index": 0x6064, "type": "INTEGER32"},
            {"index": 0x6061, "type": "INTEGER8"},
        ],
    }));
    assert_eq!(peer.read(), json!({"ready": true}));

    // TPDO1 of node 8 (0x180 + 8), event-driven (255), sent again every
    // 50 ms. Statusword 0x0237, position -1000 (0xFFFFFC18), mode 3, each
    // little-endian in mapping order.
    let mut config = TransmitterConfig::new(PdoCobId(0x188), TransmissionType::EventDrivenProfile);
    config.event_timer = EventTimer(50);
    let data = [0x37, 0x02, 0x18, 0xFC, 0xFF, 0xFF, 0x03];
    let bus = open(&name).set_filters(&[]).unwrap();
    let sender = Serving::start(move |pdo_stop| {
        let mut bus = bus;
        let clock = Clock::new();
        let mut pdo = PdoTransmitter::new(config).unwrap();
        pdo.set_data(clock.now(), &data).unwrap();
        let deadline = Instant::now() + Duration::from_secs(60);
        blocking::serve(&mut bus, &clock, &mut pdo, pdo_stop, Some(deadline), |_| {})
    });
    let reply = peer.finish();
    sender.stop();
    assert_eq!(reply["data"], "370218FCFFFF03");
    assert_eq!(reply["values"], json!([0x0237, -1000, 3]));
}
