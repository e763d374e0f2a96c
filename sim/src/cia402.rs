//! A generic CiA 402 drive behaviour for any object table that has a
//! controlword 0x6040 and a statusword 0x6041: no generated code, no
//! device manual, only the objects of CiA 402 that the table happens to
//! have.
//!
//! - Power state machine: the runtime's [`DeviceStateMachine`] takes the
//!   transitions (controlword 0x6040 written by SDO or RPDO); the
//!   statusword 0x6041 it computes is stored in the table after every input
//!   and every step, so TPDOs that map it carry it. Modes of operation
//!   0x6060 are shown in 0x6061.
//! - Profile position (1): new set-point handshake (bit 4 / bit 12),
//!   absolute or relative (bit 6; relative to the preceding target, or as
//!   the positioning option code 0x60F2 bits 0-1 say), change set
//!   immediately (bit 5) or one buffered set-point, halt (bit 8, with the
//!   halt option code 0x605D). Target reached (bit 10) once the actual
//!   position is within the position window 0x6067 (exact without it) for
//!   the window time 0x6068 (none without it).
//! - Profile velocity (3): target velocity 0x60FF, ramped with 0x6083 and
//!   0x6084; bit 10 within the velocity window 0x606D, bit 12 (speed 0)
//!   within the velocity threshold 0x606F.
//! - Homing (6): a simple homing: the axis moves at the homing speed 0x6099
//!   sub 1 (else the profile velocity) with the homing acceleration 0x609A
//!   to the home switch, which is where the model powered on at position 0;
//!   there the position is set to the home offset 0x607C (or 0) and homing
//!   attained (bit 12) and target reached (bit 10) are set. Methods 35 and
//!   37 (current position) home where the axis is, after 20 ms.
//! - Cyclic synchronous position (8): the target 0x607A is taken at once.
//! - Motion: a trapezoid (the `profiler` module) in the device's own
//!   position units (no factor group), with profile velocity 0x6081 (at most 0x607F),
//!   acceleration 0x6083 and deceleration 0x6084; where one is absent or 0
//!   the `DEFAULT_*` constants below apply. Published: position actual
//!   0x6064 (and 0x6063), demand 0x6062 (and 0x60FC), velocity actual
//!   0x606C, velocity demand 0x606B, following error actual 0x60F4.
//! - Software position limits 0x607D sub 1/2 (active when min < max):
//!   targets are clamped, statusword bit 11 (internal limit active) is set.
//! - Following error: [`Cia402::set_lag`] makes the actual position lag the
//!   demand; more than the window 0x6065 for longer than 0x6066 ms sets
//!   statusword bit 13 (and [`Cia402Event::FollowingError`]); it is a
//!   warning here, not a fault (what a drive does next is vendor specific).
//! - Quick stop: the option code 0x605A (2 without it) picks the ramp: 0
//!   coasts, 1 and 5 the profile deceleration 0x6084, the others the quick
//!   stop deceleration 0x6085; 0..=4 then go to Switch on disabled
//!   (transition 12), 5..=8 stay in Quick stop active. The state machine
//!   takes the option code at power-on and whenever it is in Switch on
//!   disabled (a write in another state waits for that state).
//! - Faults: [`Cia402::inject_fault`] raises one (error code 0x603F, the
//!   error register 0x1001 bit 0, EMCY); a fault reset (transition 15)
//!   clears them and sends the EMCY "error reset".
//!
//! Every object but 0x6040/0x6041 is optional: it is read only when the
//! table has it, and values the model publishes go only to the entries the
//! table has. A mode whose objects are missing ([`mode_needs`]) is refused
//! with abort 0x06090030 when 0x6060 is written; a mode the drive does not
//! run is refused too, unless 0x6502 declares it ([`declares_mode`]: taken,
//! shown in 0x6061, the axis holds its position).

pub(crate) mod axis;
mod drive;
mod logic;
mod monitor;
mod objects;
pub(crate) mod profiler;

use std::time::Duration;

