//! LINAK TECHLINE CANopen actuator (LA14 … LA77, LC3 IC): a behaviour model
//! written from the German "CANopen Montageanleitung" (../shared/seeds/001_*,
//! page numbers from its table of contents), on the generated table
//! [`eds2rust_drivers::linak_techline::od`].
//!
//! What it does, with the page each part comes from:
//! - Command RPDO1 0x2000 (p. 30-31): position 0..=64255 × 0.1 mm runs to
//!   that position; 0xFB00 clear error, 0xFB01 run out, 0xFB02 run in,
//!   0xFB03 stop, 0xFB04/0xFB05 recovery run out/in, 0xFB06.. invalid ("the
//!   actuator does not move": the model stops). Current limit (0.25 A),
//!   speed (0.5 % PWM, 201-250 = 100 %), soft start and soft stop (0.05 s);
//!   0xFB in any of them takes the configuration 0x4000 sub 1-7 (p. 40),
//!   0xFC-0xFF is invalid (no motion). Speed and limits may change during a
//!   run (p. 25-26).
//! - Start and operating conditions (p. 27): no command is accepted without
//!   the master's heartbeat (0x1016 sub 1 must name a producer and a time,
//!   and its heartbeat must not be lost); status bit 5 shows it missing.
//!   Run in / run out (and here every position command) are refused while
//!   the error code is not 0. On every entry into NMT Operational the
//!   actuator needs Stop or Clear error first: error code 1 "power-up lock"
//!   (p. 27-28, error table p. 47).
//! - Start-up trace (p. 28): node 32, boot-up, TPDO1 on entering
//!   Operational with status 0x81 and error 1, AUX byte 0xC0, a stroke of
//!   50.3 mm; running at 1.5 A and 4.9-5.0 mm/s.
//! - Clear error (p. 29): 0xFB00 clears the errors whose cause is gone.
//! - Feedback TPDO1 0x2001 (p. 32-34): position, current (0 = not
//!   running), status flags, error code, speed (0.1 mm/s), AUX inputs.
//!   Status and error changes are sent at once; while moving, position,
//!   current and speed are refreshed once per event timer (0x1800 sub 5,
//!   250 ms), so the TPDO comes at that rate (0x1800 sub 2 is 254,
//!   "manufacturer-specific event"; which events the firmware uses is not
//!   in the manual).
//! - Heartbeat loss (p. 27, error 5 p. 48, EMCY 0x8130 p. 52): the actuator
//!   stops, drops the command, sets status bit 5, error 5 and sends the
//!   EMCY; Clear error ends error 5 once the heartbeat is back.
//! - Faults to inject through [`crate::Device::with_model`]:
//!   [`LinakTechline::set_obstacle_out`] (current limit reached: status bit
//!   2 "overcurrent", stop reason 8, counters 0x4000 sub 0x1C-0x1F),
//!   [`LinakTechline::set_jammed`] (error 12 "position not changing", EMCY
//!   0xFF05, stop reason 512) and [`LinakTechline::set_undervoltage`] (error
//!   4, EMCY 0x3221, cleared by itself when the supply is back, p. 47).
//! - Counters of 0x4000 (p. 42-46): starts and end stops in/out, overload
//!   stops, undervoltage stops, communication errors, total running time,
//!   maximum measured current and the five "reasons for the last stop".
//!
//! Modelled, not from the manual: the factory configuration of 0x4000
//! (limits, ramps, see the constants), the fixed factory current limit,
//! the priority among active errors, the detection time of a jam, the
//! speed and current being constant at a given PWM duty (no load model),
//! the model's TPDO2 (parallel feedback) being disabled (no parallel
//! system; the trace shows none), and LSS identity values beyond the vendor
//! id (taken from the CiA certificate of one unit).

mod diagnostics;
mod logic;
mod motion;

use std::time::Duration;

