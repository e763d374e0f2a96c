//! The device side of the CiA 402 power drive state machine, for drive
//! simulators: it is fed controlword writes, faults and the verdicts of a
//! motion model, and computes the statusword.
//!
//! Transitions (numbers as in CiA 402 / IEC 61800-7-201):
//!
//! | no. | from → to | cause |
//! |---|---|---|
//! | 0 | start → Not ready to switch on | [`DeviceStateMachine::new`] |
//! | 1 | Not ready → Switch on disabled | [`DeviceConfig::start_up`] elapsed |
//! | 2 | Switch on disabled → Ready to switch on | Shutdown |
//! | 3 | Ready → Switched on | Switch on (Enable operation: 3 then 4) |
//! | 4 | Switched on → Operation enabled | Enable operation |
//! | 5 | Operation enabled → Switched on | Disable operation |
//! | 6 | Switched on → Ready | Shutdown |
//! | 7 | Ready → Switch on disabled | Disable voltage, Quick stop |
//! | 8 | Operation enabled → Ready | Shutdown |
//! | 9 | Operation enabled → Switch on disabled | Disable voltage |
//! | 10 | Switched on → Switch on disabled | Disable voltage, Quick stop |
//! | 11 | Operation enabled → Quick stop active | Quick stop |
//! | 12 | Quick stop active → Switch on disabled | quick stop ended (option codes other than 5..8), Disable voltage |
//! | 13 | any → Fault reaction active | [`DeviceStateMachine::raise_fault`] |
//! | 14 | Fault reaction active → Fault | fault reaction ended |
//! | 15 | Fault → Switch on disabled | rising edge of controlword bit 7, unless the fault persists |
//! | 16 | Quick stop active → Operation enabled | Enable operation, option codes 5..8 |
//!
//! While controlword bit 7 is set no other command is evaluated (every
//! other command has bit 7 = 0 in the CiA 402 table).
//!
//! Operation modes: in profile position mode a rising edge of bit 4 in
//! Operation enabled is acknowledged at once (statusword bit 12, target
//! reached cleared, [`DeviceEvent::NewSetPoint`]); bit 4 falling clears the
//! acknowledge. In homing mode the rising edge starts homing (bits 10, 12,
//! 13 cleared, [`DeviceEvent::HomingStarted`]) and the motion model ends it
//! with [`DeviceStateMachine::homing_done`]. Target reached and following
//! error come from the motion model.

use core::time::Duration;

use super::words::{Controlword, ModeOfOperation, State, Statusword};
use crate::Instant;
use crate::queue::Ring;

/// How the simulated device behaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeviceConfig {
    /// Time spent in Not ready to switch on before transition 1.
    pub start_up: Duration,
    /// Duration of the fault reaction (transition 14 when it ends); `None`:
    /// it ends only with [`DeviceStateMachine::complete_fault_reaction`].
    pub fault_reaction: Option<Duration>,
    /// Duration of the quick stop ramp; `None`: it ends only with
    /// [`DeviceStateMachine::complete_quick_stop`].
    pub quick_stop: Option<Duration>,
    /// Quick stop option code (object 0x605A): 5..=8 stay in Quick stop
    /// active after the ramp (transition 16 possible), any other value goes
    /// to Switch on disabled (transition 12).
    pub quick_stop_option_code: i16,
    /// Statusword bit 4 (voltage enabled).
    pub voltage_enabled: bool,
    /// Statusword bit 9 (remote).
    pub remote: bool,
}

impl Default for DeviceConfig {
    /// Instant start-up, fault reaction and quick stop; option code 2
    /// (quick stop ramp, then Switch on disabled); voltage and remote on.
    fn default() -> DeviceConfig {
        DeviceConfig {
            start_up: Duration::ZERO,
            fault_reaction: Some(Duration::ZERO),
            quick_stop: Some(Duration::ZERO),
            quick_stop_option_code: 2,
            voltage_enabled: true,
            remote: true,
        }
    }
}

impl DeviceConfig {
    /// Whether the option code keeps the drive in Quick stop active.
    pub const fn stays_in_quick_stop(&self) -> bool {
        matches!(self.quick_stop_option_code, 5..=8)
    }
}

