//! What the generic drive does at each step of the shared axis
//! ([`Drive`]): the modes' motion in Operation enabled, the quick stop
//! ramp of the option code, set-points, and the following error and
//! target reached monitors.

use eds2rust_runtime::cia402::{DeviceStateMachine, ModeOfOperation, State};

use super::axis::{Axis, Drive};
use super::logic::Ctx;
use super::objects::{self as obj, int};
use super::profiler::{Goal, Profiler};
use super::{Cia402, Cia402Event};

impl Drive for Cia402 {
    type Event = Cia402Event;

    fn axis(&mut self) -> &mut Axis {
        &mut self.axis
    }

    fn quick_stop(&mut self, ctx: Ctx<'_, '_>) -> (f64, bool) {
        let (code, stays) = self.axis.sm.as_ref().map_or((2, false), |sm| {
            (
                sm.config().quick_stop_option_code,
                sm.config().stays_in_quick_stop(),
            )
        });
        (obj::braking(ctx.table(), i64::from(code)), stays)
    }

    fn stop_motion(&mut self) {
        self.homing_in_place = None;
        self.axis.stop_motion();
    }

    fn run_enabled(&mut self, ctx: Ctx<'_, '_>, seconds: f64) {
        let halt = self.halted();
        match self.mode() {
            ModeOfOperation::CyclicSynchronousPosition => {
                // The axis takes each target at once; no interpolation.
                let raw = int(ctx.table(), obj::TARGET_POSITION).unwrap_or(0) as f64;
                let target = self.limit(ctx, raw);
                self.axis.profiler = Profiler::at(target);
                self.axis.goal = target;
            }
            ModeOfOperation::ProfilePosition => {
                let goal = if halt {
                    self.halt_goal(ctx)
                } else {
                    let p = obj::profile(ctx.table());
                    Goal::Target {
                        target: self.axis.goal,
                        velocity: p.velocity,
                        acceleration: p.acceleration,
                        deceleration: p.deceleration,
                    }
                };
                if self.axis.profiler.run(seconds, goal)
                    && !halt
                    && let Some(next) = self.axis.queued.take()
                {
                    self.axis.start_motion(next);
                }
            }
            ModeOfOperation::ProfileVelocity => {
                let goal = if halt {
                    self.halt_goal(ctx)
                } else {
                    let p = obj::profile(ctx.table());
                    let target = int(ctx.table(), obj::TARGET_VELOCITY).unwrap_or(0) as f64;
                    Goal::Velocity {
                        velocity: obj::limit_velocity(ctx.table(), target),
                        acceleration: p.acceleration,
                        deceleration: p.deceleration,
                    }
                };
                self.axis.profiler.run(seconds, goal);
                // At a software limit the axis stops (bit 11).
                let position = self.axis.profiler.position;
                let limited = self.limit(ctx, position);
                if limited != position {
                    self.axis.profiler = Profiler::at(limited);
                }
                self.axis.goal = self.axis.profiler.position;
            }
            ModeOfOperation::Homing => {
                let homing = self
                    .axis
                    .sm
                    .as_ref()
                    .is_some_and(DeviceStateMachine::homing_active);
                let goal = if halt || !homing || self.homing_in_place.is_some() {
                    self.halt_goal(ctx)
                } else {
                    let p = obj::homing_profile(ctx.table());
                    Goal::Target {
                        target: self.home_switch,
                        velocity: p.velocity,
                        acceleration: p.acceleration,
                        deceleration: p.deceleration,
                    }
                };
                if let Some(at) = self.homing_in_place {
                    if homing && ctx.now() >= at {
                        self.homing_in_place = None;
                        self.home_here(ctx);
                    }
                } else if self.axis.profiler.run(seconds, goal) && homing && !halt {
                    self.home_here(ctx);
                }
            }
            _ => {
                self.axis.profiler.run(
                    seconds,
                    Goal::Stop {
                        deceleration: obj::profile(ctx.table()).deceleration,
                    },
                );
            }
        }
    }

