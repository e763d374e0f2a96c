//! The command semantics of RPDO1 (p. 30-31), the conditions of p. 27,
//! the run of the motor and the feedback TPDO1 (p. 32-34).

use std::time::Duration;

use eds2rust_drivers::linak_techline::errors::{LastStopReasons, LinakErrors};
use eds2rust_drivers::linak_techline::od::{
    command as cmd, configuration as cfg, consumer_heartbeat_time, feedback as fb,
    tpdo1_communication_parameter as tpdo1,
};
use eds2rust_runtime::nmt::NmtState;
use eds2rust_runtime::od::Scaled as _;

use super::diagnostics::{bump, raise_to, record_stop};
use super::motion::{Arrival, Goal, Profile};
use super::{
    Direction, FACTORY_CURRENT_LIMIT_A, Feedback, JAM_DETECTION, LinakTechline, LinakTechlineEvent,
    Refusal, Run, StopReason,
};
use crate::Context;

type Ctx<'a, 'b> = &'a mut Context<'b, LinakTechlineEvent>;

/// An invalid value (0xFC-0xFF) in a command setting: "the actuator does
/// not move" (p. 30-31).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct InvalidSetting;

impl LinakTechline {
    /// Whether the master's heartbeat is there (p. 27): 0x1016 sub 1 names a
    /// producer and a time, and no loss is pending.
    pub(super) fn heartbeat_ok(&self, ctx: Ctx<'_, '_>) -> bool {
        let configured = ctx
            .get::<consumer_heartbeat_time::ConsumerHeartbeatTime<1>>()
            .is_some_and(|v| v.node_id() != 0 && v.heartbeat_time() != 0);
        configured && !self.heartbeat_lost
    }

    /// Why a command (0x2000 sub 1) cannot be taken now, if it cannot.
    pub(super) fn refusal(&self, ctx: Ctx<'_, '_>, command: cmd::PositionValue) -> Option<Refusal> {
        use cmd::PositionKind as K;
        let kind = command.kind();
        let motion = matches!(
            kind,
            K::Number(_) | K::RunOut | K::RunIn | K::RecoveryRunOut | K::RecoveryRunIn
        );
        if !motion {
            return None;
        }
        if ctx.nmt_state() != NmtState::Operational {
            return Some(Refusal::NotOperational);
        }
        let error = self.errors.reported();
        let blocked = match kind {
            // Recovery runs are the way out of a fault (the manual names
            // them only; modelled): refused only by the power-up lock and
            // the supply.
            K::RecoveryRunOut | K::RecoveryRunIn => {
                self.errors.has(LinakErrors::PowerUpLock)
                    || self.errors.has(LinakErrors::Undervoltage)
            }
            _ => error != LinakErrors::NoError,
        };
        blocked.then_some(Refusal::Error(error))
    }

    /// Carries out a command that passed [`LinakTechline::refusal`].
    pub(super) fn execute(&mut self, ctx: Ctx<'_, '_>, command: cmd::PositionValue) {
        use cmd::PositionKind as K;
        match command.kind() {
            K::ClearError => {
                // p. 29: clears what is no longer there; the run ends.
                self.overcurrent = false;
                self.errors.clear(ctx, LinakErrors::PowerUpLock);
                self.errors.clear(ctx, LinakErrors::PositionNotChanging);
                if self.heartbeat_ok(ctx) {
                    self.errors
                        .clear(ctx, LinakErrors::CommunicationSynchronisation);
                }
                self.halt(StopReason::Command);
            }
            K::Stop => {
                // p. 27 / error 1: Stop ends the power-up lock.
                self.errors.clear(ctx, LinakErrors::PowerUpLock);
                self.halt(StopReason::Command);
            }
            K::RunOut | K::RecoveryRunOut => self.start(ctx, command, Goal::Out),
            K::RunIn | K::RecoveryRunIn => self.start(ctx, command, Goal::In),
            K::Number(n) => self.start(ctx, command, Goal::To(n.value())),
            K::Invalid(_) => self.halt(StopReason::Invalid),
        }
    }

