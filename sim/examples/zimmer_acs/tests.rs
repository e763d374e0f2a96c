//! The tests of the example `zimmer_acs`.

use serde_json::Value as Json;

use super::common::decoded::*;
use super::common::run_at;
use super::*;

/// `expected` appears in `trace` in this order (other frames between).
fn assert_in_order(trace: &[String], expected: &[&str]) {
    let mut rest = trace.iter();
    for frame in expected {
        assert!(
            rest.any(|line| line == frame),
            "{frame} missing (in order) from the trace:\n{}",
            trace.join("\n")
        );
    }
}

#[test]
fn enables_and_moves_to_the_target_on_the_virtual_bus() {
    let (summary, text) = run_at(20.0, run);
    assert_eq!(summary.state, Some(State::OperationEnabled), "{text}");
    assert_eq!(summary.position_um, TARGET_UM);
    assert_eq!(
        summary.states,
        [
            State::SwitchOnDisabled,
            State::ReadyToSwitchOn,
            State::SwitchedOn,
            State::OperationEnabled
        ]
    );
    assert!(
        text.contains("state: Switched on -> Operation enabled (statusword 0x4037)"),
        "{text}"
    );
    assert!(
        text.contains("target reached (bit 10) at 40.000 mm"),
        "{text}"
    );
    // The master's frames and the device's frames each in their order
    // (between the two, only cause and effect is ordered on the bus).
    let from = |ids: &[&str]| -> Vec<String> {
        summary
            .trace
            .iter()
            .filter(|l| ids.iter().any(|id| l.starts_with(id)))
            .cloned()
            .collect()
    };
    assert_in_order(
        &from(&["000#", "628#"]),
        &[
            "628#4041600000000000", // SDO read 0x6041
            "000#0128",             // NMT start node 40
            "628#2B40600006000000", // controlword Shutdown
            "628#2B40600007000000", // Switch on
            "628#2B4060000F000000", // Enable operation
            "628#2F60600001000000", // modes of operation: 1
            "628#2381600032000000", // profile velocity 50 mm/s
            "628#23836000F4010000", // profile acceleration 500 mm/s²
            "628#23846000F4010000", // profile deceleration 500 mm/s²
            "628#237A6000409C0000", // target 40 000 µm
            "628#2B4060001F000000", // new set-point (bit 4)
            "628#2B4060000F000000", // bit 4 back to 0 after the acknowledge
        ],
    );
    assert_in_order(
        &from(&["728#", "5A8#4B41", "1A8#"]),
        &[
            "728#00",               // boot-up of node 40
            "5A8#4B41600040000000", // statusword 0x0040
            "1A8#400000000000",     // TPDO1: Switch on disabled, 0 µm
            "1A8#210000000000",     // Ready to switch on
            "1A8#330000000000",     // Switched on, voltage enabled
            "1A8#374000000000",     // Operation enabled, angle found
            "1A8#375000000000",     // set-point acknowledge
            "1A8#374000000000",     // acknowledge cleared with bit 4
            "1A8#3744409C0000",     // target reached at 40 000 µm
        ],
    );
}

// The trace decoded with the seed table (eds/zimmer_acs.yaml) against
// what the example printed.

/// `record` is an SDO transfer of node 40's entry `index` sub `sub`.
fn is_transfer(record: &Json, index: u16, sub: u8, direction: &str) -> bool {
    record["event"] == "sdo-transfer"
        && record["node"] == NODE.get()
        && record["index"] == index
        && record["subindex"] == sub
        && record["direction"] == direction
}

/// A `0x...` number of the printed text.
fn hex(text: &str) -> u16 {
    let digits = text.trim().trim_start_matches("0x");
    u16::from_str_radix(digits, 16).unwrap_or_else(|_| panic!("{text} is no hex number"))
}

/// A statusword and position the example handed to its state machine:
/// from a TPDO1, or from its SDO reads of 0x6041 and then 0x6064.
struct Seen {
    at: usize,
    statusword: u16,
    /// The decoded statusword (with its CiA 402 state).
    text: String,
    /// The position's physical value and unit.
    position: f64,
    unit: String,
}

