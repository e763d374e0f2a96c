use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::Duration;

use eds2rust_runtime::blocking;
use eds2rust_runtime::boot::SlaveState;
use eds2rust_runtime::master::Master;
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::transport::ManualClock;
use eds2rust_runtime::{Instant, Service};

use super::*;

fn machine() -> Network {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../eds/machine/bus.yml");
    Network::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn node(id: u8) -> NodeId {
    NodeId::new(id).unwrap()
}

fn frames(sim: &mut Simulation) -> Vec<String> {
    std::iter::from_fn(|| sim.poll_transmit())
        .map(|f| f.to_string())
        .collect()
}

#[test]
fn the_seed_machine_loads_with_its_node_ids_and_drives() {
    let network = machine();
    let nodes: Vec<(u8, &str, bool)> = network
        .slaves
        .iter()
        .map(|s| (s.node.get(), s.name.as_str(), s.drive))
        .collect();
    assert_eq!(
        nodes,
        [
            (5, "conveyor", true),
            (32, "actuator", false),
            (40, "axis", true)
        ]
    );
    assert_eq!(network.plan().slaves.len(), 3);
    assert_eq!(network.node_named("axis"), Some(node(40)));
}

#[test]
fn every_slave_boots_unless_missing_or_late() {
    let network = machine();
    let faults = [
        NodeFault::new(node(32), Fault::Missing),
        NodeFault::new(node(40), Fault::LateBoot(Duration::from_millis(300))),
    ];
    let mut sim = network.simulation(&faults, Instant::ZERO).unwrap();
    assert_eq!(frames(&mut sim), ["705#00"]);
    assert!(!sim.is_powered(node(32)));
    assert_eq!(
        sim.poll_timeout(),
        Some(Instant::from_millis(300)).min(sim.poll_timeout())
    );
    let mut t = Instant::ZERO;
    let mut seen = Vec::new();
    while t < Instant::from_millis(400) {
        t = sim.poll_timeout().unwrap();
        sim.handle_timeout(t);
        seen.extend(frames(&mut sim).into_iter().map(|f| (t, f)));
    }
    assert!(
        seen.contains(&(Instant::from_millis(300), "728#00".to_string())),
        "{seen:?}"
    );
    assert!(!seen.iter().any(|(_, f)| f.starts_with("720#")));
}

#[test]
fn a_fault_on_a_node_the_network_lacks_names_its_slaves() {
    let network = machine();
    let error = network
        .simulation(&[NodeFault::new(node(9), Fault::Missing)], Instant::ZERO)
        .unwrap_err();
    assert!(
        error.to_string().contains("no slave with node id 9"),
        "{error}"
    );
    assert!(error.to_string().contains("40 (axis)"), "{error}");
    let error = network
        .simulation(
            &[NodeFault::new(node(40), Fault::ConfigurationCurrent)],
            Instant::ZERO,
        )
        .unwrap_err();
    assert!(error.to_string().contains("0x1020"), "{error}");
}

#[test]
fn the_blocking_master_boots_the_machine_in_virtual_time() {
    let network = machine();
    let time = ManualClock::new();
    let faults = [NodeFault::new(
        node(5),
        Fault::Identity(IdentityField::ProductCode, 0xDEAD),
    )];
    let sim = network.simulation(&faults, time.now()).unwrap();
    let bus = InlineBus::manual(sim, time.clone()).with_trace();
    let core = Master::for_network(network.plan()).unwrap();
    let mut master = blocking::Master::with_clock(bus, core, time.clock());
    master.start().unwrap();
    let real = std::time::Instant::now();
    let report = master
        .boot_network(network.plan().clone(), Instant::from_millis(10_000))
        .unwrap();
    assert!(real.elapsed() < Duration::from_secs(5));
    let states: Vec<(u8, SlaveState)> = report
        .slaves
        .iter()
        .map(|s| (s.node.get(), s.state))
        .collect();
    assert_eq!(
        states,
        [
            (5, SlaveState::Failed),
            (32, SlaveState::Operational),
            (40, SlaveState::Operational)
        ],
        "{:#?}",
        report
    );
    // The PDOs flow afterwards.
    master
        .run_until(time.now() + Duration::from_millis(100), |_| {
            ControlFlow::<()>::Continue(())
        })
        .ok();
    let bus = master.bus();
    assert_eq!(
        bus.service().nmt_state(node(40)),
        Some(eds2rust_runtime::nmt::NmtState::Operational)
    );
}

#[test]
fn the_seed_machine_boots_and_its_pdos_flow_both_ways() {
    let network = machine();
    let time = ManualClock::new();
    let sim = network.simulation(&[], time.now()).unwrap();
    let bus = InlineBus::manual(sim, time.clone()).with_trace();
    let core = Master::for_network(network.plan()).unwrap();
    let mut master = blocking::Master::with_clock(bus, core, time.clock());
    master.start().unwrap();
    let report = master
        .boot_network(network.plan().clone(), Instant::from_millis(10_000))
        .unwrap();
    assert!(report.booted, "{report:#?}");
    assert!(
        report
            .slaves
            .iter()
            .all(|s| s.state == SlaveState::Operational),
        "{report:#?}"
    );
    let from = time.now();
    // The process data the master sends to the axis: controlword 0x000F
    // (enable operation), target 1000.
    let now = master.now();
    let axis_rpdo = eds2rust_runtime::CanId::Standard(0x228);
    let tx = master
        .core_mut()
        .pdo_tx
        .iter_mut()
        .find(|tx| tx.can_id() == axis_rpdo)
        .expect("the master sends the axis's RPDO 1");
    tx.set_data(now, &[0x0F, 0x00, 0xE8, 0x03, 0x00, 0x00])
        .unwrap();
    master.run_for(Duration::from_millis(200)).unwrap();
    let count = |id: u16| {
        master
            .bus()
            .trace()
            .iter()
            .filter(|(t, f)| *t >= from && f.standard_id() == Some(id))
            .count()
    };
    // The axis's TPDO 1 (statusword, position) and RPDO 1 (controlword,
    // target, from the master) every 10 ms SYNC.
    assert!(count(0x1A8) >= 19, "{}", count(0x1A8));
    assert!(count(0x228) >= 19, "{}", count(0x228));
    // The conveyor's TPDO 4 each SYNC.
    assert!(count(0x485) >= 19, "{}", count(0x485));
}

#[test]
fn an_inline_bus_on_the_real_clock_boots_the_machine_in_real_time() {
    let network = machine();
    let clock = eds2rust_runtime::transport::Clock::new();
    let sim = network.simulation(&[], clock.now()).unwrap();
    let bus = InlineBus::new(sim, clock.clone());
    let core = Master::for_network(network.plan()).unwrap();
    let mut master = blocking::Master::with_clock(bus, core, clock);
    master.start().unwrap();
    let real = std::time::Instant::now();
    let report = master
        .boot_network(
            network.plan().clone(),
            std::time::Instant::now() + Duration::from_secs(10),
        )
        .unwrap();
    assert!(report.booted, "{report:#?}");
    // Waits for the first heartbeats (100 ms) took real time, not more.
    let took = real.elapsed();
    assert!(took < Duration::from_secs(3), "{took:?}");
}

#[test]
fn faults_injected_while_running_happen_from_then_on() {
    let network = machine();
    let mut sim = network.simulation(&[], Instant::ZERO).unwrap();
    frames(&mut sim);
    let now = Instant::from_millis(500);
    let loss = Fault::PowerLoss {
        at: Duration::ZERO,
        off: Duration::from_millis(100),
    };
    sim.inject(NodeFault::new(node(40), loss), now).unwrap();
    assert!(!sim.is_powered(node(40)));
    assert_eq!(
        sim.poll_timeout().map(|t| t <= Instant::from_millis(600)),
        Some(true)
    );
    let back = Instant::from_millis(600);
    while sim.poll_timeout().is_some_and(|t| t <= back) {
        let t = sim.poll_timeout().unwrap();
        sim.handle_timeout(t);
        frames(&mut sim);
    }
    assert!(sim.is_powered(node(40)));
    let events: Vec<Event> = std::iter::from_fn(|| sim.poll_event()).collect();
    assert!(events.contains(&Event::PoweredOff(node(40))));
    assert!(events.contains(&Event::PoweredOn(node(40))));
    // What the device holds from power-on is no fault to inject.
    let wrong = Fault::Identity(IdentityField::VendorId, 1);
    let error = sim
        .inject(NodeFault::new(node(40), wrong), back)
        .unwrap_err();
    assert!(error.to_string().contains("Network::simulation"), "{error}");
    let error = sim
        .inject(NodeFault::new(node(9), Fault::Missing), back)
        .unwrap_err();
    assert!(error.to_string().contains("no node 9"), "{error}");
}

/// A service that sends a frame on 0x123 every 7 ms.
#[derive(Debug, Default)]
struct Beacon {
    next: Instant,
    due: bool,
}

impl Service for Beacon {
    type Event = ();
    fn handle_frame(&mut self, _: Instant, _: &eds2rust_runtime::Frame) {}
    fn handle_timeout(&mut self, now: Instant) {
        if self.next <= now {
            self.due = true;
            self.next += Duration::from_millis(7);
        }
    }
    fn poll_transmit(&mut self) -> Option<eds2rust_runtime::Frame> {
        std::mem::take(&mut self.due).then(|| eds2rust_runtime::Frame::standard(0x123, [0; 8], 0))
    }
    fn poll_event(&mut self) -> Option<()> {
        None
    }
    fn poll_timeout(&self) -> Option<Instant> {
        Some(self.next)
    }
}

#[test]
fn an_inline_bus_on_a_manual_clock_keeps_both_sides_on_time() {
    let time = ManualClock::new();
    let beacon = Beacon {
        next: Instant::from_millis(7),
        due: false,
    };
    let bus = InlineBus::manual(beacon, time.clone()).with_trace();
    let core = Master::new(node(1), Some(Duration::from_millis(20)));
    let mut master = blocking::Master::with_clock(bus, core, time.clock());
    master.start().unwrap();
    master.run_for(Duration::from_millis(100)).unwrap();
    let at = |id: u16| -> Vec<u64> {
        master
            .bus()
            .trace()
            .iter()
            .filter(|(_, f)| f.standard_id() == Some(id))
            .map(|(t, _)| t.as_micros())
            .collect()
    };
    // The service's frames at its own times, exactly.
    let beacons: Vec<u64> = (1..=14).map(|n| n * 7_000).collect();
    assert_eq!(at(0x123), beacons);
    // The master's heartbeats within one step of theirs (the one due at
    // 100 ms is past the call's end).
    let heartbeats = at(0x701);
    assert_eq!(heartbeats.len(), 5, "{heartbeats:?}");
    for (n, t) in heartbeats.iter().enumerate() {
        let due = n as u64 * 20_000;
        assert!(*t >= due && *t <= due + 1_000, "{heartbeats:?}");
    }
}
