//! The eds2rust master boots a network of python-canopen slaves over the
//! kernel's SocketCAN stack, and the PDOs the network configures flow both
//! ways.
//!
//! The network is `tests/networks/vm/python_slaves.yml`: three devices of the EDS
//! corpus (../shared), each a python-canopen `LocalNode` built from its
//! file by `tests/python/network_slaves.py` (boot-up, NMT, heartbeat, and
//! PDOs as the master configures them). The master reads the bus file at
//! run time (`network::read_file`, `configure`, `boot_plan`) and boots the
//! network with `blocking::Master::boot_network`: identity checked,
//! configuration written, slaves started. Then each slave's RPDO sent by
//! the master reaches the slave's dictionary, and each slave's TPDO (on
//! command, or on SYNC) reaches the master, decoded by the configured
//! mapping.
//!
//! Ignored by default: `tests/vm/run.sh` runs it with `--ignored` in a VM
//! whose kernel has vcan, the python venv, the corpus and the bus file
//! shared read-only at their paths. Without ../shared it prints one
//! `NOT RUN:` line and passes.
#![cfg(target_os = "linux")]

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use eds2rust::network::configured::configured_device;
use eds2rust::network::{boot_plan, config::Configured, model::Bus};
use eds2rust_decode::pdo::Raw;
use eds2rust_decode::{Decoder, Record};
use eds2rust_runtime::blocking::Master;
use eds2rust_runtime::boot::{Configuration, NetworkEvent, SlaveState};
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::pdo::PdoEvent;
use eds2rust_runtime::transport::socketcan::SocketCanBus;
use eds2rust_runtime::{CanId, Frame};
use eds2rust_tests::vcan::{iface, spawn_script};
use serde_json::{Value, json};

/// The entry of `CAN_IFACES` this test uses (the VM's test binaries run
/// one after another).
const IFACE: usize = 3;

/// How long python-canopen under an emulated CPU may take for one reply.
const REPLY: Duration = Duration::from_secs(20);

/// How long it may take to start (python, canopen and three device files,
/// read under an emulated CPU).
const START: Duration = Duration::from_secs(90);

/// The bus file and its network, read and configured as `net boot` does.
struct Network {
    bus: Bus,
    configured: Configured,
}

fn read_network(path: &Path) -> Network {
    let (bus, configured) = eds2rust_tests::configured_network(path);
    Network { bus, configured }
}

/// tests/python/network_slaves.py: its JSON lines come through a thread.
struct Slaves {
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<Value>,
    seen: Vec<Value>,
}

