//! The rig of the network boot tests (network_boot.rs, network_run.rs):
//! tests/networks/boot/matrix.yml booted by the master against the network's
//! own simulation in virtual time, with helpers to read the outcome.
#![allow(dead_code, unused_imports)] // each test file uses part of it

pub use std::time::Duration;

pub use eds2rust_runtime::blocking;
pub use eds2rust_runtime::boot::{
    BootError, BootEvent, BootStatus, Configuration, NetworkEvent, NetworkPlan, NetworkReport,
    SlaveState, SlaveStatus, Supervision,
};
pub use eds2rust_runtime::master::{Master, MasterEvent};
pub use eds2rust_runtime::od::NodeId;
pub use eds2rust_runtime::sdo::abort::AbortCode;
pub use eds2rust_runtime::transport::ManualClock;
pub use eds2rust_runtime::{Frame, Instant};
pub use eds2rust_sim::network::{Fault, IdentityField, InlineBus, Network, NodeFault, Simulation};

pub const LEFT: u8 = 2;
pub const RIGHT: u8 = 3;

pub fn id(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

pub fn network() -> Network {
    let path = eds2rust_tests::workspace_root().join("tests/networks/boot/matrix.yml");
    Network::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A master and the simulation with `faults`, in virtual time.
pub struct Rig {
    pub network: Network,
    pub time: ManualClock,
    pub master: blocking::Master<InlineBus<Simulation>>,
    /// Every network event so far, in order.
    pub events: Vec<NetworkEvent>,
}

impl Rig {
    pub fn new(faults: &[(u8, Fault)]) -> Rig {
        Rig::with_plan(faults, |_| {})
    }

    /// [`Rig::new`] with the plan changed by `edit` (flags the bus file
    /// does not set).
    pub fn with_plan(faults: &[(u8, Fault)], edit: impl FnOnce(&mut NetworkPlan)) -> Rig {
        let mut network = network();
        edit(&mut network.plan);
        let time = ManualClock::new();
        let faults: Vec<NodeFault> = faults
            .iter()
            .map(|(n, f)| NodeFault::new(id(*n), *f))
            .collect();
        let sim = network
            .simulation(&faults, time.now())
            .unwrap_or_else(|e| panic!("{e}"));
        let bus = InlineBus::manual(sim, time.clone()).with_trace();
        let core = Master::for_network(network.plan()).unwrap_or_else(|e| panic!("{e}"));
        let mut master = blocking::Master::with_clock(bus, core, time.clock());
        master.set_queue_capacity(usize::MAX);
        master.start().unwrap();
        Rig {
            network,
            time,
            master,
            events: Vec::new(),
        }
    }

    /// Boots the network (10 s of virtual time at most).
    pub fn boot(&mut self) -> NetworkReport {
        let deadline = self.time.now() + Duration::from_secs(10);
        let report = self
            .master
            .boot_network(self.network.plan().clone(), deadline)
            .unwrap_or_else(|e| panic!("{e}"));
        self.take_events();
        report
    }

    /// Runs the bus for `duration` more.
    pub fn run(&mut self, duration: Duration) {
        self.master.run_for(duration).unwrap();
        self.take_events();
    }

    pub fn take_events(&mut self) {
        for event in self.master.drain_events() {
            if let MasterEvent::Network(e) = event {
                self.events.push(e);
            }
        }
    }

    /// The master's status of slave `node` now.
    pub fn slave(&self, node: u8) -> SlaveStatus {
        self.master
            .core()
            .network()
            .expect("a network")
            .slave(id(node))
            .expect("a slave of the network")
            .clone()
    }

    pub fn now(&self) -> Instant {
        self.time.now()
    }

    pub fn sim(&self) -> &Simulation {
        self.master.bus().service()
    }

    /// The steps of `node`'s boots, in order.
    pub fn steps(&self, node: u8) -> Vec<BootEvent> {
        self.events
            .iter()
            .filter_map(|e| match e {
                NetworkEvent::Step { node: n, step } if *n == id(node) => Some(step.clone()),
                _ => None,
            })
            .collect()
    }

    /// The position of the first event `matches` takes (panics without).
    /// Where slave `node`'s reboot begins (`Rebooting`); the test fails
    /// unless a `Booted` step of `node` follows.
    pub fn rebooted(&self, node: u8) -> usize {
        let at = self.position("Rebooting", |e| *e == NetworkEvent::Rebooting(id(node)));
        let booted = NetworkEvent::Step {
            node: id(node),
            step: BootEvent::Booted,
        };
        assert!(self.events[at..].contains(&booted), "{:#?}", self.events);
        at
    }

    pub fn position(&self, what: &str, matches: impl Fn(&NetworkEvent) -> bool) -> usize {
        self.events
            .iter()
            .position(matches)
            .unwrap_or_else(|| panic!("no {what} in {:#?}", self.events))
    }

    /// The frames on the bus with `can_id` (time, frame).
    pub fn frames(&self, can_id: u16) -> Vec<(Instant, Frame)> {
        self.master
            .bus()
            .trace()
            .iter()
            .filter(|(_, f)| f.standard_id() == Some(can_id))
            .copied()
            .collect()
    }

    /// SDO download requests to `node` (initiate download, expedited or not).
    pub fn downloads(&self, node: u8) -> Vec<(u16, u8)> {
        self.frames(0x600 + u16::from(node))
            .iter()
            .filter(|(_, f)| f.data().first().is_some_and(|b| b >> 5 == 1))
            .map(|(_, f)| {
                let d = f.data();
                (u16::from_le_bytes([d[1], d[2]]), d[3])
            })
            .collect()
    }
}

pub fn state(report: &NetworkReport, node: u8) -> SlaveState {
    report
        .slaves
        .iter()
        .find(|s| s.node == id(node))
        .map(|s| s.state)
        .expect("the slave is in the report")
}

pub fn error(report: &NetworkReport, node: u8) -> BootError {
    report
        .errors()
        .find(|e| e.node == id(node))
        .cloned()
        .unwrap_or_else(|| panic!("node {node} did not fail: {report:#?}"))
}

/// The full boot of one slave, as its steps say.
pub const FULL_BOOT: [BootEvent; 5] = [
    BootEvent::BootedUp,
    BootEvent::IdentityChecked,
    BootEvent::Configured { entries: 0 },
    BootEvent::HeartbeatStarted,
    BootEvent::Booted,
];

/// `steps` with the configured count set to `entries`.
pub fn full_boot(entries: usize) -> Vec<BootEvent> {
    FULL_BOOT
        .iter()
        .map(|s| match s {
            BootEvent::Configured { .. } => BootEvent::Configured { entries },
            other => other.clone(),
        })
        .collect()
}

/// How many entries the configuration of `node` writes.
pub fn entries(network: &Network, node: u8) -> usize {
    network
        .plan()
        .slave(id(node))
        .map(|s| s.plan.configuration.len())
        .unwrap()
}
