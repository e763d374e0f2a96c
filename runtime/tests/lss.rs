//! LSS (CiA 305) master and slaves on a shared bus: every slave sees every
//! frame of the master, the master sees every answer. A fake clock advances
//! 1 ms per frame and jumps to the master's deadlines.

use std::time::Duration;

use eds2rust_runtime::lss::proto::{Request, Response};
use eds2rust_runtime::lss::{
    BitRate, BitTiming, DEFAULT_TIMEOUT, Identity, IdentityField, IdentityRange, KnownIdentity,
    LssError, LssEvent, LssMaster, LssSlave, LssSlaveEvent, LssState,
};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::{CanId, Frame, Instant, Service};
use proptest::prelude::*;

const K250: BitTiming = BitTiming::standard(BitRate::Kbit250);

fn node(n: u8) -> Option<NodeId> {
    NodeId::new(n)
}

struct Bus {
    now: Instant,
    master: LssMaster,
    slaves: Vec<LssSlave>,
    slave_events: Vec<Vec<LssSlaveEvent>>,
    /// Every frame that crossed the bus.
    log: Vec<Frame>,
}

impl Bus {
    fn new(slaves: Vec<LssSlave>) -> Bus {
        Bus {
            now: Instant::ZERO,
            master: LssMaster::new(),
            slave_events: vec![Vec::new(); slaves.len()],
            slaves,
            log: Vec::new(),
        }
    }

    fn pump(&mut self) {
        loop {
            let mut moved = false;
            while let Some(frame) = self.master.poll_transmit() {
                self.now += Duration::from_millis(1);
                for slave in &mut self.slaves {
                    slave.handle_frame(self.now, &frame);
                }
                self.log.push(frame);
                moved = true;
            }
            for i in 0..self.slaves.len() {
                while let Some(frame) = self.slaves[i].poll_transmit() {
                    self.now += Duration::from_millis(1);
                    self.master.handle_frame(self.now, &frame);
                    for slave in &mut self.slaves {
                        slave.handle_frame(self.now, &frame);
                    }
                    self.log.push(frame);
                    moved = true;
                }
            }
            for (slave, events) in self.slaves.iter_mut().zip(&mut self.slave_events) {
                events.extend(std::iter::from_fn(|| slave.poll_event()));
            }
            if !moved {
                return;
            }
        }
    }

    fn run(
        &mut self,
        start: impl FnOnce(&mut LssMaster, Instant) -> Result<(), LssError>,
    ) -> LssEvent {
        start(&mut self.master, self.now).unwrap();
        for _ in 0..1000 {
            self.pump();
            if let Some(event) = self.master.poll_event() {
                assert!(self.master.is_idle());
                return event;
            }
            let deadline = self
                .master
                .poll_timeout()
                .expect("a request waits on nothing");
            self.now = self.now.max(deadline);
            self.master.handle_timeout(self.now);
        }
        panic!("the request did not end");
    }

    /// The simulators' side of [`LssSlaveEvent::ResetCommunication`].
    fn reset_communication(&mut self) {
        for (slave, events) in self.slaves.iter_mut().zip(&mut self.slave_events) {
            if events.contains(&LssSlaveEvent::ResetCommunication) {
                slave.apply_pending();
            }
            events.clear();
        }
    }
}

/// Three drives of one product, differing in revision and serial, plus
/// their vendor's other product.
const A: Identity = Identity::new(0x0000_04D8, 0x0000_1001, 0x0001_0002, 0x0012_D687);
const B: Identity = Identity::new(0x0000_04D8, 0x0000_1001, 0x0001_0002, 0x0012_D680);
const C: Identity = Identity::new(0x0000_04D8, 0x0000_1001, 0x0001_0001, 0x0999_0000);
const D: Identity = Identity::new(0x0000_04D8, 0x0000_2000, 0x0000_0001, 0x0000_0001);

