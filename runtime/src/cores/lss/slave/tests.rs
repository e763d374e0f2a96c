//! The slave against request frames written by hand (CiA 305 layouts: byte
//! 0 command specifier, 32-bit values LSB first in bytes 1..=4), checking
//! its answers byte for byte, its state and its events.

use super::*;
use crate::CanId;

const ID: Identity = Identity::new(0x0000_017A, 0x0000_2001, 0x0003_0001, 0x0000_1234);
const K250: BitTiming = BitTiming { table: 0, index: 3 };

fn node(n: u8) -> Option<NodeId> {
    NodeId::new(n)
}

fn slave(node_id: Option<NodeId>) -> LssSlave {
    LssSlave::new(ID, node_id, K250)
}

/// Feeds one request (8 bytes on 0x7E5) and returns the answers' data.
fn send(slave: &mut LssSlave, data: [u8; 8]) -> Vec<[u8; 8]> {
    slave.handle_frame(Instant::ZERO, &Frame::standard(0x7E5, data, 8));
    core::iter::from_fn(|| slave.poll_transmit())
        .map(|frame| {
            assert_eq!(frame.id(), CanId::Standard(0x7E4));
            *frame.data_padded()
        })
        .collect()
}

fn events(slave: &mut LssSlave) -> Vec<LssSlaveEvent> {
    core::iter::from_fn(|| slave.poll_event()).collect()
}

const GLOBAL_CONFIG: [u8; 8] = [0x04, 1, 0, 0, 0, 0, 0, 0];
const GLOBAL_WAITING: [u8; 8] = [0x04, 0, 0, 0, 0, 0, 0, 0];
const SEL_VENDOR: [u8; 8] = [0x40, 0x7A, 0x01, 0, 0, 0, 0, 0];
const SEL_PRODUCT: [u8; 8] = [0x41, 0x01, 0x20, 0, 0, 0, 0, 0];
const SEL_REVISION: [u8; 8] = [0x42, 0x01, 0x00, 0x03, 0x00, 0, 0, 0];
const SEL_SERIAL: [u8; 8] = [0x43, 0x34, 0x12, 0, 0, 0, 0, 0];
const SELECTED: [u8; 8] = [0x44, 0, 0, 0, 0, 0, 0, 0];
const IDENTIFIED: [u8; 8] = [0x4F, 0, 0, 0, 0, 0, 0, 0];

#[test]
fn switch_selective_needs_all_four_in_order() {
    let mut s = slave(node(127));
    assert!(send(&mut s, SEL_VENDOR).is_empty());
    assert!(send(&mut s, SEL_PRODUCT).is_empty());
    assert!(send(&mut s, SEL_REVISION).is_empty());
    assert_eq!(send(&mut s, SEL_SERIAL), [SELECTED]);
    assert_eq!(s.state(), LssState::Configuration);
    assert_eq!(
        events(&mut s),
        [LssSlaveEvent::StateChanged(LssState::Configuration)]
    );

    // Out of order, a wrong part, or a part missing: no selection.
    for frames in [
        vec![SEL_PRODUCT, SEL_VENDOR, SEL_REVISION, SEL_SERIAL],
        vec![SEL_VENDOR, SEL_PRODUCT, SEL_SERIAL],
        vec![
            SEL_VENDOR,
            SEL_PRODUCT,
            [0x42, 0x02, 0, 0x03, 0, 0, 0, 0],
            SEL_SERIAL,
        ],
        vec![
            SEL_VENDOR,
            SEL_PRODUCT,
            SEL_REVISION,
            SEL_REVISION,
            SEL_SERIAL,
        ],
    ] {
        let mut s = slave(node(127));
        for frame in frames {
            assert!(send(&mut s, frame).is_empty());
        }
        assert_eq!(s.state(), LssState::Waiting);
    }

    // A restarted sequence (vendor again) counts from the start.
    let mut s = slave(node(127));
    for frame in [
        SEL_VENDOR,
        SEL_PRODUCT,
        SEL_VENDOR,
        SEL_PRODUCT,
        SEL_REVISION,
    ] {
        assert!(send(&mut s, frame).is_empty());
    }
    assert_eq!(send(&mut s, SEL_SERIAL), [SELECTED]);
}

