//! `eds2rust sim` on the in-process virtual bus: the runtime's blocking
//! master reads and writes the simulated device by SDO, starts it, watches
//! its heartbeat and enables a CiA 402 drive; the event lines say so.
//! (tests/sim_vcan.rs does the same over kernel vcan with python-canopen.)

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

use eds2rust_runtime::CanId;
use eds2rust_runtime::blocking::Master;
use eds2rust_runtime::nmt::NmtCommand;
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::transport::Bus;
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};

use super::{SimArgs, simulate};
use crate::live::bus::{self, LiveBus};

fn args(file: PathBuf, node: u8) -> SimArgs {
    SimArgs {
        file: Some(file),
        overlays: Vec::new(),
        network: None,
        faults: Vec::new(),
        iface: "virtual".into(),
        node: Some(node),
        duration: None,
        time_scale: 1.0,
        quiet: false,
    }
}

/// A simulation in a thread; its event lines and status lines at the end.
pub(in crate::sim) struct Running {
    pub(in crate::sim) bus: VirtualBus,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<(String, String, String)>>,
}

impl Running {
    fn start(args: SimArgs) -> Running {
        let table = eds2rust_sim::file::load_with_overlays(
            args.file.as_ref().expect("a file"),
            &args.overlays,
        )
        .expect("the file reads");
        let node = NodeId::new(args.node.unwrap()).unwrap();
        Running::spawn(move |port, stop, out, err| {
            simulate(&args, &table, node, port, stop, out, err)
        })
    }

    /// `simulate` (a device or a network) on a port of a new virtual bus,
    /// in a thread, until stopped.
    pub(in crate::sim) fn spawn(
        simulate: impl FnOnce(Box<dyn Bus + Send>, &AtomicBool, &mut Vec<u8>, &mut Vec<u8>) -> ExitCode
        + Send
        + 'static,
    ) -> Running {
        let bus = VirtualBus::new();
        let port = bus.attach();
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            let (mut out, mut err) = (Vec::new(), Vec::new());
            let code = simulate(Box::new(port), &flag, &mut out, &mut err);
            (
                format!("{code:?}"),
                String::from_utf8(out).unwrap(),
                String::from_utf8(err).unwrap(),
            )
        });
        Running {
            bus,
            stop,
            thread: Some(thread),
        }
    }

    fn master(&self, node: NodeId) -> Master<LiveBus> {
        let mut m = bus::master(LiveBus::new(Box::new(self.bus.attach())));
        bus::sdo_client(&mut m, node, Duration::from_millis(500));
        m
    }

    /// Stops it: (exit status, stdout, stderr).
    pub(in crate::sim) fn stop(mut self) -> (String, String, String) {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.take().unwrap().join().unwrap()
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

fn u32_of(data: &[u8]) -> u32 {
    let mut raw = [0u8; 4];
    for (r, d) in raw.iter_mut().zip(data) {
        *r = *d;
    }
    u32::from_le_bytes(raw)
}

/// Frames on `id` whose first byte is `first` seen by `tap` within `time`.
fn count(tap: &mut VirtualPort, id: u16, first: u8, time: Duration) -> usize {
    let end = std::time::Instant::now() + time;
    let mut n = 0;
    while let Some(left) = end.checked_duration_since(std::time::Instant::now()) {
        if let Some(f) = tap.recv(left).unwrap()
            && f.id() == CanId::Standard(id)
            && f.data().first() == Some(&first)
        {
            n += 1;
        }
    }
    n
}

fn corpus(name: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/eds-corpus/files")
        .join(name);
    if path.exists() {
        return Some(path);
    }
    eprintln!("NOT RUN: eds2rust sim on {name}: ../shared/eds-corpus is not beside this checkout");
    None
}

#[test]
fn a_corpus_drive_is_read_written_started_and_enabled() {
    let Some(file) = corpus("ros2-canopen_cia402-slave.eds") else {
        return;
    };
    let node = NodeId::new(5).unwrap();
    let sim = Running::start(args(file, 5));
    let mut tap = sim.bus.attach();
    let mut m = sim.master(node);
    // The file's values: 0x1000 0xFFFF0192, 0x1018 sub 1 0x555.
    assert_eq!(u32_of(&m.upload(node, 0x1000, 0).unwrap()), 0xFFFF_0192);
    assert_eq!(m.upload(node, 0x1018, 0).unwrap(), [4]);
    assert_eq!(u32_of(&m.upload(node, 0x1018, 1).unwrap()), 0x555);
    m.download(node, 0x1017, 0, &100u16.to_le_bytes()).unwrap();
    assert_eq!(m.upload(node, 0x1017, 0).unwrap(), 100u16.to_le_bytes());
    m.nmt(NmtCommand::Start, node).unwrap();
    let beats = count(&mut tap, 0x705, 0x05, Duration::from_millis(450));
    assert!((2..=6).contains(&beats), "{beats} operational heartbeats");
    for (cw, mask, sw) in [(0x06, 0x6F, 0x21), (0x07, 0x6F, 0x23), (0x0F, 0x6F, 0x27)] {
        m.download(node, 0x6040, 0, &[cw, 0]).unwrap();
        let got = u32_of(&m.upload(node, 0x6041, 0).unwrap());
        assert_eq!(
            got & mask,
            sw,
            "statusword {got:#06X} after controlword {cw:#04X}"
        );
    }
    let err = m.upload(node, 0x1000, 9).unwrap_err();
    assert!(err.to_string().contains("0x06090011"), "{err}");
    let (code, out, err) = sim.stop();
    assert_eq!(code, "ExitCode(unix_exit_status(0))", "{err}");
    for line in [
        "NMT: boot-up -> pre-operational",
        "CiA 402: Not ready to switch on -> Switch on disabled (transition 1, statusword 0x0250)",
        "SDO write 0x1017 Producer Heartbeat Time := 100 (0x0064) = 100 ms",
        "NMT: pre-operational -> operational",
        "CiA 402: Switch on disabled -> Ready to switch on (transition 2, statusword 0x0231)",
        "CiA 402: Ready to switch on -> Switched on (transition 3",
        "CiA 402: Switched on -> Operation enabled (transition 4",
        "SDO write 0x6040 Controlword 1 := 15 (0x000F) bits: \"switch on\", \"enable voltage\"",
        "SDO 0x1000.9 Device Type: aborted the SDO transfer: 0x06090011",
    ] {
        assert!(out.contains(line), "no {line:?} in:\n{out}");
    }
    assert!(
        err.contains(
            "as node 5 on virtual, a CiA 402 drive; no heartbeat (0x1017 is 0); until Ctrl-C"
        ),
        "{err}"
    );
}

#[test]
fn a_yaml_table_gives_the_node_id_and_a_generic_device() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../eds/linak_techline.yaml");
    let table = eds2rust_sim::file::load(&file).unwrap();
    let node = table.node.expect("the YAML table's network: node_id");
    let mut a = args(file, node.get());
    a.duration = Some(Duration::from_millis(600));
    let sim = Running::start(a);
    let mut m = sim.master(node);
    let out = m.upload(node, 0x1018, 1).unwrap();
    assert_eq!(out.len(), 4);
    let (code, out, err) = sim.thread_result();
    assert_eq!(code, "ExitCode(unix_exit_status(0))", "{err}");
    assert!(out.contains("NMT: boot-up -> pre-operational"), "{out}");
    assert!(err.contains(", a generic device; "), "{err}");
    assert!(err.contains("sim: stopped after 0."), "{err}");
}

