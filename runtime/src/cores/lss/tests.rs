//! A master and one slave over a direct loop (frames fed both ways, a fake
//! clock advancing 1 ms per hop).

use core::time::Duration;

use super::*;
use crate::{Instant, Service};

struct Loop {
    now: Instant,
    master: LssMaster,
    slave: LssSlave,
    slave_events: Vec<LssSlaveEvent>,
    frames: usize,
}

impl Loop {
    fn new(slave: LssSlave) -> Loop {
        Loop {
            now: Instant::ZERO,
            master: LssMaster::new(),
            slave,
            slave_events: Vec::new(),
            frames: 0,
        }
    }

    /// Carries frames both ways until both sides are quiet.
    fn pump(&mut self) {
        loop {
            let mut moved = false;
            while let Some(frame) = self.master.poll_transmit() {
                self.now += Duration::from_millis(1);
                self.slave.handle_frame(self.now, &frame);
                self.frames += 1;
                moved = true;
            }
            while let Some(frame) = self.slave.poll_transmit() {
                self.now += Duration::from_millis(1);
                self.master.handle_frame(self.now, &frame);
                self.frames += 1;
                moved = true;
            }
            self.slave_events
                .extend(core::iter::from_fn(|| self.slave.poll_event()));
            if !moved {
                return;
            }
        }
    }

