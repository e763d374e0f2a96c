use eds2rust_drivers::{interroll_ec5000bi as ir, linak_techline as lk, zimmer_acs as zm};
use eds2rust_runtime::Pdo;
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(rpdo = 1)]
pub struct LkRpdo1Command {
    #[pdo(entry = lk::od::command::Position)] pub position: lk::od::command::PositionValue,
    #[pdo(entry = lk::od::command::CurrentLimit)] pub current_limit: lk::od::command::CurrentLimitValue,
    #[pdo(entry = lk::od::command::Speed)] pub speed: lk::od::command::SpeedValue,
    #[pdo(entry = lk::od::command::SoftStart)] pub soft_start: lk::od::command::SoftStartValue,
    #[pdo(entry = lk::od::command::SoftStop)] pub soft_stop: lk::od::command::SoftStopValue,
    #[pdo(entry = lk::od::command::Reserved6)] pub reserved_6: u8,
    #[pdo(entry = lk::od::command::Reserved7)] pub reserved_7: u8,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 1)]
pub struct LkTpdo1Feedback {
    #[pdo(entry = lk::od::feedback::Position)] pub position: lk::od::feedback::PositionValue,
    #[pdo(entry = lk::od::feedback::Current)] pub current: lk::od::feedback::CurrentValue,
    #[pdo(entry = lk::od::feedback::StatusFlags)] pub status_flags: lk::od::feedback::StatusFlagsValue,
    #[pdo(entry = lk::od::feedback::ErrorCode)] pub error_code: lk::errors::LinakErrorsCode,
    #[pdo(entry = lk::od::feedback::Speed)] pub speed: lk::od::feedback::SpeedValue,
    #[pdo(entry = lk::od::feedback::AuxInputs)] pub aux_inputs: lk::od::feedback::AuxInputsValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 2)]
pub struct LkTpdo2ParallelFeedback {
    #[pdo(entry = lk::od::parallel_feedback::ParallelErrorSource)] pub parallel_error_source: lk::od::parallel_feedback::ParallelErrorSourceValue,
    #[pdo(entry = lk::od::parallel_feedback::ParallelErrorCode)] pub parallel_error_code: lk::errors::ParallelErrorsCode,
    #[pdo(entry = lk::od::parallel_feedback::ParallelStatusFlags)] pub parallel_status_flags: lk::od::parallel_feedback::ParallelStatusFlagsValue,
    #[pdo(entry = lk::od::parallel_feedback::Reserved4)] pub reserved_4: u8,
    #[pdo(entry = lk::od::parallel_feedback::Reserved5)] pub reserved_5: u8,
    #[pdo(entry = lk::od::parallel_feedback::Reserved6)] pub reserved_6: u8,
    #[pdo(entry = lk::od::parallel_feedback::Reserved7)] pub reserved_7: u8,
    #[pdo(entry = lk::od::parallel_feedback::Reserved8)] pub reserved_8: u8,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(rpdo = 1)]
pub struct ZmRpdo1ControlAndTargetPosition {
    #[pdo(entry = zm::od::Controlword)] pub controlword: zm::od::ControlwordValue,
    #[pdo(entry = zm::od::TargetPosition)] pub target_position: zm::od::TargetPositionValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(rpdo = 2)]
pub struct ZmRpdo2ProfileVelocity {
    #[pdo(entry = zm::od::ProfileVelocity)] pub profile_velocity: zm::od::ProfileVelocityValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 1)]
pub struct ZmTpdo1StatusAndPosition {
    #[pdo(entry = zm::od::Statusword)] pub statusword: zm::od::StatuswordValue,
    #[pdo(entry = zm::od::PositionActualValue)] pub position_actual_value: zm::od::PositionActualValueValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 2)]
pub struct ZmTpdo2Velocity {
    #[pdo(entry = zm::od::VelocityActualValue)] pub velocity_actual_value: zm::od::VelocityActualValueValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 3)]
pub struct ZmTpdo3FollowingErrorAndTorque {
    #[pdo(entry = zm::od::FollowingErrorActualValue)] pub following_error_actual_value: zm::od::FollowingErrorActualValueValue,
    #[pdo(entry = zm::od::TorqueActualValue)] pub torque_actual_value: zm::od::TorqueActualValueValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(rpdo = 1)]
pub struct IrRpdo1VelocityCommand {
    #[pdo(entry = ir::od::Controlword)] pub controlword: ir::od::ControlwordValue,
    #[pdo(entry = ir::od::ModesOfOperation)] pub modes_of_operation: ir::od::ModesOfOperationValue,
    #[pdo(entry = ir::od::ProfileVelocity)] pub profile_velocity: ir::od::ProfileVelocityValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(rpdo = 2)]
pub struct IrRpdo2PositionCommand {
    #[pdo(entry = ir::od::Controlword)] pub controlword: ir::od::ControlwordValue,
    #[pdo(entry = ir::od::TargetPosition)] pub target_position: ir::od::TargetPositionValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(rpdo = 3)]
pub struct IrRpdo3TargetVelocityCommand {
    #[pdo(entry = ir::od::Controlword)] pub controlword: ir::od::ControlwordValue,
    #[pdo(entry = ir::od::TargetVelocity)] pub target_velocity: ir::od::TargetVelocityValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 1)]
pub struct IrTpdo1Status {
    #[pdo(entry = ir::od::Statusword)] pub statusword: ir::od::StatuswordValue,
    #[pdo(entry = ir::od::ModesOfOperationDisplay)] pub modes_of_operation_display: ir::od::ModesOfOperationDisplayValue,
    #[pdo(entry = ir::od::ErrorRegister)] pub error_register: ir::od::ErrorRegisterValue,
    #[pdo(entry = ir::od::monitoring_values::ActualTemperature)] pub actual_temperature: ir::od::monitoring_values::ActualTemperatureValue,
    #[pdo(entry = ir::od::TorqueActualValue)] pub torque_actual_value: ir::od::TorqueActualValueValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 2)]
pub struct IrTpdo2Position {
    #[pdo(entry = ir::od::Statusword)] pub statusword: ir::od::StatuswordValue,
    #[pdo(entry = ir::od::PositionActualValue)] pub position_actual_value: ir::od::PositionActualValueValue,
}
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 3)]
pub struct IrTpdo3Velocity {
    #[pdo(entry = ir::od::Statusword)] pub statusword: ir::od::StatuswordValue,
    #[pdo(entry = ir::od::VelocityActualValue)] pub velocity_actual_value: ir::od::VelocityActualValueValue,
}
