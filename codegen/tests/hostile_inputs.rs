//! Inputs an attacker would try (issue 29): files that are not regular files
//! (a directory, a FIFO, a device, a kernel pseudo-file), files above the
//! size limit, and YAML tables whose `base:` leads out of the project. Each
//! is refused promptly with its own error and snapshot; nothing outside the
//! project is read or quoted. The FIFOs are made at run time with `mkfifo`.
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use eds2rust::diag::Diagnostics;
use eds2rust::input::{Options, read_device};

/// The fixtures, relative to the package directory where cargo runs
/// integration tests (so that the rendered file names are relative).
const FIXTURES: &str = "tests/fixtures/hostile_inputs";

/// Runs `f` on a thread and fails when it has not returned within 20 s
/// (a read that blocks on a FIFO or never ends on a device).
fn promptly<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(20))
        .unwrap_or_else(|_| panic!("{what}: the reader did not return within 20 s"))
}

/// A fresh scratch directory of this test run.
fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("hostile-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn mkfifo(path: &Path) {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo {}", path.display());
}

/// The rendered diagnostics with the machine's paths replaced: the
/// workspace by `<workspace>`, `dir` (a scratch directory) by `<tmp>`.
fn rendered(d: &Diagnostics, dir: Option<&Path>) -> String {
    let mut text = format!(
        "{}\n{} errors, {} warnings\n",
        d.render(),
        d.error_count(),
        d.warning_count()
    );
    if let Some(dir) = dir {
        let real = std::fs::canonicalize(dir).unwrap();
        text = text.replace(&real.display().to_string(), "<tmp>");
        text = text.replace(&dir.display().to_string(), "<tmp>");
    }
    let workspace =
        std::fs::canonicalize(Path::new(env!("CARGO_MANIFEST_DIR")).join("..")).unwrap();
    text = text.replace(&workspace.display().to_string(), "<workspace>");
    // `/proc/self` resolves to this process's id.
    text.replace(&format!("/proc/{}/", std::process::id()), "/proc/<pid>/")
}

fn codes(d: &Diagnostics) -> Vec<&'static str> {
    d.iter().map(|d| d.code).collect()
}

/// Nothing of the process's environment (what `/proc/self/environ` holds)
/// nor of the non-EDS fixture is quoted.
fn quotes_no_secret(text: &str) {
    for secret in ["CARGO_MANIFEST_DIR=", "hunter2", "HOME=/"] {
        assert!(!text.contains(secret), "`{secret}` is quoted:\n{text}");
    }
}

/// Every `base:` fixture with the default options: refused before reading
/// when it leads out of the project (the current directory, codegen/),
/// not quoted when it is inside but no EDS.
#[test]
fn base_fixtures() {
    let expected: &[(&str, &[&str])] = &[
        ("base_absolute", &["table::base-outside"]),
        ("base_dev_zero", &["table::base-outside"]),
        ("base_dotdot", &["table::base-outside"]),
        ("base_not_eds", &["table::base", "eds::no-objects"]),
        ("base_proc", &["table::base-outside"]),
    ];
    for (stem, want) in expected {
        let path = Path::new(FIXTURES).join(format!("{stem}.yaml"));
        let loaded = promptly(stem, move || read_device(&path, &Options::default()));
        let d = &loaded.diagnostics;
        assert_eq!(codes(d), *want, "{stem}:\n{}", d.render());
        let text = rendered(d, None);
        quotes_no_secret(&text);
        insta::assert_snapshot!(*stem, text);
        // A refused base is not a file read.
        if want.contains(&"table::base-outside") {
            assert_eq!(loaded.files.len(), 1, "{stem}: {:?}", loaded.files);
        }
    }
}

