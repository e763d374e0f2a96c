//! The deadlines of the blocking [`Master`] in the cores' own time.

use std::vec::Vec;

use super::*;
use crate::nmt::NmtEvent;
use crate::transport::virtual_bus::{VirtualBus, VirtualPort};
use crate::{CanId, Frame};

const PERIOD: Duration = Duration::from_millis(20);

fn node(id: u8) -> NodeId {
    NodeId::new(id).unwrap()
}

/// A started master (node 1, heartbeat every [`PERIOD`]) and a port that
/// sees its frames.
fn rig() -> (Master<VirtualPort>, VirtualPort, VirtualBus) {
    let bus = VirtualBus::new();
    let monitor = bus.attach();
    let mut m = Master::new(bus.attach(), master::Master::new(node(1), Some(PERIOD)));
    m.start().unwrap();
    (m, monitor, bus)
}

fn heartbeats(monitor: &VirtualPort) -> usize {
    std::iter::from_fn(|| monitor.try_recv())
        .filter(|f| f.to_string() == "701#7F")
        .count()
}

/// Stops at the first boot-up, with its node.
fn boot_up(event: &MasterEvent) -> ControlFlow<NodeId> {
    match event {
        MasterEvent::Nmt(NmtEvent::BootUp(n)) => ControlFlow::Break(*n),
        _ => ControlFlow::Continue(()),
    }
}

#[test]
fn run_until_takes_a_deadline_in_the_cores_time() {
    let (mut m, monitor, _bus) = rig();
    let start = m.now();
    let deadline = m.now() + Duration::from_millis(50);
    let result = m.run_until(deadline, |_| ControlFlow::<()>::Continue(()));
    assert!(matches!(result, Err(Error::DeadlinePassed)), "{result:?}");
    let end = m.now();
    assert!(end >= deadline, "returned at {end:?}, before {deadline:?}");
    assert!(end - start < Duration::from_secs(2), "{:?}", end - start);
    // The cores ran meanwhile: the heartbeats at 20 and 40 ms went out.
    assert!(heartbeats(&monitor) >= 2);
}

#[test]
fn run_until_breaks_on_an_event_before_a_core_deadline() {
    let (mut m, _monitor, bus) = rig();
    let peer = bus.attach();
    peer.transmit(&Frame::new(CanId::Standard(0x705), &[0x00]).unwrap());
    let got = m
        .run_until(m.now() + Duration::from_secs(5), boot_up)
        .unwrap();
    assert_eq!(got, node(5));
    // No deadline at all: a queued event is offered first.
    peer.transmit(&Frame::new(CanId::Standard(0x706), &[0x00]).unwrap());
    m.run_for(Duration::from_millis(5)).unwrap();
    let got = m.run_until(Deadline::NEVER, boot_up).unwrap();
    assert_eq!(got, node(6));
}

#[test]
fn a_passed_core_deadline_returns_at_once_and_std_deadlines_still_work() {
    let (mut m, _monitor, bus) = rig();
    let peer = bus.attach();
    let before = std::time::Instant::now();
    let result = m.run_until(m.now(), |_| ControlFlow::<()>::Continue(()));
    assert!(matches!(result, Err(Error::DeadlinePassed)));
    let result = m.run_until(Instant::ZERO, |_| ControlFlow::<()>::Continue(()));
    assert!(matches!(result, Err(Error::DeadlinePassed)));
    assert!(before.elapsed() < Duration::from_secs(1));
    // The std clock's instants are still taken (mapped through the clock).
    let deadline = std::time::Instant::now() + Duration::from_millis(30);
    let result = m.run_until(deadline, |_| ControlFlow::<()>::Continue(()));
    assert!(matches!(result, Err(Error::DeadlinePassed)));
    assert!(std::time::Instant::now() >= deadline);
    // The end of time: no overflow, the call ends on its event.
    peer.transmit(&Frame::new(CanId::Standard(0x707), &[0x00]).unwrap());
    let got = m.run_until(Instant::MAX, boot_up).unwrap();
    assert_eq!(got, node(7));
}

#[test]
fn wait_event_takes_a_deadline_and_run_for_a_duration() {
    let (mut m, monitor, _bus) = rig();
    let start = m.now();
    assert_eq!(
        m.wait_event(start + Duration::from_millis(30)).unwrap(),
        None
    );
    assert!(m.now() - start >= Duration::from_millis(30));
    let start = m.now();
    m.run_for(Duration::from_millis(45)).unwrap();
    assert!(m.now() - start >= Duration::from_millis(45));
    assert!(heartbeats(&monitor) >= 3);
    let _: Vec<MasterEvent> = m.drain_events().collect();
}
