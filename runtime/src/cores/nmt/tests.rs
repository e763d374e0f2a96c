use super::*;
use crate::CanId;
use crate::cores::testing::{data, events, node};
use crate::{Instant, Service};

#[test]
fn command_frames_match_cia301_layout() {
    // Start node 32: 000#0120.
    assert_eq!(
        command_frame(NmtCommand::Start, NmtTarget::Node(node(32))),
        data(0x000, &[0x01, 0x20])
    );
    // Reset communication of all nodes: 000#8200.
    assert_eq!(
        command_frame(NmtCommand::ResetCommunication, NmtTarget::All),
        data(0x000, &[0x82, 0x00])
    );
    assert_eq!(
        command_frame(NmtCommand::EnterPreOperational, NmtTarget::Node(node(127))),
        data(0x000, &[0x80, 0x7F])
    );
}

#[test]
fn parse_command_accepts_only_valid_frames() {
    assert_eq!(
        parse_command(&data(0x000, &[0x02, 0x05])),
        Some((NmtCommand::Stop, NmtTarget::Node(node(5))))
    );
    assert_eq!(
        parse_command(&data(0x000, &[0x81, 0x00])),
        Some((NmtCommand::ResetNode, NmtTarget::All))
    );
    assert_eq!(parse_command(&data(0x000, &[0x03, 0x05])), None);
    assert_eq!(parse_command(&data(0x000, &[0x01, 0x80])), None);
    assert_eq!(parse_command(&data(0x000, &[0x01])), None);
    assert_eq!(parse_command(&data(0x000, &[0x01, 0x05, 0x00])), None);
    assert_eq!(parse_command(&data(0x001, &[0x01, 0x05])), None);
    assert_eq!(
        parse_command(&Frame::remote(CanId::Standard(0), 2).unwrap()),
        None
    );
    assert_eq!(
        parse_command(&Frame::new(CanId::Extended(0), &[1, 5]).unwrap()),
        None
    );
}

#[test]
fn only_all_addresses_node_zero() {
    for b in 0..=255u8 {
        let built = [
            NmtTarget::try_from(b).ok(),
            NodeId::new(b).map(NmtTarget::from),
            NodeId::new(b).map(NmtTarget::Node),
        ];
        for target in built.into_iter().flatten() {
            let frame = command_frame(NmtCommand::ResetNode, target);
            assert_eq!(frame.data(), [0x81, b]);
            assert_ne!(target.to_byte(), 0);
        }
        assert_eq!(NmtTarget::try_from(b).is_ok(), (1..=127).contains(&b));
        let parsed = NmtTarget::from_byte(b);
        assert_eq!(parsed.map(NmtTarget::to_byte), parsed.map(|_| b));
    }
    assert_eq!(NmtTarget::try_from(0), Err(InvalidNodeId(0)));
    assert_eq!(
        command_frame(NmtCommand::ResetNode, NmtTarget::All).data(),
        [0x81, 0]
    );
}

#[test]
fn byte_conversions() {
    for b in 0..=255u8 {
        if let Some(c) = NmtCommand::from_byte(b) {
            assert_eq!(c.to_byte(), b);
        }
        if let Some(s) = NmtState::from_byte(b) {
            assert_eq!(s.to_byte(), b);
        }
    }
    assert_eq!(NmtState::from_byte(0x7F), Some(NmtState::PreOperational));
    assert_eq!(NmtState::from_byte(0x01), None);
}

#[test]
fn master_queues_commands_without_claiming_state() {
    let mut m = NmtMaster::new();
    m.send(NmtCommand::Start, NmtTarget::Node(node(32)))
        .unwrap();
    assert_eq!(m.poll_transmit(), Some(data(0x000, &[0x01, 0x20])));
    assert_eq!(m.poll_transmit(), None);
    assert_eq!(m.state(node(32)), None);
    assert_eq!(m.expected(node(32)), Some(NmtState::Operational));
    m.send(NmtCommand::Stop, NmtTarget::All).unwrap();
    assert_eq!(m.expected(node(1)), Some(NmtState::Stopped));
    assert_eq!(m.expected(node(127)), Some(NmtState::Stopped));
    assert!(events(&mut m).is_empty());
}

#[test]
fn master_outbox_is_bounded() {
    let mut m = NmtMaster::new();
    for _ in 0..MASTER_OUTBOX {
        m.send(NmtCommand::Start, NmtTarget::All).unwrap();
    }
    assert_eq!(m.send(NmtCommand::Stop, NmtTarget::All), Err(QueueFull));
    assert_eq!(core::iter::from_fn(|| m.poll_transmit()).count(), 16);
}

/// What the master reports of node `n`'s boot-up message when it last
/// reported `from`: the boot-up, then the change to Pre-operational.
fn booted_up(n: u8, from: Option<NmtState>) -> Vec<NmtEvent> {
    let to = NmtState::PreOperational;
    vec![
        NmtEvent::BootUp(node(n)),
        NmtEvent::StateChanged {
            node: node(n),
            from,
            to,
        },
    ]
}

#[test]
fn master_tracks_boot_up_and_heartbeats() {
    let mut m = NmtMaster::new();
    let t = Instant::ZERO;
    m.handle_frame(t, &data(0x720, &[0x00]));
    assert_eq!(events(&mut m), booted_up(32, None));
    // Pre-operational after the boot-up message, as CiA 301 has it:
    // its first heartbeat changes nothing.
    assert_eq!(m.state(node(32)), Some(NmtState::PreOperational));
    m.handle_frame(t, &data(0x720, &[0x7F]));
    assert!(events(&mut m).is_empty());
    // A boot-up from a node seen pre-operational is still reported.
    m.handle_frame(t, &data(0x720, &[0x00]));
    assert_eq!(events(&mut m), [NmtEvent::BootUp(node(32))]);
    // A guarding reply with the toggle bit set: 0x85 = operational.
    m.handle_frame(t, &data(0x720, &[0x85]));
    assert_eq!(m.state(node(32)), Some(NmtState::Operational));
    assert_eq!(events(&mut m).len(), 1);
    // Unknown state, wrong length, remote frames, other ids: ignored.
    m.handle_frame(t, &data(0x720, &[0x03]));
    m.handle_frame(t, &data(0x720, &[0x05, 0x00]));
    m.handle_frame(t, &Frame::remote(CanId::Standard(0x720), 1).unwrap());
    m.handle_frame(t, &data(0x700, &[0x00]));
    m.handle_frame(t, &data(0x620, &[0x00]));
    assert!(events(&mut m).is_empty());
    assert_eq!(m.state(node(32)), Some(NmtState::Operational));
    // A second boot-up is reported even after another boot-up.
    m.handle_frame(t, &data(0x720, &[0x00]));
    m.handle_frame(t, &data(0x720, &[0x00]));
    let mut twice = booted_up(32, Some(NmtState::Operational));
    twice.push(NmtEvent::BootUp(node(32)));
    assert_eq!(events(&mut m), twice);
}

#[test]
fn master_event_queue_drops_oldest() {
    let mut m = NmtMaster::new();
    for n in 1..=40u8 {
        m.handle_frame(Instant::ZERO, &data(0x700 + u16::from(n), &[0x05]));
    }
    let got = events(&mut m);
    assert_eq!(got.len(), MASTER_EVENTS);
    assert_eq!(m.dropped_events(), 8);
    assert_eq!(
        got[0],
        NmtEvent::StateChanged {
            node: node(9),
            from: None,
            to: NmtState::Operational
        }
    );
}
