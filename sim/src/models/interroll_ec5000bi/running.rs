//! The drive at work: controlword and mode writes, the roller's motion per
//! step, the conditions that raise errors, and what the model publishes in
//! the object table.

use eds2rust_drivers::interroll_ec5000bi::errors::Emcy;
use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_runtime::cia402::{Controlword, ModeOfOperation, State};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::abort::AbortCode;

use super::physics::{
    self, COAST_DECEL_MM_S2, Electrics, MIN_VELOCITY_MM_S, PositionStep, QUICK_STOP_DECEL_MM_S2,
};
use super::{Ec5000Bi, Ec5000BiEvent, round_i32};
use crate::Context;

type Ctx<'a, 'b> = &'a mut Context<'b, Ec5000BiEvent>;

/// EMCY code of a lost heartbeat (chapter 9.1).
pub(crate) const HEARTBEAT_ERROR: u16 = Emcy::NmtHeartbeatError.code() as u16;
const SUPPLY_LOW: u16 = Emcy::SupplyVoltageTooLow.code() as u16;
const SUPPLY_HIGH: u16 = Emcy::SupplyVoltageTooHigh.code() as u16;
const TEMP_HIGH: u16 = Emcy::MotorTemperatureTooHigh.code() as u16;
const TEMP_CLOSE_TO_HIGH: u16 = Emcy::MotorTemperatureCloseToHigh.code() as u16;

/// Chosen supply limits (mV): the manual names the errors, not the limits.
const SUPPLY_MIN_MV: u32 = 18_000;
const SUPPLY_MAX_MV: u32 = 30_000;
/// Chosen: the error 0x4310 comes this many K above the 0x4231 warning
/// threshold.
const TEMP_ERROR_MARGIN: f64 = 10.0;
/// Chosen: the lifetime light turns yellow after this many working hours.
const LIFETIME_YELLOW_H: u32 = 20_000;
/// Chosen: time constant of the power average 0x2200 sub 8, s.
const POWER_AVERAGE_S: f64 = 60.0;

impl Ec5000Bi {
    /// Chapter 4.1 mode matrix for a write of 0x6060 (modes 1, 3, 6 only).
    pub(crate) fn check_mode_change(&self, mode: ModeOfOperation) -> Result<(), AbortCode> {
        use ModeOfOperation as M;
        if !matches!(mode, M::ProfilePosition | M::ProfileVelocity | M::Homing) {
            return Err(AbortCode::InvalidValue);
        }
        let current = self.sm.mode();
        match self.sm.state() {
            // "Fault" row: no change.
            State::Fault | State::FaultReactionActive => Err(AbortCode::CannotTransferDeviceState),
            // Switched on, quick stop and below: the power stage is off or
            // holding; the matrix allows the change.
            State::OperationEnabled if mode != current => {
                let standing = self.v == 0.0;
                let halted = self.sm.controlword().halt();
                let allowed = match current {
                    // 51 zero motion hold - velocity -> position (30).
                    M::ProfileVelocity => standing && (mode != M::Homing || halted),
                    // 6 zero motion hold - halt -> velocity (37); homing
                    // needs the halt bit too (chapter 4.3).
                    M::ProfilePosition => standing && halted,
                    M::Homing => standing && !self.sm.homing_active(),
                    _ => standing,
                };
                if allowed {
                    Ok(())
                } else {
                    Err(AbortCode::CannotTransferDeviceState)
                }
            }
            _ => Ok(()),
        }
    }

    pub(crate) fn mode_written(&mut self, ctx: Ctx<'_, '_>) {
        let raw = ctx.get::<od::ModesOfOperation>().map_or(3, |m| m.to_raw());
        let mode = ModeOfOperation::from_i8(raw);
        if mode == self.sm.mode() {
            return;
        }
        self.sm.set_mode(mode);
        self.sm.set_target_reached(false);
        self.pp = physics::Positioning::default();
        ctx.set::<od::ModesOfOperationDisplay>(od::ModesOfOperationDisplayValue(raw));
        ctx.emit(Ec5000BiEvent::ModeChanged(mode));
        self.publish(ctx);
    }

