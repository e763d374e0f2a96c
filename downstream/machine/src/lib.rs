//! The three seed devices as one machine (eds/machine/bus.yml): a Zimmer
//! ACS axis in cyclic synchronous position mode, a LINAK TECHLINE actuator
//! and an Interroll EC5000 BI conveyor drive in profile velocity mode.
//!
//! `build.rs` generates [`machine`] from the bus file: one module per node
//! with its typed object dictionary and the PDOs the network configures
//! (`machine::axis::pdo::Rpdo1ControlAndTargetPosition`, ...), and
//! `machine::network` with the nodes, the boot plan
//! (`machine::network::PLAN`, for `Master::for_network` and
//! `boot_network`), the master's process image ([`Inputs`], [`Outputs`])
//! and the timing constants. [`Cell`] is the
//! master's side of one SYNC cycle written against that image.
#![forbid(unsafe_code)]

/// The typed network, generated from `eds/machine/bus.yml`.
pub mod machine {
    include!(concat!(env!("OUT_DIR"), "/machine.rs"));
}

use machine::network::{Inputs, Outputs};
use machine::{actuator, axis, conveyor};

/// CiA 402 controlword "enable operation" (switch on, enable voltage,
/// quick stop off, enable operation).
const ENABLE_OPERATION: u16 = 0x000F;

/// What the cell asks of its three nodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Setpoints {
    /// The axis's target position, in its increments.
    pub axis_position: i32,
    /// The actuator's target position (raw, 0.1 mm; 0xFB.. are commands).
    pub actuator_position: u16,
    /// The conveyor's profile velocity, mm/s.
    pub conveyor_speed: u32,
}

/// The master's side of the machine: the last inputs and the outputs of
/// the next SYNC.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cell {
    pub inputs: Inputs,
}

impl Default for Cell {
    fn default() -> Self {
        Cell {
            inputs: Inputs::new(),
        }
    }
}

impl Cell {
    /// The outputs for `setpoints`: every drive enabled, the conveyor in
    /// profile velocity mode (3), the actuator at default current, speed
    /// and ramps (0xFB, "use the default").
    pub fn outputs(&self, setpoints: Setpoints) -> Outputs {
        Outputs {
            axis_rpdo1: axis::pdo::Rpdo1ControlAndTargetPosition {
                controlword: axis::od::ControlwordValue(ENABLE_OPERATION),
                target_position: axis::od::TargetPositionValue(setpoints.axis_position),
            },
            actuator_rpdo1: actuator::pdo::Rpdo1Command {
                position: actuator::od::command::PositionValue(setpoints.actuator_position),
                current_limit: actuator::od::command::CurrentLimitValue(0xFB),
                speed: actuator::od::command::SpeedValue(0xFB),
                soft_start: actuator::od::command::SoftStartValue(0xFB),
                soft_stop: actuator::od::command::SoftStopValue(0xFB),
                // The two reserved bytes of the command record.
                reserved_6: Default::default(),
                reserved_7: Default::default(),
            },
            conveyor_rpdo1: conveyor::pdo::Rpdo1VelocityCommand {
                controlword: conveyor::od::ControlwordValue(ENABLE_OPERATION),
                modes_of_operation: conveyor::od::ModesOfOperationValue(3),
                profile_velocity: conveyor::od::ProfileVelocityValue(setpoints.conveyor_speed),
            },
        }
    }

    /// The axis's position as last reported (TPDO1, each SYNC).
    pub fn axis_position(&self) -> Option<i32> {
        self.inputs.axis_tpdo1.map(|t| t.position_actual_value.0)
    }

    /// The conveyor's speed as last reported (TPDO4, each SYNC).
    pub fn conveyor_speed(&self) -> Option<i32> {
        self.inputs
            .conveyor_tpdo4
            .map(|t| t.velocity_actual_value.0)
    }
}
