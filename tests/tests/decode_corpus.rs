//! The trace decoder against python-canopen 2.4.1 on the default PDOs of
//! every corpus file (../shared/eds-corpus): `tests/python/decode_pdos.py`
//! loads each file into a RemoteNode, reads every TPDO and RPDO map from the
//! object dictionary and decodes a few frames per valid map (all zero, all
//! ones, pseudo-random; of the map's data length); the same frames, as a
//! candump trace, go through `eds2rust_decode` with the file as that node.
//! Every frame must decode as the same PDO, with the same mapped entries
//! (index, subindex, bit offset and length; python-canopen's dummy entries
//! 0x0001–0x0007 left out, as the decoder leaves them out) and the same raw
//! value per field: integers sign-extended by type, BOOLEAN as 0/1, REALs
//! by their bits.
//!
//! The node id is the DCF's `[DeviceComissioning] NodeID`, else 5; the
//! script is given the same id, so both resolve `$NODEID` alike. Valid PDOs
//! of one file that share a COB-ID (a configuration CiA 301 forbids) are
//! only checked to decode as one of them: a frame cannot tell which it is.
//! Every disagreement of every file is collected, and the test fails once
//! with the list; [`ALLOWED`] holds the disagreements that are
//! python-canopen's, each with its reason (an entry that no longer
//! disagrees fails too).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

use eds2rust::eds::{Options, read_file};
use eds2rust::ir::Device;
use eds2rust_decode::pdo::{PdoLayout, Raw};
use eds2rust_decode::{Decoder, FrameRecord, Kind, Record, render};
use serde_json::{Value as Json, json};

/// Frames per valid PDO (the first two all zero and all ones).
const FRAMES: usize = 6;

/// Node id of a file without a DCF node id.
const DEFAULT_NODE: u8 = 5;

/// Disagreements that are python-canopen's: (file name, `tpdoN`/`rpdoN` or
/// `*` for every PDO of the file, reason).
const ALLOWED: &[(&str, &str, &str)] = &[
    (
        "python-canopen_sample.eds",
        "*",
        "the default mappings name CiA 402 objects the file does not define \
         (0x6040, 0x6041, 0x6060, 0x6061, 0x6064, 0x606C, 0x607A, 0x60FF); \
         python-canopen drops such an entry together with its bits (later \
         entries would move), the decoder keeps it as an untyped field at \
         its offset, as CiA 301 places it",
    ),
    (
        "canopen-rust_sample.eds",
        "*",
        "the same default mappings as python-canopen_sample.eds (same \
         parameter names and values), to the same objects it does not define",
    ),
];

/// Disagreements of one field (or of the PDO's classification or mapping)
/// over the frames of one PDO.
struct Mismatch {
    file: String,
    pdo: String,
    /// What disagrees (a field, the classification); empty for the PDO.
    key: String,
    /// The first frame's description.
    what: String,
    /// Frames that disagree the same way.
    frames: usize,
}

#[derive(Default)]
struct Counts {
    files: usize,
    loaded: usize,
    pdos: usize,
    frames: usize,
    fields: usize,
    invalid: usize,
    python_errors: usize,
    shared: usize,
}

