//! The machine booted from its generated plan (`machine::network::PLAN`)
//! on the virtual bus, against simulated devices built from the nodes'
//! own generated tables (generic CiA 402 drives for the axis and the
//! conveyor, a plain object store for the actuator), then one process
//! image exchanged through the generated `Inputs` and `Outputs`. And the
//! plan is the one `eds2rust::network::boot_plan` makes of the bus file.

use std::path::Path;
use std::time::Duration;

use eds2rust_runtime::blocking;
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::od::NodeId;
use eds2rust_sim::cia402::{self, Cia402};
use eds2rust_sim::harness::{Args, Harness};
use eds2rust_sim::{Device, DeviceConfig};
use machine::machine::network::{self, Inputs, PLAN};
use machine::machine::{actuator, axis, conveyor};
use machine::{Cell, Setpoints};

fn node(id: u8) -> NodeId {
    NodeId::new(id).expect("a node id of the bus file")
}

#[test]
fn the_plan_is_boot_plan_of_the_bus_file() {
    let bus_file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/machine/bus.yml");
    let loaded = eds2rust::network::read_file(&bus_file, &Default::default());
    let bus = loaded
        .bus
        .unwrap_or_else(|| panic!("{}", loaded.diagnostics.render()));
    let (configured, diagnostics) = eds2rust::network::configure(&bus);
    assert!(!diagnostics.has_errors(), "{}", diagnostics.render());
    assert_eq!(eds2rust::network::boot_plan(&bus, &configured), PLAN);
    // What the plan says of this machine.
    let plan = PLAN;
    let nodes: Vec<(u8, &str)> = plan
        .slaves
        .iter()
        .map(|s| (s.plan.node.get(), &*s.name))
        .collect();
    assert_eq!(nodes, [(5, "conveyor"), (32, "actuator"), (40, "axis")]);
    assert_eq!(PLAN.master.node.get(), network::MASTER_NODE_ID);
    assert_eq!(
        PLAN.master.sync_period,
        Some(Duration::from_micros(network::SYNC_PERIOD_US.into()))
    );
    assert_eq!((PLAN.receive.len(), PLAN.transmit.len()), (Inputs::LEN, 3));
}

#[test]
fn the_machine_boots_from_its_plan_and_exchanges_its_process_image() {
    let config = |id| DeviceConfig::node(node(id));
    let mut harness = Harness::start(&Args::default(), |now| {
        cia402::simulator(axis::od::OBJECTS, config(axis::NODE_ID), Cia402::new(), now)
    })
    .expect("the virtual bus");
    harness
        .add_device(|now| Device::new(actuator::od::OBJECTS, config(actuator::NODE_ID), (), now))
        .expect("the actuator");
    harness
        .add_device(|now| {
            cia402::simulator(
                conveyor::od::OBJECTS,
                config(conveyor::NODE_ID),
                Cia402::new(),
                now,
            )
        })
        .expect("the conveyor");
    let core = master::Master::for_network(&PLAN).expect("the plan's master part");
    let port = harness.take_port().expect("the master's port");
    let mut m = blocking::Master::with_clock(port, core, harness.clock());
    m.start().expect("the master starts");
    let report = m
        .boot_network(PLAN, m.now() + Duration::from_secs(10))
        .expect("the boot is decided");
    assert!(report.booted, "{report:#?}");
    for slave in &report.slaves {
        assert!(slave.error.is_none(), "{slave:#?}");
        assert_eq!(
            slave.state,
            eds2rust_runtime::boot::SlaveState::Operational,
            "{slave:#?}"
        );
    }

    // The outputs go out with the SYNCs; the slaves' TPDOs (as the boot
    // configured them) come back into the inputs.
    let mut cell = Cell::default();
    let outputs = cell.outputs(Setpoints {
        axis_position: 12_345,
        actuator_position: 1_000,
        conveyor_speed: 250,
    });
    let now = m.now();
    outputs
        .set_pdos(m.core_mut(), now)
        .expect("every output has its transmitter");
    m.run_for(Duration::from_millis(100)).expect("the bus runs");
    let syncs = m
        .drain_events()
        .filter(|e| matches!(e, MasterEvent::Pdo(_)))
        .count();
    assert!(syncs > 0, "TPDOs arrived");
    cell.inputs
        .take_latest(&m.core().pdo_rx)
        .expect("each input has its length");
    assert!(cell.inputs.axis_tpdo1.is_some(), "{:?}", cell.inputs);
    // TPDO2 of the axis has the network's mapping (velocity, torque: 6
    // bytes), not the device's default: it decodes.
    assert!(cell.inputs.axis_tpdo2.is_some(), "{:?}", cell.inputs);
    assert!(cell.inputs.conveyor_tpdo4.is_some(), "{:?}", cell.inputs);
    // The blocking master's PDO calls take the generated structs and
    // their network COB-IDs too.
    let tpdo2 = m
        .latest_pdo_on::<axis::pdo::Tpdo2>(axis::pdo::Tpdo2::COB_ID)
        .expect("watched with its length");
    assert_eq!(tpdo2, cell.inputs.axis_tpdo2);
    // The synchronous RPDO reached the axis's object dictionary.
    let target = m
        .read::<axis::od::TargetPosition>(node(axis::NODE_ID))
        .expect("0x607A of the axis");
    assert_eq!(target.0, 12_345);
    let speed = m
        .read::<conveyor::od::ProfileVelocity>(node(conveyor::NODE_ID))
        .expect("0x6081 of the conveyor");
    assert_eq!(speed.0, 250);
    harness.stop().expect("the simulators stop cleanly");
}
