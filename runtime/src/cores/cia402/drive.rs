//! The master side: [`Drive`] runs CiA 402 sequences against one drive.

use super::object;
use super::types::{DriveConfig, DriveError, Event, Move, Step, Write, WriteValue};
use super::words::{Command, Controlword, ModeOfOperation, State, Statusword};
use crate::Instant;
use crate::queue::Ring;
use crate::time::earliest;

mod plan;
use plan::{Goal, Motion, Plan, Sequence, plan};

/// How many state changes one operation follows before it gives up (a
/// drive that keeps falling back would otherwise be chased for ever).
const MAX_SEQUENCE_STEPS: u8 = 24;

/// Bits a state command keeps from the previous controlword (halt).
const KEPT_BY_COMMANDS: u16 = 0x0100;

/// A sans-IO CiA 402 helper on the master side (not a frame
/// [`Service`](crate::Service): it sees objects, not frames).
///
/// Its interface:
/// - inputs: [`Drive::update_statusword`] with every statusword the caller
///   receives (TPDO or SDO upload of 0x6041), [`Drive::handle_timeout`]
///   when the clock reaches [`Drive::poll_timeout`], and the operations
///   ([`Drive::enable`], [`Drive::move_to`], ...);
/// - outputs: [`Drive::poll_write`], the object writes to perform in order
///   (by RPDO or SDO download), and [`Drive::poll_event`]. Drain both after
///   every input.
///
/// One state-machine operation (enable, disable, quick stop, fault reset)
/// runs at a time; a new one replaces it. Each waits for the statusword to
/// show the next state, with the timeout of its [`Step`]. Independently,
/// one motion operation (a pp move or homing) runs while the drive is in
/// Operation enabled; leaving that state ends it with [`Event::Failed`].
///
/// A completion bit counts only once it was seen clear after the command
/// (target reached after the acknowledge; homing attained or error after
/// the start, where the statusword before the start counts when the mode
/// was already homing), so a statusword sent before the drive took the
/// command cannot end the wait. A move to the current position on a drive
/// that never clears bit 10 therefore ends in a timeout.
///
/// Writes are queued (16; the oldest is dropped when the caller does not
/// drain them); the cyclic synchronous target is one slot that each
/// [`Drive::set_csp_target`] overwrites.
#[derive(Debug, Clone)]
pub struct Drive {
    config: DriveConfig,
    statusword: Option<Statusword>,
    state: Option<State>,
    controlword: Controlword,
    controlword_written: bool,
    mode: Option<ModeOfOperation>,
    sequence: Option<Sequence>,
    motion: Motion,
    motion_deadline: Option<Instant>,
    writes: Ring<Write, 16>,
    csp_target: Option<i32>,
    events: Ring<Event, 32>,
}

impl Drive {
    /// A helper that has seen no statusword and written nothing.
    pub fn new(config: DriveConfig) -> Drive {
        Drive {
            config,
            statusword: None,
            state: None,
            controlword: Controlword(0),
            controlword_written: false,
            mode: None,
            sequence: None,
            motion: Motion::Idle,
            motion_deadline: None,
            writes: Ring::new(),
            csp_target: None,
            events: Ring::new(),
        }
    }

    /// The configuration.
    pub const fn config(&self) -> &DriveConfig {
        &self.config
    }

    /// The last statusword received.
    pub const fn statusword(&self) -> Option<Statusword> {
        self.statusword
    }

    /// The state of the last statusword (`None` before the first or for a
    /// pattern outside the table).
    pub const fn state(&self) -> Option<State> {
        self.state
    }

    /// The last controlword queued for writing; before the first, the
    /// command matching the last state seen (Operation enabled: 0x000F,
    /// Switched on: 0x0007, Ready to switch on: 0x0006, Quick stop active:
    /// 0x0002, otherwise 0x0000).
    pub fn controlword(&self) -> Controlword {
        if self.controlword_written {
            return self.controlword;
        }
        let command = match self.state {
            Some(State::OperationEnabled) => Command::EnableOperation,
            Some(State::SwitchedOn) => Command::SwitchOn,
            Some(State::ReadyToSwitchOn) => Command::Shutdown,
            Some(State::QuickStopActive) => Command::QuickStop,
            _ => Command::DisableVoltage,
        };
        Controlword::from_command(command)
    }