#[test]
fn configuration_services_need_the_configuration_state() {
    let mut s = slave(node(127));
    for request in [
        [0x11, 5, 0, 0, 0, 0, 0, 0],
        [0x13, 0, 2, 0, 0, 0, 0, 0],
        [0x15, 0x10, 0, 0, 0, 0, 0, 0],
        [0x17, 0, 0, 0, 0, 0, 0, 0],
        [0x5A, 0, 0, 0, 0, 0, 0, 0],
        [0x5E, 0, 0, 0, 0, 0, 0, 0],
    ] {
        assert!(send(&mut s, request).is_empty(), "{request:02X?}");
    }
    assert_eq!(s.pending_node_id(), node(127));
    assert!(events(&mut s).is_empty());
}

#[test]
fn configure_node_id_is_pending_until_applied() {
    let mut s = slave(node(127));
    assert!(send(&mut s, GLOBAL_CONFIG).is_empty());
    events(&mut s);
    // Response 0x11, byte 1 error 0, byte 2 spec 0.
    assert_eq!(
        send(&mut s, [0x11, 5, 0, 0, 0, 0, 0, 0]),
        [[0x11, 0, 0, 0, 0, 0, 0, 0]]
    );
    assert_eq!(
        (s.pending_node_id(), s.active_node_id()),
        (node(5), node(127))
    );
    assert_eq!(
        events(&mut s),
        [LssSlaveEvent::NodeIdChanged { pending: node(5) }]
    );
    // The same id again: success, no event.
    assert_eq!(
        send(&mut s, [0x11, 5, 0, 0, 0, 0, 0, 0]),
        [[0x11, 0, 0, 0, 0, 0, 0, 0]]
    );
    assert!(events(&mut s).is_empty());
    // Inquire node id answers the active one.
    assert_eq!(
        send(&mut s, [0x5E, 0, 0, 0, 0, 0, 0, 0]),
        [[0x5E, 127, 0, 0, 0, 0, 0, 0]]
    );
    s.apply_pending();
    assert_eq!(s.active_node_id(), node(5));
    assert_eq!(
        send(&mut s, [0x5E, 0, 0, 0, 0, 0, 0, 0]),
        [[0x5E, 5, 0, 0, 0, 0, 0, 0]]
    );
    // 0 and 128 are out of range: error 1, nothing changes.
    for bad in [0, 128, 200] {
        assert_eq!(
            send(&mut s, [0x11, bad, 0, 0, 0, 0, 0, 0]),
            [[0x11, 1, 0, 0, 0, 0, 0, 0]]
        );
    }
    assert_eq!(s.pending_node_id(), node(5));
    // 0xFF unconfigures.
    assert_eq!(
        send(&mut s, [0x11, 0xFF, 0, 0, 0, 0, 0, 0]),
        [[0x11, 0, 0, 0, 0, 0, 0, 0]]
    );
    assert_eq!(s.pending_node_id(), None);
    assert_eq!(
        events(&mut s),
        [LssSlaveEvent::NodeIdChanged { pending: None }]
    );
}

#[test]
fn switching_to_waiting_with_a_first_node_id_resets_communication() {
    // A node that already had an id only changes state.
    for (id, resets) in [(None, true), (node(3), false)] {
        let mut s = slave(id);
        send(&mut s, GLOBAL_CONFIG);
        send(&mut s, [0x11, 9, 0, 0, 0, 0, 0, 0]);
        events(&mut s);
        send(&mut s, GLOBAL_WAITING);
        let mut expected = Vec::new();
        if resets {
            expected.push(LssSlaveEvent::ResetCommunication);
        }
        expected.push(LssSlaveEvent::StateChanged(LssState::Waiting));
        assert_eq!(events(&mut s), expected);
        // Mode 2 is reserved: ignored.
        send(&mut s, [0x04, 2, 0, 0, 0, 0, 0, 0]);
        assert_eq!(s.state(), LssState::Waiting);
    }
}

