//! The monitor with a bus file (`--bus`): the nodes and their devices from
//! the seed machine's bus.yml, the PDOs as the network configures them;
//! decoded from configured frames and from the trace of the network booted
//! against its own simulation.

use std::path::PathBuf;
use std::time::Duration;

use eds2rust::input::Options;
use eds2rust_runtime::{CanId, Frame};

use super::*;

fn machine() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../eds/machine/bus.yml")
}

fn bus_files() -> NodeFiles {
    NodeFiles {
        nodes: Vec::new(),
        overlays: Vec::new(),
        bus: Some(machine()),
    }
}

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

/// Whether `text` (a plain table) has a line whose first cell is `first`.
fn has_row(text: &str, first: &str) -> bool {
    text.lines()
        .any(|l| l.split('|').nth(1).is_some_and(|c| c.trim() == first))
}

/// The names of a JSON record's PDO fields.
fn field_names(record: &serde_json::Value) -> Vec<&str> {
    record["fields"]
        .as_array()
        .map(|f| f.iter().filter_map(|f| f["name"].as_str()).collect())
        .unwrap_or_default()
}

/// With the seed machine's bus file, the Zimmer axis (node 40) sends TPDO2
/// as the network remaps it (velocity and torque), not as its file's
/// default (velocity only); every slave is a row from the start, named.
#[test]
fn a_bus_file_gives_the_nodes_and_the_pdos_the_network_configures() {
    let files = bus_files();
    let decoder = files
        .decoder()
        .unwrap_or_else(|_| panic!("the machine's bus file has errors"));
    let nodes: Vec<u8> = (1..=127)
        .filter(|&n| decoder.dictionary(n).is_some())
        .collect();
    assert_eq!(nodes, [5, 32, 40]);
    let mut m = Monitor::new(decoder, &nodes, None, Vec::new()).with_format(OutFormat::Json, false);
    // Velocity 1000 mm/s, torque -5 % of the rated torque.
    let tpdo2 = frame(0x2A8, &[0xE8, 0x03, 0x00, 0x00, 0xFB, 0xFF]);
    let mut out = Vec::new();
    m.frame(0.1, &tpdo2, &mut out).unwrap();
    let out = String::from_utf8(out).unwrap();
    let line: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(line["node"], 40, "{out}");
    assert_eq!(line["pdo"], "tpdo2", "{out}");
    let names: Vec<&str> = line["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        ["Velocity actual value", "Torque actual value"],
        "{out}"
    );
    assert_eq!(line["fields"][1]["raw"], -5, "{out}");

    let (decoder, names) = bus_files()
        .decoder_named()
        .unwrap_or_else(|_| panic!("the bus file has errors"));
    let mut table = Monitor::new(decoder, &nodes, Some(View::Plain), Vec::new()).with_names(names);
    let text = table.table.as_mut().unwrap().render(0.0, true);
    for row in ["5 conveyor", "32 actuator", "40 axis"] {
        assert!(has_row(&text, row), "{text}");
    }
}

/// The seed machine booted against its own simulation (`net boot
/// --simulate`'s), then run for 50 ms of SYNCs: its trace, through the
/// monitor with the bus file, has the axis's TPDO2 and the conveyor's
/// TPDO4 as the network maps them, by name. (The master's own RPDOs go
/// out once an application sets their data: none here.)
#[test]
fn the_booted_machines_trace_decodes_by_the_networks_names() {
    let network = crate::net::load::read_configured(&machine(), &Options::default(), "used")
        .unwrap_or_else(|| panic!("the machine's bus file has errors"));
    let plan = eds2rust::network::boot_plan(&network.bus, &network.configured);
    let (bus, time) =
        crate::net::boot::simulate::simulation(&network, &[]).unwrap_or_else(|e| panic!("{e}"));
    let (mut m, outcome) = crate::net::boot::boot(
        bus.with_trace(),
        time.clock(),
        &plan,
        Duration::from_secs(5),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(outcome.running(&plan), "{outcome:?}");
    m.run_for(Duration::from_millis(50)).unwrap();
    let trace: Vec<(f64, Frame)> = m
        .bus()
        .trace()
        .iter()
        .map(|(t, f)| ((*t - eds2rust_runtime::Instant::ZERO).as_secs_f64(), *f))
        .collect();

    let decoder = bus_files()
        .decoder()
        .unwrap_or_else(|_| panic!("the bus file has errors"));
    let mut monitor =
        Monitor::new(decoder, &[5, 32, 40], None, Vec::new()).with_format(OutFormat::Json, false);
    let mut out = Vec::new();
    for (t, f) in &trace {
        monitor.frame(*t, f, &mut out).unwrap();
    }
    let out = String::from_utf8(out).unwrap();
    let records: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let pdo = |node: u8, pdo: &str| {
        records
            .iter()
            .find(|r| r["node"] == node && r["pdo"] == pdo)
            .unwrap_or_else(|| panic!("no {pdo} of node {node} in:\n{out}"))
    };
    assert_eq!(
        field_names(pdo(40, "tpdo2")),
        ["Velocity actual value", "Torque actual value"]
    );
    assert_eq!(
        field_names(pdo(5, "tpdo4")),
        [
            "Statusword",
            "Velocity Actual value",
            "Monitoring Values.Actual temperature"
        ]
    );
}