use eds2rust_drivers::linak_techline::errors::{LastStopReasons, LinakErrors, LinakErrorsCode};
use eds2rust_drivers::linak_techline::od::{self, command as cmd, configuration as cfg};
use eds2rust_drivers::linak_techline::{DEFAULT_NODE_ID, VENDOR_ID};
use eds2rust_runtime::Instant;
use eds2rust_runtime::lss::{BitRate, Identity};
use eds2rust_runtime::nmt::NmtState;
use eds2rust_runtime::od::{Entry, NodeId};
use eds2rust_runtime::sdo::abort::AbortCode;

use crate::{Behaviour, Context, Device, DeviceConfig};
use diagnostics::{Errors, bump};
use motion::{Goal, Piston, Profile};

/// The node id at delivery (p. 24: 32).
pub const NODE: NodeId = match NodeId::new(DEFAULT_NODE_ID) {
    Some(node) => node,
    None => panic!("the generated default node id is 1..=127"),
};

/// The bit rate at delivery (p. 24: 250 kbit/s).
pub const BIT_RATE: BitRate = BitRate::Kbit250;

/// The simulated unit's serial number (0x1018 sub 4, = UIN 0x4000 sub 0x0A;
/// an 8-digit number, p. 38 and p. 41). Modelled.
pub const SERIAL: u32 = 12_345_678;

/// The LSS address (p. 24 names LSS): vendor 0x4AA (p. 38); product code
/// and revision as on LINAK's CiA certificate (one tested unit).
pub const IDENTITY: Identity = Identity::new(VENDOR_ID, 0x0010_0597, 0x0001_0000, SERIAL);

/// Stroke of the simulated actuator: the trace's outer end stop (p. 28).
pub const STROKE_MM: f64 = 50.3;
/// Speed at 100 % PWM duty; the trace shows 4.9 and 5.0 mm/s at the default
/// speed (p. 28). Modelled.
pub const FULL_SPEED_MM_S: f64 = 5.0;
/// Motor current while running; the trace shows 1.5 A (p. 28). Modelled as
/// constant.
pub const RUNNING_CURRENT_A: f64 = 1.5;
/// AUX inputs of the trace: input 4 at 76-100 % VCC (p. 18, p. 28).
pub const AUX_INPUTS: u8 = 0xC0;
/// Factory default current limit in/out (0x4000 sub 1/2). Modelled.
pub const DEFAULT_CURRENT_LIMIT_A: f64 = 4.0;
/// The fixed factory limit a user limit cannot exceed (p. 25). Modelled.
pub const FACTORY_CURRENT_LIMIT_A: f64 = 8.0;
/// Factory soft start and soft stop (0x4000 sub 3-6, 1 ms/bit). Modelled.
pub const DEFAULT_RAMP_MS: u16 = 300;
/// How long the motor may be powered without the position changing before
/// error 12 (mechanical time). Modelled.
pub const JAM_DETECTION: Duration = Duration::from_millis(500);

/// The manual's start-up trace (p. 28): every frame that does not depend
/// on the motion, in its order (master heartbeat, boot-up, 0x1016 sub 1
/// written and confirmed, NMT start, TPDO1 "stop required", Stop, TPDO1,
/// run out, TPDO1 at the outer end stop, run in, TPDO1 at the inner one).
pub const MANUAL_TRACE: [&str; 12] = [
    "701#05",
    "720#00",
    "620#23161001C8000100",
    "5A0#6016100100000000",
    "000#0120",
    "1A0#00000081010000C0",
    "220#03FBFBFBFBFB0000",
    "1A0#00000081000000C0",
    "220#01FBFBFBFBFB0000",
    "1A0#F7010082000000C0",
    "220#02FBFBFBFBFB0000",
    "1A0#00000081000000C0",
];