#[test]
fn fastscan_finds_the_only_slave() {
    let mut bus = Bus::new(vec![LssSlave::new(A, None, K250)]);
    assert_eq!(
        bus.run(|m, now| m.fastscan(now, KnownIdentity::NONE)),
        LssEvent::Found(A)
    );
    assert_eq!(bus.slaves[0].state(), LssState::Configuration);
    // The search is 133 requests.
    let requests = bus
        .log
        .iter()
        .filter(|f| f.id() == CanId::Standard(0x7E5))
        .count();
    assert_eq!(requests, 133);
}

#[test]
fn fastscan_without_slaves_is_not_found() {
    let mut bus = Bus::new(Vec::new());
    assert_eq!(
        bus.run(|m, now| m.fastscan(now, KnownIdentity::NONE)),
        LssEvent::NotFound
    );
    assert_eq!(bus.now, Instant::ZERO + DEFAULT_TIMEOUT);
    // Configured slaves do not take part either.
    let mut bus = Bus::new(vec![
        LssSlave::new(A, node(1), K250),
        LssSlave::new(B, node(2), K250),
    ]);
    assert_eq!(
        bus.run(|m, now| m.fastscan(now, KnownIdentity::NONE)),
        LssEvent::NotFound
    );
}

/// The usual commissioning loop: fastscan, assign the next node id, switch
/// everybody back to waiting, repeat until no non-configured slave is left.
#[test]
fn fastscan_assigns_every_slave_among_three() {
    let mut bus = Bus::new(vec![
        LssSlave::new(A, None, K250),
        LssSlave::new(B, None, K250),
        LssSlave::new(D, node(9), K250),
        LssSlave::new(C, None, K250),
    ]);
    assert_eq!(
        bus.run(LssMaster::identify_non_configured),
        LssEvent::SlavePresent
    );
    let mut found = Vec::new();
    for next_id in 10u8.. {
        match bus.run(|m, now| m.fastscan(now, KnownIdentity::NONE)) {
            LssEvent::Found(identity) => {
                // Exactly the found slave is in the configuration state.
                let states: Vec<_> = bus.slaves.iter().map(|s| s.state()).collect();
                let expected: Vec<_> = bus
                    .slaves
                    .iter()
                    .map(|s| {
                        if s.identity() == identity {
                            LssState::Configuration
                        } else {
                            LssState::Waiting
                        }
                    })
                    .collect();
                assert_eq!(states, expected);
                found.push(identity);
                let event = bus.run(|m, now| m.configure_node_id(now, node(next_id).unwrap()));
                assert_eq!(event, LssEvent::NodeIdConfigured);
                let event = bus.run(|m, now| m.switch_global(now, LssState::Waiting));
                assert_eq!(event, LssEvent::Sent);
                bus.reset_communication();
            }
            LssEvent::NotFound => break,
            other => panic!("unexpected {other:?}"),
        }
        assert!(next_id < 20, "fastscan keeps finding slaves");
    }
    // The scan prefers 0 bits, so it finds the lowest address first.
    assert_eq!(found, [C, B, A]);
    let ids: Vec<_> = bus.slaves.iter().map(|s| s.active_node_id()).collect();
    assert_eq!(ids, [node(12), node(11), node(9), node(10)]);
    assert_eq!(
        bus.run(LssMaster::identify_non_configured),
        LssEvent::NoResponse
    );
}

#[test]
fn fastscan_with_known_product_among_three() {
    let mut bus = Bus::new(vec![
        LssSlave::new(D, None, K250),
        LssSlave::new(A, None, K250),
        LssSlave::new(B, None, K250),
    ]);
    let known = KnownIdentity {
        vendor_id: Some(D.vendor_id),
        product_code: Some(D.product_code),
        ..KnownIdentity::NONE
    };
    assert_eq!(bus.run(|m, now| m.fastscan(now, known)), LssEvent::Found(D));
    // A vendor nobody has: the verification fails.
    bus.run(|m, now| m.switch_global(now, LssState::Waiting));
    let known = KnownIdentity {
        vendor_id: Some(0x1234),
        ..KnownIdentity::NONE
    };
    assert_eq!(bus.run(|m, now| m.fastscan(now, known)), LssEvent::NotFound);
}

