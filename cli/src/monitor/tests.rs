//! The monitor's state (table, plot, record stream) from frames decoded
//! with the LINAK actuator's file, and its loop on the virtual bus against
//! the LINAK simulator (tests/monitor_vcan.rs runs the binary over vcan in
//! the VM).

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use eds2rust_runtime::transport::Bus;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_runtime::{CanId, Frame};
use eds2rust_sim::models::linak_techline;

use super::plot::parse_spec;
use super::*;
use crate::served::Served;

const LINAK: u8 = 32;

fn linak_decoder() -> Decoder {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../eds/linak_techline.yaml");
    let files = NodeFiles {
        nodes: vec![(LINAK, file)],
        overlays: Vec::new(),
        bus: None,
    };
    files
        .decoder()
        .unwrap_or_else(|_| panic!("the LINAK file has errors"))
}

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

/// TPDO1 of node 32 (0x2001 feedback): position in 0.1 mm, current
/// (0.25 A), status, error, speed (0.1 mm/s), AUX inputs.
fn feedback(position: u16) -> Frame {
    let [p0, p1] = position.to_le_bytes();
    frame(0x1A0, &[p0, p1, 0x06, 0x88, 0x00, 0x31, 0x00, 0xC0])
}

fn monitor(view: Option<View>, plot: &[&str]) -> Monitor {
    let specs = plot.iter().map(|s| parse_spec(s).unwrap()).collect();
    Monitor::new(linak_decoder(), &[LINAK], view, specs)
}

/// The line of `text` (a plain table) whose first cell is `node`.
fn row_of(text: &str, node: u8) -> &str {
    text.lines()
        .find(|l| {
            l.split('|')
                .nth(1)
                .is_some_and(|c| c.trim() == node.to_string())
        })
        .unwrap_or_else(|| panic!("no row of node {node} in:\n{text}"))
}

/// Feeds `frames` at their times; the output.
fn feed(m: &mut Monitor, frames: &[(f64, Frame)]) -> String {
    let mut out = Vec::new();
    for (t, f) in frames {
        m.frame(*t, f, &mut out).unwrap();
    }
    String::from_utf8(out).unwrap()
}

#[test]
fn times_and_plot_fields_parse() {
    assert_eq!(parse_seconds("2"), Ok(Duration::from_secs(2)));
    assert_eq!(parse_seconds("0.5"), Ok(Duration::from_millis(500)));
    assert_eq!(parse_seconds("250ms"), Ok(Duration::from_millis(250)));
    assert_eq!(parse_seconds("1m"), Ok(Duration::from_secs(60)));
    assert!(parse_seconds("0").is_err());
    assert!(parse_seconds("soon").unwrap_err().contains("`soon`"));

    let spec = parse_spec("32:Feedback.Position").unwrap();
    assert_eq!(
        (spec.node, spec.field.as_str()),
        (Some(32), "Feedback.Position")
    );
    assert_eq!(spec.to_string(), "32:Feedback.Position");
    let spec = parse_spec("Feedback.Position").unwrap();
    assert_eq!(
        (spec.node, spec.field.as_str()),
        (None, "Feedback.Position")
    );
    // A colon without a node id before it is part of the name.
    assert_eq!(parse_spec("A:b").unwrap().node, None);
    assert!(parse_spec("0:X").unwrap_err().contains("not a node id"));
    assert!(parse_spec("5:").unwrap_err().contains("no field name"));
    assert!(parse_spec(" ").is_err());
}

