//! The tests of the example `interroll_ec5000bi`.

use serde_json::Value as Json;

use super::common::decoded::*;
use super::common::run_at;
use super::*;

#[test]
fn lss_then_velocity_mode_on_the_virtual_bus() {
    let (s, text) = run_at(20.0, run);
    println!("{text}");
    assert_eq!(s.node, 5);
    // Operation enabled, halted (zero motion hold), at rest.
    assert_eq!(s.statusword, 0x0237);
    assert_eq!(s.state, Some(State::OperationEnabled));
    assert_eq!(s.velocity_mm_s, 0);
    assert!(s.position_mm > 0);
    // Chapter 3 / CiA 305, byte for byte.
    let expected = [
        "7E5#40FB030000000000",
        "7E5#4101000000000000",
        "7E5#4201000100000000",
        "7E5#4387D61200000000",
        "7E4#4400000000000000",
        "7E5#1105000000000000",
        "7E4#1100000000000000",
        "7E5#1700000000000000",
        "7E4#1700000000000000",
        "7E5#0400000000000000",
        "000#827F",
        "705#00",
    ];
    let start = s
        .trace
        .iter()
        .position(|l| l == expected[0])
        .expect("switch selective in the trace");
    assert_eq!(&s.trace[start..start + expected.len()], expected);
    // Before: the drive booted at 127 and answered there (0x1018 sub 4).
    let boot = s
        .trace
        .iter()
        .position(|l| l == "77F#00")
        .expect("boot-up 127");
    assert!(boot < start);
    assert!(s.trace.iter().any(|l| l == "5FF#4318100487D61200"));
    for line in [
        "000#0105",             // NMT start node 5
        "605#2F60600003000000", // 0x6060 = 3
        "605#2B40600006000000", // shutdown
        "605#2B40600007000000", // switch on
        "605#2B4060000F000000", // enable operation
    ] {
        assert!(s.trace.iter().any(|l| l == line), "{line} missing");
    }
    // 0x60FF = 500 (INTEGER32, expedited 4 bytes) and the halt word.
    assert!(s.trace.iter().any(|l| l == "605#23FF6000F4010000"));
    assert!(s.trace.iter().any(|l| l == "605#2B4060000F010000"));
    assert!(text.contains("velocity reached"));
    assert!(text.contains("Operation enabled"));
}

// The trace decoded with the seed table (eds/interroll_ec5000bi.yaml)
// against what the example printed.

/// The next SDO transfer of `node`'s entry `index` sub `sub` from
/// `from` on.
fn transfer(
    records: &[Json],
    from: usize,
    (node, index, sub): (u8, u16, u8),
    direction: &str,
) -> usize {
    let what = format!("an SDO {direction} of {index:#06X} sub {sub} of node {node}");
    find(records, from, &what, |r| {
        r["event"] == "sdo-transfer"
            && r["node"] == node
            && r["index"] == index
            && r["subindex"] == sub
            && r["direction"] == direction
    })
}

/// A printed number, decimal or `0x` hex.
fn number(text: &str) -> u64 {
    let text = text.trim();
    match text.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16),
        None => text.parse(),
    }
    .unwrap_or_else(|_| panic!("{text} is no number"))
}

/// A printed `N unit`.
fn quantity(text: &str) -> (f64, String) {
    let (n, unit) = text.trim().split_once(' ').expect("N unit");
    (n.parse().expect("a number"), unit.to_string())
}

