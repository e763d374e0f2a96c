//! The network in operation, on the virtual bus against its own
//! simulation (the rig of network_boot.rs): a slave that resets or loses
//! its heartbeat or guarding is booted again while the other runs; the
//! start, reset and stop flags of the master; a slave the master does not
//! boot; the tokio master; every network of the repository and of the
//! network corpus booted against its own simulation.

#[path = "network_boot/rig.rs"]
mod rig;

use rig::*;

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
    assert_eq!(rig.slave(RIGHT).boots, 2);
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
    let rebooting = rig.rebooted(RIGHT);
    assert!(lost < rebooting);
    let status = rig.slave(RIGHT);
    assert_eq!(status.state, SlaveState::Operational, "{status:#?}");
    assert_eq!(status.boots, 2);
    // `left` was never lost.
    assert!(
        !rig.events
            .iter()
            .any(|e| matches!(e, NetworkEvent::Lost { node, .. } if *node == id(LEFT)))
    );
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
    let status = rig.slave(RIGHT);
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
    boots_as_its_files_say(&root.join("tests/networks/boot/matrix.yml"), true, &[]);
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
    let Some(corpus) = eds2rust_tests::network_corpus("network corpus boot test") else {
        return;
    };
    // Six Pilz PRBT joints in interpolated position mode (declared by their
    // 0x6502, taken by the generic drive), one Trinamic PD42.
    boots_as_its_files_say(&corpus.join("prbt_pilz6/bus.yml"), true, &[]);
    boots_as_its_files_say(&corpus.join("trinamic_pd42/bus.yml"), true, &[]);
}