#[test]
fn the_table_shows_state_heartbeat_emcy_pdo_rates_and_sdo() {
    let mut m = monitor(Some(View::Plain), &[]);
    let mut frames = vec![
        (0.0, frame(0x720, &[0x00])),
        (
            0.05,
            frame(0x620, &[0x2B, 0x17, 0x10, 0x00, 0x64, 0x00, 0, 0]),
        ),
        (0.06, frame(0x5A0, &[0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0])),
        (0.1, frame(0x000, &[0x01, LINAK])),
        (0.3, frame(0xA0, &[0x30, 0x81, 0x11, 0, 0, 0, 0, 0])),
        (1.9, frame(0x720, &[0x05])),
    ];
    // TPDO1 every 250 ms for 2 s.
    frames.extend((1..=8).map(|i| (f64::from(i) * 0.25, feedback(100))));
    frames.sort_by(|a, b| a.0.total_cmp(&b.0));
    let out = feed(&mut m, &frames);
    assert_eq!(out, "", "no record stream with the table");
    assert_eq!(m.frames, 14);

    let table = m.table.as_mut().unwrap();
    let row = &table.rows[&LINAK];
    assert_eq!(row.state_text(), "operational");
    assert_eq!(row.heartbeat, Some(1.9));
    let emcy = row.emcy.as_ref().unwrap();
    assert_eq!(emcy.emcy.code, 0x8130);
    let pdo = &row.pdos[&(false, 1)];
    assert_eq!(pdo.frames, 8);
    assert_eq!(pdo.rate(2.0), 4.0);
    // Half a second later the oldest two have left the window.
    assert_eq!(pdo.rate(2.5), 3.0);
    assert_eq!((row.sdo, row.sdo_aborted), (1, 0));
    assert_eq!(row.last_sdo.as_deref(), Some("download 0x1017.0"));
    // The NMT command named node 32 but is not the node's word.
    assert_eq!(table.rows.len(), 1);

    let text = table.render(2.0, true);
    eprintln!("{text}");
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].starts_with("+---"), "{text}");
    let header = lines[1];
    for title in table::HEADER {
        assert!(header.contains(title), "{header}");
    }
    let row = row_of(&text, LINAK);
    assert!(row.contains("| operational "), "{row}");
    assert!(row.contains("| 0.1 s ago "), "{row}");
    assert!(row.contains("0x8130"), "{row}");
    assert!(row.contains("TPDO1 feedback: 4.0/s (8 frames)"), "{row}");
    assert!(text.contains("last: download 0x1017.0"), "{text}");
    assert!(text.is_ascii());
    // On a terminal: box-drawing characters.
    assert!(table.render(2.0, false).contains('│'));
}

#[test]
fn nodes_are_rows_from_the_start_and_when_heard() {
    let mut table = NodeTable::new([5]);
    let text = table.render(0.0, true);
    let row = row_of(&text, 5);
    assert!(row.contains("| - "), "{row}");
    let mut m = Monitor::new(Decoder::new(), &[], Some(View::Plain), Vec::new());
    assert!(
        m.table
            .as_mut()
            .unwrap()
            .render(0.0, true)
            .contains("no node heard yet")
    );
    feed(
        &mut m,
        &[(0.5, frame(0x705, &[0x7F])), (0.6, frame(0x185, &[1, 2]))],
    );
    let table = m.table.as_mut().unwrap();
    let row = &table.rows[&5];
    assert_eq!(row.state_text(), "pre-operational");
    // Without a file: the PDO is counted, unnamed.
    assert_eq!(row.pdos[&(false, 1)].frames, 1);
    assert!(table.render(1.0, true).contains("TPDO1: "));
}

#[test]
fn the_record_stream_is_the_decoders_with_the_monitors_time() {
    let mut m = monitor(None, &[]).with_format(OutFormat::Json, false);
    let out = feed(
        &mut m,
        &[(1.25, feedback(26)), (1.5, frame(0x720, &[0x05]))],
    );
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2, "{out}");
    assert_eq!(lines[0]["time"], 1.25);
    assert_eq!(lines[0]["line"], 1);
    assert_eq!(lines[0]["pdo"], "tpdo1");
    assert_eq!(lines[0]["fields"][0]["name"], "Feedback.Position");
    assert_eq!(lines[0]["fields"][0]["value"], 2.6);
    assert_eq!(lines[1]["protocol"], "heartbeat");
    assert_eq!(lines[1]["state"], "operational");

    let mut m = monitor(None, &[]);
    let out = feed(&mut m, &[(0.5, frame(0x720, &[0x05]))]);
    assert!(
        out.contains("0.500000") && out.ends_with("heartbeat node 32: operational\n"),
        "{out}"
    );
    let mut m = monitor(None, &[]).with_format(OutFormat::Json, true);
    let out = feed(&mut m, &[(0.5, frame(0x720, &[0x05]))]);
    let line: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert!(line["time"].as_f64().unwrap() > 1.7e9, "{out}");
}