/// What happened in the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum DeviceEvent {
    /// Transition `number` (0..=16) from `from` (`None`: the start) to `to`.
    Transition {
        /// The CiA 402 transition number.
        number: u8,
        /// The state left (`None` for transition 0).
        from: Option<State>,
        /// The state entered.
        to: State,
    },
    /// A new set-point was accepted in profile position mode (the target is
    /// whatever 0x607A holds now); the flags are controlword bits 5 and 6.
    NewSetPoint {
        /// Controlword bit 5 (change set immediately).
        immediate: bool,
        /// Controlword bit 6 (relative target).
        relative: bool,
    },
    /// Homing was started (rising edge of bit 4 in homing mode).
    HomingStarted,
}

/// The running timed activity of the current state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Timer {
    StartUp,
    FaultReaction,
    QuickStop,
}

/// Device-side CiA 402 state machine (see the module documentation).
#[derive(Debug, Clone)]
pub struct DeviceStateMachine {
    config: DeviceConfig,
    state: State,
    controlword: Controlword,
    mode: ModeOfOperation,
    set_point_acknowledge: bool,
    target_reached: bool,
    following_error: bool,
    homing_active: bool,
    homing_attained: bool,
    homing_error: bool,
    speed_zero: bool,
    warning: bool,
    internal_limit: bool,
    fault_code: Option<u16>,
    fault_persists: bool,
    timer: Option<(Instant, Timer)>,
    events: Ring<DeviceEvent, 16>,
}

/// The command bits 0..3 of a controlword with bit 7 clear.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Requested {
    DisableVoltage,
    QuickStop,
    Shutdown,
    SwitchOn,
    EnableOperation,
}

fn requested(cw: Controlword) -> Requested {
    if !cw.enable_voltage() {
        Requested::DisableVoltage
    } else if !cw.quick_stop() {
        Requested::QuickStop
    } else if !cw.switch_on() {
        Requested::Shutdown
    } else if !cw.enable_operation() {
        Requested::SwitchOn
    } else {
        Requested::EnableOperation
    }
}

/// The transitions (at most two) a command causes in `state`.
fn command_transitions(
    state: State,
    command: Requested,
    stays_in_quick_stop: bool,
) -> [Option<(u8, State)>; 2] {
    use Requested as R;
    use State as S;
    let one = |number, to| [Some((number, to)), None];
    match (state, command) {
        (S::SwitchOnDisabled, R::Shutdown) => one(2, S::ReadyToSwitchOn),
        (S::ReadyToSwitchOn, R::SwitchOn) => one(3, S::SwitchedOn),
        (S::ReadyToSwitchOn, R::EnableOperation) => {
            [Some((3, S::SwitchedOn)), Some((4, S::OperationEnabled))]
        }
        (S::ReadyToSwitchOn, R::DisableVoltage | R::QuickStop) => one(7, S::SwitchOnDisabled),
        (S::SwitchedOn, R::EnableOperation) => one(4, S::OperationEnabled),
        (S::SwitchedOn, R::Shutdown) => one(6, S::ReadyToSwitchOn),
        (S::SwitchedOn, R::DisableVoltage | R::QuickStop) => one(10, S::SwitchOnDisabled),
        (S::OperationEnabled, R::SwitchOn) => one(5, S::SwitchedOn),
        (S::OperationEnabled, R::Shutdown) => one(8, S::ReadyToSwitchOn),
        (S::OperationEnabled, R::DisableVoltage) => one(9, S::SwitchOnDisabled),
        (S::OperationEnabled, R::QuickStop) => one(11, S::QuickStopActive),
        (S::QuickStopActive, R::DisableVoltage) => one(12, S::SwitchOnDisabled),
        (S::QuickStopActive, R::EnableOperation) if stays_in_quick_stop => {
            one(16, S::OperationEnabled)
        }
        _ => [None, None],
    }
}

impl DeviceStateMachine {
    /// A device powered on at `now`: transition 0 to Not ready to switch
    /// on, then transition 1 once [`DeviceConfig::start_up`] has elapsed
    /// (at once when it is zero). Mode of operation: none (0).
    pub fn new(now: Instant, config: DeviceConfig) -> DeviceStateMachine {
        let mut device = DeviceStateMachine {
            config,
            state: State::NotReadyToSwitchOn,
            controlword: Controlword(0),
            mode: ModeOfOperation::NoMode,
            set_point_acknowledge: false,
            target_reached: false,
            following_error: false,
            homing_active: false,
            homing_attained: false,
            homing_error: false,
            speed_zero: true,
            warning: false,
            internal_limit: false,
            fault_code: None,
            fault_persists: false,
            timer: None,
            events: Ring::new(),
        };
        device.events.push(DeviceEvent::Transition {
            number: 0,
            from: None,
            to: State::NotReadyToSwitchOn,
        });
        device.timer = Some((now + config.start_up, Timer::StartUp));
        device.fire_due(now);
        device
    }

