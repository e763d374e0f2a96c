//! The periodic part of [`Cia402`] (the shared axis's monitors, see
//! `drive.rs`) and the values published in the table.

use std::time::Duration;

use eds2rust_runtime::Instant;

use super::Cia402;
use super::axis::Drive;
use super::logic::{Ctx, publish};
use super::objects as obj;

impl Cia402 {
    /// The model time from `since` to `now` (the drive's times, 0x6066 and
    /// 0x6068, run at the time scale of the mechanics).
    pub(super) fn model_time_since(&self, now: Instant, since: Instant) -> Duration {
        now.saturating_duration_since(since)
            .mul_f64(self.axis.time_scale)
    }

    /// The periodic part: deferred set-point, following error, target
    /// reached and speed 0.
    pub(super) fn monitor(&mut self, ctx: Ctx<'_, '_>) {
        self.monitor_motion(ctx);
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
