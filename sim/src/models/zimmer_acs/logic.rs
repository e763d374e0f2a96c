//! The workings of [`ZimmerAcs`]: the state machine's events and their
//! effects, set-points, the mechanics, the monitors, and what is published
//! in the object table.
//!
//! What the manual and CiA 402 agree on is the shared axis
//! ([`crate::cia402::axis`]: state machine, trajectory generator,
//! set-points, settling, fault raise and reset). What stays here is where
//! the manual says something of its own:
//! - 0x6060 (11.1.2, 15.5 "The default value is 1"): only 1 and 8 exist, so no
//!   homing starts and no other mode runs.
//! - Statusword bit 4 (the LED table: "StatusWord Bit 04 (Voltage enabled) = 1 ⇒
//!   Regler ist aktiv") is the power stage with STO (16.1.3), and bit 9
//!   is not set: the state machine sets neither.
//! - 0x605A (15.5): 0, 1, 2, 5, 6; "Slow down ramp uses deceleration
//!   defined in PROFILE_DECELERATION, while Quick stop ramp uses
//!   LIM_DECELERATION_MAX" (0x300A sub 2) for 0x605A and 0x605D.
//! - Transition 15 (15.1.1): "Nach dem Verlassen des Fehlerzustands wird
//!   der Befehl Fault reset im ControlWord vom Steuergerät gelöscht".
//! - Target reached (15.1.2.1) "benötigt ein konfiguriertes
//!   Positionsfenster und eine konfigurierte Zeit": the window is 0x21F1,
//!   the time [`POSITION_WINDOW_TIME`](super::POSITION_WINDOW_TIME).
//! - A following error (15.5 0x6065) is error 0x7387 (Fault), a profile
//!   with a zero value is 0x7391 ("they should all have positive
//!   values"), enabling outside the position limits 0x3007 in a position
//!   mode is an error (15.4); every error is "power stage shutdown".

use std::time::Duration;

use eds2rust_drivers::zimmer_acs::errors::{ZimmerErrors, ZimmerErrorsCode};
use eds2rust_drivers::zimmer_acs::od;
use eds2rust_runtime::cia402::{
    Controlword, DeviceConfig as MachineConfig, DeviceEvent, ModeOfOperation, State,
};

use super::factory::{self, RAMP_MAX};
use super::{POSITION_WINDOW_TIME, STO_LATCH_TIME, ZimmerAcs, ZimmerAcsEvent};
use crate::Context;
use crate::cia402::axis::{Axis, Drive, Step};
use crate::cia402::profiler::{Goal, Profiler};

type Ctx<'a, 'b> = &'a mut Context<'b, ZimmerAcsEvent>;

/// µm per mm (positions are µm, velocities mm/s, 15.5).
const UM_PER_MM: f64 = 1000.0;

/// The state machine's settings: immediate start-up and fault reaction
/// (every modelled error is "power stage shutdown", 15.4), the quick stop
/// ramp run by the model, bits 4 and 9 set by the model.
fn machine_config() -> MachineConfig {
    MachineConfig {
        start_up: Duration::ZERO,
        fault_reaction: Some(Duration::ZERO),
        quick_stop: None,
        quick_stop_option_code: od::QuickStopOptionCodeValue::QUICK_STOP_RAMP_AND_DISABLE.0,
        voltage_enabled: false,
        remote: false,
    }
}

fn is_position_mode(mode: ModeOfOperation) -> bool {
    matches!(
        mode,
        ModeOfOperation::ProfilePosition | ModeOfOperation::CyclicSynchronousPosition
    )
}

impl ZimmerAcs {
    /// Power-on (and NMT reset node): a new state machine, the factory
    /// values where nothing was saved, the volatile entries at 0. The
    /// carriage stays where it is.
    pub(super) fn power_on(&mut self, ctx: Ctx<'_, '_>) {
        self.axis.power_off();
        self.angle_determined = false;
        self.clamp_released = false;
        self.sto_latched = false;
        self.sto_differs_since = (self.sto1 != self.sto2).then(|| ctx.now());
        factory::apply(ctx, self.variant);
        factory::volatile(ctx);
        ctx.set::<od::ErrorCode>(ZimmerErrorsCode(0));
        self.begin(ctx);
        self.finish(ctx);
    }

