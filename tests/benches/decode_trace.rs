//! Decodes a 1,000,000-frame candump log of the three seed devices with
//! `eds2rust-decode` on one core (the text read, every frame classified,
//! every PDO field named with its raw value), and, in the same run, the
//! same PDO frames with python-canopen 2.4.1's PDO maps; prints frames per
//! second and the ratio.
//!
//! `cargo bench -p eds2rust-tests --bench decode_trace`
//!
//! Rows:
//! - `trace`: the whole log as text → records; per PDO record the sink
//!   reads every field's name and raw value (what "every field named"
//!   costs). Goal: at least 1,000,000 frames/s.
//! - `pdo frames`: only the PDO frames, already parsed, through
//!   `Decoder::frame` with the same sink; against python-canopen's
//!   `map.on_message(...)` and `.raw` of every mapped variable on the same
//!   frames (bench_pdo.py, the anchor of the pdo_codec benchmark).
//! - `json`: the whole log rendered as JSON Lines into memory, for scale.

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use eds2rust_decode::{Decoder, Kind, Record, render};
use eds2rust_runtime::{CanId, Frame};
use serde_json::{Value as Json, json};

/// The default PDOs of the seed devices: device, node, kind, number, COB-ID, length.
const PDOS: [(&str, u8, &str, u16, u16, usize); 14] = [
    ("linak_techline", 32, "tpdo", 1, 0x1A0, 8),
    ("linak_techline", 32, "tpdo", 2, 0x2A0, 8),
    ("linak_techline", 32, "rpdo", 1, 0x220, 8),
    ("zimmer_acs", 40, "tpdo", 1, 0x1A8, 6),
    ("zimmer_acs", 40, "tpdo", 2, 0x2A8, 4),
    ("zimmer_acs", 40, "tpdo", 3, 0x3A8, 6),
    ("zimmer_acs", 40, "rpdo", 1, 0x228, 6),
    ("zimmer_acs", 40, "rpdo", 2, 0x328, 4),
    ("interroll_ec5000bi", 127, "tpdo", 1, 0x1FF, 8),
    ("interroll_ec5000bi", 127, "tpdo", 2, 0x2FF, 6),
    ("interroll_ec5000bi", 127, "tpdo", 3, 0x3FF, 6),
    ("interroll_ec5000bi", 127, "rpdo", 1, 0x27F, 7),
    ("interroll_ec5000bi", 127, "rpdo", 2, 0x37F, 6),
    ("interroll_ec5000bi", 127, "rpdo", 3, 0x47F, 6),
];

/// Deterministic pseudo-random bytes (xorshift64*).
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
}

/// `count` frames: 9 in 10 PDOs of the table (round robin), the others
/// heartbeats, SYNC and expedited SDO uploads with their answers.
fn frames(count: usize) -> Vec<Frame> {
    let mut random = Random(0x9E37_79B9_7F4A_7C15);
    let frame = |id: u16, data: &[u8]| Frame::new(CanId::Standard(id), data).expect("frame");
    (0..count)
        .map(|i| match i % 10 {
            9 => match (i / 10) % 4 {
                0 => frame(0x720, &[0x05]),
                1 => frame(0x080, &[]),
                2 => frame(0x628, &[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]),
                _ => frame(0x5A8, &[0x4B, 0x41, 0x60, 0, 0x37, 0x06, 0, 0]),
            },
            k => {
                let (_, _, _, _, id, len) = PDOS[(i / 10 * 9 + k) % PDOS.len()];
                frame(id, &random.next().to_le_bytes()[..len])
            }
        })
        .collect()
}

fn decoder() -> Decoder {
    let mut decoder = Decoder::new();
    let root = eds2rust_tests::workspace_root();
    for (device, node) in [
        ("linak_techline", 32),
        ("zimmer_acs", 40),
        ("interroll_ec5000bi", 127),
    ] {
        let path = root.join(format!("eds/{device}.yaml"));
        let loaded = eds2rust::input::read_device(&path, &eds2rust::input::Options::default());
        decoder.add_node(node, Arc::new(loaded.device.expect("seed device")));
    }
    decoder
}

