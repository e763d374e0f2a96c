//! The python-canopen peer harness itself (`tests/python/peer.py` and
//! `eds2rust_tests::peer`): frames both ways, replies, and how failures
//! are reported.

use std::time::Duration;

use eds2rust_runtime::transport::Bus;
use eds2rust_runtime::{CanId, Frame};
use eds2rust_tests::peer::{Outcome, PyPeer};
use serde_json::json;

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

#[test]
fn frames_cross_the_bridge_both_ways() {
    let mut py = PyPeer::spawn().unwrap_or_else(|e| panic!("{e}"));
    let objects = json!([
        {"index": 0x2000, "type": "UNSIGNED32", "access": "ro", "value": "78563412"},
    ]);
    py.command_ok(json!({"op": "local_node", "node": 5, "objects": objects}))
        .unwrap_or_else(|e| panic!("{e}"));
    // A hand-written expedited upload request (CiA 301: ccs 2 = 0x40).
    py.send(&frame(0x605, &[0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0]))
        .unwrap();
    let answer = py.recv(Duration::from_secs(5)).unwrap();
    // scs 2, expedited, size indicated, n = 0: 0x43, then the value.
    assert_eq!(
        answer,
        Some(frame(
            0x585,
            &[0x43, 0x00, 0x20, 0x00, 0x78, 0x56, 0x34, 0x12]
        )),
        "{}",
        py.failure("no upload response")
    );
    // A remote frame goes out as one too (python-canopen ignores it).
    py.send(&Frame::remote(CanId::Standard(0x705), 1).unwrap())
        .unwrap();

    // Frames python sends, in order, on every port opened before.
    let mut port = py.port();
    py.command_ok(json!({"op": "send", "frame": "123#R2"}))
        .unwrap();
    py.command_ok(json!({"op": "send", "frame": "080#"}))
        .unwrap();
    let frames = py.settle(&mut port).unwrap();
    assert_eq!(
        frames,
        vec![
            Frame::remote(CanId::Standard(0x123), 2).unwrap(),
            frame(0x080, &[])
        ]
    );
    assert_eq!(
        py.recv(Duration::from_secs(5)).unwrap(),
        Some(Frame::remote(CanId::Standard(0x123), 2).unwrap())
    );
}

#[test]
fn replies_report_aborts_and_errors() {
    let py = PyPeer::spawn().unwrap_or_else(|e| panic!("{e}"));
    py.command_ok(json!({"op": "local_node", "node": 6}))
        .unwrap();
    // A LocalNode read of a missing object: python's SdoAbortedError.
    let reply = py
        .command(json!({"op": "get", "node": 6, "index": 0x5000}))
        .unwrap();
    assert_eq!(Outcome::of(reply), Outcome::Abort(0x0602_0000));
    // Any other exception: its text, with the traceback on stderr.
    let reply = py.command(json!({"op": "no_such_op"})).unwrap();
    assert_eq!(
        Outcome::of(reply),
        Outcome::Error("ValueError: unknown op 'no_such_op'".into())
    );
    assert!(
        py.stderr_contains("Traceback", Duration::from_secs(5)),
        "{}",
        py.stderr()
    );
    // command_ok turns both into errors that carry the reply.
    let error = py
        .command_ok(json!({"op": "get", "node": 6, "index": 0x5000}))
        .unwrap_err();
    assert!(error.contains("100794368"), "{error}");
    // An SDO client timeout is an error too.
    let reply = py
        .command(json!({"op": "upload", "node": 9, "index": 0x1000, "timeout": 0.05}))
        .unwrap();
    assert_eq!(
        Outcome::of(reply),
        Outcome::Error("SdoCommunicationError: No SDO response received".into())
    );
}

#[test]
fn a_dead_peer_is_an_error_with_its_stderr() {
    let mut py = PyPeer::spawn().unwrap_or_else(|e| panic!("{e}"));
    let error = py
        .command(json!({"op": "exit", "code": 3, "message": "peer going away"}))
        .unwrap_err();
    assert!(
        error.contains("exited") && error.contains("peer going away"),
        "{error}"
    );
    let error = py.command(json!({"op": "ping"})).unwrap_err();
    assert!(error.contains("peer going away"), "{error}");
    let error = py.recv(Duration::from_secs(5)).unwrap_err();
    assert!(error.to_string().contains("peer going away"), "{error}");
}