#[test]
fn bit_timing_configure_and_activate() {
    let mut s = slave(node(1));
    s.set_bit_rate_supported(BitRate::Kbit10, false);
    send(&mut s, GLOBAL_CONFIG);
    events(&mut s);
    // Table 0 index 2 (500 kbit/s): response 0x13, error 0.
    assert_eq!(
        send(&mut s, [0x13, 0, 2, 0, 0, 0, 0, 0]),
        [[0x13, 0, 0, 0, 0, 0, 0, 0]]
    );
    let k500 = BitTiming { table: 0, index: 2 };
    assert_eq!(
        (s.pending_bit_timing(), s.active_bit_timing()),
        (k500, K250)
    );
    assert_eq!(events(&mut s), [LssSlaveEvent::BitTimingConfigured(k500)]);
    // Reserved index 5, disabled index 8, table 1: error 1.
    for (table, index) in [(0, 5), (0, 8), (0, 10), (1, 0)] {
        assert_eq!(
            send(&mut s, [0x13, table, index, 0, 0, 0, 0, 0]),
            [[0x13, 1, 0, 0, 0, 0, 0, 0]]
        );
    }
    assert_eq!(s.pending_bit_timing(), k500);
    // Activate: delay 0x01F4 = 500 ms, no answer.
    assert!(send(&mut s, [0x15, 0xF4, 0x01, 0, 0, 0, 0, 0]).is_empty());
    assert_eq!(s.active_bit_timing(), k500);
    assert_eq!(
        events(&mut s),
        [LssSlaveEvent::BitTimingActivate {
            table: 0,
            index: 2,
            delay_ms: 500
        }]
    );
}

#[test]
fn store_configuration() {
    let mut s = slave(node(1));
    send(&mut s, GLOBAL_CONFIG);
    events(&mut s);
    assert_eq!(
        send(&mut s, [0x17, 0, 0, 0, 0, 0, 0, 0]),
        [[0x17, 0, 0, 0, 0, 0, 0, 0]]
    );
    assert_eq!(events(&mut s), [LssSlaveEvent::StoreRequested]);
    s.set_store_supported(false);
    assert_eq!(
        send(&mut s, [0x17, 0, 0, 0, 0, 0, 0, 0]),
        [[0x17, 1, 0, 0, 0, 0, 0, 0]]
    );
    assert!(events(&mut s).is_empty());
}

#[test]
fn inquire_identity_answers_each_part() {
    let mut s = slave(node(1));
    send(&mut s, GLOBAL_CONFIG);
    for (cs, answer) in [
        (0x5A, [0x7A, 0x01, 0, 0]),
        (0x5B, [0x01, 0x20, 0, 0]),
        (0x5C, [0x01, 0, 0x03, 0]),
        (0x5D, [0x34, 0x12, 0, 0]),
    ] {
        let [a, b, c, d] = answer;
        assert_eq!(
            send(&mut s, [cs, 0, 0, 0, 0, 0, 0, 0]),
            [[cs, a, b, c, d, 0, 0, 0]]
        );
    }
}

/// The six identify remote slave frames (0x46..=0x4B) for a range.
fn identify(vendor: u32, product: u32, rev: (u32, u32), serial: (u32, u32)) -> Vec<[u8; 8]> {
    [vendor, product, rev.0, rev.1, serial.0, serial.1]
        .iter()
        .zip(0x46u8..)
        .map(|(value, cs)| {
            let [a, b, c, d] = value.to_le_bytes();
            [cs, a, b, c, d, 0, 0, 0]
        })
        .collect()
}

#[test]
fn identify_remote_answers_within_range() {
    let within = [
        identify(0x17A, 0x2001, (0, u32::MAX), (0, u32::MAX)),
        identify(0x17A, 0x2001, (0x0003_0001, 0x0003_0001), (0x1234, 0x1234)),
        identify(0x17A, 0x2001, (0x0003_0000, 0x0004_0000), (0x1000, 0x2000)),
    ];
    let outside = [
        identify(0x17B, 0x2001, (0, u32::MAX), (0, u32::MAX)),
        identify(0x17A, 0x2002, (0, u32::MAX), (0, u32::MAX)),
        identify(0x17A, 0x2001, (0x0003_0002, u32::MAX), (0, u32::MAX)),
        identify(0x17A, 0x2001, (0, u32::MAX), (0, 0x1233)),
        identify(0x17A, 0x2001, (0, u32::MAX), (0x1235, 0x1000)),
    ];
    for state in [GLOBAL_WAITING, GLOBAL_CONFIG] {
        let mut s = slave(node(4));
        send(&mut s, state);
        for frames in &within {
            let answers: Vec<_> = frames.iter().flat_map(|f| send(&mut s, *f)).collect();
            assert_eq!(answers, [IDENTIFIED]);
        }
        for frames in &outside {
            let answers: Vec<_> = frames.iter().flat_map(|f| send(&mut s, *f)).collect();
            assert!(answers.is_empty(), "{frames:02X?}");
        }
        // Incomplete or out of order: no answer.
        let frames = &within[0];
        for f in frames.iter().skip(1) {
            assert!(send(&mut s, *f).is_empty());
        }
    }
}