/// What a user of the records does: every PDO field's name and raw value.
fn consume(record: &Record, named: &mut usize) {
    if let Record::Frame(f) = record
        && let Kind::Pdo {
            layout: Some(layout),
            fields,
            ..
        } = &f.kind
    {
        for (field, raw) in layout.fields.iter().zip(fields) {
            black_box((&*field.name, raw));
            *named += 1;
        }
    }
}

/// Median seconds of `passes` runs of `run` (after a warm-up run).
fn median(passes: usize, mut run: impl FnMut()) -> f64 {
    run();
    let mut samples: Vec<f64> = (0..passes)
        .map(|_| {
            let start = Instant::now();
            run();
            start.elapsed().as_secs_f64()
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

/// python-canopen's ns per PDO frame, each PDO's frames weighted by their
/// share of the trace; checks that it reads the raw values we read.
fn python(pdo_frames: &[Vec<Vec<u8>>], ours: &[Vec<Vec<i128>>]) -> (f64, String) {
    let dir = eds2rust_tests::target_dir().join("decode_trace");
    std::fs::create_dir_all(&dir).expect("create target/decode_trace");
    let root = eds2rust_tests::workspace_root();
    let mut pdos = Vec::new();
    for ((device, node, kind, number, _, _), frames) in PDOS.iter().zip(pdo_frames) {
        let eds = dir.join(format!("{device}.eds"));
        if !eds.exists() {
            let yaml = root.join(format!("eds/{device}.yaml"));
            let loaded = eds2rust::input::read_device(&yaml, &eds2rust::input::Options::strict());
            std::fs::write(&eds, eds2rust::r#gen::to_eds(&loaded.device.expect("seed")))
                .expect("write EDS");
        }
        pdos.push(
            json!({"eds": eds, "node_id": node, "kind": kind, "number": number, "frames": frames}),
        );
    }
    let spec = dir.join("spec.json");
    let text = json!({"min_batch_ops": 2000, "pdos": pdos}).to_string();
    std::fs::write(&spec, text).expect("write spec");
    let out =
        eds2rust_tests::python::run_script("bench_pdo.py", &[spec.as_path()], &["--batches", "11"])
            .unwrap_or_else(|e| panic!("python-canopen benchmark failed: {e}"));
    let result: Json =
        serde_json::from_str(out.lines().last().expect("a JSON line")).expect("JSON");
    let mut total_ns = 0.0;
    let mut total = 0usize;
    for ((py, frames), ours) in result["pdos"]
        .as_array()
        .expect("pdos")
        .iter()
        .zip(pdo_frames)
        .zip(ours)
    {
        let raws: Vec<Vec<i128>> = serde_json::from_value(py["raw"].clone()).expect("raw");
        assert_eq!(&raws, ours, "python-canopen reads other raw values");
        total_ns += py["decode_ns"].as_f64().expect("ns") * frames.len() as f64;
        total += frames.len();
    }
    let version = result["canopen"].as_str().unwrap_or("?").to_string();
    (total_ns / total as f64, version)
}

fn main() {
    // `cargo test --benches` runs bench binaries without `--bench`: a quick check only.
    let quick = !std::env::args().any(|a| a == "--bench");
    let (count, passes) = if quick { (10_000, 1) } else { (1_000_000, 5) };
    let frames = frames(count);
    let text: String = frames
        .iter()
        .enumerate()
        .map(|(i, f)| {
            format!(
                "({}.{:06}) can0 {f}\n",
                1_700_000_000 + i / 1000,
                (i % 1000) * 1000
            )
        })
        .collect();

    // Every frame decodes, none is unknown, every PDO has its fields.
    let mut check = decoder();
    let mut named = 0;
    let mut records = 0;
    let summary = eds2rust_decode::decode_trace(&mut check, text.as_bytes(), |r| {
        records += 1;
        if let Record::Frame(f) = r {
            assert!(
                !matches!(f.kind, Kind::Unknown | Kind::Invalid { .. }),
                "{}",
                render::text(r)
            );
        }
        consume(r, &mut named);
        Ok(())
    })
    .expect("decode");
    assert_eq!((summary.frames, summary.bad_lines), (count, 0));
    let pdo_count = frames
        .iter()
        .enumerate()
        .filter(|(i, _)| i % 10 != 9)
        .count();
    assert!(
        named >= pdo_count,
        "{named} fields named in {pdo_count} PDO frames"
    );

    // A fresh decoder per pass (PDO mappings and SDO state start over),
    // read before the clock starts.
    let mut fresh: Vec<Decoder> = (0..=passes).map(|_| decoder()).collect();
    let trace_s = median(passes, || {
        let mut d = fresh.pop().expect("a decoder per pass");
        let mut n = 0;
        eds2rust_decode::decode_trace(&mut d, black_box(text.as_bytes()), |r| {
            consume(r, &mut n);
            Ok(())
        })
        .expect("decode");
        black_box(n);
    });
    let pdo_only: Vec<Frame> = frames
        .iter()
        .enumerate()
        .filter(|(i, _)| i % 10 != 9)
        .map(|(_, f)| *f)
        .collect();
    let mut d = decoder();
    let mut out = Vec::new();
    let pdo_s = median(passes, || {
        let mut n = 0;
        for (i, f) in pdo_only.iter().enumerate() {
            d.frame(i + 1, None, black_box(f), &mut out);
            for r in out.drain(..) {
                consume(&r, &mut n);
            }
        }
        black_box(n);
    });
    let mut fresh: Vec<Decoder> = (0..=passes.min(3)).map(|_| decoder()).collect();
    let json_s = median(passes.min(3), || {
        let mut d = fresh.pop().expect("a decoder per pass");
        let mut buf = Vec::with_capacity(text.len() * 4);
        eds2rust_decode::decode_trace(&mut d, text.as_bytes(), |r| {
            render::write_json(&mut buf, r)?;
            buf.push(b'\n');
            Ok(())
        })
        .expect("decode");
        black_box(buf.len());
    });
    let per_s = |s: f64, n: usize| n as f64 / s;
    println!(
        "decode_trace: {count} frames ({pdo_count} PDOs of 14 default PDOs of the three seed devices, the others heartbeat, SYNC, SDO); median of {passes} passes, one core"
    );
    let trace_rate = per_s(trace_s, count);
    println!(
        "  trace (text → records, every PDO field named): {:>6.3} s, {:>10.0} frames/s, {:>6.0} ns/frame",
        trace_s,
        trace_rate,
        trace_s * 1e9 / count as f64
    );
    let pdo_ns = pdo_s * 1e9 / pdo_count as f64;
    println!(
        "  pdo frames (frame → record, fields named):    {:>6.3} s, {:>10.0} frames/s, {pdo_ns:>6.0} ns/frame",
        pdo_s,
        per_s(pdo_s, pdo_count)
    );
    println!(
        "  json (text → JSON Lines):                     {:>6.3} s, {:>10.0} frames/s",
        json_s,
        per_s(json_s, count)
    );
    let verdict = if trace_rate >= 1e6 { "met" } else { "MISSED" };
    println!("summary: trace {trace_rate:.0} frames/s; goal >= 1000000 frames/s: {verdict}");
    if quick {
        println!("summary: python-canopen: not run (quick mode)");
        return;
    }
    // The same PDO frames per PDO, and the raw values we decode from them.
    let mut per_pdo: Vec<Vec<Vec<u8>>> = vec![Vec::new(); PDOS.len()];
    let mut raws: Vec<Vec<Vec<i128>>> = vec![Vec::new(); PDOS.len()];
    let mut d = decoder();
    for f in pdo_only.iter().take(PDOS.len() * 64) {
        let k = PDOS
            .iter()
            .position(|p| Some(p.4) == f.standard_id())
            .expect("a PDO of the table");
        per_pdo[k].push(f.data().to_vec());
        d.frame(0, None, f, &mut out);
        if let Some(Record::Frame(r)) = out.first()
            && let Kind::Pdo { fields, .. } = &r.kind
        {
            let ints = fields.iter().map(|raw| match raw {
                eds2rust_decode::pdo::Raw::Int(i) => *i,
                eds2rust_decode::pdo::Raw::Real(x) => *x as i128,
            });
            raws[k].push(ints.collect());
        }
        out.clear();
    }
    let (py_ns, version) = python(&per_pdo, &raws);
    println!(
        "  python-canopen {version} (map.on_message + .raw of every variable, same frames): {py_ns:.0} ns/frame"
    );
    println!(
        "summary: python-canopen / eds2rust-decode per PDO frame: {:.0}x (eds2rust {pdo_ns:.0} ns, python-canopen {py_ns:.0} ns)",
        py_ns / pdo_ns
    );
}
