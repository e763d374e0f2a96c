//! `net dcf` against lely's dcfgen (dcf-tools 2.4.2, `-v -r -S`, in the
//! oracle venv): for the corpus networks (their committed dcfgen output and
//! a fresh run) and the networks of tests/networks, master.dcf is compared
//! key by key (numbers by value) and every `.bin` entry by entry. The only
//! differences allowed are the ones `net dcf` reports as deliberate
//! ([`Difference`]), each checked for its exact shape.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use eds2rust::network::dcf::{self, Difference, Written, concise};

/// `[section]` → key → value.
type Ini = BTreeMap<String, BTreeMap<String, String>>;

fn parse_ini(text: &str) -> Ini {
    let mut ini = Ini::new();
    let mut section = String::new();
    for line in text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with(';'))
    {
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            section = name.to_string();
            ini.entry(section.clone()).or_default();
        } else if let Some((key, value)) = line.split_once('=') {
            ini.entry(section.clone())
                .or_default()
                .insert(key.trim().to_string(), value.trim().to_string());
        }
    }
    ini
}

fn number(text: &str) -> Option<i128> {
    let (negative, digits) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text),
    };
    let value = match digits
        .strip_prefix("0x")
        .or_else(|| digits.strip_prefix("0X"))
    {
        Some(hex) => i128::from_str_radix(hex, 16).ok()?,
        None => digits.parse().ok()?,
    };
    Some(if negative { -value } else { value })
}

fn same_value(ours: &str, theirs: &str) -> bool {
    match (number(ours), number(theirs)) {
        (Some(a), Some(b)) => a == b,
        _ => ours == theirs,
    }
}

/// Whether a difference at `section`/`key` is one `net dcf` reported, in
/// exactly the reported shape.
fn documented(
    differences: &[Difference],
    theirs_have_1f22: bool,
    section: &str,
    key: &str,
    ours: Option<&str>,
    theirs: Option<&str>,
) -> bool {
    let values = ours.and_then(number).zip(theirs.and_then(number));
    differences.iter().any(|d| match d {
        Difference::DisabledPdoInvalid { index, .. } => {
            section == format!("{index:04X}sub1")
                && key == "DefaultValue"
                && values.is_some_and(|(o, t)| t & 0x8000_0000 == 0 && o == t | 0x8000_0000)
        }
        Difference::HeartbeatClamped { entry, time, .. } => {
            section == "1016Value"
                && key == entry.to_string()
                && values.is_some_and(|(o, t)| {
                    o & 0xFFFF == 0xFFFF && t == (o & !0xFFFF) | (i128::from(*time as u32) & 0xFFFF)
                })
        }
        // dcfgen names its own file, or (a slave without writes) none:
        // then its master.dcf has no 0x1F22 and lists one object less.
        Difference::ConfigurationFile { node_id, file, .. } => {
            (section == format!("1F22sub{node_id:X}")
                && key == "UploadFile"
                && ours == Some(file.as_str()))
                || (!theirs_have_1f22
                    && (section == "OptionalObjects" || section.starts_with("1F22")))
        }
        Difference::UnlistedProductCode { .. } => {
            let unlisted = differences
                .iter()
                .filter(|d| matches!(d, Difference::UnlistedProductCode { .. }))
                .count();
            section == "1F86Value"
                && key == "NrOfEntries"
                && values.is_some_and(|(o, t)| t - o == unlisted as i128)
        }
    })
}

#[derive(Default)]
struct Tally {
    keys: usize,
    keys_equal: usize,
    documented: usize,
    bin_entries: usize,
    bin_equal: usize,
    failures: Vec<String>,
}

