//! The trajectory generator of the simulated drives: a trapezoidal
//! velocity profile computed on line, so that a target can change during a
//! move ("change immediately", controlword bit 5) and a halt or quick stop
//! can brake from any speed; and a ramp to a target velocity (profile
//! velocity mode). Units are the caller's: a position unit, that unit per
//! second and per second squared (the generic [`Cia402`](super::Cia402)
//! uses the device's own position units; the Zimmer model µm).
//!
//! CiA 402 profile position mode with linear ramps (a trapezoid) is what
//! is modelled; jerk limits and the motion profile type 0x6086 are not.

/// The longest integration step, in seconds of model time.
const MAX_STEP_S: f64 = 0.001;
/// The most integration steps one call runs (larger steps beyond that).
const MAX_STEPS: u32 = 100_000;
/// Closer than this (position units) to the target counts as there.
const ARRIVAL: f64 = 0.01;

/// Where the generator is heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Goal {
    /// Move to `target` with at most `velocity`, accelerating with
    /// `acceleration` and braking with `deceleration`.
    Target {
        /// Absolute target (units).
        target: f64,
        /// Profile velocity (units/s, > 0).
        velocity: f64,
        /// Profile acceleration (units/s², > 0).
        acceleration: f64,
        /// Profile deceleration (units/s², > 0).
        deceleration: f64,
    },
    /// Brake to standstill with `deceleration` (units/s², > 0).
    Stop {
        /// Deceleration (units/s²).
        deceleration: f64,
    },
    /// Run at `velocity` (signed, units/s), speeding up with `acceleration`
    /// and slowing down (towards 0 or through it) with `deceleration`.
    Velocity {
        /// Target velocity (units/s).
        velocity: f64,
        /// Acceleration (units/s², > 0).
        acceleration: f64,
        /// Deceleration (units/s², > 0).
        deceleration: f64,
    },
}

/// The demand position and velocity the generator puts out.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Profiler {
    /// Demand position (units).
    pub(crate) position: f64,
    /// Demand velocity (units/s, signed).
    pub(crate) velocity: f64,
}

impl Profiler {
    /// A generator at rest at `position`.
    pub(crate) fn at(position: f64) -> Profiler {
        Profiler {
            position,
            velocity: 0.0,
        }
    }

    /// Whether the demand stands still.
    pub(crate) fn at_rest(&self) -> bool {
        self.velocity == 0.0
    }

    /// Runs the generator for `seconds` of model time towards `goal`;
    /// returns whether the goal was reached (target: there at rest; stop:
    /// at rest; velocity: at that velocity, still moving).
    pub(crate) fn run(&mut self, seconds: f64, goal: Goal) -> bool {
        if seconds.is_nan() || seconds <= 0.0 {
            return self.reached(goal);
        }
        let steps = (seconds / MAX_STEP_S)
            .ceil()
            .clamp(1.0, f64::from(MAX_STEPS));
        let h = seconds / steps;
        // A velocity goal keeps moving once reached.
        let ends = !matches!(goal, Goal::Velocity { .. });
        for _ in 0..steps as u32 {
            if ends && self.reached(goal) {
                return true;
            }
            self.step(h, goal);
        }
        self.reached(goal)
    }

    fn reached(&self, goal: Goal) -> bool {
        match goal {
            Goal::Target { target, .. } => self.at_rest() && self.position == target,
            Goal::Stop { .. } => self.at_rest(),
            Goal::Velocity { velocity, .. } => self.velocity == velocity,
        }
    }

