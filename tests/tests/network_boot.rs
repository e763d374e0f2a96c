//! The CiA 302-2 boot fault matrix on the virtual bus: the master
//! (`blocking::Master::boot_network`, and once the tokio master) boots
//! tests/networks/boot/bus.yml against the network's own simulation
//! (`eds2rust_sim::network`) with one fault at a time, in virtual time
//! (a manual clock the simulation moves in 1 ms steps, so the whole
//! matrix takes well under a second of CPU). Each case checks the boot
//! status (A–O), the events and what the slaves hold.
//!
//! The network: `left` (node 2, mandatory) and `right` (node 3,
//! optional), the same CiA 402 drive (tests/networks/boot/drive.yaml),
//! heartbeats every 50 ms consumed by the master, SYNC every 10 ms (each
//! drive sends TPDO 1 on it), boot time 1 s.

use std::time::Duration;

use eds2rust_runtime::blocking;
use eds2rust_runtime::boot::{
    BootError, BootEvent, BootStatus, Configuration, NetworkEvent, NetworkPlan, NetworkReport,
    SlaveState, Supervision,
};
use eds2rust_runtime::master::{Master, MasterEvent};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_runtime::transport::ManualClock;
use eds2rust_runtime::{Frame, Instant};
use eds2rust_sim::network::{Fault, IdentityField, InlineBus, Network, NodeFault, Simulation};

const LEFT: u8 = 2;
const RIGHT: u8 = 3;