#[test]
fn pdo_frames_decode_as_python_canopen_decodes_them() {
    let Some(files) = eds2rust_tests::corpus_files("PDO decoding against python-canopen") else {
        return;
    };
    let mut devices = Vec::new();
    for path in &files {
        let loaded = read_file(path, &Options::default());
        let device = loaded
            .device
            .unwrap_or_else(|| panic!("{}: no device", path.display()));
        let node = device
            .commissioning
            .as_ref()
            .and_then(|c| c.node_id)
            .filter(|n| (1..=127).contains(n))
            .unwrap_or(DEFAULT_NODE);
        devices.push((path.clone(), node, Arc::new(device)));
    }
    let spec = json!({
        "frames": FRAMES,
        "files": devices
            .iter()
            .map(|(path, node, _)| json!({"eds": path, "node_id": node}))
            .collect::<Vec<_>>(),
    });
    let dir = eds2rust_tests::target_dir().join("decode_corpus");
    std::fs::create_dir_all(&dir).expect("create the spec directory");
    let spec_path = dir.join("spec.json");
    std::fs::write(&spec_path, spec.to_string()).expect("write the spec");
    let out = eds2rust_tests::python::run_script("decode_pdos.py", &[&spec_path], &[])
        .unwrap_or_else(|e| panic!("{e}"));
    let oracle: Json = serde_json::from_str(&out).expect("decode_pdos.py prints JSON");
    let results = oracle["files"].as_array().expect("files");
    assert_eq!(results.len(), devices.len());

    let mut counts = Counts::default();
    let mut mismatches = Vec::new();
    let mut not_compared = Vec::new();
    for ((path, node, device), theirs) in devices.iter().zip(results) {
        counts.files += 1;
        let file = file_name(path);
        if let Some(e) = theirs["error"].as_str() {
            not_compared.push(format!("{file}: python-canopen cannot load it: {e}"));
            continue;
        }
        counts.loaded += 1;
        let mut check = FileCheck {
            file: &file,
            node: *node,
            counts: &mut counts,
            mismatches: &mut mismatches,
            not_compared: &mut not_compared,
        };
        check.run(device, theirs);
    }

    let mut allowed_seen = vec![false; ALLOWED.len()];
    let mut failing = Vec::new();
    let mut allowed = 0;
    let mut allowed_lines = Vec::new();
    for m in &mismatches {
        let entry = ALLOWED
            .iter()
            .position(|(f, p, _)| *f == m.file && (*p == "*" || *p == m.pdo));
        match entry {
            Some(i) => {
                allowed_seen[i] = true;
                allowed += 1;
                allowed_lines.push(format!("{}: {}: {}", m.file, m.pdo, m.what));
            }
            None => failing.push(m),
        }
    }
    println!(
        "decode_corpus: {} files ({} loaded by python-canopen), {} PDOs compared \
         ({} on shared COB-IDs; {} invalid and {} python-canopen cannot read left out), \
         {} frames, {} fields compared, {} mismatches ({} allowed)",
        counts.files,
        counts.loaded,
        counts.pdos,
        counts.shared,
        counts.invalid,
        counts.python_errors,
        counts.frames,
        counts.fields,
        mismatches.len(),
        allowed,
    );
    for line in &not_compared {
        println!("  not compared: {line}");
    }
    for line in &allowed_lines {
        println!("  allowed: {line}");
    }
    let mut report = String::new();
    for m in &failing {
        let more = match m.frames {
            0 | 1 => String::new(),
            n => format!(" [{n} frames]"),
        };
        let _ = writeln!(report, "{}: {}: {}{more}", m.file, m.pdo, m.what);
    }
    for (i, (f, p, reason)) in ALLOWED.iter().enumerate() {
        if !allowed_seen[i] {
            let _ = writeln!(
                report,
                "{f}: {p}: allowed ({reason}), but decodes as python-canopen does: \
                 remove it from ALLOWED"
            );
        }
    }
    assert!(
        report.is_empty(),
        "the decoder and python-canopen disagree ({} mismatches):\n{report}",
        failing.len()
    );
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// One valid PDO python-canopen read, and where its frames are in the trace.
struct Sent<'a> {
    pdo: &'a Json,
    name: String,
    /// The identifier as the trace writes it (3 or 8 hex digits).
    cob: String,
    /// Trace line of every frame.
    lines: Vec<usize>,
    /// Every valid PDO of the file on this COB-ID (this one included).
    sharing: Vec<String>,
}

/// The comparison of one file.
struct FileCheck<'a> {
    file: &'a str,
    node: u8,
    counts: &'a mut Counts,
    mismatches: &'a mut Vec<Mismatch>,
    not_compared: &'a mut Vec<String>,
}