#[test]
fn switch_selective_picks_one_of_three() {
    let mut bus = Bus::new(vec![
        LssSlave::new(A, node(127), K250),
        LssSlave::new(B, node(127), K250),
        LssSlave::new(C, node(127), K250),
    ]);
    assert_eq!(
        bus.run(|m, now| m.switch_selective(now, B)),
        LssEvent::Selected
    );
    let states: Vec<_> = bus.slaves.iter().map(|s| s.state()).collect();
    assert_eq!(
        states,
        [
            LssState::Waiting,
            LssState::Configuration,
            LssState::Waiting
        ]
    );
    assert_eq!(
        bus.run(|m, now| m.inquire_identity(now, IdentityField::Serial)),
        LssEvent::Identity {
            field: IdentityField::Serial,
            value: B.serial
        }
    );
    // The Interroll scenario: the selected drive leaves node 127 for 5.
    assert_eq!(
        bus.run(|m, now| m.configure_node_id(now, node(5).unwrap())),
        LssEvent::NodeIdConfigured
    );
    assert_eq!(bus.run(LssMaster::store_configuration), LssEvent::Stored);
    bus.run(|m, now| m.switch_global(now, LssState::Waiting));
    let pending: Vec<_> = bus.slaves.iter().map(|s| s.pending_node_id()).collect();
    assert_eq!(pending, [node(127), node(5), node(127)]);
    assert!(bus.slave_events[1].contains(&LssSlaveEvent::StoreRequested));
    assert!(!bus.slave_events[0].contains(&LssSlaveEvent::StoreRequested));
}

#[test]
fn identify_remote_counts_any_answer_once() {
    let mut bus = Bus::new(vec![
        LssSlave::new(A, node(1), K250),
        LssSlave::new(B, node(2), K250),
        LssSlave::new(C, node(3), K250),
    ]);
    let range = IdentityRange::product(A.vendor_id, A.product_code);
    assert_eq!(
        bus.run(|m, now| m.identify_remote(now, range)),
        LssEvent::SlavePresent
    );
    let answers = bus
        .log
        .iter()
        .filter(|f| f.id() == CanId::Standard(0x7E4))
        .count();
    assert_eq!(answers, 3);
    let range = IdentityRange {
        revision_low: 0x0001_0002,
        revision_high: 0x0001_0002,
        serial_low: 0x0012_D681,
        serial_high: 0x0012_FFFF,
        ..range
    };
    assert_eq!(
        bus.run(|m, now| m.identify_remote(now, range)),
        LssEvent::SlavePresent
    );
    let range = IdentityRange::product(D.vendor_id, D.product_code);
    assert_eq!(
        bus.run(|m, now| m.identify_remote(now, range)),
        LssEvent::NoResponse
    );
}

#[test]
fn every_service_times_out_without_slaves() {
    let mut bus = Bus::new(vec![LssSlave::new(A, node(4), K250)]);
    // The only slave is in the waiting state: configuration services go
    // unanswered.
    let timeout = Duration::from_millis(20);
    bus.master.set_timeout(timeout);
    type Start = fn(&mut LssMaster, Instant) -> Result<(), LssError>;
    let requests: [Start; 7] = [
        |m, now| m.switch_selective(now, B),
        |m, now| m.configure_node_id(now, NodeId::new(5).unwrap()),
        |m, now| m.configure_bit_timing(now, K250),
        LssMaster::store_configuration,
        |m, now| m.inquire_identity(now, IdentityField::VendorId),
        LssMaster::inquire_node_id,
        LssMaster::identify_non_configured,
    ];
    for start in requests {
        let before = bus.now;
        assert_eq!(bus.run(start), LssEvent::NoResponse);
        assert_eq!(bus.now, before + timeout);
    }
    assert_eq!(bus.slaves[0].pending_node_id(), node(4));
}