    /// The configuration.
    pub const fn config(&self) -> &DeviceConfig {
        &self.config
    }

    /// The current state.
    pub const fn state(&self) -> State {
        self.state
    }

    /// The last controlword applied (0 before the first).
    pub const fn controlword(&self) -> Controlword {
        self.controlword
    }

    /// The mode of operation in effect (what 0x6061 displays).
    pub const fn mode(&self) -> ModeOfOperation {
        self.mode
    }

    /// The error code of the current fault (object 0x603F), if any.
    pub const fn fault_code(&self) -> Option<u16> {
        self.fault_code
    }

    /// Whether homing was started and has not ended yet.
    pub const fn homing_active(&self) -> bool {
        self.homing_active
    }

    /// The statusword: the state bits, bit 4 and 9 from the configuration,
    /// bits 7, 10, 11 as set, bits 12 and 13 per the mode of operation.
    pub fn statusword(&self) -> Statusword {
        let mut sw = self.state.state_bits();
        let mut set = |bit: u16, on: bool| {
            if on {
                sw |= 1 << bit;
            }
        };
        set(4, self.config.voltage_enabled);
        set(7, self.warning);
        set(9, self.config.remote);
        set(10, self.target_reached);
        set(11, self.internal_limit);
        let enabled = self.state == State::OperationEnabled;
        let (bit12, bit13) = match self.mode {
            ModeOfOperation::ProfilePosition => (self.set_point_acknowledge, self.following_error),
            ModeOfOperation::ProfileVelocity => (self.speed_zero, false),
            ModeOfOperation::Homing => (self.homing_attained, self.homing_error),
            ModeOfOperation::CyclicSynchronousPosition => (enabled, self.following_error),
            ModeOfOperation::CyclicSynchronousVelocity
            | ModeOfOperation::CyclicSynchronousTorque => (enabled, false),
            _ => (false, false),
        };
        set(12, bit12);
        set(13, bit13);
        Statusword(sw)
    }

    /// The controlword (object 0x6040) was written at `now`.
    pub fn apply_controlword(&mut self, now: Instant, cw: Controlword) {
        let previous = self.controlword;
        self.controlword = cw;
        self.fire_due(now);
        if cw.fault_reset() {
            if !previous.fault_reset() && self.state == State::Fault && !self.fault_persists {
                self.fault_code = None;
                self.enter(now, 15, State::SwitchOnDisabled);
            }
        } else {
            let command = requested(cw);
            let stays = self.config.stays_in_quick_stop();
            for (number, to) in command_transitions(self.state, command, stays)
                .into_iter()
                .flatten()
            {
                self.enter(now, number, to);
            }
        }
        let rising = cw.new_set_point() && !previous.new_set_point();
        let enabled = self.state == State::OperationEnabled;
        match self.mode {
            ModeOfOperation::ProfilePosition => {
                if rising && enabled {
                    self.set_point_acknowledge = true;
                    self.target_reached = false;
                    self.events.push(DeviceEvent::NewSetPoint {
                        immediate: cw.change_set_immediately(),
                        relative: cw.relative(),
                    });
                } else if !cw.new_set_point() {
                    self.set_point_acknowledge = false;
                }
            }
            ModeOfOperation::Homing if rising && enabled => {
                self.homing_active = true;
                self.homing_attained = false;
                self.homing_error = false;
                self.target_reached = false;
                self.events.push(DeviceEvent::HomingStarted);
            }
            _ => {}
        }
        self.fire_due(now);
    }

    /// The mode of operation (object 0x6060) was written; the device takes
    /// it at once.
    pub fn set_mode(&mut self, mode: ModeOfOperation) {
        if mode != self.mode {
            self.homing_active = false;
            self.set_point_acknowledge = false;
        }
        self.mode = mode;
    }

