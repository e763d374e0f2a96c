//! LINAK TECHLINE actuator: the start-up sequence of the manual (CANopen
//! Montageanleitung p. 28), then run out to the end stop and back in.
//!
//! ```text
//! cargo run -p eds2rust-sim --example linak_techline -- [--trace] [--time-scale F]
//! cargo run -p eds2rust-sim --example linak_techline -- --iface can0 [--simulate]
//! ```
//!
//! The master is node 1 with a heartbeat every 100 ms (0x701 [05]); the
//! actuator is node 32 at 250 kbit/s. A full stroke of the simulated
//! actuator (50.3 mm at about 5 mm/s) takes about 10 s each way, so the
//! whole run takes about 21 s at `--time-scale 1`; `--time-scale 10` makes
//! it about 3 s. On a real actuator (`--iface` without `--simulate`) the
//! time scale has no effect and each stroke may take up to a minute.
//!
//! The master first resets the actuator (NMT reset node), so that its
//! boot-up message follows the master's heartbeat as in the manual's trace
//! and the sequence works whether or not the actuator was already on.

use std::error::Error;
use std::fmt;
use std::io::Write;
use std::ops::ControlFlow;
use std::process::ExitCode;
use std::time::Duration;

use eds2rust_drivers::linak_techline::od::consumer_heartbeat_time::{
    ConsumerHeartbeatTime, ConsumerHeartbeatTimeValue,
};
use eds2rust_drivers::linak_techline::od::{command, feedback};
use eds2rust_drivers::linak_techline::pdo::{Rpdo1Command, Tpdo1Feedback};
use eds2rust_runtime::blocking;
use eds2rust_runtime::emcy::EmcyEvent;
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::nmt::{NmtCommand, NmtEvent, NmtState};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::od::Scaled as _;
use eds2rust_sim::harness::{Args, Harness, MasterPort};
use eds2rust_sim::models::linak_techline::{LinakTechline, NODE, default_config, simulator_with};

/// The master's node id in the manual's trace (0x701).
const MASTER_NODE: u8 = 1;
/// The master's heartbeat period (p. 28: every 100 ms).
const MASTER_HEARTBEAT: Duration = Duration::from_millis(100);
/// The consumer time the master writes into 0x1016 sub 1 (p. 28: 200 ms).
const CONSUMER_TIME_MS: u16 = 200;
/// Longest wait for a protocol answer (boot-up, a TPDO).
const ANSWER_TIMEOUT: Duration = Duration::from_secs(2);

/// What the run ended with.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Position at the outer end stop, mm.
    pub out_end_mm: f64,
    /// Final position, mm.
    pub final_position_mm: f64,
    /// Final status flags (0x2001 sub 3).
    pub status: u8,
    /// Final error code (0x2001 sub 4).
    pub error_code: u8,
    /// Every frame on the bus in candump's compact form.
    pub trace: Vec<String>,
}

/// A step of the scenario that did not happen.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScenarioError(pub String);

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl Error for ScenarioError {}

type Master = blocking::Master<MasterPort>;
type Result<T> = std::result::Result<T, Box<dyn Error>>;