/// Arbitrary (time step, frame) inputs: 2 bytes id, 1 byte length and step.
fn frames() -> impl Strategy<Value = Vec<(u8, Frame)>> {
    let frame = (
        prop_oneof![Just(0x7E4u16), Just(0x7E5), any::<u16>()],
        prop_oneof![Just(8usize), 0usize..=8],
        prop_oneof![
            (0x40u8..0x60).prop_map(|cs| vec![cs]),
            (prop_oneof![Just(0x04u8), Just(0x11), Just(0x13), Just(0x15), Just(0x17)])
                .prop_map(|cs| vec![cs]),
            Just(Vec::new()),
        ],
        proptest::collection::vec(any::<u8>(), 8),
        0u8..60,
    )
        .prop_map(|(id, len, head, mut data, step)| {
            data.splice(0..head.len(), head);
            let frame = Frame::new(CanId::Standard(id & 0x7FF), &data[..len]).unwrap();
            (step, frame)
        });
    proptest::collection::vec(frame, 0..64)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    /// Decoders never panic, and whatever they accept encodes back to a
    /// frame they decode the same way.
    #[test]
    fn parse_never_panics(data in proptest::collection::vec(any::<u8>(), 0..12)) {
        if let Some(request) = Request::parse(&data) {
            prop_assert_eq!(data.len(), 8);
            prop_assert_eq!(Request::from_frame(&request.to_frame()), Some(request));
        }
        if let Some(response) = Response::parse(&data) {
            prop_assert_eq!(data.len(), 8);
            prop_assert_eq!(Response::from_frame(&response.to_frame()), Some(response));
        }
    }

    /// Random frames never make the slave panic, it answers at most one
    /// frame per request, and its node ids stay valid.
    #[test]
    fn slave_takes_any_frame(input in frames(), configured in any::<bool>()) {
        let mut slave = LssSlave::new(A, if configured { node(3) } else { None }, K250);
        let mut now = Instant::ZERO;
        for (step, frame) in input {
            now += Duration::from_millis(step.into());
            slave.handle_frame(now, &frame);
            let answers = std::iter::from_fn(|| slave.poll_transmit()).count();
            prop_assert!(answers <= 1);
            while slave.poll_event().is_some() {}
        }
        prop_assert_eq!(slave.poll_timeout(), None);
    }

    /// Whatever answers arrive, every request ends with exactly one event
    /// within 133 timeouts (fastscan's longest search), and the master is
    /// idle afterwards.
    #[test]
    fn master_always_ends(input in frames(), which in 0u8..6) {
        let mut master = LssMaster::with_timeout(Duration::from_millis(30));
        let now = Instant::ZERO;
        match which {
            0 => master.fastscan(now, KnownIdentity::NONE),
            1 => master.switch_selective(now, A),
            2 => master.identify_remote(now, IdentityRange::product(1, 2)),
            3 => master.inquire_identity(now, IdentityField::Revision),
            4 => master.store_configuration(now),
            _ => master.switch_global(now, LssState::Configuration),
        }
        .unwrap();
        let mut now = now;
        let mut input = input.into_iter().cycle();
        let mut events = Vec::new();
        let mut timeouts = 0;
        for i in 0..2000 {
            while master.poll_transmit().is_some() {}
            events.extend(std::iter::from_fn(|| master.poll_event()));
            if master.is_idle() {
                break;
            }
            match input.next() {
                Some((step, frame)) if step % 3 != 0 && i % 4 != 3 => {
                    now += Duration::from_millis(step.into());
                    master.handle_frame(now, &frame);
                }
                _ => {
                    let deadline = master.poll_timeout();
                    prop_assert!(deadline.is_some());
                    now = now.max(deadline.unwrap_or(now));
                    master.handle_timeout(now);
                    timeouts += 1;
                }
            }
        }
        prop_assert!(master.is_idle());
        prop_assert_eq!(events.len(), 1);
        prop_assert!(timeouts <= 133);
    }
}
