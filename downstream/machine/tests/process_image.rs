//! The machine's process image on the virtual bus: the master sends its
//! outputs (the three nodes' RPDOs) and each node decodes its own with its
//! node module's PDO struct; the nodes send their TPDOs, encoded with their
//! structs on the COB-IDs the network configures, and the master decodes
//! them into its inputs.

use eds2rust_runtime::CanId;
use eds2rust_runtime::od::Pdo;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use machine::machine::network::{self, Inputs, Outputs};
use machine::machine::{actuator, axis, conveyor};
use machine::{Cell, Setpoints};

#[test]
fn the_network_module_says_what_the_bus_file_says() {
    assert_eq!(network::BIT_RATE_KBIT, 250);
    assert_eq!(network::SYNC_PERIOD_US, 10_000);
    assert_eq!(network::MASTER_HEARTBEAT_MS, 100);
    let ids: Vec<(&str, u8)> = network::NODES
        .iter()
        .map(|n| (n.name, n.node_id.get()))
        .collect();
    assert_eq!(ids, [("axis", 40), ("actuator", 32), ("conveyor", 5)]);
    assert_eq!(axis::NODE_ID, 40);
    // Identities from the device files.
    assert_eq!(network::nodes::ACTUATOR.vendor_id, actuator::VENDOR_ID);
    assert_eq!(network::nodes::CONVEYOR.vendor_id, 0x3FB);
    assert!(
        network::NODES
            .iter()
            .all(|n| n.heartbeat_producer_ms == 100)
    );
    assert_eq!((Inputs::LEN, Outputs::LEN), (6, 3));
}

#[test]
fn configured_pdos_have_the_networks_mapping_and_cob_ids() {
    // The axis's TPDO2 is the network's (velocity, torque), not the device
    // file's default (velocity alone).
    assert_eq!(
        axis::pdo::Tpdo2::MAPPING,
        &[0x606C_0020, 0x6077_0010],
        "the network's mapping"
    );
    assert_eq!(axis::pdo::Tpdo2::LEN, 6);
    // COB-IDs resolved for the node ids of this bus.
    assert_eq!(
        axis::pdo::Tpdo1StatusAndPosition::CAN_ID,
        CanId::Standard(0x1A8)
    );
    assert_eq!(conveyor::pdo::Tpdo4::CAN_ID, CanId::Standard(0x485));
    assert_eq!(actuator::pdo::Rpdo1Command::CAN_ID, CanId::Standard(0x220));
}

#[test]
fn one_sync_cycle_on_the_virtual_bus() {
    let bus = VirtualBus::with_bit_rate(network::BIT_RATE_KBIT * 1000);
    let master = bus.attach();
    let node = bus.attach();
    let mut cell = Cell::default();

    // The master's outputs reach the nodes, each decodable by its own struct.
    let outputs = cell.outputs(Setpoints {
        axis_position: 12_345,
        actuator_position: 1_000,
        conveyor_speed: 250,
    });
    for frame in outputs.frames() {
        master.transmit(&frame);
    }
    let mut seen = 0;
    while let Some(frame) = node.try_recv() {
        match frame.id() {
            id if id == axis::pdo::Rpdo1ControlAndTargetPosition::CAN_ID => {
                let rpdo = axis::pdo::Rpdo1ControlAndTargetPosition::decode(frame.data()).unwrap();
                assert_eq!(rpdo.target_position.0, 12_345);
                assert_eq!(rpdo.controlword.0, 0x000F);
            }
            id if id == actuator::pdo::Rpdo1Command::CAN_ID => {
                let rpdo = actuator::pdo::Rpdo1Command::decode(frame.data()).unwrap();
                assert_eq!(rpdo.position.0, 1_000);
                assert_eq!(frame.data().len(), 8);
            }
            id if id == conveyor::pdo::Rpdo1VelocityCommand::CAN_ID => {
                let rpdo = conveyor::pdo::Rpdo1VelocityCommand::decode(frame.data()).unwrap();
                assert_eq!(rpdo.profile_velocity.0, 250);
                assert_eq!(rpdo.modes_of_operation.0, 3);
            }
            other => panic!("an unexpected frame on {other}"),
        }
        seen += 1;
    }
    assert_eq!(seen, Outputs::LEN);

    // The nodes answer with their TPDOs; the master takes them in.
    let position = axis::pdo::Tpdo1StatusAndPosition {
        statusword: axis::od::StatuswordValue(0x0237),
        position_actual_value: axis::od::PositionActualValueValue(12_300),
    };
    let speed = conveyor::pdo::Tpdo4 {
        statusword: conveyor::od::StatuswordValue(0x0237),
        velocity_actual_value: conveyor::od::VelocityActualValueValue(248),
        actual_temperature: conveyor::od::monitoring_values::ActualTemperatureValue(31),
    };
    let tpdos = [
        (
            axis::pdo::Tpdo1StatusAndPosition::CAN_ID,
            encoded(&position),
        ),
        (conveyor::pdo::Tpdo4::CAN_ID, encoded(&speed)),
    ];
    for (id, (data, len)) in tpdos {
        node.transmit(&eds2rust_runtime::Frame::with_id(id, data, len as u8));
    }
    // A frame of another node's SDO: not an input.
    node.transmit(&eds2rust_runtime::Frame::standard(0x5A8, [0; 8], 8));
    let mut taken = 0;
    while let Some(frame) = master.try_recv() {
        if cell.inputs.receive(&frame).unwrap() {
            taken += 1;
        }
    }
    assert_eq!(taken, 2);
    assert_eq!(cell.axis_position(), Some(12_300));
    assert_eq!(cell.conveyor_speed(), Some(248));
    assert_eq!(cell.inputs.conveyor_tpdo4, Some(speed));
    assert_eq!(cell.inputs.actuator_tpdo1, None, "not received yet");
}

#[test]
fn a_short_tpdo_is_an_error_and_keeps_the_last_value() {
    let mut inputs = Inputs::new();
    let short = eds2rust_runtime::Frame::with_id(CanId::Standard(0x1A8), [0; 8], 3);
    assert!(inputs.receive(&short).is_err());
    assert_eq!(inputs.axis_tpdo1, None);
}

fn encoded<P: Pdo>(pdo: &P) -> ([u8; 8], usize) {
    let mut data = [0u8; 8];
    let len = pdo.encode_into(&mut data);
    (data, len)
}