    /// The last mode of operation queued for writing.
    pub const fn mode(&self) -> Option<ModeOfOperation> {
        self.mode
    }

    /// The step the state-machine operation waits in, if one runs.
    pub fn sequence_step(&self) -> Option<Step> {
        self.sequence.map(|s| s.step)
    }

    /// The step the motion operation waits in, if one runs.
    pub fn motion_step(&self) -> Option<Step> {
        self.motion.step()
    }

    /// The next object write to perform, if any.
    pub fn poll_write(&mut self) -> Option<Write> {
        self.writes.pop().or_else(|| {
            self.csp_target
                .take()
                .map(|target| Write::i32(object::TARGET_POSITION, target))
        })
    }

    /// Drops the writes not yet polled (and the csp target), for a caller
    /// whose write failed: the rest belonged to the same request.
    /// [`Drive::controlword`] still shows the last one queued.
    pub fn discard_writes(&mut self) {
        while self.writes.pop().is_some() {}
        self.csp_target = None;
    }

    /// The next event, if any.
    pub fn poll_event(&mut self) -> Option<Event> {
        self.events.pop()
    }

    /// The earliest deadline of the running operations.
    pub fn poll_timeout(&self) -> Option<Instant> {
        earliest(self.sequence.map(|s| s.deadline), self.motion_deadline)
    }

    /// A statusword (0x6041) was received at `now`.
    pub fn update_statusword(&mut self, now: Instant, sw: Statusword) {
        let previous = self.statusword.replace(sw);
        let from = self.state;
        let to = sw.state();
        self.state = to;
        let changed = previous.is_none() || from != to;
        if from != to {
            self.events.push(Event::StateChanged { from, to });
            let was_fault = from.is_some_and(State::is_fault);
            let is_fault = to.is_some_and(State::is_fault);
            if is_fault && !was_fault {
                self.events.push(Event::FaultDetected);
            } else if was_fault && to.is_some() && !is_fault {
                self.events.push(Event::FaultCleared);
            }
        }
        let previous_bit13 = previous.is_some_and(Statusword::following_error);
        if sw.following_error()
            && !previous_bit13
            && matches!(
                self.mode,
                Some(ModeOfOperation::ProfilePosition | ModeOfOperation::CyclicSynchronousPosition)
            )
        {
            self.events.push(Event::FollowingError);
        }
        if to == Some(State::OperationEnabled) {
            self.observe_motion(now, sw);
        } else if let Some(step) = self.motion.step() {
            self.end_motion();
            self.events.push(Event::Failed { step, state: to });
        }
        if changed {
            self.advance(now);
        }
    }

    /// The clock reached [`Drive::poll_timeout`].
    pub fn handle_timeout(&mut self, now: Instant) {
        if let Some(sequence) = self.sequence
            && sequence.deadline <= now
        {
            let faulted = self.state == Some(State::Fault);
            if sequence.step == Step::FaultReset
                && faulted
                && sequence.fault_resets < self.config.fault_reset_attempts
            {
                self.reset_fault(now);
            } else {
                self.sequence = None;
                self.events.push(Event::Timeout {
                    step: sequence.step,
                    state: self.state,
                });
            }
        }
        if let Some(deadline) = self.motion_deadline
            && deadline <= now
            && let Some(step) = self.motion.step()
        {
            self.end_motion();
            if self.controlword.new_set_point() {
                self.write_controlword(self.controlword.with_new_set_point(false));
            }
            self.events.push(Event::Timeout {
                step,
                state: self.state,
            });
        }
    }

    /// Brings the drive to Operation enabled from any state: fault reset
    /// (0x0000 then 0x0080, at most
    /// [`DriveConfig::fault_reset_attempts`] times), Shutdown, Switch on,
    /// Enable operation (from Quick stop active: Disable voltage first).
    /// Ends with [`Event::Enabled`], [`Event::Timeout`] or [`Event::Failed`].
    pub fn enable(&mut self, now: Instant) {
        self.start(now, Goal::Enable);
    }

