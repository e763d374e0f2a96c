//! The RollerDrive's mechanics and thermals: the roller's velocity and
//! position, the force it needs, the motor temperature, current and DC link
//! voltage.
//!
//! The manual gives the units (mm, mm/s, mm/s², chapter 7 factor group) and
//! the ranges of the objects, but no motor data. Where a number is needed
//! and the manual is silent, this module chooses what a 24 V roller drive of
//! 20 to 50 W does; each such constant says so.

/// Chosen (manual silent): the lowest velocity the drive can run
/// controlled, in mm/s. Chapter 4.2: a target below the minimum possible
/// velocity stops the drive (zero motion hold).
pub(crate) const MIN_VELOCITY_MM_S: f64 = 20.0;

/// Chosen: deceleration of an unpowered roller coasting to rest
/// ("Freilauf", chapter 2.1) under the conveyor's friction, mm/s².
pub(crate) const COAST_DECEL_MM_S2: f64 = 800.0;

/// Chosen: quick stop deceleration when 0x60C6 (max deceleration) is 0,
/// mm/s².
pub(crate) const QUICK_STOP_DECEL_MM_S2: f64 = 5000.0;

/// Chosen: profile acceleration written into 0x6083 at power-on when the
/// table holds none (the manual: "Getriebe-abhängig", no value), mm/s².
pub(crate) const DEFAULT_ACCEL_MM_S2: u32 = 1000;

/// Chosen: the roller surface speed at which the nominal power is reached
/// (m/s); gives the rated force `nominal power / this`.
const RATED_SPEED_M_S: f64 = 0.6;

/// Chosen: copper and iron losses at rated force, as a share of the nominal
/// power.
const LOSS_AT_RATED: f64 = 0.3;

/// Chosen: electronics consumption while the processor runs, W.
const IDLE_POWER_W: f64 = 1.5;

/// Chosen: thermal resistance motor to ambient, K/W.
const THERMAL_RESISTANCE_K_W: f64 = 2.5;

/// Chosen: thermal time constant of the motor, s.
const THERMAL_TIME_CONSTANT_S: f64 = 900.0;

/// Chosen: internal resistance of the 24 V supply line, Ω.
const SUPPLY_RESISTANCE_OHM: f64 = 0.2;

/// Chosen: gravity, for the rolling friction of the load, m/s².
const G: f64 = 9.81;

/// What the conveyor puts on the roller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Load {
    /// The conveyed mass moved by this roller, kg.
    pub mass_kg: f64,
    /// Rolling resistance coefficient of the load (dimensionless).
    pub rolling_resistance: f64,
    /// Constant friction of roller bearings and gear, N.
    pub friction_n: f64,
}

impl Default for Load {
    /// Chosen: a 10 kg carton on a roller conveyor.
    fn default() -> Load {
        Load {
            mass_kg: 10.0,
            rolling_resistance: 0.03,
            friction_n: 2.0,
        }
    }
}

impl Load {
    /// The friction force opposing motion, N.
    pub(crate) fn friction(&self) -> f64 {
        self.mass_kg * G * self.rolling_resistance + self.friction_n
    }
}

/// -1, 0 or 1 (`f64::signum` gives 1 for 0).
pub(crate) fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Moves `v` towards `target` by at most `accel` (when speeding up) or
/// `decel` (when slowing down or reversing) times `dt`.
pub(crate) fn ramp(v: f64, target: f64, accel: f64, decel: f64, dt: f64) -> f64 {
    let speeding_up = target.abs() > v.abs() && (v == 0.0 || v.signum() == target.signum());
    let rate = if speeding_up { accel } else { decel };
    crate::cia402::profiler::toward(v, target, rate.max(0.0) * dt)
}

/// The electrical and thermal state of the motor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Electrics {
    /// Motor temperature, °C.
    pub(crate) temperature_c: f64,
    /// Motor force at the roller surface in the last step (signed), N.
    pub(crate) force_n: f64,
    /// Mechanical power in the last step, W.
    pub(crate) mech_power_w: f64,
    /// Supply current, A.
    pub(crate) current_a: f64,
}

impl Electrics {
    pub(crate) fn new(ambient_c: f64) -> Electrics {
        Electrics {
            temperature_c: ambient_c,
            force_n: 0.0,
            mech_power_w: 0.0,
            current_a: 0.0,
        }
    }

    /// The rated force for a nominal power in W, N.
    pub(crate) fn rated_force(nominal_w: f64) -> f64 {
        (nominal_w / RATED_SPEED_M_S).max(1.0)
    }

