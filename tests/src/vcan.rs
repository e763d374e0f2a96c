//! What the tests over the kernel's SocketCAN share (they run in the VM of
//! `tests/vm/run.sh`, see tests/vm/README.md): the interface a test uses
//! and the python interpreter with python-canopen.

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};

/// The interface of test `index`: the `index`th entry of `CAN_IFACES`
/// (`tests/vm/run.sh` sets it; each test uses its own interface).
pub fn iface(index: usize) -> String {
    let Ok(list) = std::env::var("CAN_IFACES") else {
        panic!(
            "CAN_IFACES is not set: it must list SocketCAN interfaces (vcan0 vcan1 ...), \
             one per test; tests/vm/run.sh does"
        );
    };
    let names: Vec<&str> = list.split([' ', ',']).filter(|s| !s.is_empty()).collect();
    match names.get(index) {
        Some(name) => (*name).to_string(),
        None => panic!(
            "CAN_IFACES={list:?} names {} interfaces; this test uses entry {index}",
            names.len()
        ),
    }
}

/// The python interpreter with python-canopen: `VCAN_PYTHON`, or the venv
/// the python oracle tests create (in the VM, shared read-only at its
/// path).
pub fn python() -> PathBuf {
    let path = match std::env::var_os("VCAN_PYTHON") {
        Some(p) => PathBuf::from(p),
        None => crate::workspace_root().join("target/pyoracle/bin/python3"),
    };
    assert!(
        path.exists(),
        "no python interpreter at {} (set VCAN_PYTHON, or create the venv with the python \
         oracle tests; in the VM, tests/vm/run.sh shares it read-only)",
        path.display()
    );
    path
}

/// Starts `tests/python/<script>` with python-canopen's interpreter and
/// `argument` (a JSON command), its stdin and stdout piped, its stderr
/// shown with the test's.
pub fn spawn_script(script: &str, argument: &str) -> Child {
    let path = crate::workspace_root().join("tests/python").join(script);
    assert!(path.exists(), "missing {}", path.display());
    let python = python();
    Command::new(&python)
        .arg(&path)
        .arg(argument)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap_or_else(|e| panic!("starting {} {}: {e}", python.display(), path.display()))
}