    /// Disable voltage, waiting for Switch on disabled; ends with
    /// [`Event::Disabled`]. Drops a running move or homing.
    pub fn disable(&mut self, now: Instant) {
        self.end_motion();
        self.start(now, Goal::Disable);
    }

    /// Quick stop, waiting for Quick stop active (from Operation enabled)
    /// or Switch on disabled (from Ready to switch on, Switched on); ends
    /// with [`Event::QuickStopped`]. Drops a running move or homing.
    pub fn quick_stop(&mut self, now: Instant) {
        self.end_motion();
        self.start(now, Goal::QuickStop);
    }

    /// Resets a fault (as [`Drive::enable`] does) and waits for the drive
    /// to leave Fault ([`Event::FaultCleared`]); nothing to do outside the
    /// fault states.
    pub fn fault_reset(&mut self, now: Instant) {
        self.start(now, Goal::FaultReset);
    }

    /// Writes the mode of operation (0x6060). Refused while a move or
    /// homing runs (see [`Drive::cancel_motion`]).
    pub fn set_mode(&mut self, mode: ModeOfOperation) -> Result<(), DriveError> {
        if self.motion != Motion::Idle {
            return Err(DriveError::Busy);
        }
        self.mode = Some(mode);
        self.writes.push(Write::mode(mode));
        Ok(())
    }

    /// Stops following the running move or homing (the drive is not told;
    /// a set new-set-point/homing-start bit is cleared).
    pub fn cancel_motion(&mut self) {
        self.end_motion();
        if self.controlword.new_set_point() {
            self.write_controlword(self.controlword.with_new_set_point(false));
        }
    }

    /// Profile position move: writes the target (0x607A), then the
    /// controlword with new set-point (bit 4) and the [`Move`] bits; on
    /// the acknowledge (statusword bit 12) clears bit 4
    /// ([`Event::SetPointAcknowledged`]) and reports [`Event::TargetReached`]
    /// when bit 10 rises. A move may replace one waiting for its target;
    /// if the previous acknowledge is still set, the new set-point waits
    /// for it to clear ([`Step::SetPointRelease`]).
    pub fn move_to(&mut self, now: Instant, target: i32, options: Move) -> Result<(), DriveError> {
        self.require_enabled()?;
        if self.mode != Some(ModeOfOperation::ProfilePosition) {
            return Err(DriveError::WrongMode { mode: self.mode });
        }
        if !matches!(self.motion, Motion::Idle | Motion::PpTarget { .. }) {
            return Err(DriveError::Busy);
        }
        if self
            .statusword
            .is_some_and(Statusword::set_point_acknowledge)
        {
            self.set_motion(now, Motion::PpRelease { target, options });
        } else {
            self.send_set_point(now, target, options);
        }
        Ok(())
    }

    /// Writes the target velocity (0x60FF) in profile velocity mode. The
    /// drive's bits (target reached, speed 0) are in [`Drive::statusword`].
    pub fn set_velocity(&mut self, velocity: i32) -> Result<(), DriveError> {
        if self.mode != Some(ModeOfOperation::ProfileVelocity) {
            return Err(DriveError::WrongMode { mode: self.mode });
        }
        self.writes
            .push(Write::i32(object::TARGET_VELOCITY, velocity));
        Ok(())
    }

    /// Writes profile velocity (0x6081), acceleration (0x6083) and
    /// deceleration (0x6084), in the drive's user units.
    pub fn set_profile(&mut self, velocity: u32, acceleration: u32, deceleration: u32) {
        for (index, value) in [
            (object::PROFILE_VELOCITY, velocity),
            (object::PROFILE_ACCELERATION, acceleration),
            (object::PROFILE_DECELERATION, deceleration),
        ] {
            self.writes.push(Write {
                index,
                sub: 0,
                value: WriteValue::U32(value),
            });
        }
    }

