//! Interroll RollerDrive EC5000 BI (CANopen, CiA 402), modelled from its
//! interface description ("Schnittstellenbeschreibung RollerDrive EC5000
//! BI", V1.2 09/2022; chapter numbers below are that manual's).
//!
//! - Addressing (chapter 3): delivered with node id 127, which takes part
//!   in NMT and SDO like any node id and enables LSS (switch state global
//!   and selective, configure node id, store configuration). The device's
//!   LSS slave makes a configured node id active at NMT reset
//!   communication; only a stored one survives [`Device::power_cycle`].
//! - The CiA 402 state machine (chapters 2.1, 2.2) is the runtime's
//!   [`DeviceStateMachine`]; quick stop keeps the drive in Quick stop
//!   active, holding (transition 16 back to Operation enabled, chapter
//!   2.2 row 16).
//! - Profile velocity (mode 3, default, chapter 4.2): the actual velocity
//!   follows 0x60FF on the 0x6083/0x6084 ramps; halt (controlword bit 8)
//!   or a target below the minimum velocity stops it into zero motion
//!   hold. Statusword bits 10 and 12 are reserved in this mode (4.2 table)
//!   and stay 0.
//! - Profile position (mode 1, chapter 4.3): set-point handshake (bits 4,
//!   12), absolute/relative (bit 6), change set immediately (bit 5), one
//!   buffered set-point with bit 12 held while it waits, bit 9 (pass the
//!   first target at full speed), halt, target reached (bit 10).
//! - Homing (mode 6, method 37, chapter 4.3): bit 4 sets the current
//!   position to 0 without moving, at standstill (halt) or in Switched on.
//! - Mode switching (chapter 4.1 matrix): a change of 0x6060 in Operation
//!   enabled is taken only at standstill (velocity: zero motion hold;
//!   position and homing: halted); otherwise abort 0x08000022.
//! - Monitoring 0x2200, status lights 0x2210/0x2211 (chapter 6), torque
//!   0x6077 and DC link voltage 0x6079 from a load, thermal and supply
//!   model ([`Load`]); values are simulated, not measured.
//! - Errors (chapters 5, 9): EMCY with the chapter 9 codes, pre-defined
//!   error field 0x1003, error register, fault reset by a rising edge of
//!   bit 7 once no error is present; abort connection option code 0x6007
//!   on a lost heartbeat (chapter 5.2).
//! - TPDO timing (chapter 8) is the generic device's, from the table.

mod faults;
mod physics;
mod running;

use std::time::Duration;

use eds2rust_drivers::interroll_ec5000bi::{
    DEFAULT_NODE_ID, PRODUCT_CODE, REVISION_NUMBER, VENDOR_ID, od,
};
use eds2rust_runtime::Instant;
use eds2rust_runtime::cia402::{self, DeviceStateMachine, ModeOfOperation, State};
use eds2rust_runtime::lss::{BitRate, Identity};
use eds2rust_runtime::nmt::NmtState;
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::abort::AbortCode;

use crate::{Behaviour, Context, Device, DeviceConfig};
use faults::Faults;
pub use faults::is_warning;
pub use physics::Load;
use physics::{Electrics, Positioning};

/// The serial number the default simulator reports (0x1018 sub 4 and the
/// LSS address); a real drive has its own.
pub const DEFAULT_SERIAL: u32 = 0x0012_D687;