    /// Starts (or redirects) a run to `goal`.
    fn start(&mut self, ctx: Ctx<'_, '_>, command: cmd::PositionValue, goal: Goal) {
        // The conditions may have changed since the write was taken.
        let refusal = if self.heartbeat_ok(ctx) {
            self.refusal(ctx, command)
        } else {
            Some(super::Refusal::HeartbeatMissing)
        };
        if let Some(reason) = refusal {
            let command = command.to_raw();
            ctx.emit(LinakTechlineEvent::CommandRefused { command, reason });
            return;
        }
        let p = &self.piston;
        let direction = match goal {
            Goal::Out => Direction::Out,
            Goal::In => Direction::In,
            Goal::To(t) if t.min(p.stroke) > p.position => Direction::Out,
            Goal::To(t) if t < p.position => Direction::In,
            _ => return self.halt(StopReason::Target),
        };
        if (direction == Direction::Out && p.at_end_out())
            || (direction == Direction::In && p.at_end_in())
        {
            return self.halt(StopReason::EndStop(direction));
        }
        let Ok((profile, limit_a, user_limit)) = self.profile(ctx, direction) else {
            return self.halt(StopReason::Invalid);
        };
        if profile.speed <= 0.0 {
            // 0 % PWM: the motor does not turn.
            return self.halt(StopReason::Command);
        }
        self.overcurrent = false;
        let same = self.run.is_some_and(|r| r.direction == direction);
        self.run = Some(Run {
            goal,
            direction,
            profile,
            limit_a,
            user_limit,
            stalled_s: self.run.map_or(0.0, |r| r.stalled_s),
            halt_reason: StopReason::Command,
        });
        if !same {
            match direction {
                Direction::Out => bump::<cfg::StartsOut, _>(ctx),
                Direction::In => bump::<cfg::StartsIn, _>(ctx),
            }
            ctx.emit(LinakTechlineEvent::MotionStarted {
                direction,
                from_mm: self.piston.position,
            });
        }
    }

    /// Ramps the run down with the soft stop (nothing when standing).
    pub(super) fn halt(&mut self, reason: StopReason) {
        if let Some(run) = self.run.as_mut()
            && run.goal != Goal::Halt
        {
            run.goal = Goal::Halt;
            run.halt_reason = reason;
        }
    }

    /// Cuts the motor off at once.
    pub(super) fn stop_now(&mut self, ctx: Ctx<'_, '_>, reason: StopReason) {
        self.piston.velocity = 0.0;
        if self.run.take().is_some() {
            ctx.emit(LinakTechlineEvent::MotionStopped {
                position_mm: self.piston.position,
                reason,
            });
        }
    }

    /// Records a stop reason (p. 46) in 0x4000 sub 0x26.. .
    pub(super) fn record(&self, ctx: Ctx<'_, '_>, reason: LastStopReasons) {
        record_stop(ctx, reason, self.running_s as u32);
    }

