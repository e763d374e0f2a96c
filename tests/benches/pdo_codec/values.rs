use super::{hand, ir, lk, zm};

/// `head`, then `bits` as 0/1, as one array.
fn join<const K: usize>(head: &[i64], bits: &[bool]) -> [i64; K] {
    let mut v = [0; K];
    v[..head.len()].copy_from_slice(head);
    v[head.len()..].iter_mut().zip(bits).for_each(|(o, &b)| *o = i64::from(b));
    v
}
/// `head`, then the bits of `raw` at `positions` (the hand-written bit tests).
fn join_bits<const K: usize>(head: &[i64], raw: u64, positions: &[u8]) -> [i64; K] {
    let mut v = [0; K];
    v[..head.len()].copy_from_slice(head);
    v[head.len()..].iter_mut().zip(positions).for_each(|(o, &p)| *o = (raw >> p & 1) as i64);
    v
}

fn lk_status(s: lk::od::feedback::StatusFlagsValue) -> [bool; 8] {
    [s.end_stop_in(), s.end_stop_out(), s.overcurrent(), s.running_out(), s.running_in(),
     s.heartbeat_required(), s.outside_nominal_conditions(), s.always_set()]
}
fn zm_status(s: zm::od::StatuswordValue) -> [bool; 13] {
    [s.ready_to_switch_on(), s.switched_on(), s.operation_enabled(), s.fault(), s.voltage_enabled(),
     s.quick_stop(), s.switch_on_disabled(), s.warning(), s.target_reached(), s.internal_limit_active(),
     s.setpoint_ack(), s.following_error(), s.initial_angle_determination_finished()]
}
fn zm_control(c: zm::od::ControlwordValue) -> [bool; 9] {
    [c.switch_on(), c.enable_voltage(), c.quick_stop(), c.enable_operation(), c.latch_setpoint(),
     c.change_immediately(), c.abs_rel(), c.fault_reset(), c.halt()]
}
fn ir_status(s: ir::od::StatuswordValue) -> [bool; 16] {
    [s.ready_to_switch_on(), s.switched_on(), s.operation_enabled(), s.fault(), s.voltage_enabled(),
     s.quick_stop(), s.switch_on_disabled(), s.warning(), s.manufacturer_specific_error_bit(), s.remote(),
     s.target_reached(), s.internal_limit_active(), s.set_point_acknowledge(), s.following_error(),
     s.manufacturer_specific_14(), s.manufacturer_specific_15()]
}
fn ir_control(c: ir::od::ControlwordValue) -> [bool; 15] {
    [c.switch_on(), c.enable_voltage(), c.quick_stop(), c.enable_operation(), c.new_set_point(),
     c.change_set_immediately(), c.absolute_relative(), c.fault_reset(), c.halt(), c.change_of_set_point(),
     c.manufacturer_specific_11(), c.manufacturer_specific_12(), c.manufacturer_specific_13(),
     c.manufacturer_specific_14(), c.manufacturer_specific_15()]
}
fn ir_error_register(e: ir::od::ErrorRegisterValue) -> [bool; 7] {
    [e.generic_error(), e.current(), e.voltage(), e.temperature(), e.communication_error(),
     e.device_profile_specific(), e.manufacturer_specific()]
}