/// An overlay turns the heartbeat on (0x1017's default) and names a
/// manufacturer object the way the integrator's manual does.
#[test]
fn an_overlay_changes_defaults_and_names() {
    let Some(file) = corpus("ros2-canopen_cia402-slave.eds") else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("eds2rust-sim-overlay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let overlay = dir.join("heartbeat.yaml");
    std::fs::write(
        &overlay,
        "format: 1\nmodify:\n  - { index: 0x1017, default: 50 }\n  - { index: 0x6081, name: Travel speed }\n",
    )
    .unwrap();
    let node = NodeId::new(5).unwrap();
    let mut a = args(file, 5);
    a.overlays = vec![overlay];
    let sim = Running::start(a);
    let mut tap = sim.bus.attach();
    let mut m = sim.master(node);
    assert_eq!(m.upload(node, 0x1017, 0).unwrap(), 50u16.to_le_bytes());
    let beats = count(&mut tap, 0x705, 0x7F, Duration::from_millis(240));
    assert!(
        (3..=6).contains(&beats),
        "{beats} pre-operational heartbeats"
    );
    m.download(node, 0x6081, 0, &1000u32.to_le_bytes()).unwrap();
    let (code, out, err) = sim.stop();
    assert_eq!(code, "ExitCode(unix_exit_status(0))", "{err}");
    assert!(err.contains("heartbeat every 50 ms"), "{err}");
    assert!(
        out.contains("SDO write 0x6081 Travel speed := 1000"),
        "{out}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

impl Running {
    /// Waits for a run with --duration to end by itself.
    fn thread_result(mut self) -> (String, String, String) {
        self.thread.take().unwrap().join().unwrap()
    }
}
