//! The blocking master on a manual clock: timers fire exactly when due and
//! timeouts of any length take no real time; frames a peer has already sent
//! are taken at the clock's time then, and a peer behind the bus itself
//! answers after a delay in the clock's time.

#[macro_use]
mod support;

use std::collections::VecDeque;
use std::io;
use std::ops::ControlFlow;
use std::time::Duration;

use eds2rust_runtime::blocking::Master;
use eds2rust_runtime::heartbeat::HeartbeatEvent;
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::od::AccessRight;
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::server::{MemoryStore, SdoServer, ServerConfig};
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use eds2rust_runtime::transport::{Bus, Clock, ManualClock};
use eds2rust_runtime::{CanId, Frame, Instant, Service};
use support::node;

/// The master's heartbeat period.
const PERIOD: Duration = Duration::from_millis(20);
/// The node the master supervises.
const DEVICE: u8 = 0x20;

entry!(DeviceType, 0x1000, 0, Unsigned32, Ro, u32);

/// A started master (node 1) on a manual clock, supervising node 0x20's
/// heartbeat with a consumer time of 100 ms; a port for the test's peer
/// frames, which also sees the master's.
fn rig() -> (Master<VirtualPort>, ManualClock, VirtualPort, VirtualBus) {
    let bus = VirtualBus::new();
    let peer = bus.attach();
    let time = ManualClock::new();
    let mut core = master::Master::new(node(1), Some(PERIOD));
    core.consumer
        .monitor(node(DEVICE), Some(Duration::from_millis(100)));
    let mut m = Master::with_clock(bus.attach(), core, time.clock());
    m.start().unwrap();
    (m, time, peer, bus)
}

#[test]
fn heartbeats_go_out_exactly_every_period() {
    let (mut m, time, peer, _bus) = rig();
    let real = std::time::Instant::now();
    // Steps of one millisecond: a heartbeat sent during a step was due at
    // its start (a call ends at its deadline before the timers due then).
    let mut seen = Vec::new();
    while time.now() < Instant::from_millis(101) {
        let start = time.now();
        m.run_for(Duration::from_millis(1)).unwrap();
        assert_eq!(time.now(), start + Duration::from_millis(1));
        while let Some(frame) = peer.try_recv() {
            if frame.to_string() == "701#7F" {
                seen.push(start);
            }
        }
    }
    let due: Vec<Instant> = (1..=5).map(|n| Instant::from_millis(20 * n)).collect();
    assert_eq!(seen, due);
    assert!(real.elapsed() < Duration::from_secs(5));
}

#[test]
fn a_missing_heartbeat_times_out_at_the_consumer_time() {
    let (mut m, time, peer, _bus) = rig();
    // The device's boot-up and one heartbeat at 30 ms start supervision.
    peer.transmit(&Frame::new(CanId::Standard(0x700 + u16::from(DEVICE)), &[0x00]).unwrap());
    time.advance(Duration::from_millis(30));
    peer.transmit(&Frame::new(CanId::Standard(0x700 + u16::from(DEVICE)), &[0x7F]).unwrap());
    let lost = m
        .run_until(Instant::from_millis(10_000), |event| match event {
            MasterEvent::Heartbeat(HeartbeatEvent::Timeout { node }) => ControlFlow::Break(*node),
            _ => ControlFlow::Continue(()),
        })
        .unwrap();
    assert_eq!(lost, node(DEVICE));
    assert_eq!(time.now(), Instant::from_millis(130));
}

#[test]
fn a_silent_node_fails_an_sdo_read_after_its_timeout_in_no_real_time() {
    let (mut m, time, peer, _bus) = rig();
    let real = std::time::Instant::now();
    let timeout = m.core_mut().sdo_or_default(node(0x05)).config().timeout;
    assert!(m.read::<DeviceType>(node(0x05)).is_err());
    assert_eq!(time.now(), Instant::ZERO + timeout);
    assert!(real.elapsed() < Duration::from_secs(5));
    // The request went out at time zero, the abort at the timeout.
    let sent: Vec<String> = std::iter::from_fn(|| peer.try_recv())
        .map(|f| f.to_string())
        .filter(|f| f.starts_with("605#"))
        .collect();
    assert_eq!(sent, ["605#4000100000000000", "605#8000100000000405"]);
}

/// The other end of the master's bus: an SDO server (node 0x20) that
/// answers each request `delay` after it came, in the manual clock's time,
/// and a log of every frame the master sent with when it was sent.
struct SlowServer {
    clock: Clock,
    server: SdoServer<MemoryStore>,
    delay: Duration,
    answers: VecDeque<(Instant, Frame)>,
    sent: Vec<(Instant, Frame)>,
}

impl Bus for SlowServer {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        let now = self.clock.now();
        self.sent.push((now, *frame));
        self.server.handle_frame(now, frame);
        while let Some(answer) = self.server.poll_transmit() {
            self.answers.push_back((now + self.delay, answer));
        }
        Ok(())
    }

    fn recv(&mut self, _timeout: Duration) -> io::Result<Option<Frame>> {
        let due = self
            .answers
            .front()
            .is_some_and(|(at, _)| *at <= self.clock.now());
        Ok(due
            .then(|| self.answers.pop_front().map(|(_, f)| f))
            .flatten())
    }
}

#[test]
fn the_heartbeat_keeps_its_period_during_a_slow_sdo_read() {
    let time = ManualClock::new();
    let mut store = MemoryStore::new();
    store.insert_fixed(0x1000, 0, AccessRight::Ro, &0x0002_0192u32.to_le_bytes());
    let bus = SlowServer {
        clock: time.clock(),
        server: SdoServer::new(ServerConfig::new(Channel::default_for(node(DEVICE))), store),
        delay: Duration::from_millis(300),
        answers: VecDeque::new(),
        sent: Vec::new(),
    };
    let core = master::Master::new(node(1), Some(PERIOD));
    let mut m = Master::with_clock(bus, core, time.clock());
    m.start().unwrap();
    assert_eq!(m.read::<DeviceType>(node(DEVICE)).unwrap(), 0x0002_0192);
    // The answer came 300 ms after the request, which went out at once.
    assert_eq!(time.now(), Instant::from_millis(300));
    let sent = &m.bus().sent;
    assert_eq!(sent[0], (Instant::ZERO, frame(0x701, &[0x00])));
    assert_eq!(sent[1].0, Instant::ZERO);
    assert_eq!(sent[1].1.standard_id(), Some(0x620));
    // Meanwhile every heartbeat went out exactly on time.
    let beats: Vec<Instant> = sent[2..]
        .iter()
        .map(|(at, f)| {
            assert_eq!(*f, frame(0x701, &[0x7F]));
            *at
        })
        .collect();
    let due: Vec<Instant> = (1..=15).map(|n| Instant::from_millis(20 * n)).collect();
    assert_eq!(beats, due);
}

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}
