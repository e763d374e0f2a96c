//! `eds2rust monitor` over the kernel's SocketCAN stack: the LINAK
//! actuator's simulator on its own vcan interface, its heartbeat turned on
//! by an SDO download and NMT start sent from the test's own socket, and
//! three monitors listening at once: the JSON record stream and the node
//! table (not a terminal: printed as plain text), each for a --duration,
//! and a chart of two PDO fields, stopped by SIGINT.
//!
//! The VM test is ignored by default: `tests/vm/run.sh` runs it with
//! `--ignored` in a VM whose kernel has vcan. `CAN_IFACES` names the
//! interfaces (this test takes entry [`MONITOR`]); `EDS2RUST_CLI` the binary
//! (default: the one cargo built). The other tests need no bus.
#![cfg(target_os = "linux")]

mod vcan;

use vcan::{Ended, Running, fails, ok, rig};

use std::path::Path;
use std::time::Duration;

use eds2rust_runtime::transport::Bus;
use eds2rust_runtime::transport::socketcan::SocketCanBus;
use eds2rust_runtime::{CanId, Frame};
use eds2rust_sim::models::linak_techline;
use serde_json::Value;

/// The index of this test's interface in `CAN_IFACES` (tests/vm/run.sh
/// creates one more than the other VM tests use).
const MONITOR: usize = 8;

const LINAK: &str = include_str!("../../eds/linak_techline.yaml");

/// The --duration of the JSON and table monitors (seconds).
const DURATION: &str = "12";

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

/// Waits (up to 5 s) for a frame on `id` whose first byte is `first`.
fn expect_frame(bus: &mut SocketCanBus, id: u16, first: u8, what: &str) {
    let deadline = std::time::Instant::now() + Duration::from_secs(5);
    while std::time::Instant::now() < deadline {
        let got = bus.recv(Duration::from_millis(100)).unwrap();
        if let Some(f) = got
            && f.id() == CanId::Standard(id)
            && f.data().first() == Some(&first)
        {
            return;
        }
    }
    panic!("no {what} (0x{id:03X} [{first:02X} ..]) within 5 s");
}

/// Waits up to 5 s for a frame with `id` on `bus`.
fn expect_id(bus: &mut SocketCanBus, id: u16, what: &str) {
    let deadline = std::time::Instant::now() + Duration::from_secs(5);
    while std::time::Instant::now() < deadline {
        let got = bus.recv(Duration::from_millis(100)).unwrap();
        if got.is_some_and(|f| f.id() == CanId::Standard(id)) {
            return;
        }
    }
    panic!("no {what} (0x{id:03X}) within 5 s");
}

#[test]
fn an_interface_that_cannot_be_opened_is_named_with_what_to_do_and_the_os_error() {
    let err = fails(1, &["monitor", "-i", "nosuchcan0", "--duration", "1"]);
    assert!(
        err.starts_with("error: nosuchcan0: no such CAN interface; create one with `ip link add"),
        "{err}"
    );
    assert!(err.contains("(os error "), "{err}");
}

#[test]
fn usage_errors_and_help() {
    let err = fails(
        2,
        &["monitor", "-i", "vcan0", "--plot", "200:Feedback.Position"],
    );
    assert!(
        err.contains("`200` in `200:Feedback.Position` is not a node id"),
        "{err}"
    );
    let err = fails(
        2,
        &["monitor", "-i", "vcan0", "--table", "--format", "json"],
    );
    assert!(err.contains("cannot be used with"), "{err}");
    let err = fails(2, &["monitor", "-i", "vcan0", "--plot-file", "x.svg"]);
    assert!(err.contains("--plot <FIELD>"), "{err}");
    let err = fails(2, &["monitor", "-i", "vcan0", "--duration", "soon"]);
    assert!(err.contains("`soon` is not a time in seconds"), "{err}");
    // A node's file is read before the bus is opened.
    let err = fails(
        1,
        &["monitor", "-i", "vcan0", "--node", "5=no/such/file.yaml"],
    );
    assert!(err.contains("not used for node 5"), "{err}");
    let help = ok(&["monitor", "--help"]);
    for text in [
        "--iface <IFACE>",
        "--node <N=FILE>",
        "--table",
        "--plot <FIELD>...",
        "--plot-file <FILE>",
        "--duration <SECONDS>",
        "seconds since the monitor started",
    ] {
        assert!(help.contains(text), "no {text:?} in:\n{help}");
    }
}

/// The stderr line `eds2rust monitor` prints once it listens.
const LISTENING: &str = "monitor: listening on ";

/// The line of a plain table whose first cell is `node`.
fn row_of(table: &str, node: u8) -> &str {
    table
        .lines()
        .find(|l| {
            l.split('|')
                .nth(1)
                .is_some_and(|c| c.trim() == node.to_string())
        })
        .unwrap_or_else(|| panic!("no row of node {node} in:\n{table}"))
}

/// The frames/s of the first `NAME: R/s` in `text`.
fn rate_after(text: &str, name: &str) -> f64 {
    let at = text
        .find(name)
        .unwrap_or_else(|| panic!("no {name} in {text}"));
    let rest = &text[at + name.len()..];
    let end = rest
        .find("/s")
        .unwrap_or_else(|| panic!("no rate in {rest}"));
    rest[..end].trim().parse().unwrap()
}