    pub(crate) fn controlword_written(&mut self, ctx: Ctx<'_, '_>) {
        let raw = ctx.get::<od::Controlword>().map_or(0, |c| c.to_raw());
        let cw = Controlword(raw);
        let previous = self.sm.controlword();
        let now = ctx.now();
        self.sm.apply_controlword(now, cw);
        self.pump(ctx);
        // Homing may also be started in Switched on ("Operation disabled",
        // chapter 4.3); the state machine itself starts it only when
        // enabled.
        if self.sm.mode() == ModeOfOperation::Homing
            && self.sm.state() == State::SwitchedOn
            && cw.new_set_point()
            && !previous.new_set_point()
        {
            self.home(ctx);
        }
        // Halt released: a halted positioning goes on (chapter 4.3).
        if previous.halt() && !cw.halt() && self.pp.active {
            self.sm.set_target_reached(false);
        }
        self.publish(ctx);
    }

    /// A lost heartbeat: what 0x6007 asks for (chapter 5.2).
    pub(crate) fn connection_lost(&mut self, ctx: Ctx<'_, '_>, node: NodeId) {
        let option = ctx
            .get::<od::AbortConnectionOptionCode>()
            .map_or(0, |o| o.to_raw());
        ctx.emit(Ec5000BiEvent::ConnectionLost { node, option });
        let now = ctx.now();
        let cw = self.sm.controlword();
        match option {
            1 => self.raise_error(ctx, HEARTBEAT_ERROR),
            // Disable voltage: bit 1 cleared (transitions 7, 9, 10, 12).
            2 => self.sm.apply_controlword(now, Controlword(cw.0 & !0x0082)),
            // Quick stop: bit 2 cleared, bit 1 set (transitions 7, 10, 11).
            3 => self
                .sm
                .apply_controlword(now, Controlword((cw.0 & !0x0084) | 0x0002)),
            // 0: no action; manufacturer specific (< 0) and reserved
            // values: the manual defines no action either.
            _ => {}
        }
        self.pump(ctx);
        self.publish(ctx);
    }