fn seen(records: &[Json]) -> Vec<Seen> {
    let mut out = Vec::new();
    let mut read = None;
    for (at, r) in records.iter().enumerate() {
        if r["pdo"] == "tpdo1" && r["node"] == NODE.get() {
            let sw = field(r, "Statusword");
            let p = field(r, "Position actual value");
            out.push(Seen {
                at,
                statusword: sw["raw"].as_u64().expect("a statusword") as u16,
                text: sw["text"].as_str().expect("text").to_string(),
                position: p["value"].as_f64().expect("a position"),
                unit: p["unit"].as_str().unwrap_or_default().to_string(),
            });
        } else if is_transfer(r, 0x6041, 0, "upload") {
            read = Some(r);
        } else if is_transfer(r, 0x6064, 0, "upload")
            && let Some(sw) = read.take()
        {
            let (position, unit) = physical(r);
            out.push(Seen {
                at,
                statusword: sw["value"].as_u64().expect("a statusword") as u16,
                text: sw["text"].as_str().expect("text").to_string(),
                position,
                unit,
            });
        }
    }
    out
}

/// A position in µm as the example prints it (mm, three decimals).
fn as_mm(value: f64, unit: &str) -> String {
    assert_eq!(unit, "µm", "positions are µm on the bus");
    format!("{:.3}", value / 1000.0)
}