    /// A new set-point (bits 4-6): the target, its limits, then now (bit 5
    /// or at rest) or after the running move.
    fn start_set_point(&mut self, ctx: Ctx<'_, '_>, immediate: bool, relative: bool) {
        let raw = int(ctx.table(), obj::TARGET_POSITION).unwrap_or(0) as f64;
        let requested = if relative {
            // 0x60F2 bits 0-1: 0 preceding target, 1 demand, 2 actual.
            let option = int(ctx.table(), obj::POSITIONING_OPTION_CODE).unwrap_or(0) & 3;
            let reference = match option {
                1 => self.axis.profiler.position,
                2 => self.axis.actual,
                _ => self.axis.queued.unwrap_or(self.axis.goal),
            };
            reference + raw
        } else {
            raw
        };
        let target = self.limit(ctx, requested);
        if target != requested {
            ctx.emit(Cia402Event::TargetLimited {
                requested: requested.round() as i64,
                limited: target.round() as i64,
            });
        }
        ctx.emit(Cia402Event::SetPointAccepted {
            target: target.round() as i64,
            relative,
            immediate,
        });
        if self.axis.take_set_point(target, immediate) {
            self.axis.start_motion(target);
        }
    }

    /// Outside the window 0x6065 for longer than 0x6066 ms: bit 13.
    fn check_following_error(&mut self, ctx: Ctx<'_, '_>) {
        let now = ctx.now();
        let position_mode = matches!(
            self.mode(),
            ModeOfOperation::ProfilePosition | ModeOfOperation::CyclicSynchronousPosition
        );
        let error = self.axis.profiler.position - self.axis.actual;
        let outside = self.state() == Some(State::OperationEnabled)
            && position_mode
            && obj::window(ctx.table(), obj::FOLLOWING_ERROR_WINDOW)
                .is_some_and(|window| error.abs() > window);
        if !outside {
            self.axis.outside_since = None;
            if let Some(sm) = self.axis.sm.as_mut() {
                sm.set_position_following_error(false);
            }
            return;
        }
        let since = *self.axis.outside_since.get_or_insert(now);
        let timeout = obj::millis(ctx.table(), obj::FOLLOWING_ERROR_TIME_OUT);
        let late = self.model_time_since(now, since) > timeout;
        let Some(sm) = self.axis.sm.as_mut() else {
            return;
        };
        let was = sm.statusword().following_error();
        if late && !was {
            sm.set_position_following_error(true);
            ctx.emit(Cia402Event::FollowingError {
                error: error.round() as i64,
            });
        }
    }

    /// Bit 10 (pp: within 0x6067 for 0x6068 ms; pv: within 0x606D of the
    /// target velocity; halted: standstill) and bit 12 in pv (speed 0).
    fn update_target_reached(&mut self, ctx: Ctx<'_, '_>) {
        let now = ctx.now();
        let enabled = self.state() == Some(State::OperationEnabled);
        let halt = self.halted();
        let table = ctx.table();
        let reached = match self.mode() {
            ModeOfOperation::ProfilePosition if enabled => {
                let window = obj::window(table, obj::POSITION_WINDOW).unwrap_or(0.0);
                if self.axis.settled(halt, window) {
                    let since = *self.axis.inside_since.get_or_insert(now);
                    self.model_time_since(now, since)
                        >= obj::millis(table, obj::POSITION_WINDOW_TIME)
                } else {
                    self.axis.inside_since = None;
                    false
                }
            }
            ModeOfOperation::ProfileVelocity if enabled => {
                let target = int(table, obj::TARGET_VELOCITY).unwrap_or(0) as f64;
                let target = obj::limit_velocity(table, target);
                let window = int(table, obj::VELOCITY_WINDOW).unwrap_or(0) as f64;
                if halt {
                    self.axis.profiler.at_rest()
                } else {
                    (self.actual_velocity - target).abs() <= window
                }
            }
            // Homing sets bit 10 itself (homing_done); csp has no bit 10.
            ModeOfOperation::Homing => return,
            _ => false,
        };
        let threshold = int(table, obj::VELOCITY_THRESHOLD).unwrap_or(0) as f64;
        let speed_zero = self.actual_velocity.abs() <= threshold;
        let moving = self.axis.moving;
        let Some(sm) = self.axis.sm.as_mut() else {
            return;
        };
        sm.set_target_reached(reached);
        sm.set_speed_zero(speed_zero);
        if reached && moving && !halt && self.mode() == ModeOfOperation::ProfilePosition {
            self.axis.moving = false;
            ctx.emit(Cia402Event::TargetReached {
                position: self.axis.actual.round() as i64,
            });
        }
    }
}