    /// One step of `dt` device seconds of mechanics, electrics and
    /// lifetime counters.
    pub(crate) fn move_roller(&mut self, ctx: Ctx<'_, '_>, dt: f64) {
        if dt <= 0.0 {
            return;
        }
        let state = self.sm.state();
        let cw = self.sm.controlword();
        let powered = matches!(state, State::OperationEnabled | State::QuickStopActive);
        let (vs, _) = Ec5000Bi::signs(ctx);
        let accel = f64::from(
            ctx.get::<od::ProfileAcceleration>()
                .map_or(0, |a| a.to_raw()),
        );
        let accel = if accel > 0.0 {
            accel
        } else {
            f64::from(physics::DEFAULT_ACCEL_MM_S2)
        };
        let decel = self.deceleration(ctx, accel);
        let vmax = f64::from(
            ctx.get::<od::MaxProfileVelocity>()
                .map_or(2000, |v| v.to_raw()),
        );
        let mut limited = false;
        let (wanted, mut up, down) = if !powered {
            (0.0, 0.0, COAST_DECEL_MM_S2)
        } else if state == State::QuickStopActive {
            let qs = f64::from(ctx.get::<od::MaxDeceleration>().map_or(0, |d| d.to_raw()));
            (
                0.0,
                accel,
                if qs > 0.0 { qs } else { QUICK_STOP_DECEL_MM_S2 },
            )
        } else {
            match self.sm.mode() {
                ModeOfOperation::ProfileVelocity => {
                    let t =
                        vs * f64::from(ctx.get::<od::TargetVelocity>().map_or(0, |t| t.to_raw()));
                    let t = if cw.halt() || t.abs() < MIN_VELOCITY_MM_S {
                        0.0
                    } else if t.abs() > vmax {
                        limited = true;
                        physics::sign(t) * vmax
                    } else {
                        t
                    };
                    (t, accel, decel)
                }
                ModeOfOperation::ProfilePosition if !cw.halt() => {
                    let pv = f64::from(ctx.get::<od::ProfileVelocity>().map_or(0, |v| v.to_raw()));
                    (
                        self.pp.wanted_velocity(self.pos, pv.min(vmax), decel),
                        accel,
                        decel,
                    )
                }
                _ => (0.0, accel, decel),
            }
        };
        // The force the motor may give (0x6073, per mille of rated) limits
        // the acceleration.
        let nominal = f64::from(self.nominal_power_w);
        let rated = Electrics::rated_force(nominal);
        let max_current = f64::from(ctx.get::<od::MaxCurrent>().map_or(1000, |c| c.to_raw()));
        let f_max = rated * max_current / 1000.0;
        let friction = self.load.friction();
        let mass = self.load.mass_kg.max(0.1);
        if powered {
            let a_force = ((f_max - friction) / mass * 1000.0).max(0.0);
            if up > a_force && wanted.abs() > self.v.abs() {
                up = a_force;
                limited = true;
            }
        }
        let v0 = self.v;
        self.v = physics::ramp(v0, wanted, up, down, dt);
        let a = (self.v - v0) / dt;
        let force = if powered {
            mass * a / 1000.0 + friction * physics::sign(self.v)
        } else {
            0.0
        };
        let p0 = self.pos;
        self.pos += (v0 + self.v) / 2.0 * dt;
        if powered && self.sm.mode() == ModeOfOperation::ProfilePosition && !cw.halt() {
            let mut v = self.v;
            match self.pp.arrive(p0, &mut self.pos, &mut v, dt) {
                PositionStep::Reached => {
                    self.sm.set_target_reached(true);
                    let position_mm = self.position_user(ctx);
                    ctx.emit(Ec5000BiEvent::TargetReached { position_mm });
                }
                PositionStep::NextSetPoint | PositionStep::Moving => {}
            }
            self.v = v;
        }
        if powered
            && cw.halt()
            && self.v == 0.0
            && self.sm.mode() == ModeOfOperation::ProfilePosition
        {
            // CiA 402: halted and at rest counts as target reached.
            self.sm.set_target_reached(true);
        }
        self.internal_limit = limited;
        let supply = f64::from(self.supply_mv) / 1000.0;
        self.electrics
            .step(dt, force, self.v, nominal, supply, self.ambient_c);
        self.life.uptime_s += dt;
        self.life.distance_mm += (self.pos - p0).abs();
        if self.v != 0.0 {
            self.life.working_s += dt;
        }
        let k = (dt / POWER_AVERAGE_S).min(1.0);
        self.life.power_avg_w += (self.electrics.mech_power_w - self.life.power_avg_w) * k;
        if !self.moving && self.v != 0.0 {
            self.moving = true;
            self.life.start_stops = self.life.start_stops.saturating_add(1);
            ctx.emit(Ec5000BiEvent::MotionStarted);
            self.update_monitoring(ctx);
        } else if self.moving && self.v == 0.0 {
            self.moving = false;
            let position_mm = self.position_user(ctx);
            ctx.emit(Ec5000BiEvent::Standstill { position_mm });
            self.update_monitoring(ctx);
        }
    }