/// What the model reports besides the generic device events.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ec5000BiEvent {
    /// A CiA 402 transition (chapter 2.2 numbers).
    Transition {
        /// The transition number (0 to 16).
        number: u8,
        /// The state left (`None` at power-on).
        from: Option<State>,
        /// The state entered.
        to: State,
    },
    /// The mode of operation in effect changed (0x6061).
    ModeChanged(ModeOfOperation),
    /// The roller started to turn.
    MotionStarted,
    /// The roller came to rest (zero motion hold when powered, freewheel
    /// otherwise), at this position in mm.
    Standstill {
        /// 0x6064 in mm.
        position_mm: i32,
    },
    /// A profile-position set-point was taken (chapter 4.3).
    SetPoint {
        /// The set-point in mm.
        target_mm: i32,
        /// Whether it was buffered behind the running positioning.
        buffered: bool,
    },
    /// The final profile-position target was reached.
    TargetReached {
        /// 0x6064 in mm.
        position_mm: i32,
    },
    /// Homing method 37 ended; `false`: refused because the roller moved.
    Homed(bool),
    /// An error (must be acknowledged) was raised with this EMCY code.
    Error(u16),
    /// A warning was raised with this EMCY code.
    Warning(u16),
    /// The condition behind this code went away.
    Cleared(u16),
    /// The heartbeat of `node` was lost; `option` is 0x6007.
    ConnectionLost {
        /// The silent node.
        node: NodeId,
        /// The abort connection option code in effect.
        option: i16,
    },
}

/// Drive-wide figures the manual calls remanent ("teilweise remanent
/// gespeichert", chapter 6.1): they survive resets and power cycles.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Lifetime {
    start_stops: u32,
    working_s: f64,
    uptime_s: f64,
    t_min: Option<f64>,
    t_max: Option<f64>,
    quick_stops: u16,
    distance_mm: f64,
    power_avg_w: f64,
}

/// The RollerDrive EC5000 BI behaviour (see the module documentation).
#[derive(Debug, Clone)]
pub struct Ec5000Bi {
    time_scale: f64,
    serial: u32,
    nominal_power_w: u8,
    load: Load,
    ambient_c: f64,
    supply_mv: u32,
    started: bool,
    sm: DeviceStateMachine,
    last: Instant,
    /// Roller surface velocity (mm/s) and position (mm), before polarity.
    v: f64,
    pos: f64,
    internal_limit: bool,
    moving: bool,
    pp: Positioning,
    electrics: Electrics,
    faults: Faults,
    life: Lifetime,
    monitor_in: f64,
}

impl Default for Ec5000Bi {
    fn default() -> Self {
        Ec5000Bi::new()
    }
}

/// The CiA 402 behaviour: instant start-up and fault reaction (the
/// unpowered roller then coasts), quick stop ramp ended by the model, and
/// an option code that stays in Quick stop active (chapter 2.2 row 16).
fn sm_config() -> cia402::DeviceConfig {
    cia402::DeviceConfig {
        start_up: Duration::ZERO,
        fault_reaction: Some(Duration::ZERO),
        quick_stop: None,
        quick_stop_option_code: 6,
        voltage_enabled: true,
        remote: true,
    }
}

impl Ec5000Bi {
    /// A 35 W drive with serial [`DEFAULT_SERIAL`], the default [`Load`],
    /// 25 °C ambient and a 24 V supply, in real time.
    pub fn new() -> Ec5000Bi {
        Ec5000Bi {
            time_scale: 1.0,
            serial: DEFAULT_SERIAL,
            nominal_power_w: 35,
            load: Load::default(),
            ambient_c: 25.0,
            supply_mv: 24_000,
            started: false,
            sm: DeviceStateMachine::new(Instant::ZERO, sm_config()),
            last: Instant::ZERO,
            v: 0.0,
            pos: 0.0,
            internal_limit: false,
            moving: false,
            pp: Positioning::default(),
            electrics: Electrics::new(25.0),
            faults: Faults::default(),
            life: Lifetime::default(),
            monitor_in: 0.0,
        }
    }

    /// Mechanics and thermals run `factor` times faster than real time
    /// (non-positive or non-finite values are taken as 1.0).
    pub fn with_time_scale(mut self, factor: f64) -> Ec5000Bi {
        self.time_scale = if factor.is_finite() && factor > 0.0 {
            factor
        } else {
            1.0
        };
        self
    }

    /// The serial number (0x1018 sub 4; use the same in the LSS address).
    pub fn with_serial(mut self, serial: u32) -> Ec5000Bi {
        self.serial = serial;
        self
    }