    /// Sets halt (controlword bit 8) and writes the controlword; the drive
    /// stops with its halt option code. Target reached is not reported
    /// while halted (bit 10 then means standstill).
    pub fn halt(&mut self) {
        self.write_controlword(self.controlword().with_halt(true));
    }

    /// Clears halt (bit 8) and writes the controlword; a pp move continues
    /// and must show bit 10 clear again before it can be reported reached.
    pub fn resume(&mut self) {
        if let Motion::PpTarget { armed } = &mut self.motion {
            *armed = false;
        }
        self.write_controlword(self.controlword().with_halt(false));
    }

    /// Homing: writes mode 6 (when another mode is set), the homing method
    /// (0x6098) when given, then the controlword with homing start (bit 4,
    /// after a write with bit 4 clear when it was set). Ends with
    /// [`Event::HomingAttained`] (bits 12 and 10) or [`Event::HomingError`]
    /// (bit 13), after which bit 4 is cleared.
    pub fn home(&mut self, now: Instant, method: Option<i8>) -> Result<(), DriveError> {
        self.require_enabled()?;
        if self.motion != Motion::Idle {
            return Err(DriveError::Busy);
        }
        let was_homing = self.mode == Some(ModeOfOperation::Homing);
        if !was_homing {
            self.mode = Some(ModeOfOperation::Homing);
            self.writes.push(Write::mode(ModeOfOperation::Homing));
        }
        if let Some(method) = method {
            self.writes.push(Write {
                index: object::HOMING_METHOD,
                sub: 0,
                value: WriteValue::I8(method),
            });
        }
        let current = self.operating_controlword();
        let base = current
            .with_new_set_point(false)
            .with_change_set_immediately(false)
            .with_relative(false);
        if current.new_set_point() {
            self.write_controlword(base);
        }
        self.write_controlword(base.with_new_set_point(true));
        let armed = was_homing
            && self
                .statusword
                .is_some_and(|sw| !sw.homing_attained() && !sw.homing_error());
        self.set_motion(now, Motion::Homing { armed });
        Ok(())
    }

    /// Cyclic synchronous position: the next target position (0x607A),
    /// to send with the next SYNC. Overwrites a target not yet polled.
    pub fn set_csp_target(&mut self, target: i32) {
        self.csp_target = Some(target);
    }

    /// Motion needs Operation enabled and no disable or quick stop under
    /// way.
    fn require_enabled(&self) -> Result<(), DriveError> {
        if self.state != Some(State::OperationEnabled) {
            Err(DriveError::NotEnabled { state: self.state })
        } else if self.sequence.is_some() {
            Err(DriveError::Busy)
        } else {
            Ok(())
        }
    }

    /// The controlword of a motion command: Enable operation, halt and the
    /// operation-mode bits kept.
    fn operating_controlword(&self) -> Controlword {
        self.controlword().with_command(Command::EnableOperation)
    }

    fn write_controlword(&mut self, cw: Controlword) {
        self.controlword = cw;
        self.controlword_written = true;
        self.writes.push(Write::controlword(cw));
    }

    /// A state command: bits 0..3 and 7 of `command`, halt kept, every
    /// other bit 0.
    fn send_command(&mut self, command: Command) {
        let kept = Controlword(self.controlword().0 & KEPT_BY_COMMANDS);
        self.write_controlword(kept.with_command(command));
    }

    fn set_motion(&mut self, now: Instant, motion: Motion) {
        self.motion = motion;
        self.motion_deadline = motion.step().map(|step| now + self.config.timeout(step));
    }

    fn end_motion(&mut self) {
        self.motion = Motion::Idle;
        self.motion_deadline = None;
    }

    fn send_set_point(&mut self, now: Instant, target: i32, options: Move) {
        self.writes
            .push(Write::i32(object::TARGET_POSITION, target));
        let current = self.operating_controlword();
        let base = current.with_new_set_point(false);
        if current.new_set_point() {
            self.write_controlword(base);
        }
        let cw = base
            .with_new_set_point(true)
            .with_change_set_immediately(options.immediate)
            .with_relative(options.relative);
        self.write_controlword(cw);
        self.set_motion(now, Motion::PpAcknowledge);
    }

