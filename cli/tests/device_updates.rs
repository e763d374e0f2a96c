//! The worked example of docs/device-updates.md, run as a user runs it: a
//! corpus drive DCF (maxon EPOS4, ../shared/eds-corpus) as firmware 1, and
//! a copy edited the way a firmware update edits it as firmware 2 (a
//! standard object renamed, a default changed, an object removed, one
//! added, an access right narrowed). `eds2rust diff` in its three formats
//! and the diff of the two `eds2rust api` listings must be exactly the
//! blocks of the document: the document shows real output, and changes
//! with the code. `UPDATE_DOCS=1` rewrites the blocks instead.

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use common::{BIN, tempdir};

const DRIVE: &str = "maxon_epos4-50-15_ec90flat_node1.dcf";
const DOC: &str = "../docs/device-updates.md";

fn shared() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared");
    dir.is_dir().then_some(dir)
}

/// A DCF as lines (without line ends; written back with CRLF, as read).
struct Dcf {
    lines: Vec<String>,
}

impl Dcf {
    fn parse(text: &str) -> Dcf {
        Dcf {
            lines: text
                .lines()
                .map(|l| l.trim_end_matches('\r').to_string())
                .collect(),
        }
    }

    fn text(&self) -> String {
        self.lines.iter().map(|l| format!("{l}\r\n")).collect()
    }

    /// Lines of section `name`: its header to the line before the next one.
    fn section(&self, name: &str) -> std::ops::Range<usize> {
        let header = format!("[{name}]");
        let start = self
            .lines
            .iter()
            .position(|l| l.eq_ignore_ascii_case(&header))
            .unwrap_or_else(|| panic!("{DRIVE}: no section {header}"));
        let end = self.lines[start + 1..]
            .iter()
            .position(|l| l.starts_with('['))
            .map_or(self.lines.len(), |p| start + 1 + p);
        start..end
    }

    fn set(&mut self, section: &str, key: &str, value: &str) {
        let range = self.section(section);
        let prefix = format!("{key}=");
        let line = self.lines[range]
            .iter_mut()
            .find(|l| l.starts_with(&prefix))
            .unwrap_or_else(|| panic!("{DRIVE}: [{section}] has no {key}"));
        *line = format!("{key}={value}");
    }

    /// Removes object `index` (and its sub sections) and its list entry,
    /// renumbering the list.
    fn remove_object(&mut self, index: &str, list: &str) {
        let range = self.section(index);
        self.lines.drain(range);
        while let Some(sub) = (0..=255).map(|s| format!("{index}sub{s:X}")).find(|s| {
            let header = format!("[{s}]");
            self.lines.iter().any(|l| l.eq_ignore_ascii_case(&header))
        }) {
            let range = self.section(&sub);
            self.lines.drain(range);
        }
        let mut entries = self.list(list);
        entries.retain(|e| !e.eq_ignore_ascii_case(&format!("0x{index}")));
        self.set_list(list, &entries);
    }

    /// Adds an object's section (before the next higher index of its list)
    /// and its list entry.
    fn add_object(&mut self, index: &str, list: &str, keys: &[&str]) {
        let mut entries = self.list(list);
        let value = |e: &str| u16::from_str_radix(e.trim_start_matches("0x"), 16).unwrap();
        let new = u16::from_str_radix(index, 16).unwrap();
        let next = entries.iter().find(|e| value(e) > new).cloned();
        let at = match next {
            Some(next) => self.section(next.trim_start_matches("0x")).start,
            None => self.lines.len(),
        };
        let mut section = vec![format!("[{index}]")];
        section.extend(keys.iter().map(|k| k.to_string()));
        section.push(String::new());
        self.lines.splice(at..at, section);
        entries.push(format!("0x{index}"));
        entries.sort_by_key(|e| value(e));
        self.set_list(list, &entries);
    }

    fn list(&self, list: &str) -> Vec<String> {
        self.lines[self.section(list)]
            .iter()
            .skip(1)
            .filter(|l| !l.starts_with("SupportedObjects=") && l.contains('='))
            .map(|l| l.split_once('=').unwrap().1.to_string())
            .collect()
    }

    fn set_list(&mut self, list: &str, entries: &[String]) {
        let range = self.section(list);
        let mut lines = vec![
            format!("[{list}]"),
            format!("SupportedObjects={}", entries.len()),
        ];
        lines.extend(
            entries
                .iter()
                .enumerate()
                .map(|(i, e)| format!("{}={e}", i + 1)),
        );
        lines.push(String::new());
        self.lines.splice(range, lines);
    }
}