    /// The power variant, 20, 35 or 50 W (0x4048; the manual's default
    /// column reads "20/35/50").
    pub fn with_nominal_power(mut self, watts: u8) -> Ec5000Bi {
        self.nominal_power_w = watts.max(1);
        self
    }

    /// What the conveyor puts on the roller.
    pub fn with_load(mut self, load: Load) -> Ec5000Bi {
        self.load = load;
        self
    }

    /// The time scale.
    pub fn time_scale(&self) -> f64 {
        self.time_scale
    }

    /// The serial number.
    pub fn serial(&self) -> u32 {
        self.serial
    }

    /// The CiA 402 state.
    pub fn state(&self) -> State {
        self.sm.state()
    }

    /// The roller surface velocity in mm/s (before polarity).
    pub fn velocity_mm_s(&self) -> f64 {
        self.v
    }

    /// The roller position in mm (before polarity).
    pub fn position_mm(&self) -> f64 {
        self.pos
    }

    /// The simulated motor temperature in °C.
    pub fn temperature_c(&self) -> f64 {
        self.electrics.temperature_c
    }

    /// Changes the load from now on.
    pub fn set_load(&mut self, load: Load) {
        self.load = load;
    }

    /// Sets the supply voltage in mV (24 V nominal). Below 18 V the drive
    /// raises 0x3220, above 30 V 0x3210 (thresholds chosen; the manual
    /// gives none); the next step checks.
    pub fn set_supply_voltage_mv(&mut self, mv: u32) {
        self.supply_mv = mv;
    }

    /// Sets the ambient temperature in °C.
    pub fn set_ambient_temperature(&mut self, celsius: f64) {
        if celsius.is_finite() {
            self.ambient_c = celsius;
        }
    }

    /// Sets the motor temperature in °C at once (as after a long time in a
    /// hot place); 0x4231 decides on warning and error at the next step.
    pub fn set_motor_temperature(&mut self, celsius: f64) {
        if celsius.is_finite() {
            self.electrics.temperature_c = celsius;
        }
    }

    /// Raises the chapter 9 code `code` as present: a warning (class W)
    /// sets statusword bit 7; an error makes the drive go to Fault. Sends
    /// the EMCY and enters 0x1003 when it was not present yet.
    pub fn raise_error(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>, code: u16) {
        if !self.faults.raise(code) {
            return;
        }
        self.write_error_register(ctx);
        ctx.emcy(code, [0; 5]);
        if is_warning(code) {
            ctx.emit(Ec5000BiEvent::Warning(code));
            self.sm.set_warning(true);
        } else {
            ctx.emit(Ec5000BiEvent::Error(code));
            self.sm.set_fault_persists(true);
            self.sm.raise_fault(ctx.now(), code);
            self.pump(ctx);
        }
        self.publish(ctx);
    }

    /// The condition behind `code` went away: a warning is withdrawn (EMCY
    /// 0x0000 when nothing is signalled any more); an error may now be
    /// acknowledged.
    pub fn clear_error(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>, code: u16) {
        if !self.faults.clear(code) {
            return;
        }
        ctx.emit(Ec5000BiEvent::Cleared(code));
        self.sm.set_fault_persists(self.faults.persists());
        self.sm.set_warning(!self.faults.warnings.is_empty());
        if is_warning(code) {
            self.write_error_register(ctx);
            if self.faults.all_clear() {
                ctx.emcy(0, [0; 5]);
            }
        }
        self.publish(ctx);
    }

    fn write_error_register(&self, ctx: &mut Context<'_, Ec5000BiEvent>) {
        ctx.set::<od::ErrorRegister>(od::ErrorRegisterValue(self.faults.error_register()));
    }

