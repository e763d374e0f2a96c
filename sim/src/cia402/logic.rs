//! The workings of [`Cia402`]: the state machine's events and their
//! effects, set-points, the mechanics, the monitors, and what is published
//! in the object table.

use std::time::Duration;

use eds2rust_runtime::cia402::{
    Controlword, DeviceConfig as MachineConfig, DeviceEvent, DeviceStateMachine, ModeOfOperation,
    State,
};

use super::axis::{Drive, Step};
use super::objects::{self as obj, int};
use super::profiler::{Goal, Profiler};
use super::{Cia402, Cia402Event};
use crate::Context;

pub(super) type Ctx<'a, 'b> = &'a mut Context<'b, Cia402Event>;

/// Homing methods that home on the current position (CiA 402: 35 and 37).
const HOMING_ON_POSITION: [i64; 2] = [35, 37];

/// How long homing on the current position takes: not at once, so that a
/// master sees homing attained clear after the start, as on a real drive.
pub(crate) const HOMING_IN_PLACE_TIME: Duration = Duration::from_millis(20);

/// The state machine's settings: immediate start-up and fault reaction,
/// the quick stop ramp run by the model, voltage enabled and remote on.
fn machine_config(quick_stop_option_code: i16) -> MachineConfig {
    MachineConfig {
        start_up: Duration::ZERO,
        fault_reaction: Some(Duration::ZERO),
        quick_stop: None,
        quick_stop_option_code,
        voltage_enabled: true,
        remote: true,
    }
}

/// Stores `value` into (index, sub) when the table has it.
pub(super) fn publish(ctx: Ctx<'_, '_>, index: u16, sub: u8, value: i64) {
    // Absent or non-numeric entries are skipped: every object but
    // 0x6040/0x6041 is optional.
    let _ = ctx.table_mut().set_int(index, sub, value);
}

impl Cia402 {
    /// Power-on (and NMT reset node): a new state machine; the axis stays
    /// where it is.
    pub(super) fn power_on(&mut self, ctx: Ctx<'_, '_>) {
        self.homing_in_place = None;
        self.axis.power_off();
        self.option_code_changed = false;
        self.emcy_sent = false;
        self.begin(ctx);
        self.finish(ctx);
    }

    /// Before handling an input: the state machine exists, the mechanics
    /// are at `ctx.now()`.
    pub(super) fn begin(&mut self, ctx: Ctx<'_, '_>) {
        if self.axis.sm.is_none() {
            let table = ctx.table();
            // Without 0x6060 nothing can choose a mode: profile position.
            let mode = int(table, obj::MODES_OF_OPERATION)
                .or_else(|| {
                    table
                        .info(obj::MODES_OF_OPERATION, 0)
                        .is_none()
                        .then_some(1)
                })
                .unwrap_or(0);
            let config = machine_config(obj::quick_stop_option_code(table));
            let mode = ModeOfOperation::from_i8(mode as i8);
            self.axis.switch_on(ctx.now(), config, mode);
        }
        self.advance(ctx);
    }

    /// After handling an input: the state machine's events and their
    /// effects, the published values.
    pub(super) fn finish(&mut self, ctx: Ctx<'_, '_>) {
        // Effects can cause transitions, which are events again; a few
        // rounds settle every chain.
        for _ in 0..8 {
            let events = self.axis.poll_events();
            if events.is_empty() {
                break;
            }
            for event in events {
                self.on_event(ctx, event);
            }
        }
        self.publish_values(ctx);
    }

    /// A new quick stop option code, taken now when in Switch on disabled
    /// (or before), else at the next entry to it.
    pub(super) fn take_option_code(&mut self, ctx: Ctx<'_, '_>) {
        let idle = matches!(
            self.state(),
            Some(State::SwitchOnDisabled | State::NotReadyToSwitchOn)
        );
        if !self.option_code_changed || !idle {
            return;
        }
        self.option_code_changed = false;
        let mode = self.mode();
        let code = obj::quick_stop_option_code(ctx.table());
        let mut sm = DeviceStateMachine::new(ctx.now(), machine_config(code));
        // The new machine's transitions 0 and 1 end where the old one was.
        while sm.poll_event().is_some() {}
        sm.set_mode(mode);
        self.axis.sm = Some(sm);
    }

    /// Raises a fault with `code`: 0x603F, 0x1001 bit 0, EMCY, Fault.
    pub(super) fn fault(&mut self, ctx: Ctx<'_, '_>, code: u16) {
        if !self.axis.raise_fault(ctx.now(), code) {
            return;
        }
        publish(ctx, obj::ERROR_CODE, 0, i64::from(code));
        let register = int(ctx.table(), obj::ERROR_REGISTER).unwrap_or(0) | 1;
        publish(ctx, obj::ERROR_REGISTER, 0, register);
        ctx.emcy(code, [0; 5]);
        self.emcy_sent = true;
        ctx.emit(Cia402Event::Fault(code));
    }

    pub(super) fn apply_controlword(&mut self, ctx: Ctx<'_, '_>) {
        let cw = int(ctx.table(), obj::CONTROLWORD).unwrap_or(0);
        let now = ctx.now();
        if let Some(sm) = self.axis.sm.as_mut() {
            sm.apply_controlword(now, Controlword(cw as u16));
        }
    }