/// A direction of travel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Outwards (the piston extends).
    Out,
    /// Inwards.
    In,
}

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// An end stop in the direction of travel.
    EndStop(Direction),
    /// The commanded position.
    Target,
    /// Stop, Clear error or another command that ends the run.
    Command,
    /// An invalid command value (0xFB06.. or 0xFC-0xFF in a setting).
    Invalid,
    /// The current limit was reached (status bit 2).
    Overcurrent,
    /// The master's heartbeat was lost.
    HeartbeatLost,
    /// The device left NMT Operational.
    NotOperational,
    /// A fault with this error code.
    Fault(LinakErrors),
}

/// Why a command was not taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// No master heartbeat (p. 27).
    HeartbeatMissing,
    /// An error code is present (p. 27, p. 29).
    Error(LinakErrors),
    /// Motion only in NMT Operational.
    NotOperational,
}

/// What the simulated actuator reports to the application.
#[derive(Debug, Clone, PartialEq)]
pub enum LinakTechlineEvent {
    /// The motor started in `direction` from `from_mm`.
    MotionStarted {
        /// Direction of travel.
        direction: Direction,
        /// Position at the start, mm.
        from_mm: f64,
    },
    /// The motor stopped at `position_mm`.
    MotionStopped {
        /// Position, mm.
        position_mm: f64,
        /// Why.
        reason: StopReason,
    },
    /// The error code of the feedback changed.
    ErrorCode(LinakErrorsCode),
    /// A command (raw 0x2000 sub 1 value) was refused.
    CommandRefused {
        /// The command's raw position value.
        command: u16,
        /// Why.
        reason: Refusal,
    },
}

/// One run of the motor.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Run {
    goal: Goal,
    direction: Direction,
    profile: Profile,
    /// Current limit in A and whether it is the user's (RPDO) limit.
    limit_a: f64,
    user_limit: bool,
    /// Mechanical seconds powered without the position changing.
    stalled_s: f64,
    /// What ends the run when a halt completes.
    halt_reason: StopReason,
}

/// The TPDO1 values (0x2001 sub 1-6) in their raw form.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Feedback {
    position: u16,
    current: u8,
    status: u8,
    error: u8,
    speed: u16,
    aux: u8,
}

/// The LINAK TECHLINE actuator model (see the module documentation).
#[derive(Debug, Clone)]
pub struct LinakTechline {
    time_scale: f64,
    full_speed: f64,
    running_current: f64,
    aux: u8,
    piston: Piston,
    run: Option<Run>,
    pending: Option<cmd::PositionValue>,
    errors: Errors,
    overcurrent: bool,
    heartbeat_lost: bool,
    obstacle_out: Option<f64>,
    jammed: bool,
    undervoltage: bool,
    last_step: Option<Instant>,
    published: Option<Feedback>,
    last_publish: Instant,
    shown_error: u8,
    running_s: f64,
}

impl Default for LinakTechline {
    fn default() -> Self {
        LinakTechline::new()
    }
}

impl LinakTechline {
    /// An actuator as in the manual's trace: 50.3 mm stroke, fully in.
    pub fn new() -> LinakTechline {
        LinakTechline {
            time_scale: 1.0,
            full_speed: FULL_SPEED_MM_S,
            running_current: RUNNING_CURRENT_A,
            aux: AUX_INPUTS,
            piston: Piston {
                position: 0.0,
                velocity: 0.0,
                stroke: STROKE_MM,
            },
            run: None,
            pending: None,
            errors: Errors::default(),
            overcurrent: false,
            heartbeat_lost: false,
            obstacle_out: None,
            jammed: false,
            undervoltage: false,
            last_step: None,
            published: None,
            last_publish: Instant::ZERO,
            shown_error: 0,
            running_s: 0.0,
        }
    }

    /// Mechanics `factor` times faster than real time (> 0; others are
    /// ignored). Bus timing (heartbeat, event timer) stays real.
    pub fn with_time_scale(mut self, factor: f64) -> LinakTechline {
        if factor.is_finite() && factor > 0.0 {
            self.time_scale = factor;
        }
        self
    }

