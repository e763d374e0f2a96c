//! The CiA 402 objects the generic drive reads and publishes, and the
//! values it reads with their fallbacks: every read goes through the table
//! and gives `None` (or the documented fallback) when the entry is absent.

use eds2rust_runtime::cia402::{ModeOfOperation, object};

use super::{
    DEFAULT_PROFILE_ACCELERATION, DEFAULT_PROFILE_DECELERATION, DEFAULT_PROFILE_VELOCITY,
    DEFAULT_QUICK_STOP_DECELERATION, DEFAULT_QUICK_STOP_OPTION_CODE,
};
use crate::store::ObjectTable;

pub(crate) use object::{
    CONTROLWORD, ERROR_CODE, MODES_OF_OPERATION, MODES_OF_OPERATION_DISPLAY, POSITION_ACTUAL_VALUE,
    PROFILE_ACCELERATION, PROFILE_DECELERATION, PROFILE_VELOCITY, QUICK_STOP_OPTION_CODE,
    STATUSWORD, TARGET_POSITION, TARGET_VELOCITY, VELOCITY_ACTUAL_VALUE,
};

/// Error register (CiA 301).
pub(crate) const ERROR_REGISTER: u16 = 0x1001;
/// Halt option code (INTEGER16).
pub(crate) const HALT_OPTION_CODE: u16 = 0x605D;
/// Position demand value (INTEGER32).
pub(crate) const POSITION_DEMAND_VALUE: u16 = 0x6062;
/// Position actual internal value (INTEGER32).
pub(crate) const POSITION_ACTUAL_INTERNAL: u16 = 0x6063;
/// Following error window (UNSIGNED32).
pub(crate) const FOLLOWING_ERROR_WINDOW: u16 = 0x6065;
/// Following error time out (UNSIGNED16, ms).
pub(crate) const FOLLOWING_ERROR_TIME_OUT: u16 = 0x6066;
/// Position window (UNSIGNED32).
pub(crate) const POSITION_WINDOW: u16 = 0x6067;
/// Position window time (UNSIGNED16, ms).
pub(crate) const POSITION_WINDOW_TIME: u16 = 0x6068;
/// Velocity demand value (INTEGER32).
pub(crate) const VELOCITY_DEMAND_VALUE: u16 = 0x606B;
/// Velocity window (UNSIGNED16).
pub(crate) const VELOCITY_WINDOW: u16 = 0x606D;
/// Velocity threshold (UNSIGNED16).
pub(crate) const VELOCITY_THRESHOLD: u16 = 0x606F;
/// Home offset (INTEGER32).
pub(crate) const HOME_OFFSET: u16 = 0x607C;
/// Software position limit (ARRAY: sub 1 min, sub 2 max).
pub(crate) const SOFTWARE_POSITION_LIMIT: u16 = 0x607D;
/// Max profile velocity (UNSIGNED32).
pub(crate) const MAX_PROFILE_VELOCITY: u16 = 0x607F;
/// Quick stop deceleration (UNSIGNED32).
pub(crate) const QUICK_STOP_DECELERATION: u16 = 0x6085;
/// Homing method (INTEGER8).
pub(crate) const HOMING_METHOD: u16 = 0x6098;
/// Homing speeds (ARRAY: sub 1 during search for switch).
pub(crate) const HOMING_SPEEDS: u16 = 0x6099;
/// Homing acceleration (UNSIGNED32).
pub(crate) const HOMING_ACCELERATION: u16 = 0x609A;
/// Positioning option code (UNSIGNED16).
pub(crate) const POSITIONING_OPTION_CODE: u16 = 0x60F2;
/// Supported drive modes (UNSIGNED32): bit n - 1 for mode n.
pub(crate) const SUPPORTED_DRIVE_MODES: u16 = 0x6502;
/// Following error actual value (INTEGER32).
pub(crate) const FOLLOWING_ERROR_ACTUAL: u16 = 0x60F4;
/// Position demand internal value (INTEGER32).
pub(crate) const POSITION_DEMAND_INTERNAL: u16 = 0x60FC;

/// The objects (index, name) a mode of operation needs besides the
/// controlword and statusword: profile position and cyclic synchronous
/// position need 0x607A Target position, profile velocity 0x60FF Target
/// velocity; homing needs nothing. Modes the generic drive does not run
/// need nothing here: [`supports_mode`] refuses them (unless 0x6502
/// declares them: [`declares_mode`]).
pub fn mode_needs(mode: ModeOfOperation) -> &'static [(u16, &'static str)] {
    match mode {
        ModeOfOperation::ProfilePosition | ModeOfOperation::CyclicSynchronousPosition => {
            &[(TARGET_POSITION, "Target position")]
        }
        ModeOfOperation::ProfileVelocity => &[(TARGET_VELOCITY, "Target velocity")],
        _ => &[],
    }
}

/// Whether the generic drive runs `mode` on `table`: no mode (0), profile
/// position (1), profile velocity (3), homing (6) and cyclic synchronous
/// position (8), each only when the table has what [`mode_needs`] lists.
pub fn supports_mode(table: &ObjectTable, mode: ModeOfOperation) -> bool {
    runs(mode)
        && mode_needs(mode)
            .iter()
            .all(|(index, _)| table.info(*index, 0).is_some())
}