use eds2rust_runtime::Instant;
use eds2rust_runtime::cia402::{ModeOfOperation, State};
use eds2rust_runtime::od::ObjectInfo;
use eds2rust_runtime::sdo::abort::AbortCode;

use crate::{Behaviour, Context, Device, DeviceConfig};
use axis::Axis;
pub use objects::{declares_mode, mode_needs, supports_mode};

/// Profile velocity (position units/s) when 0x6081 is absent or 0.
pub const DEFAULT_PROFILE_VELOCITY: f64 = 10_000.0;
/// Profile acceleration (units/s²) when 0x6083 is absent or 0.
pub const DEFAULT_PROFILE_ACCELERATION: f64 = 100_000.0;
/// Profile deceleration (units/s²) when 0x6084 is absent or 0.
pub const DEFAULT_PROFILE_DECELERATION: f64 = 100_000.0;
/// Quick stop deceleration (units/s²) when 0x6085 is absent or 0.
pub const DEFAULT_QUICK_STOP_DECELERATION: f64 = 1_000_000.0;
/// The quick stop option code when 0x605A is absent (CiA 402's default:
/// quick stop ramp, then Switch on disabled).
pub const DEFAULT_QUICK_STOP_OPTION_CODE: i16 = 2;
/// The error code (0x603F, EMCY) of [`Cia402::inject_fault`] callers that
/// have none of their own: CiA 402 "generic drive error" is not defined, so
/// this is CiA 301's "generic error" 0x1000.
pub const GENERIC_ERROR: u16 = 0x1000;

/// What the generic drive reports to the application.
#[derive(Debug, Clone, PartialEq)]
pub enum Cia402Event {
    /// The state machine took transition `transition`.
    StateChanged {
        /// The CiA 402 transition number.
        transition: u8,
        /// The state left (`None` at power-on).
        from: Option<State>,
        /// The state entered.
        to: State,
    },
    /// A new set-point was taken (profile position).
    SetPointAccepted {
        /// The absolute target it gives (after the limits).
        target: i64,
        /// Controlword bit 6.
        relative: bool,
        /// Controlword bit 5.
        immediate: bool,
    },
    /// A target outside the software position limits was clamped.
    TargetLimited {
        /// The target asked for.
        requested: i64,
        /// The target used.
        limited: i64,
    },
    /// Target reached (statusword bit 10) after a move.
    TargetReached {
        /// The actual position.
        position: i64,
    },
    /// Homing attained; the position is now the home offset.
    HomingAttained {
        /// The actual position (the home offset).
        position: i64,
    },
    /// The following error exceeded its window for longer than its time
    /// (statusword bit 13).
    FollowingError {
        /// Demand minus actual position.
        error: i64,
    },
    /// A fault was raised with this error code (0x603F).
    Fault(u16),
}

/// The generic CiA 402 drive (see the module documentation).
#[derive(Debug, Clone)]
pub struct Cia402 {
    /// The axis (positions in the device's units).
    axis: Axis,
    /// Actual velocity (units/s).
    actual_velocity: f64,
    /// Where the home switch is, in the current coordinates.
    home_switch: f64,
    /// Homing on the current position ends at this time.
    homing_in_place: Option<Instant>,
    /// The actual position follows the demand at most this fast (units/s).
    lag: Option<f64>,
    /// 0x605A was written; the state machine takes it in Switch on disabled.
    option_code_changed: bool,
    /// An EMCY with an error was sent and not yet reset.
    emcy_sent: bool,
}

impl Default for Cia402 {
    fn default() -> Self {
        Cia402::new()
    }
}

impl Cia402 {
    /// A drive at position 0, following its demand exactly, in real time.
    pub fn new() -> Cia402 {
        Cia402 {
            axis: Axis::new(),
            actual_velocity: 0.0,
            home_switch: 0.0,
            homing_in_place: None,
            lag: None,
            option_code_changed: false,
            emcy_sent: false,
        }
    }

    /// This model with the mechanics `factor` times faster than real time
    /// (a factor that is not a positive number leaves it unchanged).
    pub fn with_time_scale(mut self, factor: f64) -> Cia402 {
        self.axis.set_time_scale(factor);
        self
    }