fn check_json(stream: &str) {
    let records: Vec<Value> = stream
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{l:?}: {e}")))
        .collect();
    let of_node = |protocol: &str| -> Vec<&Value> {
        records
            .iter()
            .filter(|r| r["protocol"] == protocol && r["node"] == 32)
            .collect()
    };
    let heartbeats = of_node("heartbeat");
    assert!(
        heartbeats.iter().any(|r| r["state"] == "operational"),
        "no heartbeat `operational` of node 32 in:\n{stream}"
    );
    let pdos = of_node("pdo");
    assert!(
        pdos.len() >= 4,
        "{} PDOs of node 32 in:\n{stream}",
        pdos.len()
    );
    let tpdo = pdos.last().unwrap();
    assert_eq!(tpdo["pdo"], "tpdo1");
    let names: Vec<&str> = tpdo["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        &names[..2],
        ["Feedback.Position", "Feedback.Current"],
        "{tpdo}"
    );
    assert_eq!(tpdo["fields"][0]["unit"], "mm", "{tpdo}");
    let transfer = records
        .iter()
        .find(|r| r["event"] == "sdo-transfer")
        .unwrap_or_else(|| panic!("no SDO transfer in:\n{stream}"));
    assert_eq!(transfer["index"], 0x1017, "{transfer}");
    assert_eq!(transfer["name"], "Producer heartbeat time", "{transfer}");
    assert_eq!(transfer["value"], 100, "{transfer}");
    // Seconds since the monitor started, in order; lines are frame numbers.
    let times: Vec<f64> = records.iter().filter_map(|r| r["time"].as_f64()).collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "{times:?}");
    assert!(
        times[0] >= 0.0 && *times.last().unwrap() < 13.0,
        "{times:?}"
    );
    assert_eq!(records[0]["line"], 1);
}

fn check_table(printed: &str) {
    // Printed once a second and at the end: the last one counts.
    let tables: Vec<&str> = printed.split("eds2rust monitor ").skip(1).collect();
    assert!(tables.len() >= 4, "{} tables in:\n{printed}", tables.len());
    let last = tables.last().unwrap();
    let row = row_of(last, 32);
    assert!(row.contains("| operational "), "{last}");
    assert!(row.contains(" s ago "), "{last}");
    let rate = rate_after(row, "TPDO1 feedback: ");
    // Every 250 ms (the event timer).
    assert!((2.0..=6.0).contains(&rate), "TPDO1 at {rate}/s in:\n{last}");
    assert!(last.contains("last: download 0x1017.0"), "{last}");
}

fn check_plot(ended: &Ended, svg: &Path) {
    assert!(
        ended
            .stdout
            .contains("TPDO1 node 32 (feedback): Feedback.Position="),
        "{}",
        ended.stdout
    );
    assert!(
        ended
            .stderr
            .contains(&format!("monitor: wrote {} (2 fields)", svg.display())),
        "{}",
        ended.stderr
    );
    let text = std::fs::read_to_string(svg)
        .unwrap_or_else(|e| panic!("no chart at {}: {e}", svg.display()));
    assert!(text.starts_with("<svg"), "{text}");
    assert!(text.contains("32:Feedback.Position [mm]"), "{text}");
    assert!(text.contains("32:Feedback.Current [A]"), "{text}");
    assert!(text.contains("time [s]"), "{text}");
}

#[test]
#[ignore = "needs vcan: tests/vm/run.sh"]
fn monitor_streams_tables_and_plots_the_linak_actuator() {
    let (i, dir, od, _sim) = rig(
        MONITOR,
        ("monitor-vcan", "linak"),
        ("linak_techline.yaml", LINAK),
        linak_techline::simulator,
    );
    let node = format!("32={od}");
    let svg = dir.join("position.svg");
    let svg_arg = svg.display().to_string();

    let base = ["monitor", "-i", i.as_str(), "--node", node.as_str()];
    let with = |rest: &[&'static str]| [&base[..], rest].concat();
    // Started together, each reads the file first (slow in the VM): the
    // durations leave room for that and for the traffic after it.
    let mut json = Running::spawn(
        &with(&["--duration", DURATION, "--format", "json"]),
        LISTENING,
    );
    let mut table = Running::spawn(&with(&["--duration", DURATION, "--table"]), LISTENING);
    let mut plot = Running::spawn(
        &[
            &base[..],
            &["--plot", "Feedback.Position", "32:Feedback.Current"],
            &["--plot-file", &svg_arg],
        ]
        .concat(),
        LISTENING,
    );
    for m in [&mut json, &mut table, &mut plot] {
        m.ready();
    }

    // The master's part, from a socket of this test: the heartbeat every
    // 100 ms (an SDO download of 0x1017), then NMT start: operational,
    // TPDO1 every 250 ms (its event timer).
    let mut master = SocketCanBus::open(&i).unwrap();
    master
        .send(&frame(0x620, &[0x2B, 0x17, 0x10, 0x00, 100, 0, 0, 0]))
        .unwrap();
    expect_frame(&mut master, 0x5A0, 0x60, "SDO download response");
    master.send(&frame(0x000, &[0x01, 32])).unwrap();
    expect_frame(&mut master, 0x720, 0x05, "heartbeat `operational`");
    for m in [&mut json, &mut table, &mut plot] {
        m.assert_running();
    }
    // Ten TPDO1s (2.5 s at the event timer) for the monitors to record.
    for n in 0..10 {
        expect_id(&mut master, 0x1A0, &format!("TPDO1 number {}", n + 1));
    }
    json.assert_running();
    table.assert_running();

    // Ctrl-C stops the chart's monitor cleanly: exit 0, the SVG written.
    plot.interrupt();
    let ended = plot.wait();
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    check_plot(&ended, &svg);

    let ended = json.wait();
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    check_json(&ended.stdout);

    let ended = table.wait();
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    check_table(&ended.stdout);
}