/// Firmware 2: the edits of the document's list, in its order.
fn firmware_2(v1: &str) -> String {
    let mut dcf = Dcf::parse(v1);
    // 1. A standard object renamed in the vendor's tool.
    dcf.set(
        "6064",
        "ParameterName",
        "Position actual value (increments)",
    );
    // 2. A default changed.
    dcf.set("6065", "DefaultValue", "5000");
    // 3. An object removed.
    dcf.remove_object("6067", "OptionalObjects");
    // 4. An object added.
    dcf.add_object(
        "2011",
        "ManufacturerObjects",
        &[
            "ParameterName=Motor temperature",
            "ObjectType=0x7",
            "DataType=0x6",
            "AccessType=ro",
            "PDOMapping=1",
            "ObjFlags=0",
            "ParameterValue=0",
        ],
    );
    // 5. An access right narrowed: the node id is now set by LSS only.
    dcf.set("2000", "AccessType", "ro");
    dcf.text()
}

/// Runs the binary in `dir` (so the file names in its output are the
/// user's relative ones); exit code and stdout.
fn run_in(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = Command::new(BIN)
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run eds2rust");
    let status = out.status.code().expect("exit code");
    assert_ne!(
        status,
        2,
        "eds2rust {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (status, String::from_utf8(out.stdout).expect("UTF-8 output"))
}

/// The blocks the document shows, by the name in the `<!-- output: NAME -->`
/// line before each fenced block.
fn outputs(dir: &Path) -> Vec<(&'static str, String)> {
    let (status, text) = run_in(dir, &["diff", "drive-v1.dcf", "drive-v2.dcf"]);
    assert_eq!(status, 1, "a breaking change fails the default --fail-on");
    let (_, json) = run_in(
        dir,
        &["diff", "drive-v1.dcf", "drive-v2.dcf", "--format", "json"],
    );
    let (_, markdown) = run_in(
        dir,
        &[
            "diff",
            "drive-v1.dcf",
            "drive-v2.dcf",
            "--format",
            "markdown",
        ],
    );
    let (status, _) = run_in(
        dir,
        &["diff", "drive-v1.dcf", "drive-v2.dcf", "--fail-on", "never"],
    );
    assert_eq!(status, 0);
    let (_, api_v1) = run_in(dir, &["api", "drive-v1.dcf"]);
    let (_, api_v2) = run_in(dir, &["api", "drive-v2.dcf"]);
    let listing_diff = similar::TextDiff::from_lines(&api_v1, &api_v2)
        .unified_diff()
        .context_radius(0)
        .header("api v1", "api v2")
        .to_string();
    let head: String = api_v1.lines().take(6).map(|l| format!("{l}\n")).collect();
    vec![
        ("diff-text", text),
        ("diff-json", json),
        ("diff-markdown", markdown),
        ("api-head", head),
        ("api-diff", listing_diff),
    ]
}

/// The document with each named block replaced by `outputs`.
fn with_outputs(doc: &str, outputs: &[(&str, String)]) -> String {
    let mut out = String::new();
    let mut lines = doc.lines();
    while let Some(line) = lines.next() {
        out.push_str(line);
        out.push('\n');
        let Some(name) = line
            .strip_prefix("<!-- output: ")
            .and_then(|l| l.strip_suffix(" -->"))
        else {
            continue;
        };
        let (_, text) = outputs
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("{DOC}: no output named {name}"));
        let fence = lines.next().expect("a fenced block after the marker");
        assert!(fence.starts_with("```"), "{DOC}: {name}: {fence:?}");
        out.push_str(fence);
        out.push('\n');
        for l in lines.by_ref() {
            if l == "```" {
                break;
            }
        }
        out.push_str(text);
        if !text.ends_with('\n') {
            out.push('\n');
        }
        out.push_str("```\n");
    }
    out
}

#[test]
fn the_documents_worked_example_is_the_real_output() {
    let Some(shared) = shared() else {
        let _ = writeln!(
            std::io::stderr(),
            "NOT RUN: device-updates worked example: ../shared/eds-corpus is not beside this checkout"
        );
        return;
    };
    let v1 = std::fs::read_to_string(shared.join("eds-corpus/files").join(DRIVE))
        .expect("the corpus drive is UTF-8");
    let dir = tempdir().join("device-updates");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("drive-v1.dcf"), &v1).unwrap();
    std::fs::write(dir.join("drive-v2.dcf"), firmware_2(&v1)).unwrap();
    let outputs = outputs(&dir);
    let doc_path = Path::new(env!("CARGO_MANIFEST_DIR")).join(DOC);
    let doc = std::fs::read_to_string(&doc_path).expect("docs/device-updates.md");
    let expected = with_outputs(&doc, &outputs);
    if std::env::var_os("UPDATE_DOCS").is_some() {
        std::fs::write(&doc_path, &expected).unwrap();
        return;
    }
    assert!(
        doc == expected,
        "docs/device-updates.md does not show the real output; run with UPDATE_DOCS=1 \
         and review the change. Differences:\n{}",
        similar::TextDiff::from_lines(&doc, &expected).unified_diff()
    );
}