    /// Power-on of the application: state machine, mechanics at rest at
    /// position 0, errors forgotten (physical conditions are checked
    /// again at the next step).
    fn start(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>) {
        let now = ctx.now();
        self.sm = DeviceStateMachine::new(now, sm_config());
        let mode = ctx.get::<od::ModesOfOperation>().map_or(3, |m| m.to_raw());
        self.sm.set_mode(ModeOfOperation::from_i8(mode));
        ctx.set::<od::ModesOfOperationDisplay>(od::ModesOfOperationDisplayValue(mode));
        self.last = now;
        self.v = 0.0;
        self.pos = 0.0;
        self.moving = false;
        self.pp = Positioning::default();
        self.faults.present.clear();
        self.faults.latched.clear();
        self.faults.warnings.clear();
        self.monitor_in = 0.0;
        self.started = true;
        self.pump(ctx);
        self.write_error_register(ctx);
        self.update_monitoring(ctx);
        self.publish(ctx);
    }

    /// Takes the state machine's events: transitions, set-points, homing.
    fn pump(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>) {
        while let Some(event) = self.sm.poll_event() {
            match event {
                cia402::DeviceEvent::Transition { number, from, to } => {
                    ctx.emit(Ec5000BiEvent::Transition { number, from, to });
                    if to == State::QuickStopActive {
                        self.life.quick_stops = self.life.quick_stops.saturating_add(1);
                        self.update_monitoring(ctx);
                    }
                    if number == 15 {
                        self.faults.latched.clear();
                        self.write_error_register(ctx);
                        if self.faults.all_clear() {
                            ctx.emcy(0, [0; 5]);
                        }
                    }
                    if to != State::OperationEnabled {
                        self.pp.active = false;
                        self.pp.buffered = None;
                    }
                }
                cia402::DeviceEvent::NewSetPoint {
                    immediate,
                    relative,
                } => {
                    self.new_set_point(ctx, immediate, relative);
                }
                cia402::DeviceEvent::HomingStarted => self.home(ctx),
                _ => {}
            }
        }
    }

    /// Homing method 37 (chapter 4.3): the current position becomes 0; the
    /// drive must stand still.
    fn home(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>) {
        let ok = self.v == 0.0;
        if ok {
            self.pos = 0.0;
            self.pp = Positioning::default();
        }
        self.sm.homing_done(ok);
        ctx.emit(Ec5000BiEvent::Homed(ok));
        self.publish(ctx);
    }

    /// The polarity signs (0x607E bit 6 velocity, bit 7 position; CiA 402).
    fn signs(ctx: &Context<'_, Ec5000BiEvent>) -> (f64, f64) {
        let p = ctx.get::<od::Polarity>().map_or(0, |p| p.to_raw());
        let v = if p & 0x40 != 0 { -1.0 } else { 1.0 };
        let x = if p & 0x80 != 0 { -1.0 } else { 1.0 };
        (v, x)
    }

    /// A set-point in profile position mode, from 0x607A.
    fn new_set_point(
        &mut self,
        ctx: &mut Context<'_, Ec5000BiEvent>,
        immediate: bool,
        relative: bool,
    ) {
        let (_, x) = Ec5000Bi::signs(ctx);
        let raw = f64::from(ctx.get::<od::TargetPosition>().map_or(0, |t| t.to_raw()));
        let base = if self.pp.active {
            self.pp.target
        } else {
            self.pos
        };
        let target = if relative { base + x * raw } else { x * raw };
        let buffered = self.pp.active && !immediate;
        if buffered {
            // At most one set-point waits (chapter 4.3); a further one
            // while bit 12 is still set is ignored.
            if self.pp.buffered.is_some() {
                return;
            }
            self.pp.buffered = Some(target);
            self.pp.pass_through = self.sm.controlword().bit(9);
        } else {
            self.pp.target = target;
            self.pp.buffered = None;
            self.pp.active = true;
        }
        self.sm.set_target_reached(false);
        ctx.emit(Ec5000BiEvent::SetPoint {
            target_mm: round_i32(x * target),
            buffered,
        });
    }
}

/// `v` rounded into an i32 (saturating).
fn round_i32(v: f64) -> i32 {
    v.round().clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
}

impl Behaviour for Ec5000Bi {
    type Event = Ec5000BiEvent;