    /// Another stroke length in mm (> 0, at most 6425.5 mm, the feedback's
    /// range); the position is clamped to it.
    pub fn with_stroke_mm(mut self, stroke: f64) -> LinakTechline {
        if stroke.is_finite() && stroke > 0.0 {
            self.piston.stroke = stroke.min(6425.5);
            self.piston.position = self.piston.position.min(self.piston.stroke);
        }
        self
    }

    /// The position at power-on in mm (clamped to the stroke).
    pub fn with_position_mm(mut self, position: f64) -> LinakTechline {
        if position.is_finite() {
            self.piston.position = position.clamp(0.0, self.piston.stroke);
        }
        self
    }

    /// The speed at 100 % PWM in mm/s (>= 0).
    pub fn with_full_speed_mm_s(mut self, speed: f64) -> LinakTechline {
        if speed.is_finite() && speed >= 0.0 {
            self.full_speed = speed.min(401.5);
        }
        self
    }

    /// The motor current while running in A (>= 0).
    pub fn with_running_current_a(mut self, amps: f64) -> LinakTechline {
        if amps.is_finite() && amps >= 0.0 {
            self.running_current = amps;
        }
        self
    }

    /// The AUX input byte (p. 18: four 2-bit levels).
    pub fn with_aux_inputs(mut self, aux: u8) -> LinakTechline {
        self.aux = aux;
        self
    }

    /// The mechanics' speed-up over real time.
    pub fn time_scale(&self) -> f64 {
        self.time_scale
    }

    /// The stroke in mm.
    pub fn stroke_mm(&self) -> f64 {
        self.piston.stroke
    }

    /// The piston position in mm.
    pub fn position_mm(&self) -> f64 {
        self.piston.position
    }

    /// The piston speed in mm/s, positive outwards.
    pub fn velocity_mm_s(&self) -> f64 {
        self.piston.velocity
    }

    /// The direction of the run in progress, if the motor runs.
    pub fn running(&self) -> Option<Direction> {
        self.run.map(|r| r.direction)
    }

    /// The error the feedback shows.
    pub fn error(&self) -> LinakErrors {
        self.errors.reported()
    }

    /// Puts an obstacle (or removes it) that stops the piston running out
    /// at `at_mm`: the current reaches the limit and the motor is cut off.
    pub fn set_obstacle_out(&mut self, at_mm: Option<f64>) {
        self.obstacle_out = at_mm.filter(|x| x.is_finite());
    }

    /// Jams the spindle (or frees it): the motor is powered but the
    /// position does not change; after [`JAM_DETECTION`] error 12.
    pub fn set_jammed(&mut self, jammed: bool) {
        self.jammed = jammed;
    }

    /// Sets the AUX input byte the feedback reports.
    pub fn set_aux_inputs(&mut self, aux: u8) {
        self.aux = aux;
    }

    /// Supply below the operating voltage (or back): the motor stops, error
    /// 4 and EMCY 0x3221; it clears by itself when the supply is back
    /// (p. 47-48).
    pub fn set_undervoltage(&mut self, ctx: &mut Context<'_, LinakTechlineEvent>, low: bool) {
        if low == self.undervoltage {
            return;
        }
        self.undervoltage = low;
        if low {
            if self.run.is_some() {
                bump::<cfg::StopsUndervoltage, _>(ctx);
                self.record(ctx, LastStopReasons::Undervoltage);
            }
            self.stop_now(ctx, StopReason::Fault(LinakErrors::Undervoltage));
            self.errors.raise(ctx, LinakErrors::Undervoltage);
        } else {
            self.errors.clear(ctx, LinakErrors::Undervoltage);
        }
        self.publish(ctx, true);
    }