#[test]
fn identify_non_configured_needs_no_node_id() {
    let request = [0x4C, 0, 0, 0, 0, 0, 0, 0];
    let answer = [0x50, 0, 0, 0, 0, 0, 0, 0];
    assert_eq!(send(&mut slave(None), request), [answer]);
    assert!(send(&mut slave(node(127)), request).is_empty());
    // A pending node id counts as configured.
    let mut s = slave(None);
    send(&mut s, GLOBAL_CONFIG);
    send(&mut s, [0x11, 5, 0, 0, 0, 0, 0, 0]);
    assert!(send(&mut s, request).is_empty());
}

/// A fastscan request: id (bytes 1..=4), bit check, LSS sub, LSS next.
fn scan(id: u32, bit_check: u8, sub: u8, next: u8) -> [u8; 8] {
    let [a, b, c, d] = id.to_le_bytes();
    [0x51, a, b, c, d, bit_check, sub, next]
}

#[test]
fn fastscan_answers_per_bit_check() {
    let mut s = slave(None);
    // Confirm (bit check 0x80): answered, scan position reset.
    assert_eq!(send(&mut s, scan(0, 0x80, 0, 0)), [IDENTIFIED]);
    // Vendor 0x17A: bit 31 0 matches; bits 31..=8 = 0x00000100 match; 0x00000200 does not.
    assert_eq!(send(&mut s, scan(0, 31, 0, 0)), [IDENTIFIED]);
    assert_eq!(send(&mut s, scan(0x100, 8, 0, 0)), [IDENTIFIED]);
    assert!(send(&mut s, scan(0x200, 8, 0, 0)).is_empty());
    assert!(send(&mut s, scan(0x17B, 0, 0, 1)).is_empty());
    // Another sub than the current position: ignored.
    assert!(send(&mut s, scan(0, 31, 1, 1)).is_empty());
    // The full vendor id with next = 1 moves the position to the product.
    assert_eq!(send(&mut s, scan(0x17A, 0, 0, 1)), [IDENTIFIED]);
    assert!(send(&mut s, scan(0x17A, 0, 0, 1)).is_empty());
    assert_eq!(send(&mut s, scan(0x2001, 0, 1, 2)), [IDENTIFIED]);
    assert_eq!(send(&mut s, scan(0x0003_0001, 0, 2, 3)), [IDENTIFIED]);
    assert_eq!(s.state(), LssState::Waiting);
    // The serial with next 0 < sub 3: configuration state.
    assert_eq!(send(&mut s, scan(0x1234, 0, 3, 0)), [IDENTIFIED]);
    assert_eq!(s.state(), LssState::Configuration);
    assert_eq!(
        events(&mut s),
        [LssSlaveEvent::StateChanged(LssState::Configuration)]
    );
    // In the configuration state fastscan is ignored.
    assert!(send(&mut s, scan(0, 0x80, 0, 0)).is_empty());
}

#[test]
fn fastscan_ignores_configured_slaves_and_bad_fields() {
    assert!(send(&mut slave(node(5)), scan(0, 0x80, 0, 0)).is_empty());
    let mut s = slave(None);
    for bad in [
        scan(0, 32, 0, 0),
        scan(0, 0x81, 0, 0),
        scan(0, 1, 4, 0),
        scan(0, 1, 0, 4),
    ] {
        assert!(send(&mut s, bad).is_empty());
    }
}

#[test]
fn other_frames_are_ignored() {
    let mut s = slave(None);
    let mut ignored = |frame: Frame| {
        s.handle_frame(Instant::ZERO, &frame);
        assert_eq!(s.poll_transmit(), None);
    };
    let request = [0x4C, 0, 0, 0, 0, 0, 0, 0];
    ignored(Frame::new(CanId::Standard(0x7E5), &request[..7]).unwrap());
    ignored(Frame::new(CanId::Standard(0x7E4), &request).unwrap());
    ignored(Frame::new(CanId::Extended(0x7E5), &request).unwrap());
    ignored(Frame::remote(CanId::Standard(0x7E5), 8).unwrap());
    assert_eq!(s.poll_timeout(), None);
}