    /// Before handling an input: the state machine exists, the mechanics
    /// are at `ctx.now()`.
    pub(super) fn begin(&mut self, ctx: Ctx<'_, '_>) {
        if self.axis.sm.is_none() {
            let mode = ctx.get::<od::ModesOfOperation>().map_or(1, |v| v.0);
            let mode = ModeOfOperation::from_i8(mode);
            self.axis.switch_on(ctx.now(), machine_config(), mode);
        }
        self.advance(ctx);
    }

    /// After handling an input: the state machine's events and their
    /// effects, the STO check, the clamp, the published values.
    pub(super) fn finish(&mut self, ctx: Ctx<'_, '_>) {
        // Effects can raise faults, which are events again; a few rounds
        // settle every chain.
        for _ in 0..8 {
            let events = self.axis.poll_events();
            // 15.4 0x3280: the power stage is asked for while STO is active.
            let sto_fault = !self.sto_ok() && self.power_requested();
            if events.is_empty() && !sto_fault {
                break;
            }
            for event in events {
                self.on_event(ctx, event);
            }
            if sto_fault && self.power_requested() {
                self.fault(ctx, ZimmerErrors::StoEnabled);
            }
        }
        self.update_clamp(ctx);
        self.publish(ctx);
    }

    pub(super) fn sto_ok(&self) -> bool {
        self.sto1 && self.sto2 && !self.sto_latched
    }

    /// The states in which the power stage is switched on (15.1.1
    /// transitions 3 and 4; off again with 5..10, 12, 14).
    fn power_requested(&self) -> bool {
        matches!(
            self.state(),
            Some(State::SwitchedOn | State::OperationEnabled | State::QuickStopActive)
        )
    }

    /// Whether the power stage is on (statusword bit 4).
    pub(super) fn power_stage_on(&self) -> bool {
        self.power_requested() && self.sto_ok()
    }

    /// Whether the carriage follows the demand.
    fn movable(&self) -> bool {
        self.power_stage_on()
            && matches!(
                self.state(),
                Some(State::OperationEnabled | State::QuickStopActive)
            )
            && self.clamp_released
            && !self.blocked
    }

    fn mode(&self) -> ModeOfOperation {
        self.axis.mode()
    }

    /// Raises `error` (15.4): 0x603F, Fault, EMCY with the error ID.
    pub(super) fn fault(&mut self, ctx: Ctx<'_, '_>, error: ZimmerErrors) {
        let code = u16::try_from(error.code()).unwrap_or(u16::MAX);
        let persists = error == ZimmerErrors::StoAbnormalFault;
        if persists && let Some(sm) = self.axis.sm.as_mut() {
            // 16.1.3: latched until the next power-on.
            sm.set_fault_persists(true);
        }
        if !self.axis.raise_fault(ctx.now(), code) {
            return;
        }
        ctx.set::<od::ErrorCode>(ZimmerErrorsCode::from_kind(error));
        ctx.emcy(code, [0; 5]);
        ctx.emit(ZimmerAcsEvent::Fault(error));
    }

    pub(super) fn apply_controlword(&mut self, ctx: Ctx<'_, '_>) {
        let cw = ctx.get::<od::Controlword>().map_or(0, |v| v.0);
        let now = ctx.now();
        if let Some(sm) = self.axis.sm.as_mut() {
            sm.apply_controlword(now, Controlword(cw));
        }
    }

    pub(super) fn apply_mode(&mut self, ctx: Ctx<'_, '_>) {
        let mode = ctx.get::<od::ModesOfOperation>().map_or(1, |v| v.0);
        if let Some(sm) = self.axis.sm.as_mut() {
            sm.set_mode(ModeOfOperation::from_i8(mode));
        }
        self.stop_motion();
    }

    fn on_event(&mut self, ctx: Ctx<'_, '_>, event: DeviceEvent) {
        // 11.1.2: no homing mode (0x6060 refuses 6), so no homing starts.
        if let Some(Step::Transition { number, from, to }) = self.axis.take_event(event) {
            ctx.emit(ZimmerAcsEvent::StateChanged {
                transition: number,
                from,
                to,
            });
            self.on_transition(ctx, number, to);
        }
    }