    /// Power-on: factory configuration, errors reset, power-up lock.
    fn power_on(&mut self, ctx: &mut Context<'_, LinakTechlineEvent>) {
        let limit = cfg::CurrentLimitOutValue::from_raw((DEFAULT_CURRENT_LIMIT_A / 0.25) as u8);
        ctx.set::<cfg::CurrentLimitOut>(limit);
        ctx.set::<cfg::CurrentLimitIn>(cfg::CurrentLimitInValue::from_raw(limit.to_raw()));
        ctx.set::<cfg::SoftStartOut>(cfg::SoftStartOutValue::from_raw(DEFAULT_RAMP_MS));
        ctx.set::<cfg::SoftStartIn>(cfg::SoftStartInValue::from_raw(DEFAULT_RAMP_MS));
        ctx.set::<cfg::SoftStopOut>(cfg::SoftStopOutValue::from_raw(DEFAULT_RAMP_MS));
        ctx.set::<cfg::SoftStopIn>(cfg::SoftStopInValue::from_raw(DEFAULT_RAMP_MS));
        ctx.set::<cfg::MaxSpeed>(cfg::MaxSpeedValue::from_raw(0xC8));
        ctx.set::<cfg::Uin>(SERIAL);
        ctx.set::<od::identity::ProductCode>(IDENTITY.product_code);
        ctx.set::<od::identity::RevisionNumber>(IDENTITY.revision);
        ctx.set::<od::identity::SerialNumber>(IDENTITY.serial);
        // The command's settings start at "default" (0xFB), so that a
        // position written alone (SDO, p. 29) runs with the configuration.
        ctx.set::<cmd::CurrentLimit>(cmd::CurrentLimitValue::DEFAULT);
        ctx.set::<cmd::Speed>(cmd::SpeedValue::DEFAULT);
        ctx.set::<cmd::SoftStart>(cmd::SoftStartValue::DEFAULT);
        ctx.set::<cmd::SoftStop>(cmd::SoftStopValue::DEFAULT);
        ctx.set::<cmd::Position>(cmd::PositionValue::STOP);
        self.run = None;
        self.piston.velocity = 0.0;
        self.pending = None;
        self.overcurrent = false;
        self.errors.reset();
        self.errors.raise(ctx, LinakErrors::PowerUpLock);
        if self.undervoltage {
            self.errors.raise(ctx, LinakErrors::Undervoltage);
        }
        self.communication_reset(ctx);
    }

    /// After power-on and NMT resets: the heartbeat consumer starts afresh;
    /// RPDO1 is asynchronous (0x1400 sub 2 = 255: the manual gives no
    /// default, its trace shows commands acted on without SYNC, p. 28);
    /// TPDO2 (parallel feedback) is marked invalid.
    fn communication_reset(&mut self, ctx: &mut Context<'_, LinakTechlineEvent>) {
        self.heartbeat_lost = false;
        use eds2rust_runtime::od::standard::TransmissionType as Type;
        use od::rpdo1_communication_parameter::TransmissionType;
        use od::tpdo2_communication_parameter::CobIdUsedByTpdo;
        ctx.set::<TransmissionType>(Type::EventDrivenProfile);
        if let Some(cob) = ctx.get::<CobIdUsedByTpdo>() {
            ctx.set::<CobIdUsedByTpdo>(cob.with_valid(false));
        }
        self.publish(ctx, true);
    }
}

impl Behaviour for LinakTechline {
    type Event = LinakTechlineEvent;

    fn check_write(
        &mut self,
        ctx: &mut Context<'_, LinakTechlineEvent>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), AbortCode> {
        if index != cmd::INDEX {
            return Ok(());
        }
        let position = sub == cmd::Position::SUBINDEX;
        let refusal = if !self.heartbeat_ok(ctx) {
            Some(Refusal::HeartbeatMissing)
        } else {
            None
        };
        let (command, refusal) = match data {
            [lo, hi] if position => {
                let command = u16::from_le_bytes([*lo, *hi]);
                let refusal =
                    refusal.or_else(|| self.refusal(ctx, cmd::PositionValue::from_raw(command)));
                (Some(command), refusal)
            }
            _ => (None, refusal),
        };
        match (command, refusal) {
            (_, None) => Ok(()),
            (Some(command), Some(reason)) => {
                // One event per command, not per field of the RPDO.
                ctx.emit(LinakTechlineEvent::CommandRefused { command, reason });
                Err(AbortCode::CannotTransferDeviceState)
            }
            (None, Some(_)) => Err(AbortCode::CannotTransferDeviceState),
        }
    }