impl Slaves {
    fn spawn(command: &Value) -> Slaves {
        let mut child = spawn_script("network_slaves.py", &command.to_string());
        let stdin = child.stdin.take();
        let stdout = BufReader::new(child.stdout.take().expect("piped stdout"));
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for line in stdout.lines() {
                let Ok(line) = line else { break };
                let value = serde_json::from_str(&line)
                    .unwrap_or_else(|e| json!({"error": format!("printed {line:?}: {e}")}));
                if tx.send(value).is_err() {
                    break;
                }
            }
        });
        Slaves {
            child,
            stdin,
            lines,
            seen: Vec::new(),
        }
    }

    fn send(&mut self, request: &Value) {
        let stdin = self.stdin.as_mut().expect("stdin open");
        writeln!(stdin, "{request}").expect("writing to network_slaves.py");
        stdin.flush().expect("flushing network_slaves.py's stdin");
    }

    /// Takes the lines that came within `wait`; panics on an `error` line
    /// or the end.
    fn take(&mut self, wait: Duration) {
        let mut wait = wait;
        loop {
            match self.lines.recv_timeout(wait) {
                Ok(value) => {
                    assert!(
                        value.get("error").is_none(),
                        "network_slaves.py failed: {value}"
                    );
                    self.seen.push(value);
                    wait = Duration::ZERO;
                }
                Err(RecvTimeoutError::Timeout) => return,
                Err(RecvTimeoutError::Disconnected) => panic!(
                    "network_slaves.py ended (its stderr is above); it printed {}",
                    self.summary(0)
                ),
            }
        }
    }

    /// The lines seen from `from` on, a repeated line once with its count.
    fn summary(&self, from: usize) -> String {
        let mut out: Vec<(String, usize)> = Vec::new();
        for line in self.seen.get(from..).unwrap_or_default() {
            let text = line.to_string();
            match out.last_mut() {
                Some((last, n)) if *last == text => *n += 1,
                _ => out.push((text, 1)),
            }
        }
        out.iter()
            .map(|(line, n)| {
                if *n > 1 {
                    format!("{line} ×{n}")
                } else {
                    line.clone()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// Where the next line will be, for [`Slaves::wait_for`].
    fn mark(&self) -> usize {
        self.seen.len()
    }

    /// The first line from line `from` on that `matches`, while `master`
    /// runs the bus.
    fn wait_for<B: eds2rust_runtime::transport::Bus>(
        &mut self,
        master: &mut Master<B>,
        what: &str,
        from: usize,
        matches: impl Fn(&Value) -> bool,
    ) -> Value {
        let deadline = Instant::now() + REPLY;
        loop {
            if let Some(found) = self
                .seen
                .get(from..)
                .and_then(|s| s.iter().find(|v| matches(v)))
            {
                return found.clone();
            }
            assert!(
                Instant::now() < deadline,
                "network_slaves.py did not report {what} (a line from {from} on) within \
                 {REPLY:?}; it printed:\n{}",
                self.summary(0)
            );
            master.run_for(Duration::from_millis(20)).expect("the bus");
            self.take(Duration::ZERO);
        }
    }
}

impl Drop for Slaves {
    fn drop(&mut self) {
        drop(self.stdin.take());
        if std::thread::panicking() {
            let _ = self.child.kill();
        }
        let _ = self.child.wait();
    }
}

/// The master's next TPDO on `can_id`, decoded by the network's mapping:
/// (index, sub) → raw value.
fn decoded_tpdo<B: eds2rust_runtime::transport::Bus>(
    master: &mut Master<B>,
    decoder: &mut Decoder,
    can_id: u16,
) -> Vec<((u16, u8), i128)> {
    let deadline = Instant::now() + REPLY;
    let data = master
        .run_until(deadline, |event| match event {
            MasterEvent::Pdo(e @ PdoEvent::Received { .. })
                if e.can_id() == CanId::Standard(can_id) =>
            {
                std::ops::ControlFlow::Break(e.data().unwrap_or_default().to_vec())
            }
            _ => std::ops::ControlFlow::Continue(()),
        })
        .unwrap_or_else(|e| panic!("no TPDO on 0x{can_id:03X} at the master: {e}"));
    let frame = Frame::new(CanId::Standard(can_id), &data).expect("a classic frame");
    let mut records = Vec::new();
    decoder.frame(1, None, &frame, &mut records);
    let Some(Record::Frame(record)) = records.first() else {
        panic!("0x{can_id:03X}: no record for {frame}");
    };
    let fields = record.kind.pdo_fields();
    assert!(
        !fields.is_empty(),
        "0x{can_id:03X} not decoded as a PDO: {record:?}"
    );
    fields
        .into_iter()
        .map(|f| match f.raw {
            Raw::Int(v) => ((f.index, f.subindex), v),
            Raw::Real(v) => panic!("{}: a REAL {v}", f.name),
        })
        .collect()
}

/// Sets the data of the master's RPDO on `can_id`.
fn set_rpdo<B: eds2rust_runtime::transport::Bus>(master: &mut Master<B>, can_id: u16, data: &[u8]) {
    let now = master.now();
    let tx = master
        .core_mut()
        .pdo_tx
        .iter_mut()
        .find(|tx| tx.can_id() == CanId::Standard(can_id))
        .unwrap_or_else(|| panic!("the master sends no RPDO on 0x{can_id:03X}"));
    tx.set_data(now, data).expect("RPDO data");
    master.flush().expect("the bus");
}

#[test]
#[ignore = "needs SocketCAN and python-canopen in a VM: run by tests/vm/run.sh"]
fn master_boots_python_slaves_and_pdos_flow() {
    let bus_file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("networks/vm/python_slaves.yml");
    let corpus = bus_file
        .parent()
        .expect("a folder")
        .join("../../../../shared/eds-corpus/files");
    if !corpus.is_dir() {
        eds2rust_tests::not_run(
            "vcan_network: ../shared/eds-corpus is not beside this checkout \
             (the network's device files)",
        );
        return;
    }
    let network = read_network(&bus_file);
    let plan = boot_plan(&network.bus, &network.configured);
    let name = iface(IFACE);
    let nodes: Vec<Value> = network
        .configured
        .nodes
        .iter()
        .map(|n| {
            let file = &network.bus.slaves[n.slave].device_file;
            json!({"node": n.node_id, "file": file})
        })
        .collect();
    assert_eq!(nodes.len(), 3, "{nodes:?}");
    let mut slaves = Slaves::spawn(&json!({"channel": name, "nodes": nodes}));
    let deadline = Instant::now() + START;
    while !slaves.seen.iter().any(|v| v.get("ready").is_some()) {
        assert!(
            Instant::now() < deadline,
            "network_slaves.py: not ready within {START:?}"
        );
        slaves.take(Duration::from_millis(200));
    }
    // The boot's lines come after this one.
    let ready = slaves.mark();

    let bus = SocketCanBus::open(&name).unwrap_or_else(|e| panic!("opening {name}: {e}"));
    let core = master::Master::for_network(&plan).expect("the plan's master");
    let mut master = Master::new(bus, core);
    master.start().expect("the bus");
    let report = master
        .boot_network(plan.clone(), Instant::now() + Duration::from_secs(60))
        .expect("the boot is decided");
    let events: Vec<NetworkEvent> = master
        .drain_events()
        .filter_map(|e| match e {
            MasterEvent::Network(e) => Some(e),
            _ => None,
        })
        .collect();
    assert!(report.booted, "{report:#?}\nevents: {events:#?}");
    for slave in &report.slaves {
        assert_eq!(slave.state, SlaveState::Operational, "{slave:#?}");
        assert!(slave.identity_checked, "{slave:#?}");
        assert!(
            matches!(slave.configuration, Some(Configuration::Written(n)) if n > 0),
            "{slave:#?}"
        );
        assert!(
            events.contains(&NetworkEvent::Started(slave.node)),
            "{}: no Started event in {events:#?}",
            slave.name
        );
    }
    // Each slave saw NMT start, and holds the configuration written to it:
    // the heartbeat producer time (200 ms) and, for `io`, its RPDO1 mapping
    // as the bus file remaps it.
    for node in [2, 3, 4] {
        slaves.wait_for(&mut master, "Operational", ready, |v| {
            v["node"] == node && v["nmt"] == "OPERATIONAL"
        });
        let from = slaves.mark();
        slaves.send(&json!({"op": "read", "node": node, "index": 0x1017, "sub": 0}));
        let reply = slaves.wait_for(&mut master, "0x1017", from, |v| {
            v["node"] == node && v.get("value").is_some()
        });
        assert_eq!(reply["value"], "C800", "node {node} 0x1017");
    }
    let from = slaves.mark();
    slaves.send(&json!({"op": "read", "node": 2, "index": 0x1600, "sub": 1}));
    let reply = slaves.wait_for(&mut master, "0x1600 sub 1", from, |v| {
        v["node"] == 2 && v.get("value").is_some()
    });
    assert_eq!(
        reply["value"], "10011164",
        "io RPDO1 mapping 1: 0x6411 sub 1, 16 bits"
    );

    // The master's RPDOs reach the slaves' dictionaries: io and demo_io
    // event-driven, drive at the next SYNC.
    let from = slaves.mark();
    set_rpdo(&mut master, 0x202, &[0x34, 0x12, 0x5A]);
    let got = slaves.wait_for(&mut master, "io RPDO1", from, |v| {
        v["node"] == 2 && v["rpdo"] == 1
    });
    assert_eq!(got["values"], json!({"6411:01": "3412", "6200:01": "5A"}));
    let from = slaves.mark();
    set_rpdo(&mut master, 0x203, &[1, 2, 3, 4, 0xCD, 0xAB]);
    let got = slaves.wait_for(&mut master, "demo_io RPDO1", from, |v| {
        v["node"] == 3 && v["rpdo"] == 1
    });
    assert_eq!(
        got["values"],
        json!({"2000:01": "01", "2000:02": "02", "2000:03": "03", "2000:04": "04", "2101:00": "CDAB"})
    );
    let target: i32 = -1000;
    let mut drive = vec![0x0F, 0x00];
    drive.extend_from_slice(&target.to_le_bytes());
    let from = slaves.mark();
    set_rpdo(&mut master, 0x204, &drive);
    let got = slaves.wait_for(&mut master, "drive RPDO1 with the new data", from, |v| {
        v["node"] == 4 && v["rpdo"] == 1 && v["values"]["6040:00"] == "0F00"
    });
    assert_eq!(
        got["values"],
        json!({"6040:00": "0F00", "607A:00": "18FCFFFF"})
    );

    // The slaves' TPDOs reach the master, decoded by the configured mapping.
    let mut decoder = Decoder::new();
    for node in &network.configured.nodes {
        let device = configured_device(&network.bus.slaves[node.slave].device, node);
        decoder.add_node(node.node_id, Arc::new(device));
    }
    slaves.send(&json!({"op": "set", "node": 2, "values": {"6401:01": "7856", "6000:01": "A5"}}));
    slaves.send(&json!({"op": "tpdo", "node": 2, "number": 1}));
    assert_eq!(
        decoded_tpdo(&mut master, &mut decoder, 0x182),
        [((0x6401, 1), 0x5678), ((0x6000, 1), 0xA5)]
    );
    slaves.send(&json!({"op": "set", "node": 3, "values": {
        "2001:01": "0100", "2001:02": "0200", "2001:03": "0300", "2001:04": "FFFF"}}));
    slaves.send(&json!({"op": "tpdo", "node": 3, "number": 1}));
    let fields = decoded_tpdo(&mut master, &mut decoder, 0x183);
    assert_eq!(
        fields.iter().map(|(k, _)| *k).collect::<Vec<_>>(),
        [(0x2001, 1), (0x2001, 2), (0x2001, 3), (0x2001, 4)]
    );
    assert_eq!(fields.first().map(|f| f.1), Some(1));
    // The drive sends its TPDO1 on every SYNC: wait for the new values.
    slaves.send(
        &json!({"op": "set", "node": 4, "values": {"6041:00": "3706", "6064:00": "E8030000"}}),
    );
    let deadline = Instant::now() + REPLY;
    loop {
        let fields = decoded_tpdo(&mut master, &mut decoder, 0x184);
        if fields == [((0x6041, 0), 0x0637), ((0x6064, 0), 1000)] {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "drive TPDO1 on SYNC stayed {fields:?}"
        );
    }

    // Supervision kept every slave: no loss, no reboot during the flows.
    let later: Vec<MasterEvent> = master.drain_events().collect();
    assert!(
        !later.iter().any(|e| matches!(
            e,
            MasterEvent::Network(NetworkEvent::Lost { .. } | NetworkEvent::Rebooting(_))
        )),
        "{later:#?}"
    );
}