    /// One step of `dt` seconds: the motor delivers `force_n` at `v_mm_s`
    /// (both signed; force 0 when unpowered); `supply_v` feeds it; the motor heats towards
    /// ambient plus losses.
    pub(crate) fn step(
        &mut self,
        dt: f64,
        force_n: f64,
        v_mm_s: f64,
        nominal_w: f64,
        supply_v: f64,
        ambient_c: f64,
    ) {
        let rated = Electrics::rated_force(nominal_w);
        let mech = (force_n * v_mm_s / 1000.0).max(0.0);
        let load = force_n / rated;
        let losses = LOSS_AT_RATED * nominal_w * load * load + IDLE_POWER_W;
        self.force_n = force_n;
        self.mech_power_w = mech;
        self.current_a = if supply_v > 1.0 {
            (mech + losses) / supply_v
        } else {
            0.0
        };
        let settle = ambient_c + THERMAL_RESISTANCE_K_W * losses;
        let k = (dt / THERMAL_TIME_CONSTANT_S).min(1.0);
        self.temperature_c += (settle - self.temperature_c) * k;
    }

    /// The DC link voltage under the present current, V.
    pub(crate) fn dc_link(&self, supply_v: f64) -> f64 {
        (supply_v - SUPPLY_RESISTANCE_OHM * self.current_a).max(0.0)
    }
}

/// The profile-position trajectory (chapter 4.3).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Positioning {
    /// The set-point being approached, mm.
    pub(crate) target: f64,
    /// A buffered set-point (at most one, "Set of Set-Points").
    pub(crate) buffered: Option<f64>,
    /// Controlword bit 9 when the set-point was buffered: pass the first
    /// target at full speed.
    pub(crate) pass_through: bool,
    /// A positioning is in progress.
    pub(crate) active: bool,
}

/// What a positioning step brought.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum PositionStep {
    /// Still on the way.
    Moving,
    /// The first target was passed; the buffered one is next.
    NextSetPoint,
    /// The final target is reached (position snapped to it).
    Reached,
}

impl Positioning {
    /// The velocity wanted now at `pos` with profile velocity `vmax` and
    /// deceleration `decel`: as fast as allowed while still able to stop
    /// at the end point.
    pub(crate) fn wanted_velocity(&self, pos: f64, vmax: f64, decel: f64) -> f64 {
        if !self.active {
            return 0.0;
        }
        let d = self.target - pos;
        let mut brake_distance = d.abs();
        if self.pass_through
            && let Some(next) = self.buffered
        {
            let d_next = next - pos;
            if sign(d_next) == sign(d) {
                brake_distance = d_next.abs();
            }
        }
        let v = (2.0 * decel.max(1.0) * brake_distance).sqrt().min(vmax);
        // A crawl speed near the end, so a discrete step always arrives.
        let v = v.max(MIN_VELOCITY_MM_S.min(vmax)).min(vmax);
        sign(d) * v
    }

    /// Checks arrival after moving from `before` to `*pos`; snaps to the
    /// target at the end.
    pub(crate) fn arrive(
        &mut self,
        before: f64,
        pos: &mut f64,
        v: &mut f64,
        dt: f64,
    ) -> PositionStep {
        if !self.active {
            return PositionStep::Moving;
        }
        let d_before = self.target - before;
        let d_after = self.target - *pos;
        let passed = d_before == 0.0 || sign(d_before) != sign(d_after);
        let close = d_after.abs() <= (v.abs() * dt).max(0.05);
        if !(passed || close) {
            return PositionStep::Moving;
        }
        if let Some(next) = self.buffered.take() {
            self.target = next;
            self.pass_through = false;
            return PositionStep::NextSetPoint;
        }
        *pos = self.target;
        *v = 0.0;
        self.active = false;
        PositionStep::Reached
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_limits_the_change_per_step() {
        assert_eq!(ramp(0.0, 500.0, 1000.0, 2000.0, 0.1), 100.0);
        assert_eq!(ramp(450.0, 500.0, 1000.0, 2000.0, 0.1), 500.0);
        assert_eq!(ramp(500.0, 0.0, 1000.0, 2000.0, 0.1), 300.0);
        assert_eq!(ramp(100.0, -100.0, 1000.0, 500.0, 0.1), 50.0);
    }

    #[test]
    fn positioning_snaps_to_the_target() {
        let mut p = Positioning {
            target: 100.0,
            active: true,
            ..Positioning::default()
        };
        let mut pos = 99.99;
        let mut v = 20.0;
        assert_eq!(
            p.arrive(99.0, &mut pos, &mut v, 0.01),
            PositionStep::Reached
        );
        assert_eq!((pos, v, p.active), (100.0, 0.0, false));
    }
}
