//! `eds2rust sim` over the kernel's SocketCAN stack: a CiA 402 drive of
//! the EDS corpus simulated on its own vcan interface, python-canopen as
//! its master (cli/tests/python/sim_master.py): SDO reads of 0x1000 and
//! 0x1018 with the file's values (expedited and block), a segmented write
//! of a rw object read back, the heartbeat turned on and seen, NMT start,
//! and the CiA 402 state machine to Operation enabled by the controlword.
//! The simulator's event lines say each of these; Ctrl-C stops it with
//! exit status 0.
//!
//! The VM test is ignored by default: `tests/vm/run.sh` runs it with
//! `--ignored` in a VM whose kernel has vcan (and shares the corpus and the
//! python venv into it). `CAN_IFACES` names the interfaces (this test
//! takes entry [`SIM`]); `EDS2RUST_CLI` the binary (default: the one cargo
//! built); `VCAN_PYTHON` the python with python-canopen (default: the venv
//! the python oracle tests create). Without ../shared beside the checkout
//! it prints one `NOT RUN:` line and passes.
#![cfg(target_os = "linux")]

mod vcan;

use vcan::{Ended, Running, iface, python};

use std::path::{Path, PathBuf};
use std::process::Stdio;

use serde_json::{Value, json};

/// The index of this test's interface in `CAN_IFACES` (tests/vm/run.sh
/// creates one more than the other VM tests use).
const SIM: usize = 9;

/// The corpus drive (read where it is, never copied).
const DRIVE: &str = "ros2-canopen_cia402-slave.eds";

const NODE: &str = "5";

/// The corpus file, if ../shared is beside the checkout (lexically: the
/// VM mounts the corpus at the same path, without the checkout's parents).
fn corpus(name: &str) -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent()?.parent()?;
    let path = root.join("shared/eds-corpus/files").join(name);
    path.exists().then_some(path)
}

/// Runs cli/tests/python/sim_master.py with `command`; its JSON result.
fn python_master(command: &Value) -> Value {
    let out = python("sim_master.py")
        .arg(command.to_string())
        .stdin(Stdio::null())
        .stderr(Stdio::inherit())
        .output()
        .unwrap_or_else(|e| panic!("starting python for sim_master.py: {e}"));
    let text = String::from_utf8_lossy(&out.stdout);
    let last = text.lines().last().unwrap_or_default();
    let value: Value = serde_json::from_str(last)
        .unwrap_or_else(|e| panic!("sim_master.py printed {text:?}: {e}"));
    assert!(
        value.get("error").is_none(),
        "sim_master.py failed: {value}"
    );
    assert!(
        out.status.success(),
        "sim_master.py exited with {}",
        out.status
    );
    value
}

#[test]
#[ignore = "needs vcan and python-canopen: tests/vm/run.sh"]
fn python_canopen_masters_a_simulated_corpus_drive() {
    let Some(file) = corpus(DRIVE) else {
        eprintln!(
            "NOT RUN: eds2rust sim over vcan: ../shared/eds-corpus is not beside this checkout"
        );
        return;
    };
    let i = iface(SIM);
    let file = file.display().to_string();
    // The status line comes once the device booted.
    let mut sim = Running::spawn(&["sim", &file, "--node", NODE, "--iface", &i], "sim: ");
    sim.ready();

    // 0x6081 Profile velocity (rw, UNSIGNED32) := 10000.
    let result = python_master(&json!({
        "channel": i,
        "node": 5,
        "rw": [0x6081, 0, "10270000"],
    }));
    sim.interrupt();
    let Ended {
        code,
        stdout: out,
        stderr: err,
    } = sim.wait();
    assert_eq!(code, Some(0), "{err}");

    // The file's values: 0x1000 DefaultValue=0xFFFF0192, 0x1018 sub 0 4,
    // sub 1 0x555, subs 2 and 3 0.
    assert_eq!(
        result["values"],
        json!({
            "1000:00": "9201FFFF",
            "1018:00": "04",
            "1018:01": "55050000",
            "1018:02": "00000000",
            "1018:03": "00000000",
            "1018:01 block": "55050000",
            "6081:00": "10270000",
            "1017:00": "6400",
        }),
        "{result}"
    );
    let beats = result["heartbeats"].as_array().unwrap();
    assert_eq!(beats.first(), Some(&json!("PRE-OPERATIONAL")), "{result}");
    assert_eq!(beats.last(), Some(&json!("OPERATIONAL")), "{result}");
    let states: Vec<u64> = result["statuswords"]
        .as_array()
        .unwrap()
        .iter()
        .map(|sw| sw.as_u64().unwrap() & 0x6F)
        .collect();
    assert_eq!(states, [0x21, 0x23, 0x27], "{result}");

    assert!(
        err.contains(&format!(
            "as node 5 on {i}, a CiA 402 drive; no heartbeat (0x1017 is 0)"
        )),
        "{err}"
    );
    for line in [
        "NMT: boot-up -> pre-operational",
        "SDO write 0x6081 Profile Velocity in pp-mode 1 := 10000 (0x00002710)",
        "SDO write 0x1017 Producer Heartbeat Time := 100 (0x0064) = 100 ms",
        "NMT: pre-operational -> operational",
        "CiA 402: Switch on disabled -> Ready to switch on (transition 2",
        "CiA 402: Ready to switch on -> Switched on (transition 3",
        "CiA 402: Switched on -> Operation enabled (transition 4",
        "SDO write 0x6040 Controlword 1 := 15 (0x000F)",
    ] {
        assert!(out.contains(line), "no {line:?} in:\n{out}");
    }
    assert!(err.contains("sim: stopped after "), "{err}");
}