    fn on_transition(&mut self, ctx: Ctx<'_, '_>, number: u8, to: State) {
        let now = ctx.now();
        if let Some(sm) = self.axis.sm.as_mut() {
            // Set again by the monitor after the window time.
            sm.set_target_reached(false);
        }
        match to {
            State::OperationEnabled => {
                self.angle_determined = true;
                self.stop_motion();
                let (min, max) = self.position_limits(ctx);
                if is_position_mode(self.mode())
                    && (self.axis.actual < min || self.axis.actual > max)
                {
                    self.fault(ctx, ZimmerErrors::PositionOutOfLimitsInPositionMode);
                }
            }
            State::QuickStopActive => {
                let code = ctx.get::<od::QuickStopOptionCode>().map_or(2, |v| v.0);
                if code == od::QuickStopOptionCodeValue::DISABLE_POWER_STAGE.0 {
                    self.stop_motion();
                    if let Some(sm) = self.axis.sm.as_mut() {
                        sm.complete_quick_stop(now);
                    }
                }
            }
            _ => self.stop_motion(),
        }
        if number == 15 {
            // CiA 301: EMCY "error reset"; 15.1.1: the device clears the
            // fault reset bit once it has left Fault.
            ctx.emcy(0, [0; 5]);
            let cw = ctx.get::<od::Controlword>().map_or(0, |v| v.0) & !0x0080;
            ctx.set::<od::Controlword>(od::ControlwordValue(cw));
            self.axis.clear_fault_bits();
            if let Some(sm) = self.axis.sm.as_mut() {
                sm.apply_controlword(now, Controlword(cw));
            }
        }
    }

    /// 0x3007 sub 1 and 2 (µm).
    fn position_limits(&self, ctx: Ctx<'_, '_>) -> (f64, f64) {
        use od::position_limits as pos;
        let min = ctx
            .get::<pos::MinimumPositionLimit>()
            .map_or(i32::MIN, |v| v.0);
        let max = ctx
            .get::<pos::MaximumPositionLimit>()
            .map_or(i32::MAX, |v| v.0);
        (f64::from(min), f64::from(max))
    }

    /// Profile velocity, acceleration, deceleration in µm/s and µm/s²,
    /// restricted to 0x3008..0x300A (15.5); `None` when one is 0 (15.4
    /// 0x7391: "they should all have positive values").
    fn profile(&self, ctx: Ctx<'_, '_>) -> Option<(f64, f64, f64)> {
        let v = ctx.get::<od::ProfileVelocity>()?.0;
        let a = ctx.get::<od::ProfileAcceleration>()?.0;
        let d = ctx.get::<od::ProfileDeceleration>()?.0;
        if v == 0 || a == 0 || d == 0 {
            return None;
        }
        let restrict = |value: u32, min: Option<u32>, max: Option<u32>| {
            let value = value.max(min.unwrap_or(0));
            f64::from(max.map_or(value, |m| value.min(m).max(1))) * UM_PER_MM
        };
        use od::{acceleration_limits as al, deceleration_limits as dl, velocity_limits as vl};
        Some((
            restrict(
                v,
                ctx.get::<vl::MinimumVelocityLimit>().map(|x| x.0),
                ctx.get::<vl::MaximumVelocityLimit>().map(|x| x.0),
            ),
            restrict(
                a,
                ctx.get::<al::MinimumAccelerationLimit>().map(|x| x.0),
                ctx.get::<al::MaximumAccelerationLimit>().map(|x| x.0),
            ),
            restrict(
                d,
                ctx.get::<dl::MinimumDecelerationLimit>().map(|x| x.0),
                ctx.get::<dl::MaximumDecelerationLimit>().map(|x| x.0),
            ),
        ))
    }

    /// The braking ramp of an option code (15.5): slow down ramp = 0x6084,
    /// quick stop ramp = 0x300A/2 (µm/s²).
    fn ramp(&self, ctx: Ctx<'_, '_>, quick: bool) -> f64 {
        let mm = if quick {
            ctx.get::<od::deceleration_limits::MaximumDecelerationLimit>()
                .map_or(RAMP_MAX, |v| v.0)
        } else {
            ctx.get::<od::ProfileDeceleration>()
                .map_or(RAMP_MAX, |v| v.0)
        };
        f64::from(mm.max(1)) * UM_PER_MM
    }

    /// Runs the mechanics from the last input to `ctx.now()`; the carriage
    /// follows the demand only when it can move (power stage, clamp).
    fn advance(&mut self, ctx: Ctx<'_, '_>) {
        self.run_mechanics(ctx);
        if self.movable() {
            self.axis.actual = self.axis.profiler.position;
        }
    }

    fn start_motion(&mut self, ctx: Ctx<'_, '_>, target: f64) {
        ctx.emit(ZimmerAcsEvent::MotionStarted {
            from_um: self.axis.actual.round() as i32,
            to_um: target.round() as i32,
        });
        self.axis.start_motion(target);
    }