    /// Follows the motion operation with a statusword in Operation enabled.
    fn observe_motion(&mut self, now: Instant, sw: Statusword) {
        match self.motion {
            Motion::Idle => {}
            Motion::PpRelease { target, options } => {
                if !sw.set_point_acknowledge() {
                    self.send_set_point(now, target, options);
                }
            }
            Motion::PpAcknowledge => {
                if sw.set_point_acknowledge() {
                    self.events.push(Event::SetPointAcknowledged);
                    self.write_controlword(self.controlword.with_new_set_point(false));
                    let armed = !sw.target_reached();
                    self.set_motion(now, Motion::PpTarget { armed });
                }
            }
            Motion::PpTarget { armed } => {
                if self.controlword.halt() {
                    // Bit 10 means standstill while halted.
                } else if !sw.target_reached() {
                    self.motion = Motion::PpTarget { armed: true };
                } else if armed {
                    self.end_motion();
                    self.events.push(Event::TargetReached);
                }
            }
            Motion::Homing { armed } => {
                let attained = sw.homing_attained() && sw.target_reached();
                if !armed {
                    if !sw.homing_attained() && !sw.homing_error() {
                        self.motion = Motion::Homing { armed: true };
                    }
                } else if sw.homing_error() || attained {
                    self.end_motion();
                    self.write_controlword(self.controlword.with_new_set_point(false));
                    self.events.push(if sw.homing_error() {
                        Event::HomingError
                    } else {
                        Event::HomingAttained
                    });
                }
            }
        }
    }

    fn start(&mut self, now: Instant, goal: Goal) {
        self.sequence = Some(Sequence {
            goal,
            step: Step::Statusword,
            deadline: now,
            fault_resets: 0,
            steps_left: MAX_SEQUENCE_STEPS,
        });
        self.advance(now);
    }

    /// Takes the next action of the running sequence for the current state.
    fn advance(&mut self, now: Instant) {
        let Some(mut sequence) = self.sequence else {
            return;
        };
        let Some(steps_left) = sequence.steps_left.checked_sub(1) else {
            self.sequence = None;
            self.events.push(Event::Failed {
                step: sequence.step,
                state: self.state,
            });
            return;
        };
        sequence.steps_left = steps_left;
        self.sequence = Some(sequence);
        match plan(sequence.goal, self.state) {
            Plan::Done => {
                self.sequence = None;
                match sequence.goal {
                    Goal::Enable => self.events.push(Event::Enabled),
                    Goal::Disable => self.events.push(Event::Disabled),
                    Goal::QuickStop => self.events.push(Event::QuickStopped),
                    Goal::FaultReset => {}
                }
            }
            Plan::Wait(step) => self.wait(now, step),
            Plan::Send(command, step) => {
                self.send_command(command);
                self.wait(now, step);
            }
            Plan::ResetFault => {
                if sequence.fault_resets < self.config.fault_reset_attempts {
                    self.reset_fault(now);
                } else {
                    self.sequence = None;
                    self.events.push(Event::Failed {
                        step: Step::FaultReset,
                        state: self.state,
                    });
                }
            }
        }
    }

    fn wait(&mut self, now: Instant, step: Step) {
        if let Some(sequence) = &mut self.sequence {
            sequence.step = step;
            sequence.deadline = now + self.config.timeout(step);
        }
    }

    /// One fault-reset attempt: bit 7 low, then high (halt kept).
    fn reset_fault(&mut self, now: Instant) {
        if let Some(sequence) = &mut self.sequence {
            sequence.fault_resets = sequence.fault_resets.saturating_add(1);
        }
        let kept = Controlword(self.controlword().0 & KEPT_BY_COMMANDS);
        self.write_controlword(kept);
        self.write_controlword(kept.with_command(Command::FaultReset));
        self.wait(now, Step::FaultReset);
    }
}

#[cfg(test)]
mod tests;