    /// Runs the request started by `start` to its event.
    fn run(
        &mut self,
        start: impl FnOnce(&mut LssMaster, Instant) -> Result<(), LssError>,
    ) -> LssEvent {
        start(&mut self.master, self.now).unwrap();
        for _ in 0..1000 {
            self.pump();
            if let Some(event) = self.master.poll_event() {
                assert!(self.master.is_idle());
                assert_eq!(self.master.poll_event(), None);
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

    /// Gives the configured slave node id `id`.
    fn configure_node_id(&mut self, id: u8) {
        let configured = self.run(|m, now| m.configure_node_id(now, node(id).unwrap()));
        assert_eq!(configured, LssEvent::NodeIdConfigured);
    }

    /// Switches every slave back to waiting; returns what the slave reported
    /// since it was created.
    fn switch_to_waiting(&mut self) -> &[LssSlaveEvent] {
        let sent = self.run(|m, now| m.switch_global(now, LssState::Waiting));
        assert_eq!(sent, LssEvent::Sent);
        &self.slave_events
    }
}

/// What a slave reports when it is configured with node id `id`, then
/// `between` happens, then it is switched back to waiting.
fn configured(id: u8, between: LssSlaveEvent) -> [LssSlaveEvent; 4] {
    [
        LssSlaveEvent::StateChanged(LssState::Configuration),
        LssSlaveEvent::NodeIdChanged { pending: node(id) },
        between,
        LssSlaveEvent::StateChanged(LssState::Waiting),
    ]
}

const DRIVE: Identity = Identity::new(0x0000_04D8, 0x0000_1001, 0x0001_0002, 0x0012_D687);
const K500: BitTiming = BitTiming::standard(BitRate::Kbit500);

fn node(n: u8) -> Option<NodeId> {
    NodeId::new(n)
}

#[test]
fn switch_selective_then_inquire() {
    let mut bus = Loop::new(LssSlave::new(DRIVE, node(127), K500));
    let other = Identity {
        serial: DRIVE.serial + 1,
        ..DRIVE
    };
    assert_eq!(
        bus.run(|m, now| m.switch_selective(now, other)),
        LssEvent::NoResponse
    );
    assert_eq!(bus.slave.state(), LssState::Waiting);
    assert_eq!(
        bus.run(|m, now| m.switch_selective(now, DRIVE)),
        LssEvent::Selected
    );
    assert_eq!(bus.slave.state(), LssState::Configuration);
    for field in IdentityField::ALL {
        assert_eq!(
            bus.run(|m, now| m.inquire_identity(now, field)),
            LssEvent::Identity {
                field,
                value: DRIVE.get(field)
            }
        );
    }
    assert_eq!(bus.run(LssMaster::inquire_node_id), LssEvent::NodeId(127));
}

/// The Interroll scenario: a drive answers at node 127 until LSS assigns it
/// another id, which it stores and uses after reset communication.
#[test]
fn configure_node_127_to_5_and_store() {
    let mut bus = Loop::new(LssSlave::new(DRIVE, node(127), K500));
    assert_eq!(
        bus.run(|m, now| m.switch_global(now, LssState::Configuration)),
        LssEvent::Sent
    );
    bus.configure_node_id(5);
    assert_eq!(bus.run(LssMaster::store_configuration), LssEvent::Stored);
    assert_eq!(
        bus.switch_to_waiting(),
        configured(5, LssSlaveEvent::StoreRequested)
    );
    assert_eq!(
        (bus.slave.active_node_id(), bus.slave.pending_node_id()),
        (node(127), node(5))
    );
    // The simulator's NMT reset communication.
    bus.slave.apply_pending();
    assert_eq!(bus.slave.active_node_id(), node(5));
}

#[test]
fn store_not_supported_and_bad_bit_timing_fail() {
    let mut slave = LssSlave::new(DRIVE, node(127), K500);
    slave.set_store_supported(false);
    slave.set_bit_rate_supported(BitRate::Kbit1000, false);
    let mut bus = Loop::new(slave);
    bus.run(|m, now| m.switch_global(now, LssState::Configuration));
    assert_eq!(
        bus.run(LssMaster::store_configuration),
        LssEvent::ConfigureFailed {
            service: ConfigureService::Store,
            error: 1,
            spec: 0
        }
    );
    assert_eq!(
        bus.run(|m, now| m.configure_bit_timing(now, BitTiming::standard(BitRate::Kbit1000))),
        LssEvent::ConfigureFailed {
            service: ConfigureService::BitTiming,
            error: 1,
            spec: 0
        }
    );
    let k125 = BitTiming::standard(BitRate::Kbit125);
    assert_eq!(
        bus.run(|m, now| m.configure_bit_timing(now, k125)),
        LssEvent::BitTimingConfigured
    );
    assert_eq!(
        bus.run(|m, now| m.activate_bit_timing(now, 200)),
        LssEvent::Sent
    );
    assert_eq!(bus.slave.active_bit_timing(), k125);
    assert_eq!(
        bus.slave_events.last(),
        Some(&LssSlaveEvent::BitTimingActivate {
            table: 0,
            index: 4,
            delay_ms: 200
        })
    );
}

#[test]
fn identify_non_configured_and_remote() {
    let mut bus = Loop::new(LssSlave::new(DRIVE, None, K500));
    assert_eq!(
        bus.run(LssMaster::identify_non_configured),
        LssEvent::SlavePresent
    );
    let range = IdentityRange::product(DRIVE.vendor_id, DRIVE.product_code);
    assert_eq!(
        bus.run(|m, now| m.identify_remote(now, range)),
        LssEvent::SlavePresent
    );
    let range = IdentityRange {
        serial_high: DRIVE.serial - 1,
        ..range
    };
    assert_eq!(
        bus.run(|m, now| m.identify_remote(now, range)),
        LssEvent::NoResponse
    );

    let mut bus = Loop::new(LssSlave::new(DRIVE, node(3), K500));
    assert_eq!(
        bus.run(LssMaster::identify_non_configured),
        LssEvent::NoResponse
    );
}

#[test]
fn fastscan_then_configure() {
    let mut bus = Loop::new(LssSlave::new(DRIVE, None, K500));
    assert_eq!(
        bus.run(|m, now| m.fastscan(now, KnownIdentity::NONE)),
        LssEvent::Found(DRIVE)
    );
    assert_eq!(bus.slave.state(), LssState::Configuration);
    // 133 requests; one answer per matching step: the confirmation, the
    // four verifications, and each bit that is 0.
    let zeros: u32 = IdentityField::ALL
        .iter()
        .map(|&f| DRIVE.get(f).count_zeros())
        .sum();
    assert_eq!(bus.frames, 133 + 5 + zeros as usize);
    // 133 steps of one timeout each.
    assert_eq!(bus.now, Instant::ZERO + DEFAULT_TIMEOUT * 133);
    bus.configure_node_id(20);
    assert_eq!(
        bus.switch_to_waiting(),
        configured(20, LssSlaveEvent::ResetCommunication)
    );
    // Now configured (pending), it no longer takes part.
    assert_eq!(
        bus.run(|m, now| m.fastscan(now, KnownIdentity::NONE)),
        LssEvent::NotFound
    );
}

#[test]
fn fastscan_with_known_vendor_and_product() {
    let mut bus = Loop::new(LssSlave::new(DRIVE, None, K500));
    let known = KnownIdentity {
        vendor_id: Some(DRIVE.vendor_id),
        product_code: Some(DRIVE.product_code),
        ..KnownIdentity::NONE
    };
    assert_eq!(
        bus.run(|m, now| m.fastscan(now, known)),
        LssEvent::Found(DRIVE)
    );
    assert_eq!(bus.now, Instant::ZERO + DEFAULT_TIMEOUT * (1 + 2 + 66));
}