    /// The periodic part: STO latch, deferred set-point, following error,
    /// target reached.
    pub(super) fn monitor(&mut self, ctx: Ctx<'_, '_>) {
        let now = ctx.now();
        if let Some(since) = self.sto_differs_since
            && !self.sto_latched
            && now.saturating_duration_since(since) >= STO_LATCH_TIME
        {
            self.sto_latched = true;
            ctx.emit(ZimmerAcsEvent::StoLatched);
            self.fault(ctx, ZimmerErrors::StoAbnormalFault);
        }
        self.monitor_motion(ctx);
    }

    /// 11.6: the clamping element follows the state machine unless 0x2129
    /// overrides it.
    fn update_clamp(&mut self, ctx: Ctx<'_, '_>) {
        let released = match ctx.get::<od::ClampingElementOverride>() {
            Some(od::ClampingElementOverrideValue::RELEASE) => true,
            Some(od::ClampingElementOverrideValue::LOCK) => false,
            _ => {
                self.power_stage_on()
                    && matches!(
                        self.state(),
                        Some(State::OperationEnabled | State::QuickStopActive)
                    )
            }
        };
        if released != self.clamp_released {
            self.clamp_released = released;
            ctx.emit(ZimmerAcsEvent::Clamp { released });
        }
    }

    /// Writes the statusword and the actual values into the table.
    fn publish(&mut self, ctx: Ctx<'_, '_>) {
        let Some(sm) = self.axis.sm.as_ref() else {
            return;
        };
        let sw = od::StatuswordValue(sm.statusword().0 & !(1 << 9))
            .with_voltage_enabled(self.power_stage_on())
            .with_initial_angle_determination_finished(self.angle_determined);
        let mode = sm.mode().as_i8();
        ctx.set::<od::Statusword>(sw);
        ctx.set::<od::ModesOfOperationDisplay>(od::ModesOfOperationDisplayValue(mode));
        ctx.set::<od::PositionActualValue>(od::PositionActualValueValue(
            self.axis.actual.round() as i32
        ));
        let velocity = if self.movable() {
            self.axis.profiler.velocity
        } else {
            0.0
        };
        ctx.set::<od::VelocityActualValue>(od::VelocityActualValueValue(
            (velocity / UM_PER_MM).round() as i32,
        ));
        ctx.set::<od::FollowingErrorActualValue>(od::FollowingErrorActualValueValue(
            (self.axis.profiler.position - self.axis.actual).round() as i32,
        ));
        // 16.1.3 and 15.5 0x251A; the STO supply is always fine here.
        let (sto1, sto2) = (self.sto1, self.sto2);
        let report = if self.sto_latched {
            !(sto1 || sto2)
        } else {
            sto1 && sto2
        };
        ctx.set::<od::StoStatus>(
            od::StoStatusValue(0)
                .with_sto1(sto1)
                .with_sto2(sto2)
                .with_sto_supply_ok(true)
                .with_sto_abnormal_fault(sto1 != sto2 || self.sto_latched)
                .with_sto_report(report),
        );
    }
}

impl Drive for ZimmerAcs {
    type Event = ZimmerAcsEvent;

    fn axis(&mut self) -> &mut Axis {
        &mut self.axis
    }

    fn quick_stop(&mut self, ctx: Ctx<'_, '_>) -> (f64, bool) {
        let code = ctx.get::<od::QuickStopOptionCode>().map_or(2, |v| v.0);
        // 15.5: options 0..2 disable the drive after the ramp (12), 5 and
        // 6 stay in Quick stop active; 2 and 6 brake on the quick stop ramp.
        (
            self.ramp(ctx, matches!(code, 2 | 6)),
            !matches!(code, 0..=2),
        )
    }

    fn stop_motion(&mut self) {
        self.axis.stop_motion();
    }

