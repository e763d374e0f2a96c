//! The CiA 402 axis both simulated drives are built on (the generic
//! [`Cia402`](super::Cia402) and the Zimmer ACS model): the device state
//! machine, the trajectory generator and the set-point bookkeeping of
//! profile position mode, with the rules CiA 402 gives them and the two
//! models share. Each model keeps only what is its own around it (its
//! objects and units, the mechanics' options, its monitors' reactions).

use std::time::Duration;

use eds2rust_runtime::Instant;
use eds2rust_runtime::cia402::{
    DeviceConfig as MachineConfig, DeviceEvent, DeviceStateMachine, ModeOfOperation, State,
};

use super::profiler::{Goal, Profiler};
use crate::Context;

/// The state machine, the mechanics and the set-points of one axis.
#[derive(Debug, Clone)]
pub(crate) struct Axis {
    /// How much faster than real time the mechanics move.
    pub(crate) time_scale: f64,
    /// The device state machine (`None` before power-on).
    pub(crate) sm: Option<DeviceStateMachine>,
    /// When the mechanics were last run.
    pub(crate) last: Option<Instant>,
    /// Actual position; it survives power cycles.
    pub(crate) actual: f64,
    pub(crate) profiler: Profiler,
    /// The target the generator heads for.
    pub(crate) goal: f64,
    /// The next set-point of a set of set-points.
    pub(crate) queued: Option<f64>,
    /// A new set-point waiting for the next step: (immediate, relative).
    pub(crate) pending: Option<(bool, bool)>,
    /// A move was started and its target reached is not reported yet.
    pub(crate) moving: bool,
    /// Outside the following error window since.
    pub(crate) outside_since: Option<Instant>,
    /// Settled within the position window since.
    pub(crate) inside_since: Option<Instant>,
}

/// What a state machine event asks of the model.
pub(crate) enum Step {
    /// A transition (CiA 402 numbering) from one state to another.
    Transition {
        number: u8,
        from: Option<State>,
        to: State,
    },
    /// Homing started (bit 4 rising in homing mode).
    HomingStarted,
}

impl Axis {
    /// An axis at position 0, in real time, before power-on.
    pub(crate) fn new() -> Axis {
        Axis {
            time_scale: 1.0,
            sm: None,
            last: None,
            actual: 0.0,
            profiler: Profiler::at(0.0),
            goal: 0.0,
            queued: None,
            pending: None,
            moving: false,
            outside_since: None,
            inside_since: None,
        }
    }

    /// Power-on (and NMT reset node): no state machine until the next
    /// input ([`Axis::switch_on`]); the axis stays where it is.
    pub(crate) fn power_off(&mut self) {
        self.sm = None;
        self.last = None;
        self.stop_motion();
    }

    /// The first input after power-on: a new state machine with `config`
    /// in `mode`; the mechanics run from `now`.
    pub(crate) fn switch_on(&mut self, now: Instant, config: MachineConfig, mode: ModeOfOperation) {
        let mut sm = DeviceStateMachine::new(now, config);
        sm.set_mode(mode);
        self.sm = Some(sm);
        self.last = Some(now);
    }

    /// The mechanics `factor` times faster than real time (a factor that
    /// is not a positive number leaves it unchanged).
    pub(crate) fn set_time_scale(&mut self, factor: f64) {
        if factor.is_finite() && factor > 0.0 {
            self.time_scale = factor;
        }
    }

    /// The axis at rest at `position`.
    pub(crate) fn place(&mut self, position: f64) {
        self.actual = position;
        self.profiler = Profiler::at(position);
        self.goal = position;
    }

    /// The CiA 402 state (`None` before power-on).
    pub(crate) fn state(&self) -> Option<State> {
        self.sm.as_ref().map(DeviceStateMachine::state)
    }

    /// The mode of operation in effect (`NoMode` before power-on).
    pub(crate) fn mode(&self) -> ModeOfOperation {
        self.sm
            .as_ref()
            .map_or(ModeOfOperation::NoMode, DeviceStateMachine::mode)
    }

    /// Whether the controlword's halt bit (8) is set.
    pub(crate) fn halted(&self) -> bool {
        self.sm.as_ref().is_some_and(|sm| sm.controlword().halt())
    }

    /// The motion stops where the axis is: no set-point waits, no monitor
    /// runs.
    pub(crate) fn stop_motion(&mut self) {
        self.profiler = Profiler::at(self.actual);
        self.goal = self.actual;
        self.queued = None;
        self.pending = None;
        self.moving = false;
        self.outside_since = None;
        self.inside_since = None;
    }

    /// The model time (seconds, at the time scale) from the last run of
    /// the mechanics to `now`, which becomes the last.
    pub(crate) fn elapsed(&mut self, now: Instant) -> f64 {
        let elapsed = self
            .last
            .map_or(Duration::ZERO, |last| now.saturating_duration_since(last));
        self.last = Some(now);
        elapsed.as_secs_f64() * self.time_scale
    }

    /// Quick stop active: the generator brakes with `deceleration`; at
    /// rest the quick stop completes (transition 12) unless the option
    /// code keeps the drive in Quick stop active (`stays`).
    pub(crate) fn brake_quick_stop(
        &mut self,
        now: Instant,
        seconds: f64,
        deceleration: f64,
        stays: bool,
    ) {
        if self.profiler.run(seconds, Goal::Stop { deceleration })
            && !stays
            && let Some(sm) = self.sm.as_mut()
        {
            sm.complete_quick_stop(now);
        }
    }