impl FileCheck<'_> {
    fn run(&mut self, device: &Arc<Device>, theirs: &Json) {
        let file = self.file;
        let mut trace = String::new();
        let mut sent: Vec<Sent> = Vec::new();
        let mut line = 0;
        for pdo in theirs["pdos"].as_array().expect("pdos") {
            let name = format!(
                "{}{}",
                pdo["kind"].as_str().expect("kind"),
                pdo["number"].as_u64().expect("number")
            );
            if let Some(e) = pdo["error"].as_str() {
                self.counts.python_errors += 1;
                self.not_compared.push(format!(
                    "{file}: {name}: python-canopen cannot read it: {e}"
                ));
                continue;
            }
            if pdo["enabled"] != true {
                self.counts.invalid += 1;
                continue;
            }
            let entry = pdo["cob_id_entry"].as_u64().expect("COB-ID entry");
            let extended = entry & 1 << 29 != 0;
            let cob = if extended {
                format!("{:08X}", entry & 0x1FFF_FFFF)
            } else {
                format!("{:03X}", entry & 0x7FF)
            };
            if !extended && entry & 0x1FFF_F800 != 0 {
                let what = format!(
                    "COB-ID entry {entry:#010X} has bits 11-28 set in an 11-bit COB-ID: \
                     python-canopen expects identifier {:#X}, the decoder 0x{cob}",
                    pdo["cob_id"].as_u64().unwrap_or(0)
                );
                self.push(&name, what);
            }
            let mut lines = Vec::new();
            for frame in pdo["frames"].as_array().expect("frames") {
                line += 1;
                let _ = writeln!(trace, "{cob}#{}", frame["data"].as_str().expect("data"));
                lines.push(line);
            }
            self.counts.pdos += 1;
            sent.push(Sent {
                pdo,
                name,
                cob,
                lines,
                sharing: Vec::new(),
            });
        }
        let mut by_cob: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for s in &sent {
            by_cob
                .entry(s.cob.clone())
                .or_default()
                .push(s.name.clone());
        }
        for s in &mut sent {
            s.sharing = by_cob[&s.cob].clone();
        }
        for (cob, names) in by_cob.iter().filter(|(_, n)| n.len() > 1) {
            self.not_compared.push(format!(
                "{file}: {} share COB-ID 0x{cob}: only checked to decode as one of them",
                names.join(", ")
            ));
        }

        let mut decoder = Decoder::new();
        decoder.add_node(self.node, device.clone());
        let mut records: BTreeMap<usize, (FrameRecord, Json)> = BTreeMap::new();
        let summary = eds2rust_decode::decode_trace(&mut decoder, trace.as_bytes(), |r| {
            if let Record::Frame(f) = r {
                records.insert(f.line, (f.clone(), render::json(r)));
            }
            Ok(())
        })
        .expect("decode the trace");
        assert_eq!(
            summary.bad_lines, 0,
            "{file}: the trace has bad lines:\n{trace}"
        );

        for s in &sent {
            if s.sharing.len() > 1 {
                self.counts.shared += 1;
            }
            self.compare_pdo(s, &records);
        }
    }

    /// Records a disagreement of `key` (a field, the classification) in
    /// one frame of `pdo`; one seen before in another frame only counts it.
    fn push_keyed(&mut self, pdo: &str, key: &str, what: String) {
        let seen = self
            .mismatches
            .iter_mut()
            .find(|m| m.file == self.file && m.pdo == pdo && m.key == key);
        match seen {
            Some(m) => m.frames += 1,
            None => self.mismatches.push(Mismatch {
                file: self.file.into(),
                pdo: pdo.into(),
                key: key.into(),
                what,
                frames: 1,
            }),
        }
    }

    /// Records a disagreement of the whole PDO (its COB-ID, its mapping).
    fn push(&mut self, pdo: &str, what: String) {
        self.mismatches.push(Mismatch {
            file: self.file.into(),
            pdo: pdo.into(),
            key: String::new(),
            what,
            frames: 0,
        });
    }

    fn compare_pdo(&mut self, s: &Sent, records: &BTreeMap<usize, (FrameRecord, Json)>) {
        let node = self.node;
        let vars = their_variables(s.pdo);
        let theirs = their_mapping(&vars);
        let mut mapping_checked = false;
        let frames = s.pdo["frames"].as_array().expect("frames");
        for (frame, &line) in frames.iter().zip(&s.lines) {
            self.counts.frames += 1;
            let data = frame["data"].as_str().unwrap_or_default().to_uppercase();
            let at = format!("frame {}#{data}", s.cob);
            let Some((rec, json)) = records.get(&line) else {
                self.push_keyed(&s.name, "no record", format!("no record: {at}"));
                continue;
            };
            let decoded_as = json["pdo"].as_str().unwrap_or_default();
            if json["protocol"] != "pdo"
                || !s.sharing.iter().any(|n| n == decoded_as)
                || rec.node != Some(node)
            {
                let what = format!(
                    "classified: decoded as {} {} of node {}, python-canopen: {} of node {node} ({at})",
                    json["protocol"], json["pdo"], json["node"], s.name
                );
                self.push_keyed(&s.name, "classified", what);
                continue;
            }
            if decoded_as != s.name {
                continue; // a shared COB-ID: decoded as another PDO on it
            }
            let Kind::Pdo {
                layout: Some(layout),
                problem,
                ..
            } = &rec.kind
            else {
                let what = format!("no mapping: the decoder knows none for it ({at}): {json}");
                self.push_keyed(&s.name, "no mapping", what);
                continue;
            };
            let problem = problem
                .as_ref()
                .map_or_else(String::new, |p| format!(" (decoder: {p})"));
            let ours = ours_mapping(layout);
            if !mapping_checked {
                mapping_checked = true;
                if ours != theirs {
                    let what = format!(
                        "mapping differs: decoder {}; python-canopen {}{problem}",
                        list(&ours),
                        list(&theirs)
                    );
                    self.push(&s.name, what);
                }
            }
            let fields = rec.kind.pdo_fields();
            let raws = frame["raw"].as_array().expect("raw values");
            for (field, (i, var)) in fields.iter().zip(&vars) {
                let same_entry = (u64::from(field.index), u64::from(field.subindex))
                    == (
                        var["index"].as_u64().unwrap_or(0),
                        var["subindex"].as_u64().unwrap_or(0),
                    );
                if !same_entry {
                    break; // told once above, as a mapping difference
                }
                self.counts.fields += 1;
                let value = &raws[*i];
                let width = width_of(layout, field.index, field.subindex);
                if !same_raw(field.raw, value, width) {
                    let key = format!("0x{:04X}.{}", field.index, field.subindex);
                    let what = format!(
                        "{key} {:?} ({} bits at bit {}, data type {:#06X}): decoder {} vs \
                         python-canopen {} ({at}){problem}",
                        field.name,
                        width,
                        var["offset"],
                        var["data_type"].as_u64().unwrap_or(0),
                        raw_text(field.raw),
                        their_text(value),
                    );
                    self.push_keyed(&s.name, &key, what);
                }
            }
        }
    }
}