fn main() -> ExitCode {
    let args = match Args::from_env() {
        Ok(args) => args,
        Err(e) => {
            eprintln!("linak_techline: {e}");
            return ExitCode::from(2);
        }
    };
    match run(&args, &mut std::io::stdout()) {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("linak_techline: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Runs the scenario (see the file's documentation) and prints its
/// progress to `out`.
pub fn run(args: &Args, out: &mut dyn Write) -> Result<Summary> {
    let scale = args.time_scale;
    let mut harness = Harness::start(args, |now| {
        simulator_with(
            LinakTechline::new().with_time_scale(scale),
            default_config(),
            now,
        )
    })?;
    let me = NodeId::new(MASTER_NODE).ok_or_else(|| ScenarioError("master node id".into()))?;
    let mut core = master::Master::new(me, Some(MASTER_HEARTBEAT));
    core.heartbeat.set_state(NmtState::Operational);
    let mut m = Master::with_clock(harness.take_port()?, core, harness.clock());
    // A stroke takes about 10 s at 5 mm/s; a real actuator may be longer
    // and slower, and does not follow the time scale.
    let stroke_time = if args.simulates() {
        Duration::from_secs_f64(30.0 / scale) + ANSWER_TIMEOUT
    } else {
        Duration::from_secs(60)
    };

    m.start()?;
    m.run_for(MASTER_HEARTBEAT + MASTER_HEARTBEAT / 2)?;
    writeln!(
        out,
        "master node {MASTER_NODE}: heartbeat 0x701 every 100 ms"
    )?;
    // Only the boot-up after the reset counts.
    m.drain_events();
    m.nmt(NmtCommand::ResetNode, NODE)?;
    wait_boot_up(&mut m)?;
    writeln!(
        out,
        "node {NODE}: booted (0x{:03X} [00])",
        0x700 + u16::from(NODE.get())
    )?;

    let consume = ConsumerHeartbeatTimeValue::from_raw(0)
        .with_node_id(MASTER_NODE)
        .with_heartbeat_time(CONSUMER_TIME_MS);
    m.write::<ConsumerHeartbeatTime<1>>(NODE, consume)?;
    writeln!(
        out,
        "node {NODE}: consumes the heartbeat of node {MASTER_NODE}, {CONSUMER_TIME_MS} ms (0x1016 sub 1)"
    )?;
    m.nmt(NmtCommand::Start, NODE)?;
    let first = next_feedback(&mut m, ANSWER_TIMEOUT, "after NMT start")?;
    report(out, "operational", &first)?;

    send(&mut m, command::PositionValue::STOP)?;
    let ready = wait_feedback(
        &mut m,
        out,
        ANSWER_TIMEOUT,
        "error code 0 after Stop",
        |f| f.error_code.to_raw() == 0,
    )?;
    report(out, "stop", &ready)?;

    send(&mut m, command::PositionValue::RUN_OUT)?;
    writeln!(out, "run out")?;
    let outside = wait_feedback(&mut m, out, stroke_time, "end stop out", |f| {
        f.status_flags.end_stop_out()
    })?;
    report(out, "end stop out", &outside)?;

    send(&mut m, command::PositionValue::RUN_IN)?;
    writeln!(out, "run in")?;
    let inside = wait_feedback(&mut m, out, stroke_time, "end stop in", |f| {
        f.status_flags.end_stop_in() && !f.status_flags.running_in()
    })?;
    report(out, "end stop in", &inside)?;

    let trace = harness.stop()?;
    Ok(Summary {
        out_end_mm: position_mm(&outside),
        final_position_mm: position_mm(&inside),
        status: inside.status_flags.to_raw(),
        error_code: inside.error_code.to_raw(),
        trace,
    })
}

/// Waits for the actuator's boot-up message.
fn wait_boot_up(m: &mut Master) -> Result<()> {
    let deadline = std::time::Instant::now() + ANSWER_TIMEOUT;
    m.run_until(deadline, |e| match e {
        MasterEvent::Nmt(NmtEvent::BootUp(n)) if *n == NODE => ControlFlow::Break(()),
        _ => ControlFlow::Continue(()),
    })
    .map_err(|e| {
        wait_error(
            e,
            &format!(
                "node {NODE}: no boot-up message within {ANSWER_TIMEOUT:?} after NMT reset node"
            ),
        )
    })
}

/// Sends RPDO1 with `position` and every other field at its default
/// (0xFB), as the manual's trace does.
fn send(m: &mut Master, position: command::PositionValue) -> Result<()> {
    let command = Rpdo1Command {
        position,
        current_limit: command::CurrentLimitValue::DEFAULT,
        speed: command::SpeedValue::DEFAULT,
        soft_start: command::SoftStartValue::DEFAULT,
        soft_stop: command::SoftStopValue::DEFAULT,
        reserved_6: 0,
        reserved_7: 0,
    };
    m.send_pdo(NODE, &command)
        .map_err(|e| ScenarioError(format!("node {NODE}: RPDO1 {command:?}: {e}")))?;
    Ok(())
}

/// The next TPDO1 of the actuator; an EMCY from it meanwhile is an error.
fn next_feedback(m: &mut Master, timeout: Duration, what: &str) -> Result<Tpdo1Feedback> {
    let feedback = m
        .next_pdo::<Tpdo1Feedback>(NODE, timeout)
        .map_err(|e| ScenarioError(format!("node {NODE}: TPDO1 {what}: {e}")))?;
    for event in m.drain_events() {
        if let MasterEvent::Emcy(EmcyEvent::Emergency { node, emcy }) = event
            && node == NODE
            && emcy.code != 0
        {
            return Err(ScenarioError(format!(
                "node {NODE}: EMCY 0x{:04X} while waiting for {what}",
                emcy.code
            ))
            .into());
        }
    }
    Ok(feedback)
}

/// TPDO1s until `done` holds, printing those on the way.
fn wait_feedback(
    m: &mut Master,
    out: &mut dyn Write,
    timeout: Duration,
    what: &str,
    done: impl Fn(&Tpdo1Feedback) -> bool,
) -> Result<Tpdo1Feedback> {
    let end = std::time::Instant::now() + timeout;
    loop {
        let left = end.saturating_duration_since(std::time::Instant::now());
        let f = next_feedback(m, left, what)?;
        if done(&f) {
            return Ok(f);
        }
        let s = f.status_flags;
        if s.running_out() || s.running_in() {
            report(
                out,
                if s.running_out() {
                    "running out"
                } else {
                    "running in"
                },
                &f,
            )?;
        }
    }
}

fn wait_error(e: blocking::Error, what: &str) -> Box<dyn Error> {
    match e {
        blocking::Error::DeadlinePassed => Box::new(ScenarioError(what.to_string())),
        e => Box::new(e),
    }
}

fn position_mm(f: &Tpdo1Feedback) -> f64 {
    f.position.number().map_or(f64::NAN, |n| n.value())
}

/// One line: position in mm, current, speed, flags, error.
fn report(out: &mut dyn Write, label: &str, f: &Tpdo1Feedback) -> Result<()> {
    let current = match f.current.kind() {
        feedback::CurrentKind::Number(n) => format!("{:.2} A", n.value()),
        other => other.name().to_string(),
    };
    let speed = f
        .speed
        .number()
        .map_or_else(|| "?".into(), |n| format!("{:.1} mm/s", n.value()));
    let s = f.status_flags;
    let flags: Vec<&str> = [
        (s.end_stop_in(), "end stop in"),
        (s.end_stop_out(), "end stop out"),
        (s.overcurrent(), "overcurrent"),
        (s.running_out(), "running out"),
        (s.running_in(), "running in"),
        (s.heartbeat_required(), "heartbeat required"),
        (s.outside_nominal_conditions(), "outside nominal conditions"),
    ]
    .into_iter()
    .filter_map(|(on, name)| on.then_some(name))
    .collect();
    let error = f.error_code.kind();
    writeln!(
        out,
        "  {label}: {:.1} mm, {current}, {speed}, [{}], error {} ({})",
        position_mm(f),
        flags.join(", "),
        f.error_code.to_raw(),
        error.name(),
    )?;
    Ok(())
}

/// Decoding the recorded trace with the seed table (the tests).
#[cfg(test)]
#[path = "decoded/mod.rs"]
#[allow(
    clippy::duplicate_mod,
    reason = "each example is a crate of its own; the demo includes all three"
)]
mod decoded;

#[cfg(test)]
mod tests {
    use super::*;

    /// The manual's trace (p. 28), every frame that does not depend on the
    /// motion, in its order.
    const MANUAL: [&str; 12] = [
        "701#05",
        "720#00",
        "620#23161001C8000100",
        "5A0#6016100100000000",
        "000#0120",
        "1A0#00000081010000C0",
        "220#03FBFBFBFBFB0000",
        "1A0#00000081000000C0",
        "220#01FBFBFBFBFB0000",
        "1A0#F7010082000000C0",
        "220#02FBFBFBFBFB0000",
        "1A0#00000081000000C0",
    ];

    /// Positions in `trace` where the lines of `wanted` appear in order.
    fn subsequence(trace: &[String], wanted: &[&str]) -> Option<Vec<usize>> {
        let mut at = Vec::new();
        let mut from = 0;
        for w in wanted {
            let i = from + trace.get(from..)?.iter().position(|l| l == w)?;
            at.push(i);
            from = i + 1;
        }
        Some(at)
    }

    #[test]
    fn the_manuals_start_up_then_out_and_back() {
        let args = Args {
            time_scale: 25.0,
            ..Args::default()
        };
        let mut out = Vec::new();
        let summary = run(&args, &mut out)
            .unwrap_or_else(|e| panic!("{e}\n{}", String::from_utf8_lossy(&out)));
        let text = String::from_utf8_lossy(&out);
        assert_eq!(summary.out_end_mm, 50.3, "{text}");
        assert_eq!(summary.final_position_mm, 0.0);
        assert_eq!(summary.status, 0x81);
        assert_eq!(summary.error_code, 0);
        let trace = &summary.trace;
        let at = subsequence(trace, &MANUAL)
            .unwrap_or_else(|| panic!("manual frames not in order:\n{}", trace.join("\n")));
        // The first frame of the actuator after NMT start is the "stop
        // required" TPDO1 (no TPDO2, no EMCY).
        let start = at[4];
        let next = trace[start + 1..].iter().find(|l| !l.starts_with("701#"));
        assert_eq!(next.map(String::as_str), Some("1A0#00000081010000C0"));
        // While running out / in: 1.5 A (0x06) and status 0x88 / 0x90.
        assert!(
            trace[at[8]..at[9]]
                .iter()
                .any(|l| l.get(4..12).is_some_and(|d| d.ends_with("0688"))),
            "{trace:?}"
        );
        assert!(
            trace[at[10]..at[11]]
                .iter()
                .any(|l| l.get(4..12).is_some_and(|d| d.ends_with("0690"))),
            "{trace:?}"
        );
        // No EMCY at all.
        assert!(!trace.iter().any(|l| l.starts_with("0A0#")), "{trace:?}");
        assert!(text.contains("end stop out: 50.3 mm"), "{text}");
        assert!(text.contains("end stop in: 0.0 mm"), "{text}");
    }

    // The trace decoded with the seed table (eds/linak_techline.yaml)
    // against what the example printed.

    use eds2rust_decode::Decoder;

    use super::decoded::{self, *};
    use serde_json::Value as Json;

    /// A decoder that knows node 32 by `eds/linak_techline.yaml`.
    fn seed_decoder() -> Decoder {
        let device = decoded::seed("linak_techline");
        let mut decoder = Decoder::new();
        decoder.add_node(NODE.get(), device);
        decoder
    }

    fn is_pdo(record: &Json, pdo: &str) -> bool {
        record["pdo"] == pdo && record["node"] == NODE.get()
    }

    /// The bit fields a decoded field's text names (`bits: "a", "b"`).
    fn bits(field: &Json) -> Vec<String> {
        let text = field["text"].as_str().expect("text");
        let Some((_, list)) = text.split_once("bits: ") else {
            return Vec::new();
        };
        list.split(", ")
            .map(|b| b.trim_matches('"').to_string())
            .collect()
    }

    /// The printed `N.N unit` of a field with a physical value.
    fn shown(field: &Json, decimals: usize) -> String {
        let value = field["value"]
            .as_f64()
            .unwrap_or_else(|| panic!("no number: {field}"));
        let unit = field["unit"].as_str().unwrap_or_default();
        format!("{value:.decimals$} {unit}")
    }

    /// One `report` line: `0.3 mm, 1.50 A, 3.4 mm/s, [running out], error 0 (no error)`.
    struct Report<'a> {
        position: &'a str,
        current: &'a str,
        speed: &'a str,
        flags: Vec<&'a str>,
        error: u8,
        error_name: &'a str,
    }

    fn report_line(text: &str) -> Report<'_> {
        let (values, rest) = text.split_once(", [").expect("values, [flags]");
        let parts: Vec<&str> = values.split(", ").collect();
        let [position, current, speed] = parts[..] else {
            panic!("{text}")
        };
        let (flags, error) = rest.split_once("], error ").expect("flags, error");
        let (code, name) = error.split_once(" (").expect("code (name)");
        Report {
            position,
            current,
            speed,
            flags: flags.split(", ").filter(|f| !f.is_empty()).collect(),
            error: code.parse().expect("an error code"),
            error_name: name.trim_end_matches(')'),
        }
    }

    #[test]
    fn the_trace_decodes_to_the_printed_values() {
        let args = Args {
            time_scale: 25.0,
            ..Args::default()
        };
        let mut out = Vec::new();
        let summary = run(&args, &mut out)
            .unwrap_or_else(|e| panic!("{e}\n{}", String::from_utf8_lossy(&out)));
        let text = String::from_utf8(out).expect("utf-8");
        println!("{text}");
        let records = decode(&mut seed_decoder(), &summary.trace);
        assert_every_frame_decodes(&records);
        let node = NODE.get();
        // Everything printed so far was seen by record `at`.
        let mut at = 0;
        // The TPDO1 of the last report line.
        let mut last_report = None;
        let mut reports = Vec::new();
        for line in text.lines() {
            if let Some(rest) = line.strip_prefix("master node ") {
                // `1: heartbeat 0x701 every 100 ms` (the trace has no times:
                // the period is not checked).
                let (master, rest) = rest.split_once(": heartbeat ").expect("heartbeat");
                let id = rest.split(' ').next().expect("0x...");
                let id = u32::from_str_radix(id.trim_start_matches("0x"), 16).expect("hex");
                let master: u8 = master.parse().expect("a node id");
                at = find(&records, at, line, |r| {
                    r["protocol"] == "heartbeat"
                        && r["id"] == id
                        && r["node"] == master
                        && r["state"] == "operational"
                });
            } else if let Some(rest) = line.strip_prefix(&format!("node {node}: booted (")) {
                // `0x720 [00])`: the boot-up after the master's reset.
                let id = rest.split(' ').next().expect("0x...");
                let id = u32::from_str_radix(id.trim_start_matches("0x"), 16).expect("hex");
                let reset = find(&records, at, "NMT reset node", |r| {
                    r["protocol"] == "nmt" && r["command"] == "reset node" && r["target"] == node
                });
                at = find(&records, reset, line, |r| {
                    r["protocol"] == "heartbeat"
                        && r["id"] == id
                        && r["node"] == node
                        && r["data"] == "00"
                        && r["state"] == "boot-up"
                });
            } else if let Some(rest) =
                line.strip_prefix(&format!("node {node}: consumes the heartbeat of node "))
            {
                // `1, 200 ms (0x1016 sub 1)`
                let (producer, rest) = rest.split_once(", ").expect("node, time");
                let (ms, rest) = rest.split_once(" ms (0x").expect("time");
                let (index, sub) = rest.trim_end_matches(')').split_once(" sub ").expect("sub");
                let index = u16::from_str_radix(index, 16).expect("hex");
                let sub: u8 = sub.parse().expect("a sub");
                let i = find(&records, at, line, |r| {
                    r["event"] == "sdo-transfer"
                        && r["node"] == node
                        && r["index"] == index
                        && r["subindex"] == sub
                        && r["direction"] == "download"
                });
                let value = records[i]["value"].as_u64().expect("a value");
                assert_eq!(value & 0xFFFF, ms.parse::<u64>().expect("ms"), "{line}");
                assert_eq!(
                    value >> 16 & 0x7F,
                    producer.parse::<u64>().expect("node"),
                    "{line}"
                );
                let decoded = records[i]["text"].as_str().expect("text");
                let time = format!("\"heartbeat time\"={ms} = {ms} ms");
                let producer = format!("\"node id\"={producer}");
                assert!(
                    decoded.contains(&time) && decoded.contains(&producer),
                    "{line}: {decoded}"
                );
                at = i;
            } else if let Some(command) = line.strip_prefix("run ") {
                // `run out`, `run in`: RPDO1 with that command, sent before
                // the line.
                let command = format!("run {command}");
                at = find(&records, at + 1, line, |r| {
                    is_pdo(r, "rpdo1") && field(r, "Command.Position")["value"] == command.as_str()
                });
            } else if let Some((label, values)) =
                line.strip_prefix("  ").and_then(|l| l.split_once(": "))
            {
                let printed = report_line(values);
                let (from, first) = match label {
                    // The first TPDO1 after NMT start.
                    "operational" => {
                        let start = find(&records, at, "NMT start", |r| {
                            r["protocol"] == "nmt" && r["command"] == "start" && r["target"] == node
                        });
                        let first = find(&records, start, line, |r| is_pdo(r, "tpdo1"));
                        (first, Some(first))
                    }
                    // A TPDO1 without error after RPDO1 Stop.
                    "stop" => {
                        let stop = find(&records, at + 1, "RPDO1 stop", |r| {
                            is_pdo(r, "rpdo1") && field(r, "Command.Position")["value"] == "stop"
                        });
                        (stop + 1, None)
                    }
                    _ => (at + 1, None),
                };
                let i = find(&records, from, line, |r| {
                    is_pdo(r, "tpdo1")
                        && shown(field(r, "Feedback.Position"), 1) == printed.position
                        && field(r, "Feedback.Error code")["raw"] == printed.error
                });
                let r = &records[i];
                if let Some(first) = first {
                    assert_eq!(i, first, "{line}: not the first TPDO1 after NMT start");
                }
                // TPDO1s between two report lines are not printed: they show
                // no motion (the example prints every one that does).
                for skipped in &records[last_report.map_or(i, |l: usize| l + 1)..i] {
                    if is_pdo(skipped, "tpdo1") {
                        let flags = bits(field(skipped, "Feedback.Status flags"));
                        assert!(
                            !flags
                                .iter()
                                .any(|f| f == "running out" || f == "running in"),
                            "{line}: a TPDO1 with motion was not printed: {skipped}"
                        );
                    }
                }
                let current = field(r, "Feedback.Current");
                if printed.current.ends_with(" A") {
                    assert_eq!(shown(current, 2), printed.current, "{line}: {r}");
                } else {
                    assert_eq!(current["value"], printed.current, "{line}: {r}");
                }
                let speed = field(r, "Feedback.Speed");
                if printed.speed == "?" {
                    assert!(speed["value"].is_string(), "{line}: {r}");
                } else {
                    assert_eq!(shown(speed, 1), printed.speed, "{line}: {r}");
                }
                // Bit 7 (reserved, always set) is not printed.
                let flags = field(r, "Feedback.Status flags");
                let decoded: Vec<String> = bits(flags)
                    .into_iter()
                    .filter(|f| f != "always set")
                    .collect();
                assert_eq!(decoded, printed.flags, "{line}: {r}");
                if label != "operational" && label != "stop" {
                    assert!(printed.flags.contains(&label), "{line}");
                }
                // The code, named by the table's `error_table`.
                let error = field(r, "Feedback.Error code");
                assert_eq!(error["raw"], printed.error, "{line}: {r}");
                assert_eq!(error["value"], printed.error_name, "{line}: {r}");
                reports.push((label, i));
                (at, last_report) = (i, Some(i));
            } else {
                panic!("a line this test does not know: {line}\n{text}");
            }
        }
        // The last line reports the final TPDO1; the summary has its values
        // and the position at the outer end stop.
        let labels: Vec<&str> = reports.iter().map(|(l, _)| *l).collect();
        assert_eq!(labels.first(), Some(&"operational"), "{text}");
        assert_eq!(labels.last(), Some(&"end stop in"), "{text}");
        let position = |at: usize| field(&records[at], "Feedback.Position")["value"].as_f64();
        let (_, out_end) = reports
            .iter()
            .find(|(l, _)| *l == "end stop out")
            .expect("end stop out was printed");
        assert_eq!(position(*out_end), Some(summary.out_end_mm));
        let (_, last) = reports[reports.len() - 1];
        assert_eq!(position(last), Some(summary.final_position_mm));
        let last = &records[last];
        assert_eq!(field(last, "Feedback.Status flags")["raw"], summary.status);
        assert_eq!(
            field(last, "Feedback.Error code")["raw"],
            summary.error_code
        );
    }
}
