//! The command line on inputs that are not device files (issue 29): a
//! device, a FIFO, a file above `--max-input-size`, a table whose `base:`
//! leads out of the current directory. Each fails at once with its error.
#![cfg(unix)]

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{BIN, example};

/// Runs eds2rust in `dir`; fails when it has not exited within 20 s.
fn run_in(dir: &Path, args: &[&str]) -> (i32, String) {
    let mut child = Command::new(BIN)
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("run eds2rust");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            let out = child.wait_with_output().expect("output");
            let code = status.code().expect("exit code");
            return (code, String::from_utf8_lossy(&out.stdout).into_owned());
        }
        if start.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("eds2rust {args:?} did not exit within 20 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn scratch(test: &str) -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cli-hostile-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn devices_and_fifos_fail_at_once() {
    let dir = scratch("fifo");
    let status = Command::new("mkfifo")
        .arg(dir.join("pipe.eds"))
        .status()
        .expect("mkfifo runs");
    assert!(status.success());
    for input in ["/dev/zero", "pipe.eds"] {
        let (code, out) = run_in(&dir, &["check", input]);
        assert_eq!(code, 1, "{input}: {out}");
        assert!(out.contains("error[input::not-a-file]"), "{input}: {out}");
        assert!(out.contains("not a regular file"), "{input}: {out}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn max_input_size() {
    let dir = scratch("size");
    let (code, out) = run_in(&dir, &["check", "--max-input-size", "100", &example()]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("error[input::too-large]"), "{out}");
    assert!(out.contains("--max-input-size"), "{out}");
    let (code, out) = run_in(&dir, &["check", "--max-input-size", "1000000", &example()]);
    assert_eq!(code, 0, "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn base_stays_in_the_current_directory() {
    let dir = scratch("base");
    let project = dir.join("project");
    std::fs::create_dir_all(&project).unwrap();
    std::fs::copy(example(), dir.join("outside.eds")).unwrap();
    std::fs::write(
        project.join("table.yaml"),
        "format: 1\nbase: ../outside.eds\n",
    )
    .unwrap();
    let (code, out) = run_in(&project, &["check", "table.yaml"]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("error[table::base-outside]"), "{out}");
    assert!(out.contains("--allow-base-dir"), "{out}");
    let (code, out) = run_in(&project, &["check", "--allow-base-dir", "..", "table.yaml"]);
    assert_eq!(code, 0, "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}
