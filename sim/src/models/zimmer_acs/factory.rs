//! The values the simulated axis leaves the factory with. The generated
//! table has defaults only where the manual gives them; the rest is filled
//! in here: the control parameters of chapter 13.2 (from the manual) and
//! the limits, profile and monitoring parameters, which the manual leaves
//! to the data sheet (assumed values, each marked).

use eds2rust_drivers::zimmer_acs::od;

use crate::Context;

/// The two sizes of the axis (chapter 5: up to 100 or 150 mm stroke;
/// chapter 13.2: control parameters per size).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Variant {
    /// ACS40: 100 mm stroke, 13.2.1 control parameters.
    #[default]
    Acs40,
    /// ACS60: 150 mm stroke, 13.2.2 control parameters.
    Acs60,
}

impl Variant {
    /// The stroke in µm (chapter 5).
    pub const fn stroke_um(self) -> i32 {
        match self {
            Variant::Acs40 => 100_000,
            Variant::Acs60 => 150_000,
        }
    }

    /// POS_KP, VEL_KP, VEL_KI, POS_KFFV, POS_KFFA, VEL_KFFA (13.2) and
    /// VEL_FDB_FIL_1_FREQ [Hz].
    const fn control(self) -> ([f32; 6], u32) {
        match self {
            Variant::Acs40 => ([0.0015, 2.0, 80.0, 0.5, 0.0, 0.002], 1000),
            Variant::Acs60 => ([0.001, 5.0, 50.0, 0.3, 0.0, 0.01], 800),
        }
    }
}

/// Lowest profile velocity [mm/s] (0x3008/1). Assumed: not in the manual.
pub(crate) const VELOCITY_MIN: u32 = 1;
/// Highest profile velocity [mm/s] (0x3008/2). Assumed: not in the manual.
pub(crate) const VELOCITY_MAX: u32 = 300;
/// Acceleration and deceleration limits [mm/s²] (0x3009, 0x300A).
/// Assumed: not in the manual.
pub(crate) const RAMP_MIN: u32 = 1;
/// See [`RAMP_MIN`].
pub(crate) const RAMP_MAX: u32 = 10_000;
/// Profile velocity [mm/s] (0x6081) at delivery. Assumed.
pub(crate) const PROFILE_VELOCITY: u32 = 100;
/// Profile acceleration and deceleration [mm/s²] (0x6083, 0x6084). Assumed.
pub(crate) const PROFILE_RAMP: u32 = 1_000;
/// Following error window [µm] (0x6065). Assumed.
pub(crate) const FOLLOWING_ERROR_WINDOW: u32 = 1_000;
/// Following error timeout [ms] (0x6066). Assumed.
pub(crate) const FOLLOWING_ERROR_TIMEOUT: u16 = 100;
/// Position window [µm] (0x21F1, 15.1.2.1: target reached needs one).
/// Assumed.
pub(crate) const POSITION_WINDOW: u32 = 10;

