//! Each device's sequence as a step per SYNC cycle: it reads the master's
//! inputs (the TPDOs last received) and writes its part of the outputs
//! (the RPDOs sent after the next SYNC). The CiA 402 drives go through
//! the runtime's [`Drive`] (enable sequence, halt); the LINAK takes its
//! commands as the manual's start-up sequence has them.

use std::io::Write;
use std::time::Duration;

use eds2rust_machine::network::{Inputs, Outputs};
use eds2rust_machine::{actuator, axis, conveyor};
use eds2rust_runtime::Instant;
use eds2rust_runtime::cia402::{Drive, DriveConfig, Event, Statusword};
use eds2rust_runtime::od::Scaled as _;

/// What a step could not do.
pub type StepResult = Result<(), Box<dyn std::error::Error>>;

/// One line of the log, with the time since the cycle started.
pub fn log(out: &mut dyn Write, at: Duration, device: &str, text: &str) -> std::io::Result<()> {
    writeln!(out, "[{:>6.2} s] {device:<8} {text}", at.as_secs_f64())
}

/// The CiA 402 events worth a line, or an error for a failure.
fn drive_events(
    drive: &mut Drive,
    out: &mut dyn Write,
    at: Duration,
    device: &str,
) -> Result<bool, Box<dyn std::error::Error>> {
    let mut enabled = false;
    while let Some(event) = drive.poll_event() {
        match event {
            Event::StateChanged { to: Some(to), .. } => log(out, at, device, &format!("{to}"))?,
            Event::Enabled => enabled = true,
            Event::FaultDetected | Event::FollowingError => {
                return Err(
                    format!("{device}: {event:?} (statusword {:?})", drive.statusword()).into(),
                );
            }
            Event::Timeout { step, state } => {
                return Err(
                    format!("{device}: no answer in step {step:?} (state {state:?})").into(),
                );
            }
            Event::Failed { .. } => return Err(format!("{device}: {event:?}").into()),
            _ => {}
        }
    }
    Ok(enabled)
}

