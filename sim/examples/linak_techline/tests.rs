//! The tests of the example `linak_techline`.

use serde_json::Value as Json;

use super::common::decoded::*;
use super::common::run_at;
use super::*;
use eds2rust_sim::models::linak_techline::MANUAL_TRACE;

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
    let (summary, text) = run_at(25.0, run);
    assert_eq!(summary.out_end_mm, 50.3, "{text}");
    assert_eq!(summary.final_position_mm, 0.0);
    assert_eq!(summary.status, 0x81);
    assert_eq!(summary.error_code, 0);
    let trace = &summary.trace;
    let at = subsequence(trace, &MANUAL_TRACE)
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
    let (summary, text) = run_at(25.0, run);
    println!("{text}");
    let records = decode_seed("linak_techline", &[NODE.get()], &summary.trace);
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
