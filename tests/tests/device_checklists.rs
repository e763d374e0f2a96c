//! The seed devices: each YAML table reads without a diagnostic, and its
//! checklist in docs/devices/ (format in docs/devices/README.md) agrees with
//! it: each manual table's `rows:` count equals the rows listed, every
//! reference resolves in the lowered device, and every entry of the device is
//! named by some row.

use std::collections::BTreeSet;

use eds2rust::eds::number::parse_int;
use eds2rust::input::{Options, read_device};
use eds2rust::ir::{Device, Entry, PdoDirection};
use eds2rust_tests::workspace_root;

const DEVICES: &[&str] = &["zimmer_acs", "linak_techline", "interroll_ec5000bi"];

fn load(name: &str) -> Device {
    let path = workspace_root().join(format!("eds/{name}.yaml"));
    let loaded = read_device(&path, &Options::strict());
    assert!(
        loaded.diagnostics.is_empty(),
        "{name}: {}",
        loaded.diagnostics.render()
    );
    loaded.device.expect("device")
}

/// One table of a checklist.
struct Section {
    title: String,
    declared: Option<usize>,
    rows: Vec<(usize, String)>,
}

fn sections(text: &str) -> Vec<Section> {
    let mut out: Vec<Section> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if let Some(title) = line.strip_prefix("## ") {
            out.push(Section {
                title: title.to_string(),
                declared: None,
                rows: Vec::new(),
            });
        } else if let Some(count) = line.strip_prefix("rows:") {
            let section = out.last_mut().expect("rows: before a section");
            section.declared = Some(count.trim().parse().expect("rows: N"));
        } else if line.starts_with('|')
            && !line.starts_with("|---")
            && let Some(section) = out.last_mut()
        {
            section.rows.push((n + 1, line.to_string()));
        }
    }
    // The first table row of each section is its header.
    for section in &mut out {
        if !section.rows.is_empty() {
            section.rows.remove(0);
        }
    }
    out
}

fn cells(row: &str) -> Vec<String> {
    row.trim_matches('|')
        .split('|')
        .map(|c| c.trim().trim_matches('`').to_string())
        .collect()
}

fn entry(device: &Device, index: u16, sub: u8) -> Option<&Entry> {
    device
        .objects
        .get(&index)?
        .entries
        .get(&sub)
        .map(Box::as_ref)
}

fn int(text: &str) -> Option<i128> {
    parse_int(text).ok()
}

/// Resolves one reference; marks the entries it names in `covered`.
fn resolve(device: &Device, reference: &str, covered: &mut BTreeSet<(u16, u8)>) -> bool {
    let (head, tail) = match reference.split_once('#') {
        Some((h, t)) => (h, Some(t)),
        None => (reference, None),
    };
    if let Some(name) = head.strip_prefix("errors:") {
        let Some(table) = device.error_tables.iter().find(|t| t.name == name) else {
            return false;
        };
        return match tail {
            None => true,
            Some(code) => {
                int(code).is_some_and(|c| table.codes.iter().any(|e| i128::from(e.code) == c))
            }
        };
    }
    if let Some(pdo) = head.strip_prefix("pdo:") {
        let (direction, number) = match (pdo.strip_prefix("tpdo"), pdo.strip_prefix("rpdo")) {
            (Some(n), _) => (PdoDirection::Tpdo, n),
            (_, Some(n)) => (PdoDirection::Rpdo, n),
            _ => return false,
        };
        let Ok(number) = number.parse::<u16>() else {
            return false;
        };
        let mapping = direction.mapping_index(number);
        return match tail {
            None => {
                device
                    .pdo_labels
                    .iter()
                    .any(|l| l.direction == direction && l.number == number)
                    || device.objects.contains_key(&mapping)
            }
            Some(k) => k
                .parse::<u8>()
                .ok()
                .and_then(|k| entry(device, mapping, k))
                .is_some_and(|e| {
                    e.default
                        .as_ref()
                        .is_some_and(|d| d.value != eds2rust::ir::Value::Integer(0))
                }),
        };
    }
    if let Some(what) = head.strip_prefix("network:") {
        let n = &device.network;
        return match (what, tail) {
            ("node_id", None) => n.node_id.is_some(),
            ("bit_rate", None) => n.bit_rate.is_some(),
            ("auto_bit_rate", None) => n.auto_bit_rate,
            ("lss", None) => n.lss.is_some(),
            ("bit_rates", Some(rate)) => rate
                .parse::<u32>()
                .is_ok_and(|r| device.capabilities.baud_rates.contains(&r)),
            ("lss", Some(service)) => n.lss.as_ref().is_some_and(|l| {
                l.services.iter().any(|s| {
                    serde_json::to_value(s)
                        .ok()
                        .and_then(|v| v.as_str().map(str::to_string))
                        .as_deref()
                        == Some(service)
                })
            }),
            _ => false,
        };
    }
    if let Some(name) = head.strip_prefix("variant:") {
        let Some(variant) = device.variants.iter().find(|v| v.name == name) else {
            return false;
        };
        return match tail {
            None => true,
            Some(target) => {
                let Some((index, sub)) = target.split_once('/') else {
                    return false;
                };
                let (Some(index), Some(sub)) = (int(index), int(sub)) else {
                    return false;
                };
                variant
                    .overrides
                    .iter()
                    .any(|o| i128::from(o.index) == index && i128::from(o.subindex) == sub)
            }
        };
    }
    if head == "note" {
        return tail
            .and_then(|n| n.parse::<usize>().ok())
            .is_some_and(|n| n >= 1 && n <= device.comments.len());
    }
    // 0xIIII or 0xIIII/S, with an optional #part.
    let (index, sub) = match head.split_once('/') {
        Some((i, s)) => (int(i), int(s).map(Some)),
        None => (int(head), Some(None)),
    };
    let (Some(index), Some(sub)) = (index, sub) else {
        return false;
    };
    let Ok(index) = u16::try_from(index) else {
        return false;
    };
    let Some(object) = device.objects.get(&index) else {
        return false;
    };
    let Some(sub) = sub else {
        if tail.is_some() {
            return false;
        }
        covered.extend(object.entries.keys().map(|&s| (index, s)));
        return true;
    };
    let Some(e) = u8::try_from(sub).ok().and_then(|s| object.entries.get(&s)) else {
        return false;
    };
    covered.insert((index, e.subindex));
    let s = &e.semantics;
    match tail {
        None => true,
        Some("numeric") => s.values.as_ref().is_some_and(|v| v.numeric.is_some()),
        Some("unit") => s.unit.is_some() || s.scale.is_some(),
        Some(part) if part.starts_with("pattern:") => {
            let name = &part["pattern:".len()..];
            s.patterns.iter().any(|p| p.name == name)
        }
        Some(part) if part.starts_with("bit") => part[3..]
            .parse::<u32>()
            .is_ok_and(|b| s.bits.iter().any(|f| f.lsb == b)),
        Some(value) => int(value).is_some_and(|v| {
            s.values
                .as_ref()
                .is_some_and(|t| t.named.iter().any(|n| n.low == v))
        }),
    }
}