    /// Speed, ramps and current limit of a run in `direction` from the
    /// command (0x2000 sub 2-5) and the configuration (0x4000 sub 1-7).
    fn profile(
        &self,
        ctx: Ctx<'_, '_>,
        direction: Direction,
    ) -> Result<(Profile, f64, bool), InvalidSetting> {
        let out = direction == Direction::Out;
        let max_pct = match ctx.get::<cfg::MaxSpeed>().map(cfg::MaxSpeedValue::kind) {
            Some(cfg::MaxSpeedKind::Number(n)) => n.value(),
            _ => 100.0,
        };
        let pct = match ctx
            .get::<cmd::Speed>()
            .unwrap_or(cmd::SpeedValue::DEFAULT)
            .kind()
        {
            cmd::SpeedKind::Number(n) => n.value(),
            cmd::SpeedKind::FullSpeed(_) => 100.0,
            cmd::SpeedKind::Default => max_pct,
            cmd::SpeedKind::Invalid(_) => return Err(InvalidSetting),
        };
        let speed = self.full_speed * pct.min(max_pct) / 100.0;
        let ms = |raw: u16| f64::from(raw) / 1000.0;
        let start = match ctx
            .get::<cmd::SoftStart>()
            .unwrap_or(cmd::SoftStartValue::DEFAULT)
            .kind()
        {
            cmd::SoftStartKind::Number(n) => n.value(),
            cmd::SoftStartKind::Default if out => ctx
                .get::<cfg::SoftStartOut>()
                .map_or(0.0, |v| ms(v.to_raw())),
            cmd::SoftStartKind::Default => ctx
                .get::<cfg::SoftStartIn>()
                .map_or(0.0, |v| ms(v.to_raw())),
            cmd::SoftStartKind::Invalid(_) => return Err(InvalidSetting),
        };
        let stop = match ctx
            .get::<cmd::SoftStop>()
            .unwrap_or(cmd::SoftStopValue::DEFAULT)
            .kind()
        {
            cmd::SoftStopKind::Number(n) => n.value(),
            cmd::SoftStopKind::Default if out => ctx
                .get::<cfg::SoftStopOut>()
                .map_or(0.0, |v| ms(v.to_raw())),
            cmd::SoftStopKind::Default => {
                ctx.get::<cfg::SoftStopIn>().map_or(0.0, |v| ms(v.to_raw()))
            }
            cmd::SoftStopKind::Invalid(_) => return Err(InvalidSetting),
        };
        let (limit, user) = match ctx
            .get::<cmd::CurrentLimit>()
            .unwrap_or(cmd::CurrentLimitValue::DEFAULT)
            .kind()
        {
            cmd::CurrentLimitKind::Number(n) => (n.value(), true),
            cmd::CurrentLimitKind::Default if out => (
                ctx.get::<cfg::CurrentLimitOut>().map_or(0.0, |v| v.value()),
                false,
            ),
            cmd::CurrentLimitKind::Default => (
                ctx.get::<cfg::CurrentLimitIn>().map_or(0.0, |v| v.value()),
                false,
            ),
            cmd::CurrentLimitKind::Invalid(_) => return Err(InvalidSetting),
        };
        Ok((
            Profile::new(speed, start, stop),
            limit.min(FACTORY_CURRENT_LIMIT_A),
            user,
        ))
    }

    /// Moves the motor on by `dt` mechanical seconds.
    pub(super) fn advance(&mut self, ctx: Ctx<'_, '_>, dt: f64) {
        let Some(mut run) = self.run else {
            return;
        };
        self.running_s += dt;
        if run.goal != Goal::Halt {
            // Speed and limits may change during a run (p. 25-26).
            match self.profile(ctx, run.direction) {
                Ok((profile, limit, user)) => {
                    (run.profile, run.limit_a, run.user_limit) = (profile, limit, user)
                }
                Err(InvalidSetting) => {
                    run.goal = Goal::Halt;
                    run.halt_reason = StopReason::Invalid;
                }
            }
        }
        if self.running_current > run.limit_a {
            return self.overcurrent_stop(ctx, &run);
        }
        if self.jammed {
            // Powered, but the position sensor sees no change.
            self.piston.velocity = 0.0;
            run.stalled_s += dt;
            self.run = Some(run);
            if run.stalled_s >= JAM_DETECTION.as_secs_f64() {
                self.record(ctx, LastStopReasons::PositionNotChanging);
                self.stop_now(ctx, StopReason::Fault(LinakErrors::PositionNotChanging));
                self.errors.raise(ctx, LinakErrors::PositionNotChanging);
            }
            return;
        }
        run.stalled_s = 0.0;
        let before = self.piston.position;
        let arrival = self.piston.advance(run.goal, &run.profile, dt);
        self.run = Some(run);
        if let Some(x) = self.obstacle_out
            && self.piston.position > x
            && before <= x
        {
            self.piston.position = x;
            return self.overcurrent_stop(ctx, &run);
        }
        let reason = match arrival {
            Arrival::Moving => return,
            Arrival::EndStopOut => {
                bump::<cfg::EndStopReachedOut, _>(ctx);
                StopReason::EndStop(Direction::Out)
            }
            Arrival::EndStopIn => {
                bump::<cfg::EndStopReachedIn, _>(ctx);
                StopReason::EndStop(Direction::In)
            }
            Arrival::Target => StopReason::Target,
            Arrival::Halted => run.halt_reason,
        };
        self.stop_now(ctx, reason);
    }