/// A mapped entry as both sides describe it.
#[derive(PartialEq)]
struct Mapped {
    index: u64,
    subindex: u64,
    offset: u64,
    bits: u64,
}

impl std::fmt::Display for Mapped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "0x{:04X}.{} at bit {} ({} bits)",
            self.index, self.subindex, self.offset, self.bits
        )
    }
}

fn list(entries: &[Mapped]) -> String {
    if entries.is_empty() {
        return "(none)".into();
    }
    let items: Vec<String> = entries.iter().map(ToString::to_string).collect();
    items.join(", ")
}

fn ours_mapping(layout: &PdoLayout) -> Vec<Mapped> {
    layout
        .fields
        .iter()
        .map(|f| Mapped {
            index: u64::from(f.index),
            subindex: u64::from(f.subindex),
            offset: u64::from(f.offset),
            bits: u64::from(f.width),
        })
        .collect()
}

/// python-canopen's variables without its dummy entries (0x0001–0x0007,
/// mapped as variables when the file has `[DummyUsage]`), with their
/// position among all its variables.
fn their_variables(pdo: &Json) -> Vec<(usize, &Json)> {
    pdo["variables"]
        .as_array()
        .expect("variables")
        .iter()
        .enumerate()
        .filter(|(_, v)| !(1..=7).contains(&v["index"].as_u64().unwrap_or(0)))
        .collect()
}

