//! The recorded python-canopen session (`eds2rust_tests::recording`): its
//! trace reads back as candump `-l` lines and holds what the session did
//! (block transfers both ways, PDOs, EMCY, heartbeats), and what
//! python-canopen reports agrees with the trace.

use std::time::Duration;

use eds2rust_runtime::Frame;
use eds2rust_runtime::trace::candump::parse_line;
use eds2rust_sim::models;
use eds2rust_tests::recording::{self, Session};

fn python_session() -> Result<Session, String> {
    recording::python_session_with(models::interroll_ec5000bi::simulator)
}

/// The frames of the trace; every line must be a timestamped log line of
/// `vcan0`, the timestamps strictly increasing.
fn frames(trace: &str) -> Vec<Frame> {
    let mut last: Option<Duration> = None;
    trace
        .lines()
        .enumerate()
        .map(|(n, text)| {
            let line = parse_line(text)
                .unwrap_or_else(|e| panic!("line {}: {e}: {text:?}", n + 1))
                .unwrap_or_else(|| panic!("line {} is blank", n + 1));
            assert_eq!(line.interface, recording::INTERFACE, "line {}", n + 1);
            let at = line.timestamp.expect("a timestamp");
            assert!(
                last.is_none_or(|l| l < at),
                "line {}: time goes back",
                n + 1
            );
            last = Some(at);
            line.frame
        })
        .collect()
}

fn command_bytes(frames: &[Frame], cob_id: u16) -> Vec<u8> {
    frames
        .iter()
        .filter(|f| f.standard_id() == Some(cob_id))
        .filter_map(|f| f.data().first().copied())
        .collect()
}

#[test]
fn python_session_is_recorded() {
    let s = python_session().unwrap_or_else(|e| panic!("{e}"));
    assert!(!s.trace.is_empty());
    assert!(s.trace.ends_with('\n'));
    let frames = frames(&s.trace);
    let node = u16::from(s.node);
    let local = u16::from(s.local_node);

    // Block transfers both ways: initiate requests (client to server) and
    // responses (server to client).
    let requests = command_bytes(&frames, 0x600 + node);
    let responses = command_bytes(&frames, 0x580 + node);
    assert!(
        requests.iter().any(|&c| c == 0xA0 || c == 0xA4),
        "no block upload initiate request (ccs 5)"
    );
    assert!(
        requests
            .iter()
            .any(|&c| (0xC0..=0xC6).contains(&c) && c & 1 == 0),
        "no block download initiate request (ccs 6)"
    );
    assert!(
        responses.iter().any(|&c| c & 0xE3 == 0xC2),
        "no block upload initiate response (scs 6)"
    );
    assert!(
        responses.iter().any(|&c| c & 0xE3 == 0xA0),
        "no block download initiate response (scs 5)"
    );

    // What python-canopen logged of its transfers: every kind, both ways.
    for upload in [true, false] {
        for (block, segmented, kind) in [
            (true, false, "block"),
            (false, true, "segmented"),
            (false, false, "expedited"),
        ] {
            assert!(
                s.sdo.iter().any(|op| op.upload == upload
                    && op.block == block
                    && op.segmented == segmented
                    && op.abort.is_none()),
                "no {kind} {} in {:#?}",
                if upload { "upload" } else { "download" },
                s.sdo
            );
        }
    }
    let block_up = s
        .sdo
        .iter()
        .find(|op| op.upload && op.block && op.index == 0x6403)
        .expect("block upload of 0x6403");
    assert_eq!(block_up.data.len(), 1000);
    assert!(
        s.sdo
            .iter()
            .any(|op| op.index == 0x1008 && op.data == b"EC5000")
    );

    // PDOs: the frames python-canopen decoded are the trace's, in order.
    let tpdo_ids: Vec<u16> = [0x180, 0x280, 0x380, 0x480].map(|b| b + node).to_vec();
    let on_bus: Vec<(u32, Vec<u8>)> = frames
        .iter()
        .filter(|f| f.standard_id().is_some_and(|id| tpdo_ids.contains(&id)))
        .map(|f| (u32::from(f.standard_id().unwrap_or(0)), f.data().to_vec()))
        .collect();
    assert!(on_bus.len() >= 2, "{} PDO frames", on_bus.len());
    let decoded: Vec<(u32, Vec<u8>)> = s.pdos.iter().map(|p| (p.cob_id, p.data.clone())).collect();
    assert_eq!(decoded, on_bus);
    for pdo in &s.pdos {
        assert!(!pdo.fields.is_empty(), "{pdo:?}");
        assert_eq!(pdo.fields[0].1, 0x6041, "statusword first: {pdo:?}");
    }

    // EMCY and heartbeats agree with the trace.
    let emcy: Vec<&Frame> = frames
        .iter()
        .filter(|f| f.standard_id() == Some(0x80 + local))
        .collect();
    assert_eq!(emcy.len(), s.emcy.len());
    assert!(!emcy.is_empty());
    for (frame, sent) in emcy.iter().zip(&s.emcy) {
        let data = frame.data();
        assert_eq!(u16::from_le_bytes([data[0], data[1]]), sent.code);
        assert_eq!(data[2], sent.register);
        assert!(data[3..].starts_with(&sent.data));
    }
    let heartbeats: Vec<(u8, u8)> = frames
        .iter()
        .filter_map(|f| {
            let id = f.standard_id()?;
            let node = u8::try_from(id.checked_sub(0x700)?).ok()?;
            (1..=127).contains(&node).then(|| (node, f.data()[0]))
        })
        .collect();
    assert_eq!(heartbeats, s.heartbeats);
    assert!(heartbeats.contains(&(s.node, 0x05)));
    assert!(heartbeats.contains(&(s.local_node, 0x7F)));

    println!(
        "{} frames, {} bytes of trace; {} SDO transfers, {} PDOs, {} EMCY, {} heartbeats",
        frames.len(),
        s.trace.len(),
        s.sdo.len(),
        s.pdos.len(),
        s.emcy.len(),
        s.heartbeats.len()
    );
}