/// Sub-index 0 that the reader added (not written in the table).
fn automatic(device: &Device, index: u16, e: &Entry) -> bool {
    e.subindex == 0
        && e.name == "Highest sub-index supported"
        && device.objects[&index].origin.line == e.origin.line
}

fn check(name: &str) -> (usize, usize) {
    let device = load(name);
    let path = workspace_root().join(format!("docs/devices/{name}.md"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut covered = BTreeSet::new();
    let mut problems = Vec::new();
    let mut rows = 0;
    for section in sections(&text) {
        let not_from_table = section.title == "Not from a manual table";
        if !not_from_table {
            match section.declared {
                Some(n) if n == section.rows.len() => {}
                Some(n) => problems.push(format!(
                    "`{}` declares {n} rows, lists {}",
                    section.title,
                    section.rows.len()
                )),
                None => problems.push(format!("`{}` has no `rows:` line", section.title)),
            }
        }
        for (line, row) in &section.rows {
            rows += 1;
            let cells = cells(row);
            let refs = if not_from_table {
                &cells[0]
            } else {
                cells.get(1).unwrap_or(&cells[0])
            };
            for reference in refs.split(", ").map(str::trim).filter(|r| !r.is_empty()) {
                if !resolve(&device, reference, &mut covered) {
                    problems.push(format!(
                        "{}:{line}: `{reference}` does not resolve",
                        path.display()
                    ));
                }
            }
        }
    }
    let mut entries = 0;
    for (index, object) in &device.objects {
        for e in object.entries.values() {
            if automatic(&device, *index, e) {
                continue;
            }
            entries += 1;
            if !covered.contains(&(*index, e.subindex)) {
                problems.push(format!(
                    "0x{index:04X} sub {} (`{}`) is named by no checklist row",
                    e.subindex, e.name
                ));
            }
        }
    }
    assert!(problems.is_empty(), "{name}:\n{}", problems.join("\n"));
    (rows, entries)
}

#[test]
fn seed_device_checklists_agree_with_their_tables() {
    for name in DEVICES {
        let (rows, entries) = check(name);
        assert!(
            rows > 100 && entries > 100,
            "{name}: {rows} rows, {entries} entries"
        );
        println!("{name}: {rows} checklist rows, {entries} entries covered");
    }
}

#[test]
fn seed_devices_carry_their_manual_facts() {
    let linak = load("linak_techline");
    assert_eq!(linak.network.node_id, Some(32));
    assert_eq!(linak.network.bit_rate, Some(250));
    assert_eq!(linak.identity.vendor_number, Some(0x4AA));
    let position = &linak.objects[&0x2000].entries[&1].semantics;
    assert_eq!(
        (position.unit.as_deref(), position.scale),
        (Some("mm"), Some(0.1))
    );
    let values = position.values.as_ref().expect("command position values");
    assert_eq!(values.numeric, Some((0, 0xFAFF)));
    let named: Vec<(i128, &str)> = values
        .named
        .iter()
        .map(|n| (n.low, n.name.as_str()))
        .collect();
    assert_eq!(named[0].0, 0xFB00);
    assert_eq!(named.len(), 7, "{named:?}");
    let current = &linak.objects[&0x2001].entries[&2].semantics;
    assert_eq!(current.scale, Some(0.25));

    let zimmer = load("zimmer_acs");
    assert_eq!(zimmer.network.node_id, Some(40));
    assert_eq!(zimmer.network.bit_rate, Some(500));
    assert!(zimmer.variants.iter().any(|v| v.name == "ACS40"));
    assert!(zimmer.variants.iter().any(|v| v.name == "ACS60"));
    let errors = zimmer
        .error_tables
        .iter()
        .find(|t| t.name == "zimmer_errors")
        .unwrap();
    assert!(errors.codes.iter().any(|c| c.code == 0x2280));

    let interroll = load("interroll_ec5000bi");
    assert_eq!(interroll.network.node_id, Some(127));
    let lss = interroll.network.lss.as_ref().expect("LSS");
    assert_eq!(lss.unconfigured_node_id, Some(127));
    assert!(
        interroll
            .error_tables
            .iter()
            .any(|t| t.codes.iter().any(|c| c.code == 0x0503_0000))
    );
}
