//! Decodes and encodes every default PDO of the three seed devices with the
//! generated code of `eds2rust-drivers`, with hand-written shift code for the
//! same PDOs, and (in the same run) with python-canopen 2.4.1's PDO maps;
//! prints ns per frame and the ratios.
//!
//! `cargo bench -p eds2rust-tests --bench pdo_codec`
//!
//! Rows: `decode` is bytes (a slice whose length the compiler does not know)
//! → the struct, handed on (`black_box`) when the frame is valid; python-canopen's decode is
//! `map.on_message(...)` and `.raw` of every mapped variable. `encode` is the
//! struct → bytes; python-canopen's sets `.raw` of every mapped variable and
//! takes `bytes(map.data)`. Before timing, every frame must decode to the same
//! values through the generated and the hand-written code (the raw value of
//! every mapped field, every named bit and bit field), python-canopen must
//! read the same raw values, all three must encode them back to the frame,
//! and frames one byte short or long (and empty) must be rejected.
//!
//! The timing loops run 16 frames per step, unrolled. At about two cycles a
//! frame, a one-frame loop times where the linker puts it as much as what
//! it runs: the same instructions at two addresses timed up to 1.3x apart.

use std::hint::black_box;
use std::time::Instant;

use eds2rust_drivers::{interroll_ec5000bi as ir, linak_techline as lk, zimmer_acs as zm};
use eds2rust_runtime::od::Pdo;
use serde_json::{Value as Json, json};

/// A CAN frame's data: up to 8 bytes.
#[derive(Clone, Copy)]
struct Frame {
    data: [u8; 8],
    len: usize,
}

impl Frame {
    fn new(bytes: &[u8]) -> Frame {
        let mut data = [0; 8];
        data[..bytes.len()].copy_from_slice(bytes);
        let len = bytes.len();
        Frame { data, len }
    }
    fn bytes(&self) -> &[u8] {
        &self.data[..self.len]
    }
}

/// `count` deterministic pseudo-random frames of `len` bytes (xorshift64*).
fn random_frames(seed: u64, len: usize, count: usize) -> Vec<Frame> {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..count)
        .map(|_| {
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            let bytes = state.wrapping_mul(0x2545_F491_4F6C_DD1D).to_le_bytes();
            Frame::new(&bytes[..len])
        })
        .collect()
}

fn hex_frames(frames: &[&str]) -> Vec<Frame> {
    let byte = |b: &str| u8::from_str_radix(b, 16).expect("hex byte");
    let frame = |f: &&str| Frame::new(&f.split(' ').map(byte).collect::<Vec<u8>>());
    frames.iter().map(frame).collect()
}

/// What an integrator writes today: fixed byte offsets, `from_le_bytes`, a
/// plain struct of raw integer fields; the bits are read with `>> bit & 1`
/// at the bit positions of the manuals (the `*_BITS` tables).
#[rustfmt::skip]
#[path = "pdo_codec/hand.rs"]
mod hand;

/// The values both sides must agree on, per decoded PDO: the raw value of
/// every mapped field in mapping order, then every named bit (0/1) and bit field.
#[rustfmt::skip]
#[path = "pdo_codec/values.rs"]
mod values;

/// The seed devices' default PDOs again, declared with `#[derive(Pdo)]`:
/// the same mappings and field types as the generated structs.
#[rustfmt::skip]
#[path = "pdo_codec/derived.rs"]
mod derived;

/// Where a PDO is and what it carries.
struct Meta {
    device: &'static str,
    node_id: u8,
    kind: &'static str,
    number: u16,
    label: &'static str,
    /// How many of the values are mapped fields (the rest are bits).
    mapped: usize,
}

/// ns per frame: [generated, derived, hand-written].
type Triple = [f64; 3];

/// One PDO: its frames, the generated values of each frame, and the timings.
struct Case {
    meta: Meta,
    len: usize,
    frames: Vec<Frame>,
    values: Vec<Vec<i64>>,
    decode: Triple,
    encode: Triple,
}

/// Batches per measurement and frame operations per batch.
#[derive(Clone, Copy)]
struct Plan {
    batches: usize,
    ops: usize,
}

