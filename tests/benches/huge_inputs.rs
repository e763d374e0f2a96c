//! Time and memory on huge, generated EDS files (issue 29): the worst cases
//! of the INI reader (one section with 200,000 keys, each special section
//! kind with as many, 100,000 duplicate sections) timed in process, and the
//! peak memory of `generate`, `api` and `dump` per 10,000 sub-entries for
//! ARRAYs of `CompactSubObj=254`, against an anchor in the same run: plain
//! VAR objects, one entry each.
//!
//! The peak memory of a case is measured in a child process (this binary
//! run again with `--child`), which does what the command line does for
//! the command and prints its own peak resident set (`VmHWM` of
//! /proc/self/status) when done. "Above base" subtracts the peak of the
//! same command on a file of one object, so that the figure is what the
//! entries cost.
//!
//! `cargo bench -p eds2rust-tests --bench huge_inputs`; `cargo test
//! --benches` runs it without `--bench`: one quick pass on inputs a tenth
//! the size (or less).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use eds2rust::diag::Levels;
use eds2rust::eds::{Options, read_bytes};

/// The file head: identity and one object 0x1000.
fn head() -> String {
    "[FileInfo]\nFileName=huge.eds\n[DeviceInfo]\nVendorName=bench\n\
     [1000]\nParameterName=Device type\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\n\
     DefaultValue=0\nPDOMapping=0\n"
        .to_string()
}

/// `arrays` ARRAY objects of `CompactSubObj=254` (254 sub-entries each).
fn arrays(arrays: usize) -> String {
    let mut s = head();
    for i in 0..arrays {
        s.push_str(&format!(
            "[{:04X}]\nParameterName=Array {i}\nObjectType=0x8\nDataType=0x0007\nAccessType=rw\n\
             PDOMapping=0\nCompactSubObj=254\n",
            0x2000 + i
        ));
    }
    s
}

/// `n` VAR objects (n ≤ 0xE000).
fn plain(n: usize) -> String {
    let mut s = head();
    for i in 0..n {
        s.push_str(&format!(
            "[{:04X}]\nParameterName=Value {i}\nObjectType=0x7\nDataType=0x0007\nAccessType=rw\n\
             DefaultValue={i}\nPDOMapping=0\n",
            0x2000 + i
        ));
    }
    s
}

/// One section `[name]` of `head_lines` and then `keys` lines made by `line`.
fn one_section(
    name: &str,
    head_lines: &str,
    keys: usize,
    line: impl Fn(usize) -> String,
) -> String {
    let mut s = head();
    if name.starts_with("2000") && name != "2000" {
        // The CompactSubObj object the names or values belong to.
        s.push_str(COMPACT);
    }
    s.push_str(&format!("[{name}]\n{head_lines}"));
    for i in 0..keys {
        s.push_str(&line(i));
        s.push('\n');
    }
    s
}

/// The INI worst cases: (name, text), each with `keys` keys.
fn parse_cases(keys: usize) -> Vec<(&'static str, String)> {
    vec![
        (
            "keys in one object section",
            one_section(
                "2000",
                "ParameterName=V\nDataType=0x0007\nAccessType=rw\n",
                keys,
                |i| format!("Key{i}={i}"),
            ),
        ),
        (
            "the same key repeated in one section",
            one_section("Comments", "Lines=1\n", keys, |i| {
                format!("Line1=comment {i}")
            }),
        ),
        (
            "[MandatoryObjects] keys",
            one_section("MandatoryObjects", "", keys, |i| {
                format!("{}=0x1000", i + 1)
            }),
        ),
        (
            "[DummyUsage] keys",
            one_section("DummyUsage", "", keys, |i| format!("Dummy{i:08X}=1")),
        ),
        (
            "[Comments] lines",
            one_section("Comments", &format!("Lines={keys}\n"), keys, |i| {
                format!("Line{}=comment", i + 1)
            }),
        ),
        (
            "[2000Name] keys (CompactSubObj names)",
            one_section("2000Name", &format!("NrOfEntries={keys}\n"), keys, |i| {
                format!("{}=name {i}", i + 1)
            }),
        ),
        (
            "[2000Value] keys (CompactSubObj values)",
            one_section("2000Value", &format!("NrOfEntries={keys}\n"), keys, |i| {
                format!("{}={i}", i + 1)
            }),
        ),
        ("duplicate sections", {
            let mut s = head();
            for _ in 0..keys / 2 {
                s.push_str("[1000]\nParameterName=Device type\n");
            }
            s
        }),
    ]
}

const COMPACT: &str = "[2000]\nParameterName=Array\nObjectType=0x8\nDataType=0x0007\nAccessType=rw\nCompactSubObj=254\n";