    pub(super) fn apply_mode(&mut self, ctx: Ctx<'_, '_>) {
        let mode = int(ctx.table(), obj::MODES_OF_OPERATION).unwrap_or(0);
        let mode = ModeOfOperation::from_i8(mode as i8);
        let Some(sm) = self.axis.sm.as_mut() else {
            return;
        };
        if sm.mode() != mode {
            sm.set_mode(mode);
            sm.set_target_reached(false);
            sm.set_internal_limit(false);
            // A change of mode in motion brakes (the new mode's goal then
            // applies); at rest nothing moves.
            self.axis.queued = None;
            self.axis.pending = None;
            self.axis.moving = false;
            self.axis.goal = self.axis.profiler.position;
        }
    }

    fn on_event(&mut self, ctx: Ctx<'_, '_>, event: DeviceEvent) {
        match self.axis.take_event(event) {
            Some(Step::Transition { number, from, to }) => {
                ctx.emit(Cia402Event::StateChanged {
                    transition: number,
                    from,
                    to,
                });
                self.on_transition(ctx, number, to);
            }
            Some(Step::HomingStarted) => self.start_homing(ctx),
            None => {}
        }
    }

    fn on_transition(&mut self, ctx: Ctx<'_, '_>, number: u8, to: State) {
        let now = ctx.now();
        let homing = self.mode() == ModeOfOperation::Homing;
        if let Some(sm) = self.axis.sm.as_mut()
            && !homing
        {
            // Set again by the monitor.
            sm.set_target_reached(false);
        }
        match to {
            State::QuickStopActive => {
                let code = self
                    .axis
                    .sm
                    .as_ref()
                    .map_or(2, |sm| sm.config().quick_stop_option_code);
                if code == 0 {
                    // Disable drive function: the axis coasts.
                    self.stop_motion();
                    if let Some(sm) = self.axis.sm.as_mut() {
                        sm.complete_quick_stop(now);
                    }
                }
            }
            State::SwitchOnDisabled => {
                self.stop_motion();
                self.take_option_code(ctx);
            }
            _ => self.stop_motion(),
        }
        if number == 15 {
            // CiA 301: EMCY "error reset" after the fault is cleared.
            publish(ctx, obj::ERROR_CODE, 0, 0);
            publish(ctx, obj::ERROR_REGISTER, 0, 0);
            if std::mem::take(&mut self.emcy_sent) {
                ctx.emcy(0, [0; 5]);
            }
            self.axis.clear_fault_bits();
        }
    }

    /// Runs the mechanics from the last input to `ctx.now()`.
    fn advance(&mut self, ctx: Ctx<'_, '_>) {
        let seconds = self.run_mechanics(ctx);
        self.follow(seconds);
    }

    /// The actual position follows the demand (at most the lag speed).
    fn follow(&mut self, seconds: f64) {
        let before = self.axis.actual;
        let movable = matches!(
            self.state(),
            Some(State::OperationEnabled | State::QuickStopActive)
        );
        if !movable {
            self.actual_velocity = 0.0;
            return;
        }
        match self.lag {
            None => {
                self.axis.actual = self.axis.profiler.position;
                self.actual_velocity = self.axis.profiler.velocity;
            }
            Some(speed) => {
                let gap = self.axis.profiler.position - self.axis.actual;
                let step = (speed * seconds).min(gap.abs());
                self.axis.actual += step * gap.signum();
                self.actual_velocity = if seconds > 0.0 {
                    (self.axis.actual - before) / seconds
                } else {
                    0.0
                };
            }
        }
    }

    pub(super) fn halted(&self) -> bool {
        self.axis.halted()
    }

    /// The braking goal of a halt (0x605D; 1, slow down ramp, without it).
    pub(super) fn halt_goal(&self, ctx: Ctx<'_, '_>) -> Goal {
        let code = int(ctx.table(), obj::HALT_OPTION_CODE).unwrap_or(1);
        Goal::Stop {
            deceleration: obj::braking(ctx.table(), code),
        }
    }

    /// `position` within the software limits; sets bit 11 when clamped
    /// (and clears it when not).
    pub(super) fn limit(&mut self, ctx: Ctx<'_, '_>, position: f64) -> f64 {
        let limited = match obj::position_limits(ctx.table()) {
            Some((min, max)) => position.clamp(min, max),
            None => position,
        };
        if let Some(sm) = self.axis.sm.as_mut() {
            sm.set_internal_limit(limited != position);
        }
        limited
    }

    /// Homing started (bit 4 rising in homing mode).
    fn start_homing(&mut self, ctx: Ctx<'_, '_>) {
        self.axis.queued = None;
        self.axis.pending = None;
        self.axis.moving = true;
        let method = int(ctx.table(), obj::HOMING_METHOD).unwrap_or(0);
        self.homing_in_place = HOMING_ON_POSITION
            .contains(&method)
            .then(|| ctx.now() + HOMING_IN_PLACE_TIME);
    }

    /// The axis is at the home switch: the position becomes the home
    /// offset; homing attained.
    pub(super) fn home_here(&mut self, ctx: Ctx<'_, '_>) {
        let offset = int(ctx.table(), obj::HOME_OFFSET).unwrap_or(0) as f64;
        self.axis.actual = offset;
        self.axis.profiler = Profiler::at(offset);
        self.axis.goal = offset;
        self.home_switch = offset;
        self.axis.moving = false;
        if let Some(sm) = self.axis.sm.as_mut() {
            sm.homing_done(true);
        }
        ctx.emit(Cia402Event::HomingAttained {
            position: offset.round() as i64,
        });
    }
}