/// Feeds a statusword to `drive` and runs its timer.
fn see(drive: &mut Drive, now: Instant, statusword: u16) {
    if drive.poll_timeout().is_some_and(|at| at <= now) {
        drive.handle_timeout(now);
    }
    drive.update_statusword(now, Statusword(statusword));
    // The writes are the controlword and the csp target, which the RPDO
    // carries from `Drive::controlword` and the trajectory.
    while drive.poll_write().is_some() {}
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum AxisPhase {
    Enabling,
    Moving { from: f64 },
    Settling,
    Done,
}

/// The Zimmer axis in cyclic synchronous position mode (0x6060 = 8 from
/// the bus file): enabled, then moved by a new target position in RPDO1
/// at each SYNC, a straight ramp at `velocity_um_s`.
#[derive(Debug)]
pub struct AxisMove {
    drive: Drive,
    phase: AxisPhase,
    /// The target position sent (µm).
    demand: f64,
    goal_um: i32,
    velocity_um_s: f64,
    started: bool,
    halfway: bool,
    /// The final position reported (µm).
    pub reached_um: Option<i32>,
}

impl AxisMove {
    /// A move of `distance_um` from where the axis stands.
    pub fn new(distance_um: i32, velocity_um_s: f64) -> AxisMove {
        AxisMove {
            drive: Drive::new(DriveConfig::default()),
            phase: AxisPhase::Enabling,
            demand: 0.0,
            goal_um: distance_um,
            velocity_um_s,
            started: false,
            halfway: false,
            reached_um: None,
        }
    }

    pub fn done(&self) -> bool {
        self.phase == AxisPhase::Done
    }

    /// One SYNC cycle of `period`.
    pub fn step(
        &mut self,
        now: Instant,
        at: Duration,
        period: Duration,
        inputs: &Inputs,
        outputs: &mut Outputs,
        out: &mut dyn Write,
    ) -> StepResult {
        let Some(tpdo) = inputs.axis_tpdo1 else {
            return Ok(());
        };
        let actual = tpdo.position_actual_value.0;
        see(&mut self.drive, now, tpdo.statusword.0);
        if !self.started {
            self.started = true;
            self.demand = f64::from(actual);
            self.goal_um = actual.saturating_add(self.goal_um);
            log(
                out,
                at,
                "axis",
                &format!("at {:.3} mm; enable (RPDO1 controlword)", mm(actual)),
            )?;
            self.drive.enable(now);
        }
        let enabled = drive_events(&mut self.drive, out, at, "axis")?;
        match self.phase {
            AxisPhase::Enabling if enabled => {
                log(
                    out,
                    at,
                    "axis",
                    &format!(
                        "csp move to {:.3} mm at {:.0} mm/s: a target position each SYNC (RPDO1)",
                        mm(self.goal_um),
                        self.velocity_um_s / 1000.0
                    ),
                )?;
                self.phase = AxisPhase::Moving { from: self.demand };
            }
            AxisPhase::Moving { from } => {
                let goal = f64::from(self.goal_um);
                let step = self.velocity_um_s * period.as_secs_f64();
                self.demand = if goal >= from {
                    (self.demand + step).min(goal)
                } else {
                    (self.demand - step).max(goal)
                };
                if !self.halfway && (f64::from(actual) - from).abs() >= (goal - from).abs() / 2.0 {
                    self.halfway = true;
                    log(
                        out,
                        at,
                        "axis",
                        &format!("halfway: position {:.3} mm (TPDO1)", mm(actual)),
                    )?;
                }
                if self.demand == goal {
                    self.phase = AxisPhase::Settling;
                }
            }
            AxisPhase::Settling if (actual - self.goal_um).abs() <= 10 => {
                log(
                    out,
                    at,
                    "axis",
                    &format!("reached {:.3} mm (TPDO1)", mm(actual)),
                )?;
                self.reached_um = Some(actual);
                self.phase = AxisPhase::Done;
            }
            _ => {}
        }
        outputs.axis_rpdo1 = axis::pdo::Rpdo1ControlAndTargetPosition {
            controlword: axis::od::ControlwordValue(self.drive.controlword().0),
            target_position: axis::od::TargetPositionValue(self.demand.round() as i32),
        };
        Ok(())
    }
}

fn mm(um: i32) -> f64 {
    f64::from(um) / 1000.0
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ActuatorPhase {
    Stop,
    RunOut,
    RunIn,
    Done,
}

/// The LINAK actuator: Stop until its error code is 0, out to the end stop
/// and back in (RPDO1 commands, TPDO1 feedback).
#[derive(Debug)]
pub struct ActuatorStroke {
    phase: ActuatorPhase,
    /// The position at the outer end stop (mm).
    pub out_end_mm: Option<f64>,
    /// The position at the end (mm).
    pub in_end_mm: Option<f64>,
}

impl Default for ActuatorStroke {
    fn default() -> Self {
        ActuatorStroke {
            phase: ActuatorPhase::Stop,
            out_end_mm: None,
            in_end_mm: None,
        }
    }
}

impl ActuatorStroke {
    pub fn done(&self) -> bool {
        self.phase == ActuatorPhase::Done
    }

    /// One SYNC cycle.
    pub fn step(
        &mut self,
        at: Duration,
        inputs: &Inputs,
        outputs: &mut Outputs,
        out: &mut dyn Write,
    ) -> StepResult {
        use actuator::od::command::PositionValue;
        if let Some(f) = inputs.actuator_tpdo1 {
            let flags = f.status_flags;
            let position = f.position.number().map_or(f64::NAN, |n| n.value());
            match self.phase {
                ActuatorPhase::Stop if f.error_code.to_raw() == 0 => {
                    log(
                        out,
                        at,
                        "actuator",
                        &format!("ready at {position:.1} mm; run out (RPDO1)"),
                    )?;
                    self.phase = ActuatorPhase::RunOut;
                }
                ActuatorPhase::RunOut if flags.end_stop_out() => {
                    log(
                        out,
                        at,
                        "actuator",
                        &format!("end stop out at {position:.1} mm; run in"),
                    )?;
                    self.out_end_mm = Some(position);
                    self.phase = ActuatorPhase::RunIn;
                }
                ActuatorPhase::RunIn if flags.end_stop_in() && !flags.running_in() => {
                    log(
                        out,
                        at,
                        "actuator",
                        &format!("end stop in at {position:.1} mm"),
                    )?;
                    self.in_end_mm = Some(position);
                    self.phase = ActuatorPhase::Done;
                }
                _ => {}
            }
            if f.error_code.to_raw() != 0 && self.phase != ActuatorPhase::Stop {
                return Err(format!("actuator: error code {:?}", f.error_code).into());
            }
        }
        outputs.actuator_rpdo1.position = match self.phase {
            ActuatorPhase::Stop | ActuatorPhase::Done => PositionValue::STOP,
            ActuatorPhase::RunOut => PositionValue::RUN_OUT,
            ActuatorPhase::RunIn => PositionValue::RUN_IN,
        };
        Ok(())
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum ConveyorPhase {
    Enabling,
    Accelerating,
    Conveying { until: Duration },
    Halting,
    Done,
}

/// The Interroll conveyor in profile velocity mode: enabled by RPDO1,
/// runs up to its target velocity, conveys for a while, halts (controlword
/// bit 8); TPDO4 reports statusword and velocity each SYNC.
#[derive(Debug)]
pub struct ConveyorRun {
    drive: Drive,
    phase: ConveyorPhase,
    target_mm_s: i32,
    conveying: Duration,
    started: bool,
    /// The velocity reached (mm/s).
    pub reached_mm_s: Option<i32>,
}

impl ConveyorRun {
    /// A run at `target_mm_s` (0x60FF, written before the cycle) held for
    /// `conveying`.
    pub fn new(target_mm_s: i32, conveying: Duration) -> ConveyorRun {
        ConveyorRun {
            drive: Drive::new(DriveConfig::default()),
            phase: ConveyorPhase::Enabling,
            target_mm_s,
            conveying,
            started: false,
            reached_mm_s: None,
        }
    }

    pub fn done(&self) -> bool {
        self.phase == ConveyorPhase::Done
    }

    /// One SYNC cycle.
    pub fn step(
        &mut self,
        now: Instant,
        at: Duration,
        inputs: &Inputs,
        outputs: &mut Outputs,
        out: &mut dyn Write,
    ) -> StepResult {
        let Some(tpdo) = inputs.conveyor_tpdo4 else {
            return Ok(());
        };
        let velocity = tpdo.velocity_actual_value.0;
        see(&mut self.drive, now, tpdo.statusword.0);
        if !self.started {
            self.started = true;
            log(
                out,
                at,
                "conveyor",
                "enable in profile velocity mode (RPDO1)",
            )?;
            self.drive.enable(now);
        }
        let enabled = drive_events(&mut self.drive, out, at, "conveyor")?;
        match self.phase {
            ConveyorPhase::Enabling if enabled => self.phase = ConveyorPhase::Accelerating,
            ConveyorPhase::Accelerating if (velocity - self.target_mm_s).abs() <= 5 => {
                log(
                    out,
                    at,
                    "conveyor",
                    &format!("conveying at {velocity} mm/s (TPDO4)"),
                )?;
                self.reached_mm_s = Some(velocity);
                self.phase = ConveyorPhase::Conveying {
                    until: at + self.conveying,
                };
            }
            ConveyorPhase::Conveying { until } if at >= until => {
                log(out, at, "conveyor", "halt (RPDO1 controlword bit 8)")?;
                self.drive.halt();
                while self.drive.poll_write().is_some() {}
                self.phase = ConveyorPhase::Halting;
            }
            ConveyorPhase::Halting if velocity == 0 => {
                let temperature = tpdo.actual_temperature.0;
                log(
                    out,
                    at,
                    "conveyor",
                    &format!("standstill, motor at {temperature} °C (TPDO4)"),
                )?;
                self.phase = ConveyorPhase::Done;
            }
            _ => {}
        }
        outputs.conveyor_rpdo1 = conveyor::pdo::Rpdo1VelocityCommand {
            controlword: conveyor::od::ControlwordValue(self.drive.controlword().0),
            modes_of_operation: conveyor::od::ModesOfOperationValue::PROFILE_VELOCITY,
            profile_velocity: conveyor::od::ProfileVelocityValue(self.target_mm_s.unsigned_abs()),
        };
        Ok(())
    }
}