    /// A fault occurs at `now` with error code `code` (0x603F): transition
    /// 13 from any state but the two fault states (there only the code is
    /// updated).
    pub fn raise_fault(&mut self, now: Instant, code: u16) {
        self.fault_code = Some(code);
        self.fire_due(now);
        if !self.state.is_fault() {
            self.enter(now, 13, State::FaultReactionActive);
        }
        self.fire_due(now);
    }

    /// While `true`, the fault condition is still present and a fault
    /// reset is refused (the device stays in Fault).
    pub fn set_fault_persists(&mut self, persists: bool) {
        self.fault_persists = persists;
    }

    /// Ends the fault reaction (transition 14) when in Fault reaction
    /// active; for [`DeviceConfig::fault_reaction`] `None`.
    pub fn complete_fault_reaction(&mut self, now: Instant) {
        if self.state == State::FaultReactionActive {
            self.enter(now, 14, State::Fault);
        }
    }

    /// Ends the quick stop ramp; for [`DeviceConfig::quick_stop`] `None`.
    /// Transition 12 unless the option code keeps the drive in Quick stop
    /// active.
    pub fn complete_quick_stop(&mut self, now: Instant) {
        if self.state == State::QuickStopActive && !self.config.stays_in_quick_stop() {
            self.enter(now, 12, State::SwitchOnDisabled);
        }
    }

    /// Statusword bit 10 (target reached), from the motion model.
    pub fn set_target_reached(&mut self, reached: bool) {
        self.target_reached = reached;
    }

    /// Statusword bit 13 in pp and csp mode (following error).
    pub fn set_position_following_error(&mut self, error: bool) {
        self.following_error = error;
    }

    /// Statusword bit 12 in pv mode (speed is 0).
    pub fn set_speed_zero(&mut self, zero: bool) {
        self.speed_zero = zero;
    }

    /// Statusword bit 7 (warning).
    pub fn set_warning(&mut self, warning: bool) {
        self.warning = warning;
    }

    /// Statusword bit 11 (internal limit active).
    pub fn set_internal_limit(&mut self, active: bool) {
        self.internal_limit = active;
    }

    /// Homing ended: `ok` sets homing attained (bit 12) and target reached
    /// (bit 10); an error sets homing error (bit 13) and target reached
    /// (the axis stands still).
    pub fn homing_done(&mut self, ok: bool) {
        self.homing_active = false;
        self.homing_attained = ok;
        self.homing_error = !ok;
        self.target_reached = true;
    }

    /// The next event, if any.
    pub fn poll_event(&mut self) -> Option<DeviceEvent> {
        self.events.pop()
    }

    /// When the running start-up, fault reaction or quick stop ends.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.timer.map(|(at, _)| at)
    }

    /// The clock reached [`DeviceStateMachine::poll_timeout`].
    pub fn handle_timeout(&mut self, now: Instant) {
        self.fire_due(now);
    }

    /// Runs the timed transitions that are due at `now`.
    fn fire_due(&mut self, now: Instant) {
        // Each timed transition enters a state without a timer, so one round
        // is enough; the bound only guards against future edits.
        for _ in 0..4 {
            let Some((at, timer)) = self.timer else {
                return;
            };
            if at > now {
                return;
            }
            self.timer = None;
            match timer {
                Timer::StartUp if self.state == State::NotReadyToSwitchOn => {
                    self.enter(now, 1, State::SwitchOnDisabled);
                }
                Timer::FaultReaction => self.complete_fault_reaction(now),
                Timer::QuickStop => self.complete_quick_stop(now),
                Timer::StartUp => {}
            }
        }
    }

    /// Takes transition `number` to `to` and starts the timer of the state.
    fn enter(&mut self, now: Instant, number: u8, to: State) {
        let from = self.state;
        self.state = to;
        if to != State::OperationEnabled {
            self.set_point_acknowledge = false;
            self.homing_active = false;
        }
        self.timer = match to {
            State::NotReadyToSwitchOn => Some((now + self.config.start_up, Timer::StartUp)),
            State::FaultReactionActive => self
                .config
                .fault_reaction
                .map(|d| (now + d, Timer::FaultReaction)),
            State::QuickStopActive if !self.config.stays_in_quick_stop() => {
                self.config.quick_stop.map(|d| (now + d, Timer::QuickStop))
            }
            _ => None,
        };
        self.events.push(DeviceEvent::Transition {
            number,
            from: Some(from),
            to,
        });
    }
}

#[cfg(test)]
mod tests;