#[test]
fn the_trace_decodes_to_the_printed_values() {
    // Slow enough that positions are printed while the carriage moves
    // (every 100 ms of the half-second move).
    let (summary, text) = run_at(2.0, run);
    println!("{text}");
    let records = decode_seed("zimmer_acs", &[NODE.get()], &summary.trace);
    let seen = seen(&records);
    let seen_from = |from: usize, what: &str, accept: &dyn Fn(&Seen) -> bool| -> &Seen {
        seen.iter()
            .find(|s| s.at >= from && accept(s))
            .unwrap_or_else(|| {
                panic!(
                    "no statusword from {from} on {what}:\n{}",
                    texts(&records, from)
                )
            })
    };
    // Everything printed so far was seen by record `at`; the last
    // statusword and position lines matched these records.
    let mut at = 0;
    let mut last_state = None;
    let mut last_position = None;
    let mut target_at = None;
    let mut end = None;
    let (mut states, mut positions) = (0, 0);
    for line in text.lines() {
        assert!(end.is_none(), "a line after the last: {line}\n{text}");
        if let Some(rest) = line.strip_prefix("state: ") {
            // `state: A -> B (statusword 0x....)`
            let (_, rest) = rest.split_once(" -> ").expect("A -> B");
            let (state, sw) = rest.split_once(" (statusword ").expect("statusword");
            let sw = hex(sw.trim_end_matches(')'));
            let after = last_state.map_or(at, |l: usize| at.max(l + 1));
            let s = seen_from(after, line, &|s| s.statusword == sw);
            assert!(names_state(&s.text, state), "{line}: {}", s.text);
            (at, last_state) = (s.at, Some(s.at));
            states += 1;
        } else if let Some(rest) = line.strip_prefix("position ") {
            // `position    0.000 mm (statusword 0x....)`
            let (mm, sw) = rest.split_once(" mm (statusword ").expect("position");
            let (mm, sw) = (mm.trim(), hex(sw.trim_end_matches(')')));
            let after = last_position.map_or(at, |l: usize| at.max(l + 1));
            let s = seen_from(after, line, &|s| {
                s.statusword == sw && as_mm(s.position, &s.unit) == mm
            });
            (at, last_position) = (s.at, Some(s.at));
            positions += 1;
        } else if line == format!("node {NODE}: NMT start") {
            at = find(&records, at, line, |r| {
                r["protocol"] == "nmt" && r["command"] == "start" && r["target"] == NODE.get()
            });
        } else if let Some(rest) = line.strip_prefix("enable: ") {
            // Announced: the writes follow, each with the state change it
            // causes, so `at` stays.
            let list = rest.split(" (").next().unwrap_or(rest);
            let mut from = at;
            for step in list.split(", ") {
                let (name, cw) = step.rsplit_once(' ').expect("NAME 0x..");
                let i = find(&records, from, step, |r| {
                    is_transfer(r, 0x6040, 0, "download") && r["value"] == hex(cw)
                });
                let decoded = records[i]["text"].as_str().expect("text");
                assert!(names_state(decoded, name), "{step}: {decoded}");
                from = i + 1;
            }
        } else if let Some(rest) = line.strip_prefix("profile position: ") {
            // `50 mm/s, 500 mm/s², target 40.000 mm`: mode 1, then the
            // profile (written before the line), then the target
            // (written by the move after it).
            let parts: Vec<&str> = rest.split(", ").collect();
            let [velocity, ramp, target] = parts[..] else {
                panic!("{line}")
            };
            let mode = find(&records, at, "modes of operation 1", |r| {
                is_transfer(r, 0x6060, 0, "download") && r["value"] == 1
            });
            let decoded = records[mode]["text"].as_str().expect("text");
            assert!(decoded.ends_with("\"profile position\""), "{decoded}");
            let mut from = mode + 1;
            for (index, printed) in [(0x6081, velocity), (0x6083, ramp), (0x6084, ramp)] {
                let (number, unit) = printed.split_once(' ').expect("N unit");
                let number: f64 = number.parse().expect("a number");
                let i = find(&records, from, printed, |r| {
                    is_transfer(r, index, 0, "download")
                });
                assert_eq!(physical(&records[i]), (number, unit.to_string()), "{line}");
                from = i + 1;
            }
            at = from - 1;
            let mm = target
                .strip_prefix("target ")
                .and_then(|t| t.strip_suffix(" mm"));
            let i = find(&records, from, target, |r| {
                is_transfer(r, 0x607A, 0, "download")
            });
            let (value, unit) = physical(&records[i]);
            assert_eq!(Some(as_mm(value, &unit).as_str()), mm, "{line}");
            target_at = Some(i);
        } else if let Some(rest) = line.strip_prefix("set-point acknowledged (bit ") {
            let bit: u32 = rest.trim_end_matches(')').parse().expect("a bit");
            let after = at.max(target_at.expect("the target was written") + 1);
            let s = seen_from(after, line, &|s| s.statusword & 1 << bit != 0);
            assert!(s.text.contains("\"setpoint ack\""), "{line}: {}", s.text);
            at = s.at;
        } else if let Some(rest) = line.strip_prefix("target reached (bit ") {
            // `10) at 40.000 mm, state Operation enabled`: the statusword
            // with bit 10, then the position read by SDO at the end.
            let (bit, rest) = rest.split_once(") at ").expect("bit");
            let (mm, state) = rest.split_once(" mm, state ").expect("position, state");
            let bit: u32 = bit.parse().expect("a bit");
            let s = seen_from(at, line, &|s| s.statusword & 1 << bit != 0);
            assert!(s.text.contains("\"target reached\""), "{line}: {}", s.text);
            assert!(names_state(&s.text, state), "{line}: {}", s.text);
            let last = records
                .iter()
                .rposition(|r| is_transfer(r, 0x6064, 0, "upload"))
                .expect("the position read at the end");
            assert!(last > s.at, "{line}:\n{}", texts(&records, s.at));
            let (value, unit) = physical(&records[last]);
            assert_eq!(as_mm(value, &unit), mm, "{line}");
            assert_eq!(f64::from(summary.position_um), value);
            assert_eq!(summary.state.map(State::name), Some(state));
            end = Some(last);
        } else {
            panic!("a line this test does not know: {line}\n{text}");
        }
    }
    assert!(end.is_some(), "no final line:\n{text}");
    assert_eq!(states, summary.states.len(), "{text}");
    assert!(positions >= 1, "{text}");
}
