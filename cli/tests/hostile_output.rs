//! Output that cannot be subverted and does not lie:
//! - `diff` (text, Markdown) and `decode` (text) of the hostile YAML table
//!   (codegen/tests/fixtures/hostile.yaml): no escape sequence, control or
//!   bidi character reaches the terminal, a backtick in a name stays inside
//!   its code span (snapshots);
//! - a failed write to standard output (`> /dev/full`) is an error, a reader
//!   that left (`| head`) ends the command quietly;
//! - `-o` writes atomically over a regular file or a new path, through a
//!   symlink, and refuses devices, FIFOs and missing directories;
//! - `--runtime-path` values that are not crate or module paths are usage
//!   errors that say what is wrong (snapshot).

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use common::{BIN, run, seed, tempdir};

fn hostile() -> String {
    format!(
        "{}/../codegen/tests/fixtures/hostile.yaml",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// A scratch directory of its own for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = tempdir().join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Asserts that `text` holds no control character but line feeds and no
/// bidi control.
fn assert_terminal_safe(what: &str, text: &str) {
    if let Some(c) = text.chars().find(|&c| eds2rust::text::is_hazard(c)) {
        panic!("{what} holds {c:?}:\n{text}");
    }
}

/// The hostile table with three names changed into other hostile names.
fn hostile_new(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(hostile()).unwrap();
    let changed = text
        .replace(
            r#"name: "Speed \u202E}; fn evil() {} //""#,
            r#"name: "Speed ``new`` \x1b[31m""#,
        )
        .replace(
            r#"{ value: 2, name: "`off`""#,
            r#"{ value: 2, name: "`off` \u202E|pipe|""#,
        )
        .replace(
            r#"name: "Error \u202E code""#,
            r#"name: "Error | code\x1b]0;t\x07""#,
        );
    assert_ne!(text, changed, "the fixture changed: fix the replacements");
    let path = dir.join("hostile_new.yaml");
    std::fs::write(&path, changed).unwrap();
    path
}

#[test]
fn diff_of_hostile_names_is_terminal_and_markdown_safe() {
    let dir = scratch("diff");
    let new = hostile_new(&dir);
    let old = hostile();
    let (code, text, stderr) = run(&["diff", &old, new.to_str().unwrap()]);
    assert_eq!(code, 1, "breaking changes: {stderr}");
    assert_terminal_safe("diff text", &text);
    insta::assert_snapshot!("diff_text", text);

    let (code, markdown, stderr) =
        run(&["diff", "--format", "markdown", &old, new.to_str().unwrap()]);
    assert_eq!(code, 1, "{stderr}");
    assert_terminal_safe("diff markdown", &markdown);
    // The header names the files, which differ per checkout.
    let body: String = markdown.lines().skip(1).collect::<Vec<_>>().join("\n");
    insta::assert_snapshot!("diff_markdown", body);
    // A name with backticks sits in a longer fence.
    assert!(markdown.contains("```Speed ``new`` ?[31m```"), "{markdown}");
}

#[test]
fn decode_text_of_hostile_names_is_terminal_safe() {
    let node = format!("5={}", hostile());
    let mut child = Command::new(BIN)
        .args(["decode", "--node", &node])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let trace = "185#0A00010200\n605#4000200000000000\n585#4B00200034120000\n085#0100000000000000\nnot a frame \x1b]0;title\x07\n";
    child
        .stdin
        .take()
        .unwrap()
        .write_all(trace.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert_terminal_safe("decode text", &text);
    insta::assert_snapshot!("decode_text", text);
}

/// `eds2rust ARGS > /dev/full`: exit status and stderr.
fn to_dev_full(args: &[&str]) -> (Option<i32>, String) {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .expect("/dev/full exists on Linux");
    let out = Command::new(BIN).args(args).stdout(full).output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_full_disk_on_stdout_is_an_error() {
    let linak = seed("linak_techline");
    for args in [
        vec!["dump", linak.as_str()],
        vec!["check", linak.as_str()],
        vec!["generate", linak.as_str()],
        vec!["api", linak.as_str()],
        vec!["export", linak.as_str()],
        vec!["diff", linak.as_str(), linak.as_str()],
    ] {
        let (code, stderr) = to_dev_full(&args);
        assert_eq!(code, Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains("cannot write to standard output: No space left on device"),
            "{args:?}: {stderr}"
        );
    }
}

#[test]
fn a_reader_that_leaves_ends_the_command_quietly() {
    // 50 KB of JSON: more than a pipe holds once the reader is gone.
    let linak = seed("linak_techline");
    let mut child = Command::new(BIN)
        .args(["dump", &linak])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.is_empty(), "{stderr}");
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn output_files_are_replaced_whole_and_only_files() {
    let dir = scratch("output");
    let linak = seed("linak_techline");
    // Through a symlink: the file it names is replaced, the link stays.
    let real = dir.join("real.rs");
    std::fs::write(&real, "old").unwrap();
    let link = dir.join("link.rs");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let (code, _, stderr) = run(&["generate", "-o", link.to_str().unwrap(), &linak]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert!(
        std::fs::read_to_string(&real)
            .unwrap()
            .starts_with("// @generated")
    );

    // A missing directory is named and not created.
    let missing = dir.join("no/such/dir/out.rs");
    let (code, _, stderr) = run(&["generate", "-o", missing.to_str().unwrap(), &linak]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains(&format!(
            "directory {} does not exist",
            dir.join("no/such/dir").display()
        )),
        "{stderr}"
    );
    assert!(!dir.join("no").exists());

    // A device stays a device.
    let (code, _, stderr) = run(&["export", "-o", "/dev/null", &linak]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("/dev/null is a character device, not a regular file"),
        "{stderr}"
    );
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device()
    );

    // A FIFO is refused at once (no open, so no waiting for a reader).
    let fifo = dir.join("fifo");
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success(), "mkfifo failed");
    let (code, _, stderr) = run(&["generate", "-o", fifo.to_str().unwrap(), &linak]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("is a FIFO, not a regular file"), "{stderr}");
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());

    // A directory is refused; nothing is left beside it.
    let (code, _, stderr) = run(&["generate", "-o", dir.to_str().unwrap(), &linak]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("is a directory"), "{stderr}");
    let mut left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["fifo", "link.rs", "real.rs"]);
}

#[test]
fn runtime_paths_that_are_not_module_paths_are_named() {
    let linak = seed("linak_techline");
    let mut messages = String::new();
    for path in [
        "Self",
        "1abc",
        "foo::",
        "a b",
        "::",
        "crate",
        "foo::self::bar",
        "",
        "x::<T>",
    ] {
        let (code, stdout, stderr) = run(&["generate", "--runtime-path", path, &linak]);
        assert_eq!(code, 2, "{path:?}: {stderr}");
        assert!(stdout.is_empty(), "{path:?}: {stdout}");
        assert!(!stderr.contains("a bug in eds2rust"), "{path:?}: {stderr}");
        messages.push_str(&stderr);
    }
    insta::assert_snapshot!("runtime_path_messages", messages);
    for path in [
        "::my::runtime",
        "crate::rt",
        "super::super::runtime",
        "r#type::x",
    ] {
        let (code, _, stderr) = run(&["generate", "--runtime-path", path, &linak]);
        assert_eq!(code, 0, "{path:?}: {stderr}");
    }
}
