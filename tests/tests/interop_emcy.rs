//! EMCY interoperability with python-canopen 2.4.1, over the `peer.py`
//! bridge: python LocalNodes send emergency messages that our consumer
//! decodes (also through a generated error table), and python's consumer
//! decodes ours.

use std::sync::OnceLock;

use eds2rust_drivers::linak_techline::errors::Emcy as LinakEmcy;
use eds2rust_runtime::emcy::{Emcy, EmcyConsumer, EmcyEvent, emcy_frame};
use eds2rust_runtime::od::{ErrorTable, NodeId};
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{Frame, Service};
use eds2rust_tests::peer::{self, PeerPort, PyPeer, hex};
use serde_json::json;

static PEER: OnceLock<PyPeer> = OnceLock::new();

fn py() -> &'static PyPeer {
    peer::shared(&PEER)
}

fn node(id: u8) -> NodeId {
    NodeId::new(id).expect("a valid node id")
}

/// Has python LocalNode `id` send an EMCY; returns what our consumer made
/// of every frame python sent meanwhile, and those frames.
fn python_emcy(
    port: &mut PeerPort,
    consumer: &mut EmcyConsumer,
    id: u8,
    code: u16,
    register: u8,
    data: &[u8],
) -> (Vec<EmcyEvent>, Vec<Frame>) {
    py().command_ok(
        json!({"op": "emcy", "node": id, "code": code, "register": register,
                            "data": hex(data)}),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let frames = py().settle(port).unwrap_or_else(|e| panic!("{e}"));
    let now = Clock::new().now();
    for frame in &frames {
        consumer.handle_frame(now, frame);
    }
    (
        std::iter::from_fn(|| consumer.poll_event()).collect(),
        frames,
    )
}

/// Python LocalNode `id` and our consumer of its EMCYs, on a port of
/// python's bus.
fn local_node(id: u8) -> (PeerPort, EmcyConsumer) {
    py().command_ok(json!({"op": "local_node", "node": id}))
        .unwrap_or_else(|e| panic!("{e}"));
    (py().port(), EmcyConsumer::only(&[node(id)]))
}

#[test]
fn python_emcy_decodes_in_our_consumer() {
    const ID: u8 = 0x40;
    let (mut port, mut consumer) = local_node(ID);
    let n = node(ID);

    // Code, register and all 5 manufacturer bytes.
    let (events, frames) =
        python_emcy(&mut port, &mut consumer, ID, 0x3211, 0x05, &[1, 2, 3, 4, 5]);
    assert_eq!(frames.len(), 1, "{frames:?}");
    assert_eq!(frames[0].standard_id(), Some(0x080 + u16::from(ID)));
    // CiA 301 layout: code little endian, register, manufacturer bytes.
    assert_eq!(frames[0].data(), &[0x11, 0x32, 0x05, 1, 2, 3, 4, 5]);
    let expected = Emcy {
        code: 0x3211,
        register: 0x05,
        manufacturer: [1, 2, 3, 4, 5],
    };
    assert_eq!(
        events,
        vec![EmcyEvent::Emergency {
            node: n,
            emcy: expected
        }]
    );
    let register = expected.error_register();
    assert!(register.generic() && register.voltage() && !register.current());

    // Fewer manufacturer bytes: python pads them with zeros.
    let (events, _) = python_emcy(&mut port, &mut consumer, ID, 0xFF02, 0x81, &[0xAB]);
    let emcy = Emcy {
        code: 0xFF02,
        register: 0x81,
        manufacturer: [0xAB, 0, 0, 0, 0],
    };
    assert_eq!(events, vec![EmcyEvent::Emergency { node: n, emcy }]);
    assert!(emcy.error_register().manufacturer());

    // Error reset.
    let (events, _) = python_emcy(&mut port, &mut consumer, ID, 0x0000, 0x00, &[]);
    let [EmcyEvent::Emergency { emcy, .. }] = events[..] else {
        panic!("one emergency expected: {events:?}");
    };
    assert!(emcy.is_reset());
    assert_eq!(emcy.to_bytes(), [0; 8]);
}

#[test]
fn python_emcy_named_by_generated_error_table() {
    const ID: u8 = 0x41;
    let (mut port, mut consumer) = local_node(ID);
    for (code, name, known) in [
        (0x3211, "overvoltage", true),
        (0x5080, "smps", true),
        (0xFF02, "heartbeat", true),
        (0x1234, "", false),
    ] {
        let (events, _) = python_emcy(&mut port, &mut consumer, ID, code, 0x01, &[9, 8, 7, 6, 5]);
        let [EmcyEvent::Emergency { emcy, .. }] = events[..] else {
            panic!("one emergency expected for {code:#06X}: {events:?}");
        };
        assert_eq!(emcy.code, code);
        let kind: LinakEmcy = emcy.describe().expect("a 16-bit code fits the table");
        assert_eq!(ErrorTable::code(kind), u64::from(code));
        assert_eq!(ErrorTable::is_known(kind), known, "{code:#06X}");
        if known {
            assert_eq!(ErrorTable::name(kind), name, "{code:#06X}");
        }
    }
}

#[test]
fn our_emcy_decodes_in_python_consumer() {
    const ID: u8 = 0x42;
    let mut port = py().port();
    // python's RemoteNode (and its EMCY consumer) first.
    let log = || {
        py().barrier().unwrap_or_else(|e| panic!("{e}"));
        py().command_ok(json!({"op": "emcy_log", "node": ID}))
            .unwrap_or_else(|e| panic!("{e}"))["log"]
            .clone()
    };
    assert_eq!(log(), json!([]));
    for emcy in [
        Emcy {
            code: 0x8130,
            register: 0x11,
            manufacturer: [0xDE, 0xAD, 0xBE, 0xEF, 0x01],
        },
        Emcy {
            code: 0x0000,
            register: 0x00,
            manufacturer: [0; 5],
        },
    ] {
        port.send(&emcy_frame(node(ID), &emcy)).unwrap();
    }
    assert_eq!(
        log(),
        json!([
            {"code": 0x8130, "register": 0x11, "data": "DEADBEEF01"},
            {"code": 0, "register": 0, "data": "0000000000"},
        ])
    );
}