#[test]
fn the_plot_records_physical_values_and_draws_an_svg() {
    let mut m = monitor(None, &["Feedback.Position", "32:Feedback.Current"]);
    feed(
        &mut m,
        &[
            (0.25, feedback(26)),
            (0.5, feedback(96)),
            (0.75, feedback(503)),
        ],
    );
    let plot = m.plot.as_ref().unwrap();
    assert!(plot.unknown().is_none());
    let position = &plot.series[0];
    assert_eq!(position.label(), "32:Feedback.Position [mm]");
    assert_eq!(position.points, [(0.25, 2.6), (0.5, 9.6), (0.75, 50.3)]);
    // 0x06 × 0.25 A.
    assert_eq!(plot.series[1].label(), "32:Feedback.Current [A]");
    assert_eq!(plot.series[1].points[0], (0.25, 1.5));
    assert_eq!(
        position.steps(1.0),
        [
            (0.25, 2.6),
            (0.5, 2.6),
            (0.5, 9.6),
            (0.75, 9.6),
            (0.75, 50.3),
            (1.0, 50.3)
        ]
    );

    let svg = plot.svg(1.0).unwrap().unwrap();
    assert!(svg.starts_with("<svg"), "{svg}");
    assert!(svg.contains("32:Feedback.Position [mm]"), "{svg}");
    assert!(svg.contains("32:Feedback.Current [A]"), "{svg}");
    assert!(svg.contains("time [s]"), "{svg}");

    let dir = std::env::temp_dir().join(format!("eds2rust-monitor-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("chart.svg");
    let mut err = Vec::new();
    assert!(m.finish_plot(&path, &mut err));
    let file = std::fs::read_to_string(&path).unwrap();
    assert!(file.starts_with("<svg") && file.contains("32:Feedback.Current [A]"));
    assert!(String::from_utf8(err).unwrap().contains("(2 fields)"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_field_never_seen_names_the_fields_that_were() {
    let mut m = monitor(None, &["Feedback.Positon", "33:Feedback.Position", "Speed"]);
    let plot = m.plot.as_ref().unwrap();
    assert!(plot.unknown().unwrap().contains("fields seen: none"));
    assert!(plot.svg(1.0).is_none());
    feed(&mut m, &[(0.25, feedback(26))]);
    let text = m.plot.as_ref().unwrap().unknown().unwrap();
    assert!(
        text.contains(
            "error: --plot Feedback.Positon: no PDO field of that name was seen; did you mean \
             `Feedback.Position`?\n"
        ),
        "{text}"
    );
    assert!(
        text.contains(
            "error: --plot 33:Feedback.Position: no PDO field of that name was seen from node 33\n"
        ),
        "{text}"
    );
    assert!(
        text.contains(
            "fields seen:\n  node 32: Feedback.Position, Feedback.Current, Feedback.Status flags, "
        ),
        "{text}"
    );
    let mut err = Vec::new();
    let path = std::env::temp_dir().join("eds2rust-monitor-never-written.svg");
    assert!(!m.finish_plot(&path, &mut err));
    assert!(!path.exists());
    let err = String::from_utf8(err).unwrap();
    assert!(
        err.contains("not written") && err.contains("did you mean"),
        "{err}"
    );
}

/// Frames in a queue, then timeouts; or an error. With `stop`, the first
/// receive that finds the queue empty sets that flag (Ctrl-C once the
/// frames are read) and returns at once.
struct Scripted {
    frames: VecDeque<Frame>,
    fail: bool,
    stop: Option<Arc<AtomicBool>>,
}

impl Bus for Scripted {
    fn send(&mut self, _: &Frame) -> std::io::Result<()> {
        Ok(())
    }

    fn recv(&mut self, timeout: Duration) -> std::io::Result<Option<Frame>> {
        if let Some(f) = self.frames.pop_front() {
            return Ok(Some(f));
        }
        if self.fail {
            return Err(std::io::Error::other("the interface went down"));
        }
        if let Some(stop) = &self.stop {
            stop.store(true, Ordering::Relaxed);
            return Ok(None);
        }
        // A quiet bus: the monitor's own timing (its std clock) runs on.
        std::thread::sleep(timeout);
        Ok(None)
    }
}

/// A reader that left.
struct ClosedPipe;

impl std::io::Write for ClosedPipe {
    fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
        Err(std::io::ErrorKind::BrokenPipe.into())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn the_loop_ends_on_stop_bus_errors_and_a_closed_pipe() {
    let stop = AtomicBool::new(false);
    let frames: VecDeque<Frame> = [frame(0x720, &[0x05]), feedback(1)].into();
    let mut m = monitor(Some(View::Plain), &[]);
    let mut bus = Scripted {
        frames: frames.clone(),
        fail: true,
        stop: None,
    };
    let mut out = Vec::new();
    let r = m.run(&mut bus, None, &stop, &mut out);
    assert!(matches!(r, Err(Failure::Bus(e)) if e.to_string() == "the interface went down"));
    // The table of what came before the error.
    assert!(String::from_utf8(out).unwrap().contains("| operational "));

    // The stop flag (Ctrl-C) ends a run without --duration.
    let mut m = monitor(None, &[]);
    let stop = Arc::new(AtomicBool::new(false));
    let mut bus = Scripted {
        frames: frames.clone(),
        fail: false,
        stop: Some(Arc::clone(&stop)),
    };
    let mut out = Vec::new();
    m.run(&mut bus, None, &stop, &mut out).unwrap();
    // Both frames were printed before the flag ended the run.
    assert!(stop.load(Ordering::Relaxed));
    assert_eq!(String::from_utf8(out).unwrap().lines().count(), 2);

    // A closed pipe ends it quietly, before its duration.
    let mut m = monitor(None, &[]);
    let mut bus = Scripted {
        frames,
        fail: false,
        stop: None,
    };
    let stop = AtomicBool::new(false);
    m.run(
        &mut bus,
        Some(Duration::from_secs(30)),
        &stop,
        &mut ClosedPipe,
    )
    .unwrap();
    assert_eq!(m.frames, 1);
}

#[test]
fn on_a_terminal_the_table_is_redrawn_in_place() {
    let mut m = monitor(Some(View::Terminal), &[]).with_title("mon".into());
    let mut bus = Scripted {
        frames: [frame(0x720, &[0x05])].into(),
        fail: false,
        stop: None,
    };
    let mut out = Vec::new();
    let stop = AtomicBool::new(false);
    m.run(&mut bus, Some(Duration::from_millis(600)), &stop, &mut out)
        .unwrap();
    let out = String::from_utf8(out).unwrap();
    assert!(out.starts_with("\x1b[2J\x1b[Hmon: 0."), "{out:?}");
    // At 0.25 s, 0.5 s and at the end.
    assert_eq!(out.matches("\x1b[H").count(), 3, "{out:?}");
    assert!(out.ends_with("\x1b[K\n\x1b[J"), "{out:?}");
}

/// The LINAK simulator on a virtual bus: its heartbeat turned on by SDO
/// and NMT start, the monitor on its own port for 1.6 s.
#[test]
fn the_loop_on_the_virtual_bus_against_the_linak_simulator() {
    let bus = VirtualBus::new();
    let sim = Served::booted(bus.attach(), linak_techline::simulator);
    let mut monitor_port = bus.attach();
    let mut master = bus.attach();
    master
        .send(&frame(0x620, &[0x2B, 0x17, 0x10, 0x00, 100, 0, 0, 0]))
        .unwrap();
    master.send(&frame(0x000, &[0x01, LINAK])).unwrap();

    let mut m = monitor(Some(View::Plain), &["Feedback.Position"]);
    let mut out = Vec::new();
    let never = AtomicBool::new(false);
    m.run(
        &mut monitor_port,
        Some(Duration::from_millis(1600)),
        &never,
        &mut out,
    )
    .unwrap();
    drop(sim);

    let out = String::from_utf8(out).unwrap();
    eprintln!("{out}");
    // Printed at 1 s and at the end.
    assert_eq!(out.matches("eds2rust monitor: ").count(), 2, "{out}");
    let last = out.rsplit("eds2rust monitor: ").next().unwrap();
    let row = row_of(last, LINAK);
    assert!(row.contains("| operational "), "{row}");
    assert!(row.contains("TPDO1 feedback: "), "{row}");
    let table = m.table.as_ref().unwrap();
    let row = &table.rows[&LINAK];
    let tpdo = &row.pdos[&(false, 1)];
    // Every 250 ms (the event timer) from NMT start on.
    assert!(
        (4..=8).contains(&tpdo.frames),
        "{} TPDO1 frames",
        tpdo.frames
    );
    assert!(tpdo.rate(m.elapsed) >= 2.0, "{}", tpdo.rate(m.elapsed));
    assert_eq!(row.sdo, 1);
    let age = m.elapsed - row.heartbeat.unwrap();
    assert!(age < 0.5, "heartbeat {age} s ago");
    let plot = m.plot.as_ref().unwrap();
    assert!(plot.unknown().is_none());
    assert!(plot.series[0].points.len() >= 4);
    assert!(
        plot.svg(m.elapsed)
            .unwrap()
            .unwrap()
            .contains("Feedback.Position")
    );
}