    /// The current reached the limit: the motor is cut off, status bit 2
    /// (p. 32), stop reason 8 "overcurrent" (p. 46) and the overload
    /// counters (p. 42).
    fn overcurrent_stop(&mut self, ctx: Ctx<'_, '_>, run: &Run) {
        self.overcurrent = true;
        match (run.user_limit, run.direction) {
            (true, Direction::Out) => {
                bump::<cfg::ResettableStopsUserCurrentLimitOverloadOut, _>(ctx)
            }
            (true, Direction::In) => bump::<cfg::ResettableStopsUserCurrentLimitOverloadIn, _>(ctx),
            (false, Direction::Out) => bump::<cfg::StopsDefaultCurrentLimitOverloadOut, _>(ctx),
            (false, Direction::In) => bump::<cfg::StopsDefaultCurrentLimitOverloadIn, _>(ctx),
        }
        let peak = (run.limit_a.max(self.running_current) / 0.25)
            .round()
            .min(255.0);
        raise_to::<cfg::MaxMeasuredCurrent, _>(ctx, peak as u64);
        self.record(ctx, LastStopReasons::Overcurrent);
        self.stop_now(ctx, StopReason::Overcurrent);
    }

    /// The TPDO1 values now.
    fn feedback(&self, ctx: Ctx<'_, '_>) -> Feedback {
        let p = &self.piston;
        let running = self.run.map(|r| r.direction);
        let status = fb::StatusFlagsValue::default()
            .with_end_stop_in(p.at_end_in())
            .with_end_stop_out(p.at_end_out())
            .with_overcurrent(self.overcurrent)
            .with_running_out(running == Some(Direction::Out))
            .with_running_in(running == Some(Direction::In))
            .with_heartbeat_required(!self.heartbeat_ok(ctx))
            .with_outside_nominal_conditions(self.undervoltage)
            .with_always_set(true);
        let current = if running.is_some() {
            (self.running_current / 0.25).round().clamp(1.0, 250.0) as u8
        } else {
            0
        };
        Feedback {
            position: (p.position * 10.0).round().clamp(0.0, 64255.0) as u16,
            current,
            status: status.to_raw(),
            error: self.errors.code().to_raw(),
            speed: (p.velocity.abs() * 10.0).round().min(4015.0) as u16,
            aux: self.aux,
        }
    }

    /// Writes the feedback into 0x2001 when the status, the error or the
    /// AUX inputs changed (or `force`), and the moving values once per event
    /// timer (0x1800 sub 5; every step when it is 0), so that the device's
    /// TPDO1 follows.
    pub(super) fn publish(&mut self, ctx: Ctx<'_, '_>, force: bool) {
        let now = ctx.now();
        let f = self.feedback(ctx);
        let timer = ctx.get::<tpdo1::EventTimer>().map_or(Duration::ZERO, |t| {
            Duration::from_millis(u64::from(t.to_raw()))
        });
        let period = crate::Behaviour::period(self);
        let due = now.saturating_duration_since(self.last_publish) + period >= timer;
        let discrete = self
            .published
            .is_none_or(|p| (p.status, p.error, p.aux) != (f.status, f.error, f.aux));
        if !(force || discrete || (self.published != Some(f) && due)) {
            return;
        }
        ctx.set::<fb::Position>(fb::PositionValue::from_raw(f.position));
        ctx.set::<fb::Current>(fb::CurrentValue::from_raw(f.current));
        ctx.set::<fb::StatusFlags>(fb::StatusFlagsValue::from_raw(f.status));
        ctx.set::<fb::ErrorCode>(self.errors.code());
        ctx.set::<fb::Speed>(fb::SpeedValue::from_raw(f.speed));
        ctx.set::<fb::AuxInputs>(fb::AuxInputsValue::from_raw(f.aux));
        self.published = Some(f);
        self.last_publish = now;
        if f.error != self.shown_error {
            self.shown_error = f.error;
            ctx.emit(LinakTechlineEvent::ErrorCode(self.errors.code()));
        }
    }
}