fn id(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

fn network() -> Network {
    let path = eds2rust_tests::workspace_root().join("tests/networks/boot/bus.yml");
    Network::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A master and the simulation with `faults`, in virtual time.
struct Rig {
    network: Network,
    time: ManualClock,
    master: blocking::Master<InlineBus<Simulation>>,
    /// Every network event so far, in order.
    events: Vec<NetworkEvent>,
}

impl Rig {
    fn new(faults: &[(u8, Fault)]) -> Rig {
        Rig::with_plan(faults, |_| {})
    }

    /// [`Rig::new`] with the plan changed by `edit` (flags the bus file
    /// does not set).
    fn with_plan(faults: &[(u8, Fault)], edit: impl FnOnce(&mut NetworkPlan)) -> Rig {
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
    fn boot(&mut self) -> NetworkReport {
        let deadline = self.time.now() + Duration::from_secs(10);
        let report = self
            .master
            .boot_network(self.network.plan().clone(), deadline)
            .unwrap_or_else(|e| panic!("{e}"));
        self.take_events();
        report
    }

    /// Runs the bus for `duration` more.
    fn run(&mut self, duration: Duration) {
        self.master.run_for(duration).unwrap();
        self.take_events();
    }

    fn take_events(&mut self) {
        for event in self.master.drain_events() {
            if let MasterEvent::Network(e) = event {
                self.events.push(e);
            }
        }
    }

    fn now(&self) -> Instant {
        self.time.now()
    }

    fn sim(&self) -> &Simulation {
        self.master.bus().service()
    }

    /// The steps of `node`'s boots, in order.
    fn steps(&self, node: u8) -> Vec<BootEvent> {
        self.events
            .iter()
            .filter_map(|e| match e {
                NetworkEvent::Step { node: n, step } if *n == id(node) => Some(step.clone()),
                _ => None,
            })
            .collect()
    }

    /// The position of the first event `matches` takes (panics without).
    fn position(&self, what: &str, matches: impl Fn(&NetworkEvent) -> bool) -> usize {
        self.events
            .iter()
            .position(matches)
            .unwrap_or_else(|| panic!("no {what} in {:#?}", self.events))
    }

    /// The frames on the bus with `can_id` (time, frame).
    fn frames(&self, can_id: u16) -> Vec<(Instant, Frame)> {
        self.master
            .bus()
            .trace()
            .iter()
            .filter(|(_, f)| f.standard_id() == Some(can_id))
            .copied()
            .collect()
    }

    /// SDO download requests to `node` (initiate download, expedited or not).
    fn downloads(&self, node: u8) -> Vec<(u16, u8)> {
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

fn state(report: &NetworkReport, node: u8) -> SlaveState {
    report
        .slaves
        .iter()
        .find(|s| s.node == id(node))
        .map(|s| s.state)
        .expect("the slave is in the report")
}

fn error(report: &NetworkReport, node: u8) -> BootError {
    report
        .errors()
        .find(|e| e.node == id(node))
        .cloned()
        .unwrap_or_else(|| panic!("node {node} did not fail: {report:#?}"))
}

/// The full boot of one slave, as its steps say.
const FULL_BOOT: [BootEvent; 5] = [
    BootEvent::BootedUp,
    BootEvent::IdentityChecked,
    BootEvent::Configured { entries: 0 },
    BootEvent::HeartbeatStarted,
    BootEvent::Booted,
];

/// `steps` with the configured count set to `entries`.
fn full_boot(entries: usize) -> Vec<BootEvent> {
    FULL_BOOT
        .iter()
        .map(|s| match s {
            BootEvent::Configured { .. } => BootEvent::Configured { entries },
            other => other.clone(),
        })
        .collect()
}

/// How many entries the configuration of `node` writes.
fn entries(network: &Network, node: u8) -> usize {
    network
        .plan()
        .slave(id(node))
        .map(|s| s.plan.configuration.len())
        .unwrap()
}

#[test]
fn without_faults_every_slave_is_identified_configured_and_started() {
    let mut rig = Rig::new(&[]);
    let real = std::time::Instant::now();
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    for node in [LEFT, RIGHT] {
        assert_eq!(state(&report, node), SlaveState::Operational);
        let s = report.slaves.iter().find(|s| s.node == id(node)).unwrap();
        assert!(s.identity_checked);
        let n = entries(&rig.network, node);
        assert_eq!(s.configuration, Some(Configuration::Written(n)));
        assert_eq!(rig.steps(node), full_boot(n));
        // What the configuration wrote is in the slave.
        assert_eq!(rig.sim().get_uint(id(node), 0x6060, 0), Some(8));
        assert_eq!(rig.sim().get_uint(id(node), 0x1017, 0), Some(50));
    }
    assert!(rig.events.contains(&NetworkEvent::Started(id(LEFT))));
    assert!(rig.events.contains(&NetworkEvent::Started(id(RIGHT))));
    assert_eq!(report.errors().count(), 0);
    assert!(
        rig.now() < Instant::from_millis(1000),
        "booted at {:?}",
        rig.now()
    );
    assert!(real.elapsed() < Duration::from_secs(5));
}

#[test]
fn a_missing_mandatory_slave_fails_the_network_with_status_b() {
    let mut rig = Rig::new(&[(LEFT, Fault::Missing)]);
    let report = rig.boot();
    assert!(!report.booted);
    let e = error(&report, LEFT);
    assert_eq!(e.status, BootStatus::NoResponse);
    assert_eq!(e.status.letter(), 'B');
    assert_eq!(e.object, Some((0x1000, 0)));
    assert!(e.to_string().starts_with("node 2: boot error B"), "{e}");
    // Decided at the boot time's end, not before.
    assert_eq!(rig.now(), Instant::from_millis(1000));
    assert!(rig.events.contains(&NetworkEvent::Failed(e)));
    assert_eq!(report.errors().count(), 1);
    // The optional slave booted meanwhile (and was started, as each slave
    // is when it is booted).
    assert_eq!(state(&report, RIGHT), SlaveState::Operational);
}

#[test]
fn a_missing_optional_slave_is_listed_as_failed_and_the_network_runs() {
    let mut rig = Rig::new(&[(RIGHT, Fault::Missing)]);
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    assert_eq!(state(&report, LEFT), SlaveState::Operational);
    assert_eq!(state(&report, RIGHT), SlaveState::Failed);
    let e = error(&report, RIGHT);
    assert_eq!(e.status, BootStatus::NoResponse);
    assert_eq!(rig.events.last(), Some(&NetworkEvent::Failed(e)));
    assert_eq!(report.errors().count(), 1);
}

/// The mandatory slave holds `value` in `field`: its boot fails with
/// `letter`, naming the object and both values.
fn wrong_identity(field: IdentityField, value: u32, letter: char) {
    let mut rig = Rig::new(&[(LEFT, Fault::Identity(field, value))]);
    let report = rig.boot();
    assert!(!report.booted);
    let e = error(&report, LEFT);
    assert_eq!(e.status.letter(), letter, "{e}");
    assert_eq!(e.object, Some(field.object()));
    assert_eq!(e.found, Some(value));
    let expected = rig.network.plan().slave(id(LEFT)).unwrap().plan.clone();
    let expected = match field {
        IdentityField::DeviceType => expected.device_type,
        IdentityField::VendorId => expected.vendor_id,
        IdentityField::ProductCode => expected.product_code,
        IdentityField::RevisionNumber => expected.revision_number,
        IdentityField::SerialNumber => expected.serial_number,
    };
    assert_ne!(expected, 0, "{field:?} is checked");
    assert_eq!(e.expected, Some(expected));
    let text = e.to_string();
    let (index, sub) = field.object();
    for part in [
        format!("node 2: boot error {letter}"),
        format!("0x{index:04X} sub {sub}"),
        format!("expected 0x{expected:08X}"),
        format!("found 0x{value:08X}"),
    ] {
        assert!(text.contains(&part), "`{text}` lacks `{part}`");
    }
    // Nothing was written to a device that is not the expected one.
    assert_eq!(rig.downloads(LEFT), []);
    assert!(rig.events.contains(&NetworkEvent::Failed(e)));
    assert!(!rig.steps(LEFT).contains(&BootEvent::IdentityChecked));
}

#[test]
fn a_wrong_device_type_is_status_c() {
    wrong_identity(IdentityField::DeviceType, 0x0002_0191, 'C');
}

#[test]
fn a_wrong_vendor_id_is_status_d() {
    wrong_identity(IdentityField::VendorId, 0x0000_0E2E, 'D');
}

#[test]
fn a_wrong_product_code_is_status_m() {
    wrong_identity(IdentityField::ProductCode, 0x0000_0004, 'M');
}

#[test]
fn a_wrong_revision_number_is_status_n() {
    wrong_identity(IdentityField::RevisionNumber, 0x0001_0001, 'N');
}

#[test]
fn a_wrong_serial_number_is_status_o() {
    wrong_identity(IdentityField::SerialNumber, 0x00BA_D000, 'O');
}

#[test]
fn an_sdo_abort_during_configuration_is_status_j_naming_object_and_abort() {
    let code = AbortCode::from_code(0x0609_0030);
    let mut rig = Rig::new(&[(
        LEFT,
        Fault::SdoAbort {
            index: 0x6060,
            sub: 0,
            code,
        },
    )]);
    let report = rig.boot();
    assert!(!report.booted);
    let e = error(&report, LEFT);
    assert_eq!(e.status, BootStatus::ConfigurationFailed);
    assert_eq!(e.status.letter(), 'J');
    assert_eq!(e.object, Some((0x6060, 0)));
    assert_eq!(e.abort, Some(code));
    let text = e.to_string();
    assert!(
        text.contains("boot error J") && text.contains("0x6060 sub 0"),
        "{text}"
    );
    assert!(text.contains(&code.to_string()), "{text}");
    // The write refused is the last one tried.
    assert_eq!(rig.downloads(LEFT).last(), Some(&(0x6060, 0)));
    assert!(rig.events.contains(&NetworkEvent::Failed(e)));
    assert!(rig.steps(LEFT).contains(&BootEvent::IdentityChecked));
}

#[test]
fn a_current_configuration_is_not_downloaded() {
    let mut rig = Rig::new(&[(LEFT, Fault::ConfigurationCurrent)]);
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    let left = report.slaves.iter().find(|s| s.node == id(LEFT)).unwrap();
    assert_eq!(left.configuration, Some(Configuration::Current));
    assert_eq!(left.state, SlaveState::Operational);
    assert!(rig.steps(LEFT).contains(&BootEvent::ConfigurationCurrent));
    assert_eq!(
        rig.downloads(LEFT),
        [],
        "nothing written to the current slave"
    );
    // The other one is configured as usual.
    assert_eq!(rig.downloads(RIGHT).len(), entries(&rig.network, RIGHT));
    // The current slave holds its configuration (saved before).
    assert_eq!(rig.sim().get_uint(id(LEFT), 0x6060, 0), Some(8));
    assert_eq!(rig.sim().get_uint(id(LEFT), 0x1017, 0), Some(50));
}

#[test]
fn a_slave_that_resets_during_operation_is_booted_again_while_the_other_runs() {
    // `right` loses power for 20 ms at 1.5 s: less than the heartbeat
    // consumer time, so the master sees a boot-up, not a loss.
    let off = Duration::from_millis(20);
    let at = Duration::from_millis(1500);
    let mut rig = Rig::new(&[(RIGHT, Fault::PowerLoss { at, off })]);
    let report = rig.boot();
    assert!(report.booted);
    rig.run(Duration::from_millis(2500) - (rig.now() - Instant::ZERO));
    let rebooting = rig.position("Rebooting", |e| *e == NetworkEvent::Rebooting(id(RIGHT)));
    assert!(
        !rig.events
            .iter()
            .any(|e| matches!(e, NetworkEvent::Lost { .. })),
        "{:#?}",
        rig.events
    );
    // Booted twice, configured twice: the reset lost the configuration.
    let n = entries(&rig.network, RIGHT);
    let mut twice = full_boot(n);
    twice.extend(full_boot(n));
    assert_eq!(rig.steps(RIGHT), twice);
    assert!(
        rig.events[rebooting..].contains(&NetworkEvent::Started(id(RIGHT))),
        "started again"
    );
    assert_eq!(rig.downloads(RIGHT).len(), 2 * n);
    assert_eq!(rig.sim().get_uint(id(RIGHT), 0x6060, 0), Some(8));
    assert_eq!(
        rig.master
            .core()
            .network()
            .unwrap()
            .slave(id(RIGHT))
            .unwrap()
            .boots,
        2
    );
    // The other slave ran on: its TPDO came every SYNC meanwhile.
    let pdos: Vec<Instant> = rig.frames(0x182).iter().map(|(t, _)| *t).collect();
    let from = Instant::ZERO + at - Duration::from_millis(100);
    let to = Instant::ZERO + at + Duration::from_millis(400);
    let during = pdos.iter().filter(|t| **t >= from && **t < to).count();
    assert!(during >= 49, "{during} TPDOs of left in 500 ms");
    assert!(rig.steps(LEFT) == full_boot(entries(&rig.network, LEFT)));
}

#[test]
fn a_lost_heartbeat_is_status_e_and_its_return_boots_the_slave_again() {
    let at = Duration::from_millis(1500);
    let resume = Some(Duration::from_millis(500));
    let mut rig = Rig::new(&[(RIGHT, Fault::HeartbeatStops { at, resume })]);
    let report = rig.boot();
    assert!(report.booted);
    rig.run(Duration::from_millis(3000) - (rig.now() - Instant::ZERO));
    let lost = rig.position("Lost", |e| {
        *e == NetworkEvent::Lost {
            node: id(RIGHT),
            status: BootStatus::HeartbeatLost,
        }
    });
    assert_eq!(BootStatus::HeartbeatLost.letter(), 'E');
    let rebooting = rig.position("Rebooting", |e| *e == NetworkEvent::Rebooting(id(RIGHT)));
    assert!(lost < rebooting);
    let booted_again = rig.events[rebooting..].iter().any(|e| {
        *e == NetworkEvent::Step {
            node: id(RIGHT),
            step: BootEvent::Booted,
        }
    });
    assert!(booted_again, "{:#?}", rig.events);
    let status = rig
        .master
        .core()
        .network()
        .unwrap()
        .slave(id(RIGHT))
        .unwrap()
        .clone();
    assert_eq!(status.state, SlaveState::Operational, "{status:#?}");
    assert_eq!(status.boots, 2);
    // `left` was never lost.
    assert!(
        !rig.events
            .iter()
            .any(|e| matches!(e, NetworkEvent::Lost { node, .. } if *node == id(LEFT)))
    );
}

#[test]
fn a_heartbeat_that_never_starts_is_status_k() {
    let stops = Fault::HeartbeatStops {
        at: Duration::ZERO,
        resume: None,
    };
    let mut rig = Rig::new(&[(LEFT, stops)]);
    let report = rig.boot();
    assert!(!report.booted);
    let e = error(&report, LEFT);
    assert_eq!(e.status, BootStatus::HeartbeatNotStarted);
    assert_eq!(e.status.letter(), 'K');
    assert_eq!(e.object, Some((0x1017, 0)));
    // Identified and configured first.
    let steps = rig.steps(LEFT);
    let n = entries(&rig.network, LEFT);
    assert_eq!(steps, full_boot(n)[..3].to_vec());
}

#[test]
fn a_slave_booting_late_within_the_boot_time_is_booted() {
    let mut rig = Rig::new(&[(LEFT, Fault::LateBoot(Duration::from_millis(600)))]);
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    assert_eq!(state(&report, LEFT), SlaveState::Operational);
    let left = report.slaves.iter().find(|s| s.node == id(LEFT)).unwrap();
    assert!(left.boot_ended.unwrap() >= Instant::from_millis(600));
    assert_eq!(rig.steps(LEFT), full_boot(entries(&rig.network, LEFT)));
}

#[test]
fn a_mandatory_slave_booting_after_the_boot_time_fails_the_network_then_boots() {
    let mut rig = Rig::new(&[(LEFT, Fault::LateBoot(Duration::from_millis(1500)))]);
    let report = rig.boot();
    assert!(!report.booted);
    assert_eq!(error(&report, LEFT).status, BootStatus::NoResponse);
    assert_eq!(rig.now(), Instant::from_millis(1000));
    // When it finally comes, it is booted (the failed network does not
    // start it).
    rig.run(Duration::from_millis(1000));
    let comes = rig.position("Rebooting", |e| *e == NetworkEvent::Rebooting(id(LEFT)));
    let booted = rig.events[comes..].iter().any(|e| {
        *e == NetworkEvent::Step {
            node: id(LEFT),
            step: BootEvent::Booted,
        }
    });
    assert!(booted, "{:#?}", rig.events);
    let status = rig
        .master
        .core()
        .network()
        .unwrap()
        .slave(id(LEFT))
        .unwrap()
        .clone();
    assert_eq!(status.state, SlaveState::Booted, "{status:#?}");
    assert_eq!(status.error, None);
}

/// NMT commands on the bus (command, node; 0 for all).
fn nmt(rig: &Rig) -> Vec<(u8, u8)> {
    rig.frames(0x000)
        .iter()
        .map(|(_, f)| (f.data()[0], f.data()[1]))
        .collect()
}

#[test]
fn start_all_nodes_starts_them_with_one_command_at_the_end() {
    let mut rig = Rig::with_plan(&[], |plan| plan.start_all_nodes = true);
    let report = rig.boot();
    assert!(report.booted);
    let starts: Vec<(u8, u8)> = nmt(&rig).into_iter().filter(|(c, _)| *c == 0x01).collect();
    assert_eq!(starts, [(0x01, 0)]);
    assert_eq!(state(&report, LEFT), SlaveState::Operational);
    assert_eq!(state(&report, RIGHT), SlaveState::Operational);
    assert_eq!(
        rig.sim().nmt_state(id(RIGHT)),
        Some(eds2rust_runtime::nmt::NmtState::Operational)
    );
}

#[test]
fn reset_all_nodes_resets_them_with_one_command() {
    let mut rig = Rig::with_plan(&[], |plan| plan.reset_all_nodes = true);
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    let resets: Vec<(u8, u8)> = nmt(&rig).into_iter().filter(|(c, _)| *c == 0x82).collect();
    assert_eq!(resets, [(0x82, 0)]);
    for node in [LEFT, RIGHT] {
        assert_eq!(rig.steps(node), full_boot(entries(&rig.network, node)));
    }
}

#[test]
fn stop_all_nodes_stops_the_network_when_a_mandatory_slave_fails() {
    let mut rig = Rig::with_plan(&[(LEFT, Fault::Missing)], |plan| {
        plan.stop_all_nodes = true;
    });
    let report = rig.boot();
    assert!(!report.booted);
    assert!(nmt(&rig).contains(&(0x02, 0)), "{:?}", nmt(&rig));
    rig.run(Duration::from_millis(50));
    assert_eq!(
        rig.sim().nmt_state(id(RIGHT)),
        Some(eds2rust_runtime::nmt::NmtState::Stopped)
    );
}

#[test]
fn a_slave_the_master_does_not_boot_is_only_started() {
    let mut rig = Rig::with_plan(&[], |plan| {
        let mut slaves = plan.slaves.to_vec();
        slaves[1].boot = false;
        plan.slaves = slaves.into();
    });
    let report = rig.boot();
    assert!(report.booted);
    let right = report.slaves.iter().find(|s| s.node == id(RIGHT)).unwrap();
    assert_eq!(right.configuration, Some(Configuration::NotManaged));
    assert_eq!(right.state, SlaveState::Operational);
    assert!(rig.frames(0x603).is_empty(), "no SDO to it");
}

#[test]
fn a_guarded_slave_that_stops_answering_is_status_f_and_booted_again() {
    let guarding = Supervision::Guarding {
        guard_time: Duration::from_millis(50),
        life_time_factor: std::num::NonZeroU8::new(3).unwrap(),
    };
    let at = Duration::from_millis(1500);
    let off = Duration::from_millis(500);
    let mut rig = Rig::with_plan(&[(RIGHT, Fault::PowerLoss { at, off })], |plan| {
        let mut slaves = plan.slaves.to_vec();
        slaves[1].supervision = guarding;
        slaves[1].plan.heartbeat = false;
        plan.slaves = slaves.into();
    });
    let report = rig.boot();
    assert!(report.booted, "{report:#?}");
    rig.run(Duration::from_millis(3000) - (rig.now() - Instant::ZERO));
    // Guarded: remote frames on 0x703, answered while powered.
    assert!(rig.frames(0x703).iter().any(|(_, f)| f.is_remote()));
    let lost = rig.position("Lost", |e| {
        *e == NetworkEvent::Lost {
            node: id(RIGHT),
            status: BootStatus::GuardingLost,
        }
    });
    let rebooting = rig.position("Rebooting", |e| *e == NetworkEvent::Rebooting(id(RIGHT)));
    assert!(lost < rebooting, "{:#?}", rig.events);
    let status = rig
        .master
        .core()
        .network()
        .unwrap()
        .slave(id(RIGHT))
        .unwrap()
        .clone();
    assert_eq!(status.state, SlaveState::Operational, "{status:#?}");
    assert_eq!(status.boots, 2);
}

#[test]
fn the_tokio_master_boots_the_same_network() {
    use eds2rust_runtime::tokio as rt;
    use eds2rust_runtime::transport::virtual_bus::VirtualBus;

    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .unwrap();
    runtime.block_on(async {
        let network = network();
        let bus = VirtualBus::new();
        let clock = rt::clock();
        let faults = [NodeFault::new(id(RIGHT), Fault::Missing)];
        let mut sim = network.simulation(&faults, clock.now()).unwrap();
        let mut port = bus.attach();
        let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
        let sim_clock = clock.clone();
        let simulated = tokio::spawn(async move {
            let shutdown = async {
                let _ = stopped.await;
            };
            rt::serve(&mut port, &sim_clock, &mut sim, shutdown, None, |_| {}).await
        });
        let core = Master::for_network(network.plan()).unwrap();
        let (master, driver) = rt::Master::new(bus.attach(), core);
        let driver = tokio::spawn(driver.run());
        master.start().await.unwrap();
        let report = master.boot_network(network.plan().clone()).await.unwrap();
        assert!(report.booted, "{report:#?}");
        assert_eq!(state(&report, LEFT), SlaveState::Operational);
        assert_eq!(state(&report, RIGHT), SlaveState::Failed);
        assert_eq!(error(&report, RIGHT).status, BootStatus::NoResponse);
        let _ = stop.send(());
        drop(master);
        let _ = driver.await;
        simulated.await.unwrap().unwrap();
    });
}

/// Boots the network of `path` against its own simulation without faults:
/// the report, or why not.
fn boot_own_simulation(path: &std::path::Path) -> Result<NetworkReport, String> {
    let network = Network::load(path).map_err(|e| e.to_string())?;
    let time = ManualClock::new();
    let sim = network
        .simulation(&[], time.now())
        .map_err(|e| e.to_string())?;
    let bus = InlineBus::manual(sim, time.clone());
    let core = Master::for_network(network.plan()).map_err(|e| e.to_string())?;
    let mut master = blocking::Master::with_clock(bus, core, time.clock());
    master.set_queue_capacity(usize::MAX);
    master.start().map_err(|e| e.to_string())?;
    let deadline = time.now() + Duration::from_secs(60);
    master
        .boot_network(network.plan().clone(), deadline)
        .map_err(|e| e.to_string())
}

/// One network of the repository and what its boot gives: whether it
/// runs, and the slaves that fail (each a J: the bus file remaps a PDO whose
/// parameters the device file makes read-only, which `net check` warns
/// about as `net::not-writable`, and the simulated device refuses as the
/// device would).
fn boots_as_its_files_say(path: &std::path::Path, booted: bool, failed: &[u8]) {
    let report = boot_own_simulation(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(report.booted, booted, "{}: {report:#?}", path.display());
    let mut failing = Vec::new();
    for error in report.errors() {
        assert_eq!(error.status, BootStatus::ConfigurationFailed, "{error}");
        assert_eq!(
            error.abort,
            Some(AbortCode::from_code(0x0601_0002)),
            "{error}"
        );
        let (index, _) = error.object.expect("the object refused");
        assert!((0x1400..=0x1BFF).contains(&index), "{error}");
        failing.push(error.node.get());
    }
    assert_eq!(failing, failed, "{}", path.display());
    for slave in report.slaves.iter().filter(|s| s.error.is_none()) {
        assert!(
            matches!(slave.state, SlaveState::Operational | SlaveState::Booted),
            "{}: {slave:#?}",
            path.display()
        );
    }
}

#[test]
fn every_network_of_the_repository_boots_against_its_own_simulation() {
    let root = eds2rust_tests::workspace_root();
    boots_as_its_files_say(&root.join("eds/machine/bus.yml"), true, &[]);
    boots_as_its_files_say(&root.join("tests/networks/boot/bus.yml"), true, &[]);
    // ros2_canopen-style networks written for `net check` and `net dcf`:
    // some remap PDOs their device files make read-only.
    let networks = root.join("tests/networks");
    boots_as_its_files_say(&networks.join("mixed_cell/bus.yml"), true, &[6]);
    boots_as_its_files_say(&networks.join("press_line/bus.yml"), false, &[10]);
    boots_as_its_files_say(
        &networks.join("conveyor_defaults/bus.yml"),
        true,
        &[21, 22, 23],
    );
}

#[test]
fn the_network_corpus_boots_against_its_own_simulation() {
    let Some(shared) = eds2rust_tests::shared_dir() else {
        eds2rust_tests::not_run(
            "network corpus boot test: ../shared/network-corpus is not beside this checkout",
        );
        return;
    };
    let corpus = shared.join("network-corpus");
    // Six Pilz PRBT joints in interpolated position mode (declared by their
    // 0x6502, taken by the generic drive), one Trinamic PD42.
    boots_as_its_files_say(&corpus.join("prbt_pilz6/bus.yml"), true, &[]);
    boots_as_its_files_say(&corpus.join("trinamic_pd42/bus.yml"), true, &[]);
}