/// Writes the factory values into a table that holds only the generated
/// defaults (a device that never saved, or after "load" and a power
/// cycle). A table restored from a "save" is recognised by its position
/// limit, which the generated defaults leave at 0, and left alone.
pub(crate) fn apply<E>(ctx: &mut Context<'_, E>, variant: Variant) {
    let saved = ctx
        .get::<od::position_limits::MaximumPositionLimit>()
        .is_some_and(|v| v.0 != 0);
    if saved {
        return;
    }
    use od::position_limits as pos;
    ctx.set::<pos::MinimumPositionLimit>(pos::MinimumPositionLimitValue(0));
    ctx.set::<pos::MaximumPositionLimit>(pos::MaximumPositionLimitValue(variant.stroke_um()));
    use od::velocity_limits as vel;
    ctx.set::<vel::MinimumVelocityLimit>(vel::MinimumVelocityLimitValue(VELOCITY_MIN));
    ctx.set::<vel::MaximumVelocityLimit>(vel::MaximumVelocityLimitValue(VELOCITY_MAX));
    use od::acceleration_limits as acc;
    ctx.set::<acc::MinimumAccelerationLimit>(acc::MinimumAccelerationLimitValue(RAMP_MIN));
    ctx.set::<acc::MaximumAccelerationLimit>(acc::MaximumAccelerationLimitValue(RAMP_MAX));
    use od::deceleration_limits as dec;
    ctx.set::<dec::MinimumDecelerationLimit>(dec::MinimumDecelerationLimitValue(RAMP_MIN));
    ctx.set::<dec::MaximumDecelerationLimit>(dec::MaximumDecelerationLimitValue(RAMP_MAX));
    ctx.set::<od::ProfileVelocity>(od::ProfileVelocityValue(PROFILE_VELOCITY));
    ctx.set::<od::ProfileAcceleration>(od::ProfileAccelerationValue(PROFILE_RAMP));
    ctx.set::<od::ProfileDeceleration>(od::ProfileDecelerationValue(PROFILE_RAMP));
    ctx.set::<od::FollowingErrorWindow>(od::FollowingErrorWindowValue(FOLLOWING_ERROR_WINDOW));
    ctx.set::<od::FollowingErrorTimeOut>(od::FollowingErrorTimeOutValue(FOLLOWING_ERROR_TIMEOUT));
    ctx.set::<od::PositionWindowX21F1>(od::PositionWindowValue(POSITION_WINDOW));
    // CiA 402 defaults of the option codes (the manual gives none).
    ctx.set::<od::QuickStopOptionCode>(od::QuickStopOptionCodeValue::QUICK_STOP_RAMP_AND_DISABLE);
    ctx.set::<od::HaltOptionCode>(od::HaltOptionCodeValue::SLOW_DOWN_RAMP);
    // Chapter 13.2: the control parameters and their factory defaults.
    let ([pos_kp, vel_kp, vel_ki, pos_kffv, pos_kffa, vel_kffa], filter) = variant.control();
    ctx.set::<od::PositionLoopKp>(pos_kp);
    ctx.set::<od::VelocityLoopKp>(vel_kp);
    ctx.set::<od::VelocityLoopKi>(vel_ki);
    ctx.set::<od::PositionLoopKffv>(pos_kffv);
    ctx.set::<od::PositionLoopKffa>(pos_kffa);
    ctx.set::<od::VelocityLoopKffa>(vel_kffa);
    ctx.set::<od::VelocityFeedbackFilter1Frequency>(od::VelocityFeedbackFilter1FrequencyValue(
        filter,
    ));
    ctx.set::<od::position_loop_kp_limits::DefaultPositionLoopKp>(pos_kp);
    ctx.set::<od::velocity_loop_kp_limits::DefaultVelocityLoopKp>(vel_kp);
    ctx.set::<od::velocity_loop_ki_limits::DefaultVelocityLoopKi>(vel_ki);
    ctx.set::<od::position_loop_kffv_limits::DefaultPositionLoopKffv>(pos_kffv);
    ctx.set::<od::position_loop_kffa_limits::DefaultPositionLoopKffa>(pos_kffa);
    ctx.set::<od::velocity_loop_kffa_limits::DefaultVelocityLoopKffa>(vel_kffa);
    use od::velocity_feedback_filter_1_frequency_limits as fil;
    ctx.set::<fil::DefaultVelocityFeedbackFilter1Frequency>(
        fil::DefaultVelocityFeedbackFilter1FrequencyValue(filter),
    );
}

/// At every power-on the entries the manual does not keep in NVM (15.5:
/// controlword, target, clamping element override) start at 0, whatever a
/// "save" copied.
pub(crate) fn volatile<E>(ctx: &mut Context<'_, E>) {
    ctx.set::<od::Controlword>(od::ControlwordValue(0));
    ctx.set::<od::TargetPosition>(od::TargetPositionValue(0));
    ctx.set::<od::ClampingElementOverride>(od::ClampingElementOverrideValue::NO_OVERRIDE);
}