/// Median ns per frame of `a`, `b` and `c`, timed in batches whose order
/// rotates so that drift hits all three.
fn triple(
    plan: Plan,
    frames: usize,
    mut a: impl FnMut(usize),
    mut b: impl FnMut(usize),
    mut c: impl FnMut(usize),
) -> Triple {
    let passes = plan.ops.div_ceil(frames);
    a(passes); // warm-up
    b(passes);
    c(passes);
    let mut samples = [Vec::new(), Vec::new(), Vec::new()];
    for batch in 0..plan.batches {
        for k in 0..3 {
            let which = (batch + k) % 3;
            let start = Instant::now();
            let run: &mut dyn FnMut(usize) = match which {
                0 => &mut a,
                1 => &mut b,
                _ => &mut c,
            };
            run(passes); // one dynamic call per batch; the loops inside are monomorphic
            let ns = start.elapsed().as_nanos() as f64;
            samples[which].push(ns / (passes * frames) as f64);
        }
    }
    samples.map(|mut s| {
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    })
}

/// Runs `f` on every item, `passes` times; each item through `black_box`,
/// so that neither its bytes nor its length are known to the compiler.
#[inline(always)]
fn each<T, R>(items: &[T], passes: usize, mut f: impl FnMut(&T) -> R) {
    let (chunks, rest) = items.as_chunks::<UNROLL>();
    assert!(rest.is_empty(), "frames come in chunks of {UNROLL}");
    for _ in 0..passes {
        for chunk in chunks {
            for item in chunk {
                f(black_box(item));
            }
        }
    }
}

/// `items` repeated to `n` items.
fn repeated<T: Copy>(items: &[T], n: usize) -> Vec<T> {
    items.iter().copied().cycle().take(n).collect()
}

/// Frames per unrolled step of the timing loops: the loop's own branch and
/// its place in the instruction cache weigh 1/16 of a frame, so that the
/// same instructions time the same wherever the linker puts them.
const UNROLL: usize = 16;

/// What a receiver does with a decoded frame: hands the struct on when the
/// frame was valid (`black_box` stands for the code that uses it). The same
/// for all three codecs, so that the timing is the decoding: keeping the
/// whole `Option` instead times how the compiler spills it, which differs
/// between a `Result` turned into an `Option` and a plain `Option` even where
/// the decoding instructions are the same.
#[inline(always)]
fn deliver<T>(decoded: Option<T>) {
    if let Some(value) = decoded {
        black_box(value);
    }
}

/// Checks one PDO (generated against hand-written, both against the frames
/// and the error paths) and times it.
#[allow(clippy::too_many_arguments)]
fn case<G: Pdo + Copy, D: Pdo + Copy, H: Copy, const N: usize, const K: usize>(
    plan: Plan,
    meta: Meta,
    frames: Vec<Frame>,
    gen_decode: impl Fn(&[u8]) -> Option<G> + Copy,
    gen_encode: impl Fn(&G) -> [u8; N] + Copy,
    gen_values: impl Fn(&G) -> [i64; K] + Copy,
    der_decode: impl Fn(&[u8]) -> Option<D> + Copy,
    der_encode: impl Fn(&D) -> [u8; N] + Copy,
    hand_decode: impl Fn(&[u8]) -> Option<H> + Copy,
    hand_encode: impl Fn(&H) -> [u8; N] + Copy,
    hand_values: impl Fn(&H) -> [i64; K] + Copy,
) -> Case {
    let what = format!("{} {}", meta.device, meta.label);
    assert_eq!(G::LEN, N, "{what}: LEN");
    let decoded = |f: &Frame| {
        (
            gen_decode(f.bytes()).unwrap(),
            hand_decode(f.bytes()).unwrap(),
        )
    };
    let (gens, hands): (Vec<G>, Vec<H>) = frames.iter().map(decoded).unzip();
    // The derived struct has the generated one's mapping and field types,
    // so it must give the same bytes back for every frame.
    assert_eq!(D::MAPPING, G::MAPPING, "{what}: derived mapping");
    let ders: Vec<D> = frames
        .iter()
        .map(|f| der_decode(f.bytes()).unwrap())
        .collect();
    for (((f, g), h), d) in frames.iter().zip(&gens).zip(&hands).zip(&ders) {
        let (ours, theirs) = (gen_values(g), hand_values(h));
        assert_eq!(ours, theirs, "{what}: values of {:02X?}", f.bytes());
        assert_eq!(gen_encode(g), f.bytes(), "{what}: generated encode");
        assert_eq!(der_encode(d), f.bytes(), "{what}: derived encode");
        assert_eq!(hand_encode(h), f.bytes(), "{what}: hand-written encode");
    }
    for bad in [&[0u8; 8][..N - 1], &[0u8; 9][..N + 1], &[]] {
        let all =
            gen_decode(bad).is_none() && der_decode(bad).is_none() && hand_decode(bad).is_none();
        assert!(all, "{what}: {} bytes decode", bad.len());
    }
    // Timed: the frames repeated to a whole number of unrolled steps.
    let n = frames.len().div_ceil(UNROLL) * UNROLL;
    let (t_frames, t_gens) = (repeated(&frames, n), repeated(&gens, n));
    let (t_ders, t_hands) = (repeated(&ders, n), repeated(&hands, n));
    let decode = triple(
        plan,
        n,
        |p| each(&t_frames, p, |f| deliver(gen_decode(f.bytes()))),
        |p| each(&t_frames, p, |f| deliver(der_decode(f.bytes()))),
        |p| each(&t_frames, p, |f| deliver(hand_decode(f.bytes()))),
    );
    let encode = triple(
        plan,
        n,
        |p| each(&t_gens, p, |g| black_box(gen_encode(g))),
        |p| each(&t_ders, p, |d| black_box(der_encode(d))),
        |p| each(&t_hands, p, |h| black_box(hand_encode(h))),
    );
    let values = gens.iter().map(|g| gen_values(g).to_vec()).collect();
    let len = N;
    Case {
        meta,
        len,
        frames,
        values,
        decode,
        encode,
    }
}