    fn check_write(
        &mut self,
        _ctx: &mut Context<'_, Ec5000BiEvent>,
        index: u16,
        _sub: u8,
        data: &[u8],
    ) -> Result<(), AbortCode> {
        match index {
            0x6060 => {
                let raw = data.first().map_or(0, |b| *b as i8);
                self.check_mode_change(ModeOfOperation::from_i8(raw))
            }
            // 607Eh: the values of the chapter 7 table only.
            0x607E => match data.first() {
                Some(0 | 64 | 128 | 192) => Ok(()),
                _ => Err(AbortCode::InvalidValue),
            },
            _ => Ok(()),
        }
    }

    fn written(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>, index: u16, _sub: u8) {
        match index {
            0x6040 => self.controlword_written(ctx),
            0x6060 => self.mode_written(ctx),
            _ => {}
        }
    }

    fn step(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>) {
        if !self.started {
            return;
        }
        let now = ctx.now();
        let dt = now.saturating_duration_since(self.last).as_secs_f64() * self.time_scale;
        self.last = now;
        self.sm.handle_timeout(now);
        self.pump(ctx);
        self.move_roller(ctx, dt);
        self.check_conditions(ctx);
        self.monitor_in -= dt;
        if self.monitor_in <= 0.0 {
            self.monitor_in = 1.0;
            self.update_monitoring(ctx);
        }
        self.publish(ctx);
    }

    fn period(&self) -> Duration {
        // Fine enough for the ramps even when time runs faster.
        let ms = (10.0 / self.time_scale).clamp(1.0, 10.0);
        Duration::from_micros((ms * 1000.0) as u64)
    }

    fn nmt_changed(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>, from: NmtState, _to: NmtState) {
        if from != NmtState::BootUp {
            return;
        }
        // Reset communication sets 0x1000..0x1FFF back; the device's own
        // values are written again at every boot.
        ctx.set::<od::identity::SerialNumber>(self.serial);
        if let Some(node) = ctx.node() {
            ctx.set::<od::bus_address::NodeIdActual>(node.get());
        }
        ctx.set::<od::NominalPower>(od::NominalPowerValue(self.nominal_power_w));
        if ctx
            .get::<od::ProfileAcceleration>()
            .map_or(0, |a| a.to_raw())
            == 0
        {
            ctx.set::<od::ProfileAcceleration>(od::ProfileAccelerationValue(
                physics::DEFAULT_ACCEL_MM_S2,
            ));
        }
        if !self.started {
            self.start(ctx);
        }
        self.write_error_register(ctx);
    }

    fn heartbeat_lost(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>, node: NodeId) {
        self.connection_lost(ctx, node);
    }

    fn heartbeat_resumed(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>, _node: NodeId) {
        self.clear_error(ctx, running::HEARTBEAT_ERROR);
    }

    fn reset_application(&mut self, ctx: &mut Context<'_, Ec5000BiEvent>) {
        let _ = ctx;
        self.started = false;
    }
}

/// The LSS address of a drive with `serial`: Interroll's vendor id, the
/// product code and revision of 0x1018 (chapter 7).
pub fn identity(serial: u32) -> Identity {
    Identity::new(VENDOR_ID, PRODUCT_CODE, REVISION_NUMBER, serial)
}

/// The delivery state (chapter 3): node id 127, LSS slave with the
/// identity of `serial`, 250 kbit/s (0x4651 sub 1 default).
pub fn default_config(serial: u32) -> DeviceConfig {
    DeviceConfig {
        node: NodeId::new(DEFAULT_NODE_ID),
        lss: Some(identity(serial)),
        bit_rate: BitRate::Kbit250,
    }
}

/// A drive as delivered, powered on at `now`.
pub fn simulator(now: Instant) -> Device<Ec5000Bi> {
    let model = Ec5000Bi::new();
    let config = default_config(model.serial());
    simulator_with(model, config, now)
}

/// A drive with `model` and `config`, powered on at `now`.
pub fn simulator_with(model: Ec5000Bi, config: DeviceConfig, now: Instant) -> Device<Ec5000Bi> {
    Device::new(od::OBJECTS, config, model, now)
}