#[test]
fn the_trace_decodes_to_the_printed_values() {
    // Slow enough that the velocity is printed during the ramp.
    let (summary, text) = run_at(2.0, run);
    println!("{text}");
    let records = decode_seed(
        "interroll_ec5000bi",
        &[DEFAULT_NODE_ID, NEW_NODE],
        &summary.trace,
    );
    let (old, new) = (DEFAULT_NODE_ID, NEW_NODE);
    let text_of = |i: usize| records[i]["text"].as_str().expect("text");
    // The master does one thing at a time: every printed line is
    // matched by records after those of the line before (`at`).
    let mut at = 0;
    let mut identity = Vec::new();
    let mut end = None;
    for line in text.lines() {
        assert!(end.is_none(), "a line after the last: {line}\n{text}");
        let sdo_line = line.trim_start();
        if let Some(rest) = line.strip_prefix(&format!("node {old} (delivery state): ")) {
            // `vendor 0x3FB, product 1, revision 0x00010001, serial number 1234567`
            for (sub, part) in (1u8..).zip(rest.split(", ")) {
                let (_, value) = part.rsplit_once(' ').expect("name value");
                at = transfer(&records, at, (old, 0x1018, sub), "upload");
                assert_eq!(records[at]["value"], number(value), "{line}: {part}");
                identity.push(number(value));
            }
        } else if let Some(serial) =
            line.strip_prefix("LSS: selecting the drive with serial number ")
        {
            // Switch state selective: vendor, product, revision, serial.
            assert_eq!(identity.last(), Some(&number(serial)), "{line}");
            let parts = ["VendorId", "ProductCode", "Revision", "Serial"];
            for (part, value) in parts.iter().zip(&identity) {
                let request = format!("LSS request: SwitchStateSelective({part}, {value})");
                at = find(&records, at, &request, |r| r["text"] == request.as_str());
            }
            at = find(&records, at, line, |r| {
                r["text"] == "LSS response: SwitchStateSelective"
            });
        } else if let Some(id) = line
            .strip_prefix("LSS: node id ")
            .and_then(|l| l.strip_suffix(" configured"))
        {
            let request = format!("LSS request: ConfigureNodeId({id})");
            at = find(&records, at, &request, |r| r["text"] == request.as_str());
            at = find(&records, at, line, |r| {
                r["text"] == "LSS response: ConfigureNodeId { error: 0, spec: 0 }"
            });
        } else if line.starts_with("LSS: configuration stored") {
            at = find(&records, at, line, |r| {
                r["text"] == "LSS request: StoreConfiguration"
            });
            at = find(&records, at, line, |r| {
                r["text"] == "LSS response: StoreConfiguration { error: 0, spec: 0 }"
            });
        } else if line == format!("NMT: node {new} booted (reset communication)") {
            at = find(&records, at, "NMT reset communication", |r| {
                r["protocol"] == "nmt"
                    && r["command"] == "reset communication"
                    && r["target"] == old
            });
            at = find(&records, at, line, |r| {
                r["protocol"] == "heartbeat" && r["node"] == new && r["state"] == "boot-up"
            });
        } else if let Some(rest) = line.strip_prefix(&format!("node {new}: ")) {
            // `EC5000, serial number 1234567`
            let (name, serial) = rest.split_once(", serial number ").expect("name, serial");
            at = transfer(&records, at, (new, 0x1008, 0), "upload");
            assert_eq!(records[at]["value"], name, "{line}");
            at = transfer(&records, at, (new, 0x1018, 4), "upload");
            assert_eq!(records[at]["value"], number(serial), "{line}");
        } else if let Some(rest) = line.strip_prefix("CiA 402: ") {
            // `profile velocity mode (0x6060 = 3)`
            let (mode, rest) = rest.split_once(" mode (0x").expect("mode (0x....");
            let (index, value) = rest.trim_end_matches(')').split_once(" = ").expect("=");
            let index = u16::from_str_radix(index, 16).expect("hex");
            at = transfer(&records, at, (new, index, 0), "download");
            assert_eq!(records[at]["value"], number(value), "{line}");
            assert!(
                text_of(at).ends_with(&format!("\"{mode}\"")),
                "{line}: {}",
                text_of(at)
            );
        } else if let Some(rest) = sdo_line.strip_prefix("statusword 0x") {
            // `0250 (Switch on disabled)`
            let (sw, state) = rest.split_once(" (").expect("sw (state)");
            at = transfer(&records, at, (new, 0x6041, 0), "upload");
            assert_eq!(records[at]["value"], number(&format!("0x{sw}")), "{line}");
            let state = state.trim_end_matches(')');
            assert!(names_state(text_of(at), state), "{line}: {}", text_of(at));
        } else if let Some(rest) = sdo_line.strip_prefix("controlword ") {
            // `0x0006 -> statusword 0x0231 (Ready to switch on)`: the
            // write, then the first read that shows the state.
            let (cw, rest) = rest.split_once(" -> statusword ").expect("cw -> sw");
            let (sw, state) = rest.split_once(" (").expect("sw (state)");
            let state = state.trim_end_matches(')');
            at = transfer(&records, at, (new, 0x6040, 0), "download");
            assert_eq!(records[at]["value"], number(cw), "{line}");
            at = find(&records, at, line, |r| {
                r["event"] == "sdo-transfer"
                    && r["node"] == new
                    && r["index"] == 0x6041
                    && r["direction"] == "upload"
                    && r["value"] == number(sw)
            });
            assert!(names_state(text_of(at), state), "{line}: {}", text_of(at));
        } else if let Some(rest) = line.strip_prefix("target velocity ") {
            // `500 mm/s (0.5 m/s)`
            let (mm_s, m_s) = rest.split_once(" (").expect("mm/s (m/s)");
            at = transfer(&records, at, (new, 0x60FF, 0), "download");
            let (value, unit) = physical(&records[at]);
            assert_eq!((value, unit.clone()), quantity(mm_s), "{line}");
            assert_eq!(unit, "mm/s");
            assert_eq!(format!("{} m/s", value / 1000.0), m_s.trim_end_matches(')'));
        } else if let Some(rest) = sdo_line
            .strip_prefix("velocity reached: ")
            .or_else(|| sdo_line.strip_prefix("velocity "))
        {
            // Polled every 25 ms, printed at most every 100 ms.
            at = find(&records, at, line, |r| {
                r["event"] == "sdo-transfer"
                    && r["node"] == new
                    && r["index"] == 0x606C
                    && r["direction"] == "upload"
                    && physical(r) == quantity(rest)
            });
        } else if line.starts_with("monitoring") {
            // A heading.
        } else if let Some(rest) = sdo_line.strip_prefix("motor temperature ") {
            // `25 °C (maximum so far 25 °C)`
            let (now, max) = rest.split_once(" (maximum so far ").expect("(maximum)");
            at = transfer(&records, at, (new, 0x2200, 6), "upload");
            assert_eq!(physical(&records[at]), quantity(now), "{line}");
            at = transfer(&records, at, (new, 0x2200, 5), "upload");
            let max = max.trim_end_matches(')');
            assert_eq!(physical(&records[at]), quantity(max), "{line}");
        } else if let Some(rest) = sdo_line.strip_prefix("DC link voltage ") {
            // `23.97 V, torque 85 ‰ of rated`: mV on the bus.
            let (volts, torque) = rest.split_once(", torque ").expect("V, torque");
            at = transfer(&records, at, (new, 0x6079, 0), "upload");
            let (mv, unit) = physical(&records[at]);
            assert_eq!(unit, "mV", "{line}");
            assert_eq!(format!("{:.2} V", mv / 1000.0), volts, "{line}");
            at = transfer(&records, at, (new, 0x6077, 0), "upload");
            let torque = torque.strip_suffix(" of rated").expect("of rated");
            assert_eq!(physical(&records[at]), quantity(torque), "{line}");
        } else if let Some(rest) = sdo_line.strip_prefix("power average ") {
            // `0 W, start/stops 1, rotations 2, working hours 0 h`
            let parts: Vec<&str> = rest.split(", ").collect();
            let [power, starts, turns, hours] = parts[..] else {
                panic!("{line}")
            };
            at = transfer(&records, at, (new, 0x2200, 8), "upload");
            assert_eq!(physical(&records[at]), quantity(power), "{line}");
            for (sub, part) in [(1, starts), (9, turns)] {
                let (_, n) = part.rsplit_once(' ').expect("name N");
                at = transfer(&records, at, (new, 0x2200, sub), "upload");
                assert_eq!(records[at]["value"], number(n), "{line}");
            }
            at = transfer(&records, at, (new, 0x2200, 2), "upload");
            let hours = hours.strip_prefix("working hours ").expect("working hours");
            assert_eq!(physical(&records[at]), quantity(hours), "{line}");
        } else if let Some(rest) = sdo_line.strip_prefix("status lights: ") {
            // `temperature green, power green, error quantity green,
            // lifetime green`: the named values of the lights.
            let entries = [(0x2211, 1), (0x2211, 2), (0x2211, 3), (0x2210, 0)];
            let parts: Vec<&str> = rest.split(", ").collect();
            assert_eq!(parts.len(), entries.len(), "{line}");
            for ((index, sub), part) in entries.into_iter().zip(parts) {
                let (_, colour) = part.rsplit_once(' ').expect("light colour");
                at = transfer(&records, at, (new, index, sub), "upload");
                let named = format!("\"{colour}\"");
                assert!(text_of(at).ends_with(&named), "{line}: {}", text_of(at));
            }
        } else if let Some(bit) = line
            .strip_prefix("halt (controlword bit ")
            .and_then(|l| l.strip_suffix(')'))
        {
            let bit = number(bit);
            at = transfer(&records, at, (new, 0x6040, 0), "download");
            let cw = records[at]["value"].as_u64().expect("a controlword");
            assert!(cw & 1 << bit != 0, "{line}: {}", text_of(at));
            assert!(text_of(at).contains("\"halt\""), "{line}: {}", text_of(at));
        } else if let Some(rest) = sdo_line.strip_prefix("standstill at ") {
            // `764 mm, statusword 0x0237 (Operation enabled, zero motion
            // hold)`: 0x606C read until 0, then 0x6064 and 0x6041.
            let (position, rest) = rest.split_once(", statusword ").expect("position, sw");
            let (sw, state) = rest.split_once(" (").expect("sw (state)");
            let (state, _) = state.split_once(", ").expect("state, hold");
            let rest = records.get(at..).unwrap_or_default();
            let stopped = at
                + rest
                    .iter()
                    .position(|r| {
                        r["event"] == "sdo-transfer"
                            && r["node"] == new
                            && r["index"] == 0x606C
                            && r["value"] == 0
                    })
                    .expect("a velocity of 0 after the halt");
            assert_eq!(physical(&records[stopped]), (0.0, "mm/s".into()));
            at = transfer(&records, stopped, (new, 0x6064, 0), "upload");
            let (mm, unit) = physical(&records[at]);
            assert_eq!((mm, unit), quantity(position), "{line}");
            assert_eq!(f64::from(summary.position_mm), mm);
            at = transfer(&records, at, (new, 0x6041, 0), "upload");
            assert_eq!(records[at]["value"], number(sw), "{line}");
            assert!(names_state(text_of(at), state), "{line}: {}", text_of(at));
            assert_eq!(records[at]["value"], summary.statusword);
            assert_eq!(summary.state.map(State::name), Some(state));
            // The last velocity read is the standstill's.
            let last = records.iter().rposition(|r| {
                r["event"] == "sdo-transfer" && r["node"] == new && r["index"] == 0x606C
            });
            assert_eq!(last, Some(stopped));
            assert_eq!(records[stopped]["value"], summary.velocity_mm_s);
            end = Some(at);
        } else {
            panic!("a line this test does not know: {line}\n{text}");
        }
    }
    assert!(end.is_some(), "no final line:\n{text}");
    assert_eq!(summary.node, new);
}