    fn run_enabled(&mut self, ctx: Ctx<'_, '_>, seconds: f64) {
        let mode = self.mode();
        if mode == ModeOfOperation::CyclicSynchronousPosition {
            // The axis takes each target at once; no interpolation between
            // set-points is modelled.
            let raw = ctx.get::<od::TargetPosition>().map_or(0, |v| v.0);
            let (min, max) = self.position_limits(ctx);
            let target = f64::from(raw).max(min).min(max);
            if let Some(sm) = self.axis.sm.as_mut() {
                sm.set_internal_limit(target != f64::from(raw));
            }
            self.axis.profiler = Profiler::at(target);
            self.axis.goal = target;
            return;
        }
        if mode != ModeOfOperation::ProfilePosition {
            return;
        }
        let halt = self.axis.halted();
        let goal = if halt {
            let code = ctx.get::<od::HaltOptionCode>().map_or(1, |v| v.0);
            Goal::Stop {
                deceleration: self.ramp(ctx, code == 2),
            }
        } else {
            match self.profile(ctx) {
                Some((velocity, acceleration, deceleration)) => Goal::Target {
                    target: self.axis.goal,
                    velocity,
                    acceleration,
                    deceleration,
                },
                None => Goal::Stop {
                    deceleration: self.ramp(ctx, true),
                },
            }
        };
        if self.axis.profiler.run(seconds, goal)
            && !halt
            && let Some(next) = self.axis.queued.take()
        {
            self.start_motion(ctx, next);
        }
    }

    /// A new set-point (15.1.1 bits 4-6): the target, its limits, the
    /// profile, then now (bit 5 or at rest) or after the running move.
    fn start_set_point(&mut self, ctx: Ctx<'_, '_>, immediate: bool, relative: bool) {
        let raw = f64::from(ctx.get::<od::TargetPosition>().map_or(0, |v| v.0));
        let reference = self.axis.queued.unwrap_or(self.axis.goal);
        let requested = if relative { reference + raw } else { raw };
        let (min, max) = self.position_limits(ctx);
        let target = requested.max(min).min(max);
        let limited = target != requested;
        if let Some(sm) = self.axis.sm.as_mut() {
            sm.set_internal_limit(limited);
        }
        if limited {
            ctx.emit(ZimmerAcsEvent::TargetLimited {
                requested_um: requested.round() as i64,
                limited_um: target.round() as i32,
            });
        }
        if self.profile(ctx).is_none() {
            self.fault(ctx, ZimmerErrors::ProfilerParametersNotValid);
            return;
        }
        ctx.emit(ZimmerAcsEvent::SetPointAccepted {
            target_um: target.round() as i32,
            relative,
            immediate,
        });
        if self.axis.take_set_point(target, immediate) {
            self.start_motion(ctx, target);
        }
        self.axis.inside_since = None;
    }

    /// 15.5 0x6065/0x6066: outside the window for longer than the timeout
    /// is a following error (bit 13, error 0x7387). 0xFFFFFFFF switches
    /// the monitor off (CiA 402).
    fn check_following_error(&mut self, ctx: Ctx<'_, '_>) {
        let now = ctx.now();
        if self.state() != Some(State::OperationEnabled) || !is_position_mode(self.mode()) {
            self.axis.outside_since = None;
            return;
        }
        let window = ctx
            .get::<od::FollowingErrorWindow>()
            .map_or(u32::MAX, |v| v.0);
        let error = (self.axis.profiler.position - self.axis.actual).abs();
        if window == u32::MAX || error <= f64::from(window) {
            self.axis.outside_since = None;
            return;
        }
        let since = *self.axis.outside_since.get_or_insert(now);
        let timeout = ctx.get::<od::FollowingErrorTimeOut>().map_or(0, |v| v.0);
        if now.saturating_duration_since(since) > Duration::from_millis(u64::from(timeout)) {
            if let Some(sm) = self.axis.sm.as_mut() {
                sm.set_position_following_error(true);
            }
            self.fault(ctx, ZimmerErrors::PositionFollowingError);
        }
    }

    /// 15.1.2.1: target reached once the position stays within 0x21F1 of
    /// the target for the window time; while halted it means standstill
    /// (CiA 402).
    fn update_target_reached(&mut self, ctx: Ctx<'_, '_>) {
        let now = ctx.now();
        let pp = self.state() == Some(State::OperationEnabled)
            && self.mode() == ModeOfOperation::ProfilePosition;
        let halt = self.axis.halted();
        let window = f64::from(ctx.get::<od::PositionWindowX21F1>().map_or(0, |v| v.0));
        let reached = if pp && self.axis.settled(halt, window) {
            let since = *self.axis.inside_since.get_or_insert(now);
            now.saturating_duration_since(since) >= POSITION_WINDOW_TIME
        } else {
            self.axis.inside_since = None;
            false
        };
        if let Some(sm) = self.axis.sm.as_mut() {
            sm.set_target_reached(reached);
        }
        if reached && self.axis.moving && !halt {
            self.axis.moving = false;
            ctx.emit(ZimmerAcsEvent::TargetReached {
                position_um: self.axis.actual.round() as i32,
            });
        }
    }
}