fn compare(written: &Written, theirs_dir: &Path) -> Tally {
    let mut tally = Tally::default();
    let mut their_names: Vec<String> = std::fs::read_dir(theirs_dir)
        .unwrap_or_else(|e| panic!("{}: {e}", theirs_dir.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".bin") || n.ends_with(".dcf"))
        .collect();
    their_names.sort();
    let mut our_names: Vec<String> = written.files.iter().map(|f| f.name.clone()).collect();
    our_names.sort();
    if our_names != their_names {
        tally.failures.push(format!(
            "files: ours {our_names:?}, dcfgen's {their_names:?}"
        ));
    }
    for file in &written.files {
        let Ok(their_bytes) = std::fs::read(theirs_dir.join(&file.name)) else {
            continue;
        };
        if file.name.ends_with(".dcf") {
            let ours = parse_ini(std::str::from_utf8(&file.bytes).unwrap());
            let theirs = parse_ini(&String::from_utf8_lossy(&their_bytes));
            let theirs_have_1f22 = theirs.contains_key("1F22");
            let sections: std::collections::BTreeSet<&String> =
                ours.keys().chain(theirs.keys()).collect();
            for section in sections {
                let empty = BTreeMap::new();
                let (o, t) = (
                    ours.get(section).unwrap_or(&empty),
                    theirs.get(section).unwrap_or(&empty),
                );
                let keys: std::collections::BTreeSet<&String> = o.keys().chain(t.keys()).collect();
                for key in keys {
                    tally.keys += 1;
                    let (ov, tv) = (
                        o.get(key).map(String::as_str),
                        t.get(key).map(String::as_str),
                    );
                    match (ov, tv) {
                        (Some(a), Some(b)) if same_value(a, b) => tally.keys_equal += 1,
                        _ if documented(
                            &written.differences,
                            theirs_have_1f22,
                            section,
                            key,
                            ov,
                            tv,
                        ) =>
                        {
                            tally.documented += 1
                        }
                        _ => tally.failures.push(format!(
                            "{}: [{section}] {key}: ours {ov:?}, dcfgen's {tv:?}",
                            file.name
                        )),
                    }
                }
            }
        } else {
            let ours = concise::decode(&file.bytes).expect("our .bin decodes");
            let theirs = match concise::decode(&their_bytes) {
                Ok(theirs) => theirs,
                Err(e) => {
                    tally
                        .failures
                        .push(format!("{}: dcfgen's file does not decode: {e}", file.name));
                    continue;
                }
            };
            tally.bin_entries += ours.len().max(theirs.len());
            for n in 0..ours.len().max(theirs.len()) {
                match (ours.get(n), theirs.get(n)) {
                    (Some(a), Some(b)) if a == b => tally.bin_equal += 1,
                    (a, b) => tally.failures.push(format!(
                        "{}: entry {}: ours {a:?}, dcfgen's {b:?}",
                        file.name,
                        n + 1
                    )),
                }
            }
        }
    }
    tally
}

/// `net dcf -r` through the library, as the CLI runs it.
fn ours(bus_file: &Path) -> Written {
    let (bus, configured) = eds2rust_tests::configured_network(bus_file);
    dcf::files(&bus, &configured, true)
}

/// dcfgen run as ros2_canopen runs it, on `expanded` from `bus_dir` (device
/// paths are relative to it), into a fresh `out`.
fn run_dcfgen(bus_dir: &Path, expanded: &Path, out: &Path) -> Result<(), String> {
    let dcfgen = eds2rust_tests::python::dcfgen()?;
    let _ = std::fs::remove_dir_all(out);
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let output = Command::new(&dcfgen)
        .args(["-v", "-r", "-S", "-d"])
        .arg(out)
        .arg(expanded)
        .current_dir(bus_dir)
        .output()
        .map_err(|e| format!("cannot run {}: {e}", dcfgen.display()))?;
    if output.status.success() {
        Ok(())
    } else {
        Err(format!(
            "dcfgen failed on {}: {}\n{}",
            expanded.display(),
            output.status,
            String::from_utf8_lossy(&output.stderr)
        ))
    }
}

struct Network {
    name: String,
    bus_file: PathBuf,
    /// dcfgen's committed output, for the corpus networks.
    committed: Option<PathBuf>,
}