fn their_mapping(vars: &[(usize, &Json)]) -> Vec<Mapped> {
    vars.iter()
        .map(|(_, v)| Mapped {
            index: v["index"].as_u64().unwrap_or(0),
            subindex: v["subindex"].as_u64().unwrap_or(0),
            offset: v["offset"].as_u64().unwrap_or(0),
            bits: v["length"].as_u64().unwrap_or(0),
        })
        .collect()
}

/// The width of field `index`.`sub` of `layout`.
fn width_of(layout: &PdoLayout, index: u16, sub: u8) -> u32 {
    layout
        .fields
        .iter()
        .find(|f| f.index == index && f.subindex == sub)
        .map_or(0, |f| f.width)
}

/// The decoder's raw value equals python-canopen's `.raw`: integers (and
/// BOOLEAN as 0/1) by value, REALs by their bits (NaN equal to NaN), byte
/// and text values by the field's `width` bits.
fn same_raw(ours: Raw, theirs: &Json, width: u32) -> bool {
    if let Some(n) = theirs.get("int") {
        let v = n
            .as_i64()
            .map(i128::from)
            .or_else(|| n.as_u64().map(i128::from));
        return matches!(ours, Raw::Int(i) if Some(i) == v);
    }
    if let Some(hex) = theirs.get("real").and_then(Json::as_str) {
        let Ok(bits) = u64::from_str_radix(hex, 16) else {
            return false;
        };
        return match ours {
            Raw::Real(r) => (r.is_nan() && f64::from_bits(bits).is_nan()) || r.to_bits() == bits,
            Raw::Int(_) => false,
        };
    }
    let Raw::Int(i) = ours else {
        return false;
    };
    let bytes: Vec<u8> = (0..width.div_ceil(8))
        .map(|k| (i >> (8 * k)) as u8)
        .collect();
    if let Some(hex) = theirs.get("hex").and_then(Json::as_str) {
        return render::hex(&bytes).eq_ignore_ascii_case(hex);
    }
    if let Some(text) = theirs.get("text").and_then(Json::as_str) {
        // python-canopen: ASCII, undecodable bytes dropped, trailing NULs stripped.
        let ascii: String = bytes
            .iter()
            .filter(|b| b.is_ascii())
            .map(|&b| char::from(b))
            .collect();
        return ascii.trim_end_matches('\0') == text;
    }
    false
}

fn int_text(i: i128) -> String {
    if i < 0 {
        i.to_string()
    } else {
        format!("{i} ({i:#X})")
    }
}

fn raw_text(raw: Raw) -> String {
    match raw {
        Raw::Int(i) => int_text(i),
        Raw::Real(r) => format!("{r:?} (REAL bits {:#018X})", r.to_bits()),
    }
}

fn their_text(value: &Json) -> String {
    if let Some(n) = value.get("int") {
        let v = n
            .as_i64()
            .map(i128::from)
            .or_else(|| n.as_u64().map(i128::from));
        return v.map_or_else(|| n.to_string(), int_text);
    }
    if let Some(hex) = value.get("real").and_then(Json::as_str) {
        let bits = u64::from_str_radix(hex, 16).unwrap_or(0);
        return format!("{:?} (REAL bits {bits:#018X})", f64::from_bits(bits));
    }
    value.to_string()
}