/// Whether the drive takes `mode` without running it: a mode of CiA 402
/// (1 to 10) the generic drive does not run (velocity, torque,
/// interpolated position, cyclic synchronous velocity and torque) that
/// the table's 0x6502 Supported drive modes declares. The drive shows it
/// in 0x6061 and holds its position; a network that configures such a
/// mode boots against the simulation as against the device.
pub fn declares_mode(table: &ObjectTable, mode: ModeOfOperation) -> bool {
    let bit = match mode.as_i8() {
        m @ 1..=10 => m - 1,
        _ => return false,
    };
    !runs(mode)
        && table
            .get_uint(SUPPORTED_DRIVE_MODES, 0)
            .is_some_and(|modes| modes >> bit & 1 == 1)
}

/// The modes the generic drive moves in.
fn runs(mode: ModeOfOperation) -> bool {
    matches!(
        mode,
        ModeOfOperation::NoMode
            | ModeOfOperation::ProfilePosition
            | ModeOfOperation::ProfileVelocity
            | ModeOfOperation::Homing
            | ModeOfOperation::CyclicSynchronousPosition
    )
}

/// The value of (index, 0) when the table has it.
pub(crate) fn int(table: &ObjectTable, index: u16) -> Option<i64> {
    table.get_int(index, 0)
}

/// A positive rate from (index, 0), else `fallback`.
fn rate(table: &ObjectTable, index: u16, sub: u8, fallback: f64) -> f64 {
    match table.get_int(index, sub) {
        Some(v) if v > 0 => v as f64,
        _ => fallback,
    }
}

/// Profile velocity, acceleration and deceleration (units/s, units/s²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Profile {
    pub(crate) velocity: f64,
    pub(crate) acceleration: f64,
    pub(crate) deceleration: f64,
}

/// The velocity at most 0x607F (when the table has it and it is not 0).
pub(crate) fn limit_velocity(table: &ObjectTable, velocity: f64) -> f64 {
    match int(table, MAX_PROFILE_VELOCITY) {
        Some(max) if max > 0 => velocity.clamp(-(max as f64), max as f64),
        _ => velocity,
    }
}

/// 0x6081 (at most 0x607F), 0x6083, 0x6084 with their fallbacks.
pub(crate) fn profile(table: &ObjectTable) -> Profile {
    Profile {
        velocity: limit_velocity(
            table,
            rate(table, PROFILE_VELOCITY, 0, DEFAULT_PROFILE_VELOCITY),
        ),
        acceleration: rate(table, PROFILE_ACCELERATION, 0, DEFAULT_PROFILE_ACCELERATION),
        deceleration: rate(table, PROFILE_DECELERATION, 0, DEFAULT_PROFILE_DECELERATION),
    }
}

/// The homing profile: 0x6099 sub 1 and 0x609A, else the profile's.
pub(crate) fn homing_profile(table: &ObjectTable) -> Profile {
    let p = profile(table);
    let acceleration = rate(table, HOMING_ACCELERATION, 0, p.acceleration);
    Profile {
        velocity: limit_velocity(table, rate(table, HOMING_SPEEDS, 1, p.velocity)),
        acceleration,
        deceleration: acceleration,
    }
}

/// Quick stop deceleration 0x6085 with its fallback.
pub(crate) fn quick_stop_deceleration(table: &ObjectTable) -> f64 {
    rate(
        table,
        QUICK_STOP_DECELERATION,
        0,
        DEFAULT_QUICK_STOP_DECELERATION,
    )
}

/// The quick stop option code 0x605A (CiA 402's 2 without it).
pub(crate) fn quick_stop_option_code(table: &ObjectTable) -> i16 {
    int(table, QUICK_STOP_OPTION_CODE).map_or(DEFAULT_QUICK_STOP_OPTION_CODE, |v| {
        v.clamp(i64::from(i16::MIN), i64::from(i16::MAX)) as i16
    })
}

/// The braking ramp of a quick stop or halt option code: 1 and 5 the
/// profile deceleration, anything else the quick stop deceleration.
pub(crate) fn braking(table: &ObjectTable, option_code: i64) -> f64 {
    match option_code {
        1 | 5 => profile(table).deceleration,
        _ => quick_stop_deceleration(table),
    }
}

/// The software position limits 0x607D sub 1 and 2, when both are there
/// and min < max.
pub(crate) fn position_limits(table: &ObjectTable) -> Option<(f64, f64)> {
    let min = table.get_int(SOFTWARE_POSITION_LIMIT, 1)?;
    let max = table.get_int(SOFTWARE_POSITION_LIMIT, 2)?;
    (min < max).then_some((min as f64, max as f64))
}

/// A window (0x6065, 0x6067, ...) when the table has it and it is not
/// 0xFFFFFFFF ("off" in CiA 402).
pub(crate) fn window(table: &ObjectTable, index: u16) -> Option<f64> {
    int(table, index)
        .filter(|v| *v != i64::from(u32::MAX))
        .map(|v| v.unsigned_abs() as f64)
}

/// A time in ms (0x6066, 0x6068), 0 without it.
pub(crate) fn millis(table: &ObjectTable, index: u16) -> std::time::Duration {
    std::time::Duration::from_millis(int(table, index).unwrap_or(0).max(0) as u64)
}