fn networks(shared: &Path) -> Vec<Network> {
    let mut networks = Vec::new();
    for name in ["prbt_pilz6", "trinamic_pd42"] {
        let dir = shared.join("network-corpus").join(name);
        networks.push(Network {
            name: name.to_string(),
            bus_file: dir.join("bus.yml"),
            committed: Some(dir.join("dcfgen-out")),
        });
    }
    let own = eds2rust_tests::workspace_root()
        .join("tests")
        .join("networks");
    let mut names: Vec<String> = std::fs::read_dir(&own)
        .unwrap_or_else(|e| panic!("{}: {e}", own.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        // A network is a folder with a bus.yml (check/ holds fixtures;
        // boot/matrix.yml and vm/python_slaves.yml use device files dcfgen
        // cannot read: a YAML table, a REAL default it refuses).
        .filter(|name| own.join(name).join("bus.yml").is_file())
        .collect();
    names.sort();
    for name in names {
        networks.push(Network {
            bus_file: own.join(&name).join("bus.yml"),
            name,
            committed: None,
        });
    }
    networks
}

#[test]
fn net_dcf_equals_dcfgen_but_for_documented_differences() {
    let Some(shared) = eds2rust_tests::shared_dir() else {
        eds2rust_tests::not_run("network_dcfgen: ../shared (network corpus and device files)");
        return;
    };
    let work = eds2rust_tests::target_dir().join("network_dcfgen");
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    for network in networks(&shared) {
        let written = ours(&network.bus_file);
        let bus_dir = network.bus_file.parent().unwrap();
        // What ros2_canopen hands dcfgen: the corpus keeps it, ours are expanded here.
        let expanded = bus_dir.join("bus.expanded.yml");
        let expanded = if network.committed.is_some() {
            let checked = eds2rust_tests::python::run_script(
                "expand_bus.py",
                &[&network.bus_file, &expanded],
                &["--check"],
            );
            if let Err(e) = checked {
                panic!("the expansion helper disagrees with the corpus: {e}");
            }
            expanded
        } else {
            std::fs::create_dir_all(&work).unwrap();
            let target = work.join(format!("{}.expanded.yml", network.name));
            eds2rust_tests::python::run_script("expand_bus.py", &[&network.bus_file, &target], &[])
                .unwrap_or_else(|e| panic!("cannot expand {}: {e}", network.bus_file.display()));
            target
        };
        let fresh = work.join(&network.name);
        if let Err(e) = run_dcfgen(bus_dir, &expanded, &fresh) {
            panic!("{e}");
        }
        let mut sources = vec![("dcfgen now", fresh)];
        if let Some(committed) = &network.committed {
            sources.push(("committed", committed.clone()));
        }
        for (source, dir) in sources {
            let tally = compare(&written, &dir);
            rows.push(format!(
                "| {:<18} | {:<10} | {:>5} | {:>5} | {:>3} | {:>4} | {:>4} |",
                network.name,
                source,
                tally.keys,
                tally.keys_equal,
                tally.documented,
                tally.bin_entries,
                tally.bin_equal
            ));
            failures.extend(
                tally
                    .failures
                    .into_iter()
                    .map(|f| format!("{} ({source}): {f}", network.name)),
            );
        }
        for difference in &written.differences {
            rows.push(format!("|   {}: {difference}", network.name));
        }
    }
    println!(
        "| network            | dcfgen     | master.dcf keys | equal | documented | .bin entries | equal |"
    );
    for row in &rows {
        println!("{row}");
    }
    assert!(
        failures.is_empty(),
        "differences from dcfgen that are not documented:\n{}",
        failures.join("\n")
    );
}

/// The seed devices as one machine (eds/machine/bus.yml, devices as YAML
/// tables): dcfgen reads only EDS/DCF, so it gets the tables exported as
/// EDS beside a copy of the bus file that names them; ours reads the bus
/// file as it is. The Zimmer manual gives no device type and its table
/// invents none, but dcfgen needs 0x1000 (mandatory in CiA 301): the export
/// gets 0x1000 = 0, which is also what the master's 0x1F84 says without it
/// ("not checked").
#[test]
fn the_seed_machine_equals_dcfgen() {
    let root = eds2rust_tests::workspace_root();
    let bus_file = root.join("eds/machine/bus.yml");
    let work = eds2rust_tests::target_dir().join("network_dcfgen/seed_machine");
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    let mut text = std::fs::read_to_string(&bus_file).unwrap();
    for table in ["zimmer_acs", "linak_techline", "interroll_ec5000bi"] {
        let loaded = eds2rust::input::read_device(
            &root.join(format!("eds/{table}.yaml")),
            &eds2rust::read::Options::default(),
        );
        let mut device = loaded.device.expect("the seed table reads");
        if !device.objects.contains_key(&0x1000) {
            let mut object = device
                .objects
                .values()
                .find(|o| o.kind == eds2rust::ir::ObjectKind::Var)
                .expect("a VAR object to shape 0x1000 after")
                .clone();
            object.index = 0x1000;
            object.name = "Device type".into();
            let entry = object.entries.get_mut(&0).unwrap();
            entry.name = "Device type".into();
            entry.data_type = eds2rust::ir::DataType::Unsigned32;
            entry.pdo_mappable = false;
            entry.access = eds2rust::ir::Access::Ro;
            entry.rust_name = None;
            entry.default = Some(eds2rust::ir::Literal {
                value: eds2rust::ir::Value::Integer(0),
                plus_node_id: false,
                text: "0".into(),
            });
            device.objects.insert(0x1000, object);
        }
        std::fs::write(
            work.join(format!("{table}.eds")),
            eds2rust::r#gen::eds::to_eds(&device),
        )
        .unwrap();
        let from = format!("\"../{table}.yaml\"");
        assert!(text.contains(&from), "the bus file names {from}");
        text = text.replace(&from, &format!("\"{table}.eds\""));
    }
    let copy = work.join("bus.yml");
    std::fs::write(&copy, text).unwrap();
    let out = work.join("dcfgen-out");
    if let Err(e) = run_dcfgen(&work, &copy, &out) {
        panic!("dcfgen does not accept the seed machine: {e}");
    }
    let written = ours(&bus_file);
    let tally = compare(&written, &out);
    println!(
        "| seed_machine | dcfgen now | {} | {} | {} | {} | {} |",
        tally.keys, tally.keys_equal, tally.documented, tally.bin_entries, tally.bin_equal
    );
    assert!(
        tally.failures.is_empty(),
        "differences from dcfgen that are not documented:\n{}",
        tally.failures.join("\n")
    );
}