    fn step(&mut self, h: f64, goal: Goal) {
        match goal {
            // Braking is a ramp to velocity 0 (never speeding up).
            Goal::Stop { deceleration } => self.step(
                h,
                Goal::Velocity {
                    velocity: 0.0,
                    acceleration: deceleration,
                    deceleration,
                },
            ),
            Goal::Velocity {
                velocity,
                acceleration,
                deceleration,
            } => {
                let v = self.velocity;
                // Speeding up (same sign, larger) uses the acceleration;
                // slowing down or reversing the deceleration.
                let speeding_up = v * velocity >= 0.0 && velocity.abs() > v.abs();
                let rate = if speeding_up {
                    acceleration
                } else {
                    deceleration
                };
                let next = toward(v, velocity, rate.max(f64::MIN_POSITIVE) * h);
                self.position += (v + next) / 2.0 * h;
                self.velocity = next;
            }
            Goal::Target {
                target,
                velocity,
                acceleration,
                deceleration,
            } => {
                let remaining = target - self.position;
                if remaining.abs() <= ARRIVAL && self.velocity.abs() <= deceleration * h {
                    self.position = target;
                    self.velocity = 0.0;
                    return;
                }
                let direction = if remaining >= 0.0 { 1.0 } else { -1.0 };
                let rem = remaining.abs();
                // Speed towards the target (negative: moving away).
                let speed = self.velocity * direction;
                let (next, travel) = if speed < 0.0 {
                    // Wrong way: brake first.
                    let next = (speed + deceleration * h).min(0.0);
                    (next, (speed + next) / 2.0 * h)
                } else if speed > 0.0 && rem - speed * h <= speed * speed / (2.0 * deceleration) {
                    // Braking point within this step: brake with the constant
                    // deceleration that stops on the target (at most the
                    // profile's; more would overshoot and come back).
                    let needed = speed * speed / (2.0 * rem);
                    let decel = needed.min(deceleration);
                    let next = (speed - decel * h).max(0.0);
                    let travel = if next == 0.0 {
                        speed * speed / (2.0 * decel)
                    } else {
                        (speed + next) / 2.0 * h
                    };
                    if needed <= deceleration && (next == 0.0 || travel >= rem) {
                        self.position = target;
                        self.velocity = 0.0;
                        return;
                    }
                    (next, travel)
                } else {
                    let next = if speed < velocity {
                        (speed + acceleration * h).min(velocity)
                    } else {
                        (speed - deceleration * h).max(velocity)
                    };
                    let travel = (speed + next) / 2.0 * h;
                    if travel >= rem {
                        self.position = target;
                        self.velocity = 0.0;
                        return;
                    }
                    (next, travel)
                };
                self.position += travel * direction;
                self.velocity = next * direction;
            }
        }
    }
}

/// `v` moved towards `target` by at most `step` (a speed ramp; the seed
/// models' mechanics use it too).
pub(crate) fn toward(v: f64, target: f64, step: f64) -> f64 {
    if (target - v).abs() <= step {
        target
    } else if target > v {
        v + step
    } else {
        v - step
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn to(target: f64) -> Goal {
        Goal::Target {
            target,
            velocity: 50_000.0,        // 50 mm/s
            acceleration: 500_000.0,   // 500 mm/s²
            deceleration: 1_000_000.0, // 1000 mm/s²
        }
    }

    #[test]
    fn a_trapezoid_takes_the_time_of_its_ramps_and_cruise() {
        // 40 mm at 50 mm/s: ramp up 0.1 s (2.5 mm), ramp down 0.05 s
        // (1.25 mm), cruise 36.25 mm in 0.725 s: 0.875 s in all.
        let mut p = Profiler::at(0.0);
        assert!(!p.run(0.872, to(40_000.0)));
        assert!(p.position < 40_000.0 && p.position > 39_990.0);
        assert!(p.run(0.004, to(40_000.0)));
        assert_eq!(p.position, 40_000.0);
        assert!(p.at_rest());
        // Half-way through the cruise the demand moves at the profile velocity.
        let mut q = Profiler::at(0.0);
        q.run(0.4, to(40_000.0));
        assert!((q.velocity - 50_000.0).abs() < 1e-6);
        assert!((q.position - (2_500.0 + 0.3 * 50_000.0)).abs() < 1.0);
    }

    #[test]
    fn a_velocity_goal_ramps_with_the_acceleration_and_holds() {
        let goal = Goal::Velocity {
            velocity: 1_000.0,
            acceleration: 10_000.0,
            deceleration: 20_000.0,
        };
        let mut p = Profiler::at(0.0);
        // 0.1 s ramp (50 units), then 1000 units/s.
        assert!(p.run(0.2, goal));
        assert_eq!(p.velocity, 1_000.0);
        assert!((p.position - (50.0 + 100.0)).abs() < 1.0);
        let back = Goal::Velocity {
            velocity: -1_000.0,
            acceleration: 10_000.0,
            deceleration: 20_000.0,
        };
        // Reversing: down to 0 with the deceleration (0.05 s), then up
        // with the acceleration (0.1 s).
        assert!(!p.run(0.14, back));
        assert!(p.run(0.011, back));
    }

    #[test]
    fn a_new_target_behind_brakes_first_and_stop_brakes_to_rest() {
        let mut p = Profiler::at(0.0);
        p.run(0.4, to(40_000.0));
        // Reverse: brake with 1000 mm/s² (50 ms), then go back to 10 mm.
        assert!(p.run(2.0, to(10_000.0)));
        assert_eq!(p.position, 10_000.0);
        let mut q = Profiler::at(0.0);
        q.run(0.4, to(40_000.0));
        let from = q.position;
        assert!(q.run(
            0.06,
            Goal::Stop {
                deceleration: 1_000_000.0
            }
        ));
        // v²/2d = 0.05² m²/s² / 2 m/s² = 1.25 mm.
        assert!((q.position - from - 1_250.0).abs() < 1.0);
    }
}
