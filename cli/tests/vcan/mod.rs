//! What the vcan tests of the `eds2rust` binary share (`live_vcan.rs`,
//! `monitor_vcan.rs`): the interfaces of `CAN_IFACES`, the binary, scratch
//! directories, running the CLI, and a seed simulator on an interface.

#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

use eds2rust_runtime::blocking;
use eds2rust_runtime::transport::socketcan::SocketCanBus;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{Instant, Service};
use eds2rust_sim::{Behaviour, Device};

pub fn iface(index: usize) -> String {
    let list = std::env::var("CAN_IFACES").unwrap_or_else(|_| {
        panic!("CAN_IFACES is not set: it must list vcan interfaces (tests/vm/run.sh does)")
    });
    let names: Vec<&str> = list.split([' ', ',']).filter(|s| !s.is_empty()).collect();
    names
        .get(index)
        .unwrap_or_else(|| panic!("CAN_IFACES={list:?} has no entry {index}"))
        .to_string()
}

pub fn cli() -> PathBuf {
    let path = std::env::var_os("EDS2RUST_CLI")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_eds2rust")));
    assert!(
        path.exists(),
        "no eds2rust binary at {} (EDS2RUST_CLI)",
        path.display()
    );
    path
}

/// A scratch directory `name` of test binary `test` (tmpfs in the VM).
pub fn scratch(test: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("eds2rust-{test}-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the CLI; prints the command line and its output.
pub fn run<S: AsRef<str>>(args: &[S]) -> Output {
    let args: Vec<&str> = args.iter().map(AsRef::as_ref).collect();
    let out = Command::new(cli())
        .args(&args)
        .output()
        .expect("running eds2rust");
    eprintln!("$ eds2rust {}", args.join(" "));
    eprint!("{}", String::from_utf8_lossy(&out.stdout));
    eprint!("{}", String::from_utf8_lossy(&out.stderr));
    eprintln!("(exit status {:?})", out.status.code());
    out
}

/// Runs the CLI, which must succeed; its stdout.
pub fn ok<S: AsRef<str>>(args: &[S]) -> String {
    let out = run(args);
    assert!(out.status.success(), "eds2rust failed");
    String::from_utf8(out.stdout).unwrap()
}

/// Runs the CLI, which must fail with `code`; its stderr.
pub fn fails<S: AsRef<str>>(code: i32, args: &[S]) -> String {
    let out = run(args);
    assert_eq!(out.status.code(), Some(code), "the exit status of eds2rust");
    String::from_utf8(out.stderr).unwrap()
}

/// A simulated device on a SocketCAN interface, in a thread.
pub struct Sim {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<std::io::Result<()>>>,
}

impl Sim {
    pub fn start<B>(name: &str, device: impl FnOnce(Instant) -> Device<B>) -> Sim
    where
        B: Behaviour + Send + 'static,
        B::Event: Send,
    {
        let mut port = SocketCanBus::open(name).unwrap_or_else(|e| panic!("opening {name}: {e}"));
        let clock = Clock::new();
        let mut device = device(clock.now());
        while let Some(frame) = device.poll_transmit() {
            port.send(&frame).unwrap();
        }
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            blocking::serve(&mut port, &clock, &mut device, &flag, None, |_| {})
        });
        Sim {
            stop,
            thread: Some(thread),
        }
    }
}

impl Drop for Sim {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let r = t.join().expect("the simulator thread panicked");
            if !std::thread::panicking() {
                r.expect("the simulator's bus failed");
            }
        }
    }
}
