//! TIME interoperability with python-canopen 2.4.1: the frames of its
//! `canopen.timestamp.TimeProducer` (on python-can's virtual bus) decode
//! with our TIME_OF_DAY codec to the same time, and our producer sends the
//! same bytes for that time. (python-canopen has no TIME consumer, so the
//! other direction has no oracle.)
//!
//! python-canopen computes `divmod(unix_seconds - 441763200, 86400)` and
//! `int(seconds * 1000)` in floating point; the timestamps below are exact
//! in binary (whole seconds, .5, .25) or, for .789, known to survive.

use std::process::Command;

use eds2rust_runtime::Service;
use eds2rust_runtime::time_stamp::{TimeConsumer, TimeEvent, TimeOfDay, TimeProducer};
use eds2rust_runtime::trace::candump::parse_frame;
use eds2rust_runtime::{Frame, Instant};
use eds2rust_tests::python::python;

/// Each timestamp through python-canopen's `TimeProducer.transmit`; one
/// frame per timestamp, in candump's compact form.
const SCRIPT: &str = r#"
import sys, can, canopen
from canopen.timestamp import TimeProducer
bus = can.Bus(interface="virtual", channel="eds2rust-interop-time", receive_own_messages=True)
producer = TimeProducer(canopen.Network(bus))
for ts in sys.argv[1:]:
    producer.transmit(float(ts))
    m = bus.recv(2)
    print(f"{m.arbitration_id:03X}#{m.data.hex().upper()}")
bus.shutdown()
"#;

fn python_frames(timestamps: &[&str]) -> Vec<Frame> {
    let interpreter = python().unwrap_or_else(|e| panic!("{e}"));
    let output = Command::new(interpreter)
        .arg("-c")
        .arg(SCRIPT)
        .args(timestamps)
        .output()
        .expect("python runs");
    assert!(
        output.status.success(),
        "python-canopen's TimeProducer failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout)
        .expect("UTF-8")
        .lines()
        .map(|line| parse_frame(line).unwrap_or_else(|e| panic!("{line}: {e:?}")))
        .collect()
}

#[test]
fn python_time_producer_frames_decode_to_the_same_time() {
    // (Unix timestamp given to python, the time it stands for in Unix ms,
    // its ISO 8601 form.)
    let cases: &[(&str, i64, &str)] = &[
        // The CANopen epoch: all six bytes zero.
        ("441763200", 441_763_200_000, "1984-01-01T00:00:00.000Z"),
        // python-canopen's own test value.
        ("1486236238", 1_486_236_238_000, "2017-02-04T19:23:58.000Z"),
        (
            "1796214896.789",
            1_796_214_896_789,
            "2026-12-02T12:34:56.789Z",
        ),
        // A leap day.
        (
            "1709164800.25",
            1_709_164_800_250,
            "2024-02-29T00:00:00.250Z",
        ),
        ("951782399.5", 951_782_399_500, "2000-02-28T23:59:59.500Z"),
        // The last day the format holds (day 65 535), last half second.
        (
            "6104073599.5",
            6_104_073_599_500,
            "2163-06-06T23:59:59.500Z",
        ),
    ];
    let stamps: Vec<&str> = cases.iter().map(|c| c.0).collect();
    let frames = python_frames(&stamps);
    assert_eq!(frames.len(), cases.len(), "{frames:?}");
    let mut consumer = TimeConsumer::new();
    let producer = TimeProducer::new(None);
    for (frame, &(stamp, unix_ms, iso)) in frames.iter().zip(cases) {
        let expected = TimeOfDay::from_unix_millis(unix_ms).unwrap();
        assert_eq!(expected.to_string(), iso);
        consumer.handle_frame(Instant::ZERO, frame);
        assert_eq!(
            consumer.poll_event(),
            Some(TimeEvent::Time {
                time: expected,
                received: Instant::ZERO
            }),
            "python sent {frame} for {stamp}"
        );
        // Our producer sends python's bytes for the same time.
        assert_eq!(producer.frame(expected), *frame, "{stamp}");
    }
    assert_eq!(frames[0].to_string(), "100#000000000000");
    assert_eq!(frames[2].to_string(), "100#952CB3023C3D");
}