    /// This model with the axis at `position` (units) at power-on; the
    /// home switch stays at 0.
    pub fn with_position(mut self, position: i64) -> Cia402 {
        self.axis.place(position as f64);
        self
    }

    /// The mechanics' speed-up over real time.
    pub fn time_scale(&self) -> f64 {
        self.axis.time_scale
    }

    /// The CiA 402 state (`None` before power-on).
    pub fn state(&self) -> Option<State> {
        self.axis.state()
    }

    /// The mode of operation in effect (`NoMode` before power-on).
    pub fn mode(&self) -> ModeOfOperation {
        self.axis.mode()
    }

    /// The actual position (units).
    pub fn position(&self) -> f64 {
        self.axis.actual
    }

    /// The demand position of the trajectory generator (units).
    pub fn demand(&self) -> f64 {
        self.axis.profiler.position
    }

    /// The actual velocity (units/s).
    pub fn velocity(&self) -> f64 {
        self.actual_velocity
    }

    /// Makes the actual position lag the demand (a test hook for the
    /// following error): with `Some(speed)` it follows at most `speed`
    /// units/s (0: the axis is blocked); `None` follows exactly.
    pub fn set_lag(&mut self, speed: Option<f64>) {
        self.lag = speed.map(|s| if s.is_finite() { s.abs() } else { 0.0 });
    }

    /// Raises a fault with error code `code` (0x603F): Fault reaction
    /// active, then Fault; 0x1001 bit 0 and an EMCY.
    pub fn inject_fault(&mut self, ctx: &mut Context<'_, Cia402Event>, code: u16) {
        self.begin(ctx);
        self.fault(ctx, code);
        self.finish(ctx);
    }
}

impl Behaviour for Cia402 {
    type Event = Cia402Event;

    fn check_write(
        &mut self,
        ctx: &mut Context<'_, Cia402Event>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), AbortCode> {
        match (index, sub, data) {
            (objects::MODES_OF_OPERATION, 0, [mode]) => {
                let mode = ModeOfOperation::from_i8(*mode as i8);
                if supports_mode(ctx.table(), mode) || declares_mode(ctx.table(), mode) {
                    Ok(())
                } else {
                    Err(AbortCode::InvalidValue)
                }
            }
            (objects::QUICK_STOP_OPTION_CODE, 0, [lo, hi]) => {
                if (0..=8).contains(&i16::from_le_bytes([*lo, *hi])) {
                    Ok(())
                } else {
                    Err(AbortCode::InvalidValue)
                }
            }
            _ => Ok(()),
        }
    }

    fn written(&mut self, ctx: &mut Context<'_, Cia402Event>, index: u16, sub: u8) {
        self.begin(ctx);
        match (index, sub) {
            (objects::CONTROLWORD, 0) => self.apply_controlword(ctx),
            (objects::MODES_OF_OPERATION, 0) => self.apply_mode(ctx),
            (objects::QUICK_STOP_OPTION_CODE, 0) => {
                self.option_code_changed = true;
                self.take_option_code(ctx);
            }
            _ => {}
        }
        self.finish(ctx);
    }

    fn step(&mut self, ctx: &mut Context<'_, Cia402Event>) {
        self.begin(ctx);
        self.monitor(ctx);
        self.finish(ctx);
    }

    fn period(&self) -> Duration {
        Duration::from_millis(5)
    }

    fn reset_application(&mut self, ctx: &mut Context<'_, Cia402Event>) {
        self.power_on(ctx);
    }
}

/// A simulated CiA 402 drive on the table `objects` (a generated
/// `od::OBJECTS` or [`crate::file::load`]'s), with `model`, powered on at
/// `now`.
pub fn simulator(
    objects: &'static [ObjectInfo],
    config: DeviceConfig,
    model: Cia402,
    now: Instant,
) -> Device<Cia402> {
    let mut device = Device::new(objects, config, model, now);
    device.with_model(now, |model, ctx| model.power_on(ctx));
    device
}
