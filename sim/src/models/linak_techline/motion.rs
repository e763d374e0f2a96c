//! The piston: position between the two end stops, a signed speed (positive
//! outwards), and ramps from the soft start and soft stop times (RPDO1 bytes
//! 4-5, p. 30-31; 0x4000 sub 3-6, p. 40). Pure arithmetic in mechanical
//! time, no bus.

use crate::cia402::profiler::toward;

/// Position resolution of the feedback (0.1 mm/bit, p. 32); a target
/// closer than half of it counts as reached.
const ARRIVAL_MM: f64 = 0.05;

/// Where a run goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Goal {
    /// Run out (0xFB01 / recovery 0xFB04) until the outer end stop.
    Out,
    /// Run in (0xFB02 / recovery 0xFB05) until the inner end stop.
    In,
    /// To a position in mm (0..=64255 × 0.1 mm), clamped to the stroke.
    To(f64),
    /// Ramp down to standstill (Stop, 0xFB03).
    Halt,
}

/// The limits of one run, from the command and the configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    /// Top speed in mm/s.
    pub speed: f64,
    /// Acceleration in mm/s² (top speed / soft start time; infinite for 0 s).
    pub accel: f64,
    /// Deceleration in mm/s² (top speed / soft stop time; infinite for 0 s).
    pub decel: f64,
}

impl Profile {
    /// A profile of top speed `speed` (mm/s) reached in `start` seconds and
    /// left in `stop` seconds.
    pub fn new(speed: f64, start: f64, stop: f64) -> Profile {
        let rate = |t: f64| if t > 0.0 { speed / t } else { f64::INFINITY };
        Profile {
            speed,
            accel: rate(start),
            decel: rate(stop),
        }
    }
}

/// What ended a run during one advance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Arrival {
    /// Still moving.
    Moving,
    /// The outer end stop (the stroke).
    EndStopOut,
    /// The inner end stop (0 mm).
    EndStopIn,
    /// A position target.
    Target,
    /// Standstill after [`Goal::Halt`].
    Halted,
}

/// The piston.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piston {
    /// Position in mm, 0 (fully in) ..= stroke.
    pub position: f64,
    /// Speed in mm/s, positive outwards.
    pub velocity: f64,
    /// Stroke length in mm.
    pub stroke: f64,
}

impl Piston {
    /// Whether the piston stands at the inner end stop.
    pub fn at_end_in(&self) -> bool {
        self.position <= 0.0
    }

    /// Whether the piston stands at the outer end stop.
    pub fn at_end_out(&self) -> bool {
        self.position >= self.stroke
    }

    /// The speed `goal` asks for now (signed), ramping down in time for a
    /// position target.
    fn desired(&self, goal: Goal, p: &Profile) -> f64 {
        match goal {
            Goal::Out => p.speed,
            Goal::In => -p.speed,
            Goal::Halt => 0.0,
            Goal::To(target) => {
                let distance = target - self.position;
                let cap = (2.0 * p.decel * distance.abs()).sqrt();
                distance.signum() * p.speed.min(cap)
            }
        }
    }

    /// Moves the piston by `dt` seconds of mechanical time towards `goal`.
    pub fn advance(&mut self, goal: Goal, p: &Profile, dt: f64) -> Arrival {
        let goal = match goal {
            Goal::To(t) => Goal::To(t.clamp(0.0, self.stroke)),
            other => other,
        };
        if let Goal::To(target) = goal
            && (target - self.position).abs() < ARRIVAL_MM
            && self.velocity.abs() <= p.decel * dt.max(1e-3)
        {
            self.position = target;
            self.velocity = 0.0;
            return Arrival::Target;
        }
        let want = self.desired(goal, p);
        let v = self.velocity;
        let reversing = (v > 0.0 && want <= 0.0) || (v < 0.0 && want >= 0.0);
        let next = if reversing {
            toward(v, 0.0, p.decel * dt)
        } else if want.abs() < v.abs() {
            toward(v, want, p.decel * dt)
        } else {
            toward(v, want, p.accel * dt)
        };
        let before = self.position;
        self.position = (before + (v + next) / 2.0 * dt).clamp(0.0, self.stroke);
        self.velocity = next;
        if let Goal::To(target) = goal {
            let crossed = (before - target) * (self.position - target) <= 0.0;
            if crossed || ((target - self.position).abs() < ARRIVAL_MM && next.abs() < 1e-9) {
                self.position = target;
                self.velocity = 0.0;
                return Arrival::Target;
            }
        }
        if self.at_end_out() && (next > 0.0 || goal == Goal::Out) {
            self.velocity = 0.0;
            return Arrival::EndStopOut;
        }
        if self.at_end_in() && (next < 0.0 || goal == Goal::In) {
            self.velocity = 0.0;
            return Arrival::EndStopIn;
        }
        match goal {
            Goal::Halt if self.velocity == 0.0 => Arrival::Halted,
            _ => Arrival::Moving,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piston(position: f64) -> Piston {
        Piston {
            position,
            velocity: 0.0,
            stroke: 50.3,
        }
    }

    fn run(p: &mut Piston, goal: Goal, profile: &Profile, limit: f64) -> (Arrival, f64) {
        let dt = 0.01;
        let mut t = 0.0;
        while t < limit {
            t += dt;
            let a = p.advance(goal, profile, dt);
            if a != Arrival::Moving {
                return (a, t);
            }
        }
        (Arrival::Moving, t)
    }

    #[test]
    fn runs_out_to_the_stroke_and_in_to_zero() {
        let profile = Profile::new(5.0, 0.3, 0.3);
        let mut p = piston(0.0);
        let (a, t) = run(&mut p, Goal::Out, &profile, 20.0);
        assert_eq!(a, Arrival::EndStopOut);
        assert_eq!(p.position, 50.3);
        // 50.3 mm at 5 mm/s plus half the 0.3 s ramp.
        assert!((t - 10.21).abs() < 0.05, "{t}");
        let (a, _) = run(&mut p, Goal::In, &profile, 20.0);
        assert_eq!(a, Arrival::EndStopIn);
        assert_eq!(p.position, 0.0);
    }

    #[test]
    fn stops_on_a_target_without_overshoot() {
        let profile = Profile::new(5.0, 0.3, 0.3);
        let mut p = piston(10.0);
        let (a, _) = run(&mut p, Goal::To(20.0), &profile, 10.0);
        assert_eq!(a, Arrival::Target);
        assert_eq!(p.position, 20.0);
        let (a, _) = run(&mut p, Goal::To(12.5), &profile, 10.0);
        assert_eq!(a, Arrival::Target);
        assert_eq!(p.position, 12.5);
        // Beyond the stroke: the end stop.
        let (a, _) = run(&mut p, Goal::To(6000.0), &profile, 20.0);
        assert_eq!(a, Arrival::Target);
        assert_eq!(p.position, 50.3);
    }

    #[test]
    fn halt_ramps_down_in_the_soft_stop_time() {
        let profile = Profile::new(5.0, 0.0, 0.5);
        let mut p = piston(10.0);
        p.advance(Goal::Out, &profile, 0.01);
        assert_eq!(p.velocity, 5.0);
        let (a, t) = run(&mut p, Goal::Halt, &profile, 2.0);
        assert_eq!(a, Arrival::Halted);
        assert!((t - 0.5).abs() < 0.02, "{t}");
    }
}
