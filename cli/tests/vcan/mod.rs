//! What the vcan tests of the `eds2rust` binary share (`live_vcan.rs`,
//! `monitor_vcan.rs`, `sim_vcan.rs`): the interfaces of `CAN_IFACES`, the
//! binary, scratch directories, running the CLI (to its end, or in the
//! background until Ctrl-C), and a seed simulator on an interface.

#![allow(dead_code)]

#[path = "../../../tests/src/served.rs"]
mod served;

use std::io::{BufRead, BufReader, Read};
use std::path::PathBuf;
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

use eds2rust_runtime::Instant;
use eds2rust_runtime::transport::socketcan::SocketCanBus;
use eds2rust_sim::{Behaviour, Device};

use served::Served;

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

/// Writes `text` to `dir/name`; its path.
pub fn write_file(dir: &std::path::Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// What a test with one simulated seed device starts from, on interface
/// `index` of `CAN_IFACES`: the interface, the scratch directory of test
/// `name` of `test`, the seed file `(file name, text)` written there (its
/// path), and `device` simulated on the interface.
pub fn rig<B>(
    index: usize,
    (test, name): (&str, &str),
    (file, text): (&str, &str),
    device: impl FnOnce(Instant) -> Device<B>,
) -> (String, PathBuf, String, Sim)
where
    B: Behaviour + Send + 'static,
    B::Event: Send,
{
    let iface = iface(index);
    let dir = scratch(test, name);
    let od = write_file(&dir, file, text);
    let sim = Sim::start(&iface, device);
    (iface, dir, od, sim)
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

/// `python3 cli/tests/python/SCRIPT`, with the python that has
/// python-canopen: `VCAN_PYTHON`, or the venv the python oracle tests
/// create (tests/vm/run.sh shares it into the VM).
pub fn python(script: &str) -> Command {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let script = dir.join("tests/python").join(script);
    assert!(script.exists(), "missing {}", script.display());
    let python = std::env::var_os("VCAN_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| dir.join("../target/pyoracle/bin/python3"));
    assert!(
        python.exists(),
        "no python with python-canopen at {} (VCAN_PYTHON; the python oracle tests create \
         the venv, tests/vm/run.sh shares it)",
        python.display()
    );
    let mut command = Command::new(&python);
    command.arg(&script).env("PYTHONDONTWRITEBYTECODE", "1");
    command
}

/// A command of the CLI running in the background (`monitor`, `sim`), its
/// stdout and stderr read in threads.
pub struct Running {
    child: Child,
    line: String,
    ready: mpsc::Receiver<()>,
    stdout: Option<JoinHandle<String>>,
    stderr: Option<JoinHandle<String>>,
}

/// What a background command printed and how it ended.
pub struct Ended {
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

impl Running {
    /// Starts `eds2rust args`; [`Running::ready`] waits for its first
    /// stderr line starting with `ready`.
    pub fn spawn(args: &[&str], ready: &'static str) -> Running {
        let line = format!("eds2rust {}", args.join(" "));
        let mut child = Command::new(cli())
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("starting {line}: {e}"));
        let mut out = child.stdout.take().unwrap();
        let stdout = std::thread::spawn(move || {
            let mut text = String::new();
            let _ = out.read_to_string(&mut text);
            text
        });
        let (tx, rx) = mpsc::channel();
        let err = BufReader::new(child.stderr.take().unwrap());
        let stderr = std::thread::spawn(move || {
            let mut text = String::new();
            for l in err.lines().map_while(Result::ok) {
                if l.starts_with(ready) {
                    let _ = tx.send(());
                }
                text.push_str(&l);
                text.push('\n');
            }
            text
        });
        Running {
            child,
            line,
            ready: rx,
            stdout: Some(stdout),
            stderr: Some(stderr),
        }
    }

    /// Waits for the ready line (printed once the command has read its
    /// files and opened the interface: seconds under emulation).
    pub fn ready(&mut self) {
        if self.ready.recv_timeout(Duration::from_secs(90)).is_err() {
            let ended = self.wait();
            panic!(
                "{} did not get ready ({:?}):\n{}{}",
                self.line, ended.code, ended.stdout, ended.stderr
            );
        }
    }

    /// Still running (the traffic comes within its --duration).
    pub fn assert_running(&mut self) {
        let status = self.child.try_wait().unwrap();
        assert!(
            status.is_none(),
            "{} ended ({status:?}) before the node's traffic: the VM is too slow for its \
             --duration",
            self.line
        );
    }

    /// Ctrl-C (SIGINT).
    pub fn interrupt(&self) {
        let pid = self.child.id().to_string();
        let status = Command::new("kill")
            .args(["-INT", &pid])
            .status()
            .expect("running kill");
        assert!(status.success(), "kill -INT {pid}: {status}");
    }

    /// Waits for the end; prints the command line and its output.
    pub fn wait(&mut self) -> Ended {
        let status = self.child.wait().expect("waiting for eds2rust");
        let join = |t: Option<JoinHandle<String>>| t.map(|t| t.join().unwrap()).unwrap_or_default();
        let (stdout, stderr) = (join(self.stdout.take()), join(self.stderr.take()));
        eprintln!("$ {}", self.line);
        eprint!("{stdout}{stderr}");
        eprintln!("(exit status {:?})", status.code());
        Ended {
            code: status.code(),
            stdout,
            stderr,
        }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        if self.stdout.is_some() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// A simulated device on a SocketCAN interface, in a thread.
pub struct Sim(Served);

impl Sim {
    pub fn start<B>(name: &str, device: impl FnOnce(Instant) -> Device<B>) -> Sim
    where
        B: Behaviour + Send + 'static,
        B::Event: Send,
    {
        let port = SocketCanBus::open(name).unwrap_or_else(|e| panic!("opening {name}: {e}"));
        Sim(Served::booted(port, device))
    }
}
