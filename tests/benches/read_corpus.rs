//! Reads every corpus file with eds2rust and, in the same run, with
//! python-canopen's `import_od`; prints both times per pass and the ratio.
//!
//! `cargo bench -p eds2rust-tests --bench read_corpus`

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

use eds2rust::eds::{Options, read_file};

fn eds2rust_pass(files: &[PathBuf]) -> usize {
    let mut entries = 0;
    for path in files {
        let loaded = read_file(path, &Options::default());
        entries += loaded.device.map_or(0, |d| {
            d.objects.values().map(|o| o.entries.len()).sum::<usize>()
        });
    }
    entries
}

/// Median seconds of `passes` passes over `files` (after one warm-up pass),
/// and the number of entries one pass read.
fn time_passes(files: &[PathBuf], passes: usize) -> (f64, usize) {
    let entries = black_box(eds2rust_pass(files));
    let mut samples: Vec<f64> = (0..passes)
        .map(|_| {
            let start = Instant::now();
            black_box(eds2rust_pass(files));
            start.elapsed().as_secs_f64()
        })
        .collect();
    samples.sort_by(|a, b| a.total_cmp(b));
    (samples[samples.len() / 2], entries)
}

fn main() {
    // `cargo test --benches` runs bench binaries without `--bench`: do one quick pass only.
    let quick = !std::env::args().any(|a| a == "--bench");
    let Some(files) = eds2rust_tests::corpus_files("read_corpus benchmark") else {
        return;
    };
    let passes = if quick { 1 } else { 50 };
    let (ours, entries) = time_passes(&files, passes);
    println!(
        "eds2rust:       {} files, {entries} entries, {:.3} ms per pass (median of {passes})",
        files.len(),
        ours * 1e3
    );
    if quick {
        return;
    }
    let paths: Vec<&std::path::Path> = files.iter().map(PathBuf::as_path).collect();
    let out = eds2rust_tests::python::run_script("bench_import.py", &paths, &["--iterations", "5"])
        .unwrap_or_else(|e| panic!("python-canopen benchmark failed: {e}"));
    let line = out
        .lines()
        .last()
        .expect("bench_import.py prints one JSON line");
    let result: serde_json::Value =
        serde_json::from_str(line).expect("bench_import.py prints JSON");
    let theirs = result["seconds_per_pass"]
        .as_f64()
        .expect("seconds_per_pass");
    println!(
        "python-canopen: {} files, {:.3} ms per pass ({})",
        result["files"],
        theirs * 1e3,
        result["statistic"].as_str().unwrap_or("?")
    );
    // The ratio is taken over the files both read: python-canopen fails on some.
    let skipped: Vec<&str> = result["skipped"]
        .as_array()
        .expect("skipped")
        .iter()
        .filter_map(|v| v.as_str())
        .collect();
    let common: Vec<PathBuf> = files
        .iter()
        .filter(|p| !skipped.contains(&p.to_str().unwrap()))
        .cloned()
        .collect();
    let (ours_common, _) = time_passes(&common, passes);
    println!(
        "eds2rust:       the same {} files, {:.3} ms per pass (median of {passes})",
        common.len(),
        ours_common * 1e3
    );
    println!(
        "ratio:          eds2rust is {:.1}x faster than python-canopen import_od on the same files",
        theirs / ours_common
    );
}