    fn written(&mut self, ctx: &mut Context<'_, LinakTechlineEvent>, index: u16, sub: u8) {
        if (index, sub) == (cmd::Position::INDEX, cmd::Position::SUBINDEX) {
            self.pending = ctx.get::<cmd::Position>();
        } else if index == od::consumer_heartbeat_time::INDEX {
            // The device restarts its consumer with the new entry.
            self.heartbeat_lost = false;
            self.publish(ctx, false);
        }
    }

    fn step(&mut self, ctx: &mut Context<'_, LinakTechlineEvent>) {
        let now = ctx.now();
        let dt = self
            .last_step
            .map_or(0.0, |t| now.saturating_duration_since(t).as_secs_f64());
        self.last_step = Some(now);
        if let Some(command) = self.pending.take() {
            self.execute(ctx, command);
        }
        self.advance(ctx, dt * self.time_scale);
        self.publish(ctx, false);
    }

    fn nmt_changed(
        &mut self,
        ctx: &mut Context<'_, LinakTechlineEvent>,
        from: NmtState,
        to: NmtState,
    ) {
        if from == NmtState::BootUp {
            self.communication_reset(ctx);
        }
        if from == NmtState::Operational && self.run.is_some() {
            self.stop_now(ctx, StopReason::NotOperational);
        }
        if to == NmtState::Operational {
            // p. 27: on entering Operational the actuator needs Stop or
            // Clear error first.
            self.errors.raise(ctx, LinakErrors::PowerUpLock);
        }
        self.publish(ctx, true);
    }

    fn heartbeat_lost(&mut self, ctx: &mut Context<'_, LinakTechlineEvent>, _node: NodeId) {
        self.heartbeat_lost = true;
        self.pending = None;
        if self.run.is_some() {
            self.record(ctx, LastStopReasons::CommunicationInterrupted);
            self.stop_now(ctx, StopReason::HeartbeatLost);
        }
        bump::<cfg::CommunicationErrors, _>(ctx);
        self.errors
            .raise(ctx, LinakErrors::CommunicationSynchronisation);
        self.publish(ctx, true);
    }

    fn heartbeat_resumed(&mut self, ctx: &mut Context<'_, LinakTechlineEvent>, _node: NodeId) {
        self.heartbeat_lost = false;
        self.publish(ctx, true);
    }

    fn reset_application(&mut self, ctx: &mut Context<'_, LinakTechlineEvent>) {
        self.published = None;
        self.power_on(ctx);
    }
}

/// The device configuration at delivery: node 32, 250 kbit/s, LSS slave
/// (p. 24).
pub fn default_config() -> DeviceConfig {
    DeviceConfig {
        node: Some(NODE),
        lss: Some(IDENTITY),
        bit_rate: BIT_RATE,
    }
}

/// A simulated actuator as delivered, powered on at `now`.
pub fn simulator(now: Instant) -> Device<LinakTechline> {
    simulator_with(LinakTechline::new(), default_config(), now)
}

/// A simulated actuator with `model` and `config`, powered on at `now`.
pub fn simulator_with(
    model: LinakTechline,
    config: DeviceConfig,
    now: Instant,
) -> Device<LinakTechline> {
    let mut device = Device::new(od::OBJECTS, config, model, now);
    device.with_model(now, |model, ctx| model.power_on(ctx));
    device
}