    /// The state machine's events since the last call.
    pub(crate) fn poll_events(&mut self) -> Vec<DeviceEvent> {
        let mut events = Vec::new();
        if let Some(sm) = self.sm.as_mut() {
            while let Some(event) = sm.poll_event() {
                events.push(event);
            }
        }
        events
    }

    /// Takes a state machine event: a new set-point in profile position
    /// mode waits for the next step (when an RPDO has written the target
    /// mapped after the controlword too); what the model must act on is
    /// returned.
    pub(crate) fn take_event(&mut self, event: DeviceEvent) -> Option<Step> {
        match event {
            DeviceEvent::Transition { number, from, to } => {
                Some(Step::Transition { number, from, to })
            }
            DeviceEvent::NewSetPoint {
                immediate,
                relative,
            } if self.mode() == ModeOfOperation::ProfilePosition => {
                self.pending = Some((immediate, relative));
                None
            }
            DeviceEvent::HomingStarted => Some(Step::HomingStarted),
            _ => None,
        }
    }

    /// Raises a fault with `code` in the state machine; false when there
    /// is none yet or it is in this fault already.
    pub(crate) fn raise_fault(&mut self, now: Instant, code: u16) -> bool {
        let Some(sm) = self.sm.as_mut() else {
            return false;
        };
        if sm.state().is_fault() && sm.fault_code() == Some(code) {
            return false;
        }
        sm.raise_fault(now, code);
        true
    }

    /// Fault reset (transition 15): the following error and internal
    /// limit bits (13, 11) are cleared with the fault.
    pub(crate) fn clear_fault_bits(&mut self) {
        if let Some(sm) = self.sm.as_mut() {
            sm.set_position_following_error(false);
            sm.set_internal_limit(false);
        }
    }

    /// The set-point deferred to this step, in Operation enabled (else it
    /// is dropped).
    pub(crate) fn deferred_set_point(&mut self) -> Option<(bool, bool)> {
        let enabled = self.state() == Some(State::OperationEnabled);
        self.pending.take().filter(|_| enabled)
    }

    /// The generator heads for `target` now.
    pub(crate) fn start_motion(&mut self, target: f64) {
        self.goal = target;
        self.moving = true;
        self.inside_since = None;
    }

    /// A new set-point `target`: started now with bit 5 (change
    /// immediately) or when the axis is at rest, else after the running
    /// move (a set of set-points). True when it started now.
    pub(crate) fn take_set_point(&mut self, target: f64, immediate: bool) -> bool {
        let busy = !self.profiler.at_rest() || self.profiler.position != self.goal;
        if immediate || !busy {
            self.queued = None;
            true
        } else {
            self.queued = Some(target);
            false
        }
    }

    /// Profile position: the generator rests with no set-point waiting,
    /// halted, or at the last target with the actual position within
    /// `window` of it.
    pub(crate) fn settled(&self, halt: bool, window: f64) -> bool {
        self.profiler.at_rest()
            && self.pending.is_none()
            && (halt
                || (self.profiler.position == self.goal
                    && self.queued.is_none()
                    && (self.goal - self.actual).abs() <= window))
    }
}

/// A simulated drive on the [`Axis`]: when each step of CiA 402 happens is
/// the axis's rule, what it does is the model's.
pub(crate) trait Drive {
    /// The model's events.
    type Event;

    /// The axis.
    fn axis(&mut self) -> &mut Axis;

    /// Operation enabled: the mode of operation moves the axis for
    /// `seconds` of model time.
    fn run_enabled(&mut self, ctx: &mut Context<'_, Self::Event>, seconds: f64);

    /// Quick stop active: the braking deceleration of the option code, and
    /// whether the drive stays in Quick stop active at rest.
    fn quick_stop(&mut self, ctx: &mut Context<'_, Self::Event>) -> (f64, bool);

    /// Any other state: the motion stops.
    fn stop_motion(&mut self);

    /// A new set-point (controlword bits 4-6), taken in Operation enabled.
    fn start_set_point(
        &mut self,
        ctx: &mut Context<'_, Self::Event>,
        immediate: bool,
        relative: bool,
    );

    /// The following error monitor (statusword bit 13).
    fn check_following_error(&mut self, ctx: &mut Context<'_, Self::Event>);

    /// Target reached (statusword bit 10).
    fn update_target_reached(&mut self, ctx: &mut Context<'_, Self::Event>);

    /// Runs the mechanics from the last input to `ctx.now()` as the state
    /// says; the model time that passed (s).
    fn run_mechanics(&mut self, ctx: &mut Context<'_, Self::Event>) -> f64 {
        let now = ctx.now();
        let seconds = self.axis().elapsed(now);
        match self.axis().state() {
            Some(State::OperationEnabled) => self.run_enabled(ctx, seconds),
            Some(State::QuickStopActive) => {
                let (deceleration, stays) = self.quick_stop(ctx);
                self.axis()
                    .brake_quick_stop(now, seconds, deceleration, stays);
            }
            _ => self.stop_motion(),
        }
        seconds
    }

    /// The periodic part: the set-point deferred to this step, the
    /// following error, target reached.
    fn monitor_motion(&mut self, ctx: &mut Context<'_, Self::Event>) {
        if let Some((immediate, relative)) = self.axis().deferred_set_point() {
            self.start_set_point(ctx, immediate, relative);
        }
        self.check_following_error(ctx);
        self.update_target_reached(ctx);
    }
}