    /// 0x6084, or when 0 the 0x4645 positioning ramp (ms per 1000 motor
    /// rpm, default 100) converted with the gear (0x6091) and feed (0x6092)
    /// into mm/s²; both 0: the acceleration.
    fn deceleration(&self, ctx: Ctx<'_, '_>, accel: f64) -> f64 {
        let d = f64::from(
            ctx.get::<od::ProfileDeceleration>()
                .map_or(0, |d| d.to_raw()),
        );
        if d > 0.0 {
            return d;
        }
        let ramp_ms = f64::from(
            ctx.get::<od::PositioningDecelerationRamp>()
                .map_or(0, |r| r.to_raw()),
        );
        let gear = ctx
            .get::<od::gear_ratio::MotorRevolutions>()
            .map_or(18.0, f64::from);
        let feed = ctx
            .get::<od::feed_constant::Feed>()
            .map_or(157.0, |f| f64::from(f.to_raw()));
        if ramp_ms <= 0.0 || gear <= 0.0 {
            return accel;
        }
        // 1000 motor rpm at the roller surface, in mm/s.
        let v1000 = 1000.0 / gear / 60.0 * feed;
        v1000 / (ramp_ms / 1000.0)
    }

    /// 0x6064 as the bus shows it (position polarity applied).
    fn position_user(&self, ctx: &Context<'_, Ec5000BiEvent>) -> i32 {
        let (_, x) = Ec5000Bi::signs(ctx);
        round_i32(x * self.pos)
    }

    /// Supply and temperature limits raise and clear their errors.
    pub(crate) fn check_conditions(&mut self, ctx: Ctx<'_, '_>) {
        let mv = self.supply_mv;
        let low_present = self.faults.present.contains(&SUPPLY_LOW);
        if mv < SUPPLY_MIN_MV {
            self.raise_error(ctx, SUPPLY_LOW);
        } else if low_present && mv >= SUPPLY_MIN_MV + 1000 {
            self.clear_error(ctx, SUPPLY_LOW);
        }
        let high_present = self.faults.present.contains(&SUPPLY_HIGH);
        if mv > SUPPLY_MAX_MV {
            self.raise_error(ctx, SUPPLY_HIGH);
        } else if high_present && mv + 1000 <= SUPPLY_MAX_MV {
            self.clear_error(ctx, SUPPLY_HIGH);
        }
        let threshold = f64::from(
            ctx.get::<od::high_temperature_warning_level::Threshold>()
                .map_or(95, |t| t.to_raw()),
        );
        let hysteresis = f64::from(
            ctx.get::<od::high_temperature_warning_level::Hysterese>()
                .map_or(2, |h| h.to_raw()),
        );
        let t = self.electrics.temperature_c;
        if t >= threshold {
            self.raise_error(ctx, TEMP_CLOSE_TO_HIGH);
        } else if t < threshold - hysteresis {
            self.clear_error(ctx, TEMP_CLOSE_TO_HIGH);
        }
        if t >= threshold + TEMP_ERROR_MARGIN {
            self.raise_error(ctx, TEMP_HIGH);
        } else if t < threshold - hysteresis {
            self.clear_error(ctx, TEMP_HIGH);
        }
    }