pub fn lk_tpdo1(f: &lk::pdo::Tpdo1Feedback) -> [i64; 18] {
    let (s, a) = (f.status_flags, f.aux_inputs);
    let head = [f.position.to_raw(), f.current.to_raw().into(), s.to_raw().into(), f.error_code.to_raw().into(),
                f.speed.to_raw(), a.to_raw().into()];
    let mut v: [i64; 18] = join(&head.map(i64::from), &lk_status(s));
    let levels = [a.input_level_1(), a.input_level_2(), a.input_level_3(), a.input_level_4()];
    v[14..].copy_from_slice(&levels.map(i64::from));
    v
}
pub fn hand_lk_tpdo1(f: &hand::LkFeedback) -> [i64; 18] {
    let head = [f.position, f.current.into(), f.status.into(), f.error_code.into(), f.speed, f.aux.into()];
    let mut v: [i64; 18] = join_bits(&head.map(i64::from), f.status.into(), &hand::LK_STATUS_BITS);
    v[14..].copy_from_slice(&[1, 2, 3, 4].map(|n| i64::from(f.aux_level(n))));
    v
}
pub fn lk_rpdo1(c: &lk::pdo::Rpdo1Command) -> [i64; 7] {
    [c.position.to_raw(), c.current_limit.to_raw().into(), c.speed.to_raw().into(), c.soft_start.to_raw().into(),
     c.soft_stop.to_raw().into(), c.reserved_6.into(), c.reserved_7.into()].map(i64::from)
}
pub fn hand_lk_rpdo1(c: &hand::LkCommand) -> [i64; 7] {
    [c.position, c.current_limit.into(), c.speed.into(), c.soft_start.into(), c.soft_stop.into(),
     c.reserved[0].into(), c.reserved[1].into()].map(i64::from)
}
pub fn lk_tpdo2(p: &lk::pdo::Tpdo2ParallelFeedback) -> [i64; 11] {
    let s = p.parallel_status_flags;
    let head = [p.parallel_error_source.to_raw(), p.parallel_error_code.to_raw(), s.to_raw(), p.reserved_4,
                p.reserved_5, p.reserved_6, p.reserved_7, p.reserved_8];
    join(&head.map(i64::from), &[s.parallel_end_stop_out(), s.parallel_end_stop_in(), s.outside_nominal_conditions()])
}
pub fn hand_lk_tpdo2(p: &hand::LkParallel) -> [i64; 11] {
    let r = p.reserved;
    let head = [p.error_source, p.error_code, p.status, r[0], r[1], r[2], r[3], r[4]];
    join_bits(&head.map(i64::from), p.status.into(), &hand::LK_PARALLEL_BITS)
}
pub fn zm_rpdo1(r: &zm::pdo::Rpdo1ControlAndTargetPosition) -> [i64; 11] {
    let c = r.controlword;
    join(&[c.to_raw().into(), r.target_position.to_raw().into()], &zm_control(c))
}
pub fn hand_zm_rpdo1(r: &hand::WordAnd32) -> [i64; 11] {
    join_bits(&[r.word.into(), r.value.into()], r.word.into(), &hand::ZM_CONTROL_BITS)
}
pub fn zm_rpdo2(r: &zm::pdo::Rpdo2ProfileVelocity) -> [i64; 1] { [r.profile_velocity.to_raw().into()] }
pub fn hand_u32(r: &hand::One32) -> [i64; 1] { [r.value.into()] }
pub fn zm_tpdo1(t: &zm::pdo::Tpdo1StatusAndPosition) -> [i64; 15] {
    let s = t.statusword;
    join(&[s.to_raw().into(), t.position_actual_value.to_raw().into()], &zm_status(s))
}
pub fn hand_zm_tpdo1(t: &hand::WordAnd32) -> [i64; 15] {
    join_bits(&[t.word.into(), t.value.into()], t.word.into(), &hand::ZM_STATUS_BITS)
}
pub fn zm_tpdo2(t: &zm::pdo::Tpdo2Velocity) -> [i64; 1] { [t.velocity_actual_value.to_raw().into()] }
pub fn hand_i32(t: &hand::One32) -> [i64; 1] { [(t.value as i32).into()] }
pub fn zm_tpdo3(t: &zm::pdo::Tpdo3FollowingErrorAndTorque) -> [i64; 2] {
    [t.following_error_actual_value.to_raw().into(), t.torque_actual_value.to_raw().into()]
}
pub fn hand_zm_tpdo3(t: &hand::ZmFollowingTorque) -> [i64; 2] { [t.following_error.into(), t.torque.into()] }
pub fn ir_rpdo1(r: &ir::pdo::Rpdo1VelocityCommand) -> [i64; 18] {
    let c = r.controlword;
    let head = [c.to_raw().into(), r.modes_of_operation.to_raw().into(), r.profile_velocity.to_raw().into()];
    join(&head, &ir_control(c))
}
pub fn hand_ir_rpdo1(r: &hand::IrVelocityCommand) -> [i64; 18] {
    let head = [r.controlword.into(), r.mode.into(), r.profile_velocity.into()];
    join_bits(&head, r.controlword.into(), &hand::IR_CONTROL_BITS)
}
pub fn ir_rpdo2(r: &ir::pdo::Rpdo2PositionCommand) -> [i64; 17] {
    join(&[r.controlword.to_raw().into(), r.target_position.to_raw().into()], &ir_control(r.controlword))
}
pub fn ir_rpdo3(r: &ir::pdo::Rpdo3TargetVelocityCommand) -> [i64; 17] {
    join(&[r.controlword.to_raw().into(), r.target_velocity.to_raw().into()], &ir_control(r.controlword))
}
pub fn hand_ir_rpdo23(r: &hand::WordAnd32) -> [i64; 17] {
    join_bits(&[r.word.into(), r.value.into()], r.word.into(), &hand::IR_CONTROL_BITS)
}
pub fn ir_tpdo1(t: &ir::pdo::Tpdo1Status) -> [i64; 28] {
    let (s, e) = (t.statusword, t.error_register);
    let head = [s.to_raw().into(), t.modes_of_operation_display.to_raw().into(), e.to_raw().into(),
                t.actual_temperature.to_raw().into(), t.torque_actual_value.to_raw().into()];
    let mut v: [i64; 28] = join(&head, &ir_status(s));
    v[21..].copy_from_slice(&ir_error_register(e).map(i64::from));
    v
}
pub fn hand_ir_tpdo1(t: &hand::IrStatus) -> [i64; 28] {
    let head = [t.statusword.into(), t.mode_display.into(), t.error_register.into(), t.temperature.into(), t.torque.into()];
    let mut v: [i64; 28] = join_bits(&head, t.statusword.into(), &hand::IR_STATUS_BITS);
    let er = u64::from(t.error_register);
    v[21..].iter_mut().zip(hand::IR_ERROR_REGISTER_BITS).for_each(|(o, p)| *o = (er >> p & 1) as i64);
    v
}
pub fn ir_tpdo2(t: &ir::pdo::Tpdo2Position) -> [i64; 18] {
    join(&[t.statusword.to_raw().into(), t.position_actual_value.to_raw().into()], &ir_status(t.statusword))
}
pub fn ir_tpdo3(t: &ir::pdo::Tpdo3Velocity) -> [i64; 18] {
    join(&[t.statusword.to_raw().into(), t.velocity_actual_value.to_raw().into()], &ir_status(t.statusword))
}
pub fn hand_ir_tpdo23(t: &hand::WordAnd32) -> [i64; 18] {
    join_bits(&[t.word.into(), t.value.into()], t.word.into(), &hand::IR_STATUS_BITS)
}