/// `pdo!(plan, module, "label", mapped fields, frames, Generated, Derived, values, HandWritten, values)`.
macro_rules! pdo {
    ($plan:expr, $m:ident, $label:literal, $mapped:literal, $frames:expr,
     $g:ident, $d:ident, $gv:path, $h:ident, $hv:path) => {{
        let kind = match <$m::pdo::$g as Pdo>::DIRECTION {
            eds2rust_runtime::od::PdoDirection::Tpdo => "tpdo",
            eds2rust_runtime::od::PdoDirection::Rpdo => "rpdo",
        };
        let number = <$m::pdo::$g as Pdo>::NUMBER;
        let device = match stringify!($m) { "lk" => "linak_techline", "zm" => "zimmer_acs", _ => "interroll_ec5000bi" };
        let meta = Meta { device, node_id: $m::DEFAULT_NODE_ID, kind, number, label: $label, mapped: $mapped };
        case($plan, meta, $frames, |d| $m::pdo::$g::decode(d).ok(), $m::pdo::$g::encode, $gv,
             |d| derived::$d::decode(d).ok(), derived::$d::encode,
             hand::$h::decode, hand::$h::encode, $hv)
    }};
}

#[rustfmt::skip]
fn cases(p: Plan) -> Vec<Case> {
    use values::*;
    // The LINAK manual's start-up trace (p. 28, node 32).
    let lk_feedback = hex_frames(&["1A 00 06 88 00 31 00 C0", "F7 01 00 82 00 00 00 C0", "60 00 06 90 00 32 00 C0",
                                   "00 00 00 81 01 00 00 C0", "00 00 00 81 00 00 00 C0"]);
    // Stop, run out, run in (trace), and a 12.3 mm set point with the other fields at their defaults.
    let lk_command = hex_frames(&["03 FB FB FB FB FB 00 00", "01 FB FB FB FB FB 00 00", "02 FB FB FB FB FB 00 00",
                                  "7B 00 FB FB FB FB 00 00"]);
    let r = random_frames;
    vec![
        pdo!(p, lk, "TPDO1 feedback", 6, lk_feedback, Tpdo1Feedback, LkTpdo1Feedback, lk_tpdo1, LkFeedback, hand_lk_tpdo1),
        pdo!(p, lk, "TPDO2 parallel feedback", 8, r(12, 8, 16), Tpdo2ParallelFeedback, LkTpdo2ParallelFeedback, lk_tpdo2, LkParallel, hand_lk_tpdo2),
        pdo!(p, lk, "RPDO1 command", 7, lk_command, Rpdo1Command, LkRpdo1Command, lk_rpdo1, LkCommand, hand_lk_rpdo1),
        pdo!(p, zm, "TPDO1 status and position", 2, r(21, 6, 16), Tpdo1StatusAndPosition, ZmTpdo1StatusAndPosition, zm_tpdo1, WordAnd32, hand_zm_tpdo1),
        pdo!(p, zm, "TPDO2 velocity", 1, r(22, 4, 16), Tpdo2Velocity, ZmTpdo2Velocity, zm_tpdo2, One32, hand_i32),
        pdo!(p, zm, "TPDO3 following error and torque", 2, r(23, 6, 16), Tpdo3FollowingErrorAndTorque, ZmTpdo3FollowingErrorAndTorque, zm_tpdo3,
             ZmFollowingTorque, hand_zm_tpdo3),
        pdo!(p, zm, "RPDO1 control and target position", 2, r(24, 6, 16), Rpdo1ControlAndTargetPosition, ZmRpdo1ControlAndTargetPosition, zm_rpdo1,
             WordAnd32, hand_zm_rpdo1),
        pdo!(p, zm, "RPDO2 profile velocity", 1, r(25, 4, 16), Rpdo2ProfileVelocity, ZmRpdo2ProfileVelocity, zm_rpdo2, One32, hand_u32),
        pdo!(p, ir, "TPDO1 status", 5, r(31, 8, 16), Tpdo1Status, IrTpdo1Status, ir_tpdo1, IrStatus, hand_ir_tpdo1),
        pdo!(p, ir, "TPDO2 position", 2, r(32, 6, 16), Tpdo2Position, IrTpdo2Position, ir_tpdo2, WordAnd32, hand_ir_tpdo23),
        pdo!(p, ir, "TPDO3 velocity", 2, r(33, 6, 16), Tpdo3Velocity, IrTpdo3Velocity, ir_tpdo3, WordAnd32, hand_ir_tpdo23),
        pdo!(p, ir, "RPDO1 velocity command", 3, r(34, 7, 16), Rpdo1VelocityCommand, IrRpdo1VelocityCommand, ir_rpdo1, IrVelocityCommand,
             hand_ir_rpdo1),
        pdo!(p, ir, "RPDO2 position command", 2, r(35, 6, 16), Rpdo2PositionCommand, IrRpdo2PositionCommand, ir_rpdo2, WordAnd32, hand_ir_rpdo23),
        pdo!(p, ir, "RPDO3 target velocity command", 2, r(36, 6, 16), Rpdo3TargetVelocityCommand, IrRpdo3TargetVelocityCommand, ir_rpdo3, WordAnd32,
             hand_ir_rpdo23),
    ]
}