/// The child: does what the command line does for `command` on `path`,
/// then prints its peak resident set in KiB.
fn child(command: &str, path: &Path) {
    let out_len = match command {
        "generate" => {
            let generated = eds2rust::build::generate_device_with(
                path,
                &[],
                &eds2rust::r#gen::rust::Options::default(),
                &Levels::new(),
            );
            match generated.result {
                Ok(out) => out.code.len() + out.warnings.render().len(),
                Err(d) => panic!("generate failed:\n{}", d.render()),
            }
        }
        "api" => match eds2rust::build::api_listing_files(path, &[], &Options::default()) {
            Ok(listing) => format!("{listing:?}").len(),
            Err(d) => panic!("api failed:\n{}", d.render()),
        },
        "dump" => {
            let loaded = eds2rust::eds::read_file(path, &Options::default());
            let name = path.display().to_string();
            eds2rust::dump::json::to_json_pretty(
                &name,
                loaded.device.as_ref(),
                &loaded.diagnostics,
                None,
            )
            .len()
        }
        other => panic!("unknown child command {other}"),
    };
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    let hwm = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .expect("VmHWM in /proc/self/status");
    println!("{hwm} {out_len}");
}

/// Runs the child on `text`: (peak KiB, seconds, output bytes).
fn measure(command: &str, text: &str, dir: &Path, name: &str) -> (u64, f64, usize) {
    let path = dir.join(format!("{name}.eds"));
    std::fs::write(&path, text).expect("write the generated file");
    let exe = std::env::current_exe().expect("the bench binary");
    let start = Instant::now();
    let out = Command::new(exe)
        .args(["--child", command])
        .arg(&path)
        .output()
        .expect("run the child");
    let seconds = start.elapsed().as_secs_f64();
    assert!(
        out.status.success(),
        "{command} {name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let mut fields = stdout
        .split_whitespace()
        .map(|f| f.parse::<u64>().expect("a number"));
    let (hwm, len) = (
        fields.next().expect("VmHWM"),
        fields.next().expect("length"),
    );
    let _ = std::fs::remove_file(&path);
    (hwm, seconds, len as usize)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--child") {
        return child(&args[i + 1], Path::new(&args[i + 2]));
    }
    let quick = !args.iter().any(|a| a == "--bench");
    let (keys, n_arrays, n_plain) = if quick {
        (20_000, 40, 5_000)
    } else {
        (200_000, 1_000, 50_000)
    };

    println!("INI reader, {keys} keys (read and lowered in process):");
    for (name, text) in parse_cases(keys) {
        let start = Instant::now();
        let loaded = read_bytes("huge.eds", text.as_bytes(), &Options::default());
        let seconds = start.elapsed().as_secs_f64();
        assert!(loaded.device.is_some(), "{name}");
        assert!(
            loaded.diagnostics.len() <= 20 * eds2rust::diag::CAP,
            "{name}: {} diagnostics, not capped",
            loaded.diagnostics.len()
        );
        println!(
            "  {name:<42} {:>6.1} MB  {:>8.1} ms  ({:.2} µs per key)",
            text.len() as f64 / 1e6,
            seconds * 1e3,
            seconds * 1e6 / keys as f64
        );
    }

    let dir: PathBuf = std::env::temp_dir().join(format!("eds2rust-huge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let array_subs = n_arrays * 255;
    let cases = [
        ("arrays", arrays(n_arrays), array_subs),
        ("plain", plain(n_plain), n_plain),
    ];
    let base = plain(0);
    println!(
        "\nPeak memory (child process): {n_arrays} ARRAYs of CompactSubObj=254 ({array_subs} sub-entries) \
         against {n_plain} VAR objects (the anchor):"
    );
    for command in ["generate", "api", "dump"] {
        let (base_kb, _, _) = measure(command, &base, &dir, "base");
        let mut per_10k = Vec::new();
        for (name, text, entries) in &cases {
            let (kb, seconds, out) = measure(command, text, &dir, name);
            let above = kb.saturating_sub(base_kb) as f64 / 1024.0;
            let per = above * 10_000.0 / *entries as f64;
            per_10k.push(per);
            println!(
                "  {command:<8} {name:<6} {entries:>7} entries  peak {:>7.1} MB  above base {above:>7.1} MB  \
                 = {per:>6.1} MB per 10,000  {seconds:>6.2} s  output {:.1} MB",
                kb as f64 / 1024.0,
                out as f64 / 1e6
            );
        }
        println!(
            "  {command:<8} ratio arrays/plain per entry: {:.2}",
            per_10k[0] / per_10k[1]
        );
    }
    // Duplicate sections: the diagnostics are capped, so memory and output stay small.
    let dup = {
        let mut s = head();
        for _ in 0..keys / 2 {
            s.push_str("[1000]\nParameterName=Device type\n");
        }
        s
    };
    let (kb, seconds, out) = measure("dump", &dup, &dir, "duplicates");
    println!(
        "  dump     {} duplicate sections ({:.1} MB)  peak {:.1} MB  {seconds:.2} s  output {:.2} MB",
        keys / 2,
        dup.len() as f64 / 1e6,
        kb as f64 / 1024.0,
        out as f64 / 1e6
    );
    let _ = std::fs::remove_dir_all(&dir);
}