/// Allowed by the caller (`--allow-base-dir /`), a device and a pseudo-file
/// are still refused, as what they are.
#[test]
fn base_devices_refused_even_when_allowed() {
    let everywhere = Options {
        allow_base_dirs: vec![PathBuf::from("/")],
        ..Options::default()
    };
    for stem in ["base_dev_zero", "base_proc"] {
        let path = Path::new(FIXTURES).join(format!("{stem}.yaml"));
        let options = everywhere.clone();
        let loaded = promptly(stem, move || read_device(&path, &options));
        let d = &loaded.diagnostics;
        assert_eq!(
            codes(d),
            ["input::not-a-file", "table::base"],
            "{stem}:\n{}",
            d.render()
        );
        let text = rendered(d, None);
        quotes_no_secret(&text);
        insta::assert_snapshot!(format!("{stem}_allowed"), text);
    }
}

/// A `base:` that is a FIFO, beside its table in an allowed directory:
/// refused at once, not waited on.
#[test]
fn base_fifo() {
    let dir = scratch("base-fifo");
    mkfifo(&dir.join("pipe.eds"));
    let table = dir.join("table.yaml");
    std::fs::write(&table, "format: 1\nbase: pipe.eds\n").unwrap();
    let options = Options {
        allow_base_dirs: vec![dir.clone()],
        ..Options::default()
    };
    let loaded = promptly("base: FIFO", move || read_device(&table, &options));
    let d = &loaded.diagnostics;
    assert_eq!(codes(d), ["input::not-a-file", "table::base"]);
    insta::assert_snapshot!("base_fifo", rendered(d, Some(&dir)));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Input files that are not regular files: each refused promptly.
#[test]
fn inputs_that_are_not_files() {
    let dir = scratch("not-files");
    let fifo = dir.join("pipe.eds");
    mkfifo(&fifo);
    let cases: [(&str, PathBuf); 4] = [
        ("input_dev_zero", PathBuf::from("/dev/zero")),
        ("input_directory", PathBuf::from(FIXTURES)),
        ("input_fifo", fifo),
        ("input_proc", PathBuf::from("/proc/self/environ")),
    ];
    for (name, path) in cases {
        let loaded = promptly(name, move || read_device(&path, &Options::default()));
        let d = &loaded.diagnostics;
        assert_eq!(codes(d), ["input::not-a-file"], "{name}:\n{}", d.render());
        let text = rendered(d, Some(&dir));
        quotes_no_secret(&text);
        insta::assert_snapshot!(name, text);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A file above the limit is refused (with how to raise it); one at the
/// limit is read. The limit applies to a table, its `base:` and overlays.
#[test]
fn oversize_files() {
    let dir = scratch("oversize");
    let eds = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../eds/example.eds"))
        .expect("eds/example.eds");
    let len = u64::try_from(eds.len()).unwrap();
    std::fs::write(dir.join("device.eds"), &eds).unwrap();
    std::fs::write(dir.join("table.yaml"), "format: 1\nbase: device.eds\n").unwrap();
    let limited = |limit: u64| Options {
        max_input_size: limit,
        allow_base_dirs: vec![dir.clone()],
        ..Options::default()
    };

    let at_limit = read_device(&dir.join("device.eds"), &limited(len));
    assert!(
        !at_limit.diagnostics.has_errors(),
        "{}",
        at_limit.diagnostics
    );
    let above = read_device(&dir.join("device.eds"), &limited(len - 1));
    assert_eq!(codes(&above.diagnostics), ["input::too-large"]);
    assert_eq!(above.files, [dir.join("device.eds")]);
    let text = rendered(&above.diagnostics, Some(&dir))
        .replace(&len.to_string(), "<len>")
        .replace(&(len - 1).to_string(), "<len - 1>");
    insta::assert_snapshot!("input_too_large", text);

    // The table is small, its base is not.
    let base = read_device(&dir.join("table.yaml"), &limited(100));
    assert_eq!(
        codes(&base.diagnostics),
        ["input::too-large", "table::base"],
        "{}",
        base.diagnostics
    );
    // A whole MiB limit is said in MiB too.
    let mib = eds2rust::bounded::read_input(&dir.join("device.eds"), 0).unwrap_err();
    assert!(matches!(
        mib,
        eds2rust::bounded::Refused::TooLarge {
            limit: 0,
            size: Some(_)
        }
    ));
    let _ = std::fs::remove_dir_all(&dir);
}