/// Exports the seed devices as EDS, runs `bench_pdo.py` on every case's
/// frames, checks that its raw values and encodings agree with ours, and
/// returns its ns per frame ([decode, encode]) per case and a header line.
fn python(cases: &[Case]) -> (Vec<[f64; 2]>, String) {
    let dir = eds2rust_tests::target_dir().join("pdo_codec");
    std::fs::create_dir_all(&dir).expect("create target/pdo_codec");
    let mut pdos = Vec::new();
    let mut exported = std::collections::BTreeSet::new();
    for c in cases {
        let eds = dir.join(format!("{}.eds", c.meta.device));
        if exported.insert(c.meta.device) {
            let root = eds2rust_tests::workspace_root();
            let yaml = root.join(format!("eds/{}.yaml", c.meta.device));
            let options = eds2rust::input::Options::strict();
            let device = eds2rust::input::read_device(&yaml, &options)
                .device
                .expect("seed device");
            std::fs::write(&eds, eds2rust::r#gen::to_eds(&device)).expect("write EDS");
        }
        let frames: Vec<&[u8]> = c.frames.iter().map(Frame::bytes).collect();
        let (node_id, kind, number) = (c.meta.node_id, c.meta.kind, c.meta.number);
        pdos.push(json!({"eds": eds, "node_id": node_id, "kind": kind, "number": number, "frames": frames}));
    }
    let spec = dir.join("spec.json");
    let text = json!({"min_batch_ops": 1000, "pdos": pdos}).to_string();
    std::fs::write(&spec, text).expect("write spec");
    let extra = ["--batches", "21"];
    let out = eds2rust_tests::python::run_script("bench_pdo.py", &[spec.as_path()], &extra)
        .unwrap_or_else(|e| panic!("python-canopen benchmark failed: {e}"));
    let line = out
        .lines()
        .last()
        .expect("bench_pdo.py prints one JSON line");
    let result: Json = serde_json::from_str(line).expect("bench_pdo.py prints JSON");
    let mut times = Vec::new();
    for (c, py) in cases.iter().zip(result["pdos"].as_array().expect("pdos")) {
        let what = format!("{} {} (python-canopen)", c.meta.device, c.meta.label);
        let raws: Vec<Vec<i64>> = serde_json::from_value(py["raw"].clone()).expect("raw");
        let encoded: Vec<Vec<u8>> = serde_json::from_value(py["encoded"].clone()).expect("encoded");
        assert_eq!(raws.len(), c.frames.len(), "{what}: frames");
        for (((f, ours), theirs), enc) in c.frames.iter().zip(&c.values).zip(&raws).zip(&encoded) {
            let (ours, f) = (&ours[..c.meta.mapped], f.bytes());
            assert_eq!(ours, theirs.as_slice(), "{what}: raw values of {f:02X?}");
            assert_eq!(enc.as_slice(), f, "{what}: encoded");
        }
        let ns = |key: &str| py[key].as_f64().expect("ns per frame");
        times.push([ns("decode_ns"), ns("encode_ns")]);
    }
    let mut header = format!(
        "python-canopen {} (Python {}): median of {} batches of >= 1000 frames; its raw values and encodings agree with ours on every frame of all {} PDOs",
        result["canopen"].as_str().unwrap_or("?"),
        result["python"].as_str().unwrap_or("?"),
        result["batches"],
        cases.len()
    );
    for note in result["notes"].as_array().into_iter().flatten() {
        header += &format!("\n  note: {}", note.as_str().unwrap_or("?"));
    }
    (times, header)
}

fn geomean(xs: &[f64]) -> f64 {
    (xs.iter().map(|x| x.ln()).sum::<f64>() / xs.len() as f64).exp()
}

fn main() {
    // `cargo test --benches` runs bench binaries without `--bench`: check and time briefly, no python.
    let quick = !std::env::args().any(|a| a == "--bench");
    let (batches, ops) = if quick { (3, 1000) } else { (101, 100_000) };
    let plan = Plan { batches, ops };
    let cases = cases(plan);
    let (py, header) = match quick {
        true => (
            vec![[f64::NAN; 2]; cases.len()],
            "python-canopen: not run (quick mode)".into(),
        ),
        false => python(&cases),
    };
    println!(
        "pdo_codec: ns per frame; Rust: median of {batches} batches of >= {ops} frames, generated, derived (`#[derive(Pdo)]`, same mapping) and hand-written in rotating batches"
    );
    println!("{header}");
    // [generated/hand-written, derived/hand-written] per row.
    let mut ratios: [Vec<(f64, String)>; 2] = Default::default();
    let mut py_ratios: Vec<(f64, String)> = Vec::new();
    for (c, py) in cases.iter().zip(&py) {
        let name = format!("{} {}", c.meta.device, c.meta.label);
        let (len, mapped, values, frames) =
            (c.len, c.meta.mapped, c.values[0].len(), c.frames.len());
        println!(
            "\n{name}: {len} bytes, {mapped} mapped fields, {values} values with bits, {frames} frames"
        );
        println!(
            "  {:<8}generated    derived  hand-written  python-canopen  gen/hand  der/hand  python/gen",
            ""
        );
        let rows = [("decode", c.decode, py[0]), ("encode", c.encode, py[1])];
        for (op, [g, d, h], p) in rows {
            let (py_col, ratio_col) = if p.is_nan() {
                ("-".to_string(), "-".to_string())
            } else {
                py_ratios.push((p / g, format!("{name} {op}")));
                (format!("{p:.0} ns"), format!("{:.0}x", p / g))
            };
            ratios[0].push((g / h, format!("{name} {op} (generated)")));
            ratios[1].push((d / h, format!("{name} {op} (derived)")));
            println!(
                "  {op:<6} {g:>8.2} ns {d:>7.2} ns {h:>10.2} ns {py_col:>15} {:>8.3}x {:>8.3}x {ratio_col:>11}",
                g / h,
                d / h
            );
        }
    }
    println!();
    let ratio_list = |rs: &[(f64, String)]| rs.iter().map(|r| r.0).collect::<Vec<f64>>();
    for (what, rs) in ["generated", "derived"].iter().zip(&ratios) {
        let (max, which) = rs.iter().max_by(|a, b| a.0.total_cmp(&b.0)).expect("cases");
        let mean = geomean(&ratio_list(rs));
        let over: Vec<String> = rs
            .iter()
            .filter(|r| r.0 > 1.05)
            .map(|r| format!("{} {:.2}x", r.1, r.0))
            .collect();
        let verdict = match over.len() {
            _ if quick => "not judged (a quick check, not a measurement: run with --bench)".into(),
            0 => "met".to_string(),
            n => format!("MISSED in {n} of {} rows: {}", rs.len(), over.join(", ")),
        };
        println!(
            "summary: {what}/hand-written geometric mean {mean:.3}x, max {max:.3}x ({which}); goal <= 1.05x per row: {verdict}"
        );
    }
    if let Some((min, which)) = py_ratios.iter().min_by(|a, b| a.0.total_cmp(&b.0)) {
        let (mean, verdict) = (
            geomean(&ratio_list(&py_ratios)),
            if *min >= 1000.0 { "met" } else { "MISSED" },
        );
        println!(
            "summary: python-canopen/generated geometric mean {mean:.0}x, min {min:.0}x ({which}); goal >= 1000x: {verdict}"
        );
    }
}
