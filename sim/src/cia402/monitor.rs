//! The periodic part of [`Cia402`]: deferred set-points, following error,
//! target reached and speed 0, and the values published in the table.

use std::time::Duration;

use eds2rust_runtime::Instant;
use eds2rust_runtime::cia402::{ModeOfOperation, State};

use super::logic::{Ctx, publish};
use super::objects::{self as obj, int};
use super::{Cia402, Cia402Event};

impl Cia402 {
    /// The model time from `since` to `now` (the drive's times, 0x6066 and
    /// 0x6068, run at the time scale of the mechanics).
    fn model_time_since(&self, now: Instant, since: Instant) -> Duration {
        now.saturating_duration_since(since)
            .mul_f64(self.axis.time_scale)
    }

    /// The periodic part: deferred set-point, following error, target
    /// reached and speed 0.
    pub(super) fn monitor(&mut self, ctx: Ctx<'_, '_>) {
        if let Some((immediate, relative)) = self.axis.deferred_set_point() {
            self.start_set_point(ctx, immediate, relative);
        }
        self.check_following_error(ctx);
        self.update_target_reached(ctx);
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

    /// Writes the statusword, the mode display and the actual values into
    /// the entries the table has.
    pub(super) fn publish_values(&mut self, ctx: Ctx<'_, '_>) {
        let Some(sm) = self.axis.sm.as_ref() else {
            return;
        };
        let statusword = i64::from(sm.statusword().0);
        let mode = i64::from(sm.mode().as_i8());
        publish(ctx, obj::STATUSWORD, 0, statusword);
        publish(ctx, obj::MODES_OF_OPERATION_DISPLAY, 0, mode);
        let actual = self.axis.actual.round() as i64;
        let demand = self.axis.profiler.position.round() as i64;
        for (index, value) in [
            (obj::POSITION_ACTUAL_VALUE, actual),
            (obj::POSITION_ACTUAL_INTERNAL, actual),
            (obj::POSITION_DEMAND_VALUE, demand),
            (obj::POSITION_DEMAND_INTERNAL, demand),
            (
                obj::VELOCITY_ACTUAL_VALUE,
                self.actual_velocity.round() as i64,
            ),
            (
                obj::VELOCITY_DEMAND_VALUE,
                self.axis.profiler.velocity.round() as i64,
            ),
            (obj::FOLLOWING_ERROR_ACTUAL, demand - actual),
        ] {
            publish(ctx, index, 0, value);
        }
    }
}