    /// 0x2200, 0x2210, 0x2211: written at intervals and on start/stop
    /// (chapter 6.1), not on every step.
    pub(crate) fn update_monitoring(&mut self, ctx: Ctx<'_, '_>) {
        use od::monitoring_values as m;
        let t = self.electrics.temperature_c;
        let t_min = self.life.t_min.map_or(t, |v| v.min(t));
        let t_max = self.life.t_max.map_or(t, |v| v.max(t));
        self.life.t_min = Some(t_min);
        self.life.t_max = Some(t_max);
        let feed = ctx
            .get::<od::feed_constant::Feed>()
            .map_or(157.0, |f| f64::from(f.to_raw()))
            .max(1.0);
        let hours = |s: f64| (s / 3600.0) as u32;
        let temp = |c: f64| c.round().clamp(-32768.0, 32767.0) as i16;
        ctx.set::<m::StartStops>(self.life.start_stops);
        ctx.set::<m::WorkingHours>(m::WorkingHoursValue(hours(self.life.working_s)));
        ctx.set::<m::UptimeLaufzeit>(m::UptimeLaufzeitValue(hours(self.life.uptime_s)));
        ctx.set::<m::AbsoluteMinimumTemperature>(m::AbsoluteMinimumTemperatureValue(temp(t_min)));
        ctx.set::<m::AbsoluteMaximumTemperature>(m::AbsoluteMaximumTemperatureValue(temp(t_max)));
        ctx.set::<m::ActualTemperature>(m::ActualTemperatureValue(temp(t)));
        ctx.set::<m::NumberOfQuickStops>(self.life.quick_stops);
        let power = self.life.power_avg_w.round().clamp(0.0, 255.0) as u8;
        ctx.set::<m::PowerAverageMech>(m::PowerAverageMechValue(power));
        ctx.set::<m::NumberOfRotations>((self.life.distance_mm / feed) as u32);
        // Status lights (0 green, 1 yellow, 2 red); the limits are chosen,
        // the manual gives only the colours.
        let threshold = f64::from(
            ctx.get::<od::high_temperature_warning_level::Threshold>()
                .map_or(95, |t| t.to_raw()),
        );
        let light_t = if t >= threshold + TEMP_ERROR_MARGIN {
            2
        } else if t >= threshold {
            1
        } else {
            0
        };
        let share = self.life.power_avg_w / f64::from(self.nominal_power_w);
        let light_p = if share >= 1.0 {
            2
        } else if share >= 0.8 {
            1
        } else {
            0
        };
        let light_e = match self.faults.lifetime_count {
            0 => 0,
            1..=9 => 1,
            _ => 2,
        };
        let life = u8::from(hours(self.life.working_s) >= LIFETIME_YELLOW_H);
        use od::health_traffic_light as h;
        ctx.set::<h::Temperature>(h::TemperatureValue(light_t));
        ctx.set::<h::Power>(h::PowerValue(light_p));
        ctx.set::<h::ErrorQuantity>(h::ErrorQuantityValue(light_e));
        ctx.set::<od::LifetimeTrafficLight>(od::LifetimeTrafficLightValue(life));
    }

    /// The statusword and the process values of every step.
    pub(crate) fn publish(&mut self, ctx: Ctx<'_, '_>) {
        self.sm.set_internal_limit(self.internal_limit);
        self.sm.set_warning(!self.faults.warnings.is_empty());
        let mut sw = self.sm.statusword().0;
        match self.sm.mode() {
            // Bits 10 and 12 are reserved in velocity mode (chapter 4.2).
            ModeOfOperation::ProfileVelocity => sw &= !((1 << 10) | (1 << 12)),
            // A buffered set-point holds bit 12 (chapter 4.3).
            ModeOfOperation::ProfilePosition if self.pp.buffered.is_some() => sw |= 1 << 12,
            _ => {}
        }
        ctx.set::<od::Statusword>(od::StatuswordValue(sw));
        let (vs, x) = Ec5000Bi::signs(ctx);
        let v = round_i32(vs * self.v);
        ctx.set::<od::VelocityActualValue>(od::VelocityActualValueValue(v));
        ctx.set::<od::VelocityDemandValue>(od::VelocityDemandValueValue(v));
        ctx.set::<od::PositionActualValue>(od::PositionActualValueValue(round_i32(x * self.pos)));
        let demand = if self.pp.active {
            self.pp.target
        } else {
            self.pos
        };
        ctx.set::<od::PositionDemandValue>(od::PositionDemandValueValue(round_i32(x * demand)));
        let rated = Electrics::rated_force(f64::from(self.nominal_power_w));
        let torque = (vs * self.electrics.force_n / rated * 1000.0)
            .round()
            .clamp(-32768.0, 32767.0) as i16;
        ctx.set::<od::TorqueActualValue>(od::TorqueActualValueValue(torque));
        let supply = f64::from(self.supply_mv) / 1000.0;
        let mv = (self.electrics.dc_link(supply) * 1000.0)
            .round()
            .clamp(0.0, 65535.0) as u16;
        ctx.set::<od::DcLinkCircuitVoltage>(od::DcLinkCircuitVoltageValue(mv));
    }
}
