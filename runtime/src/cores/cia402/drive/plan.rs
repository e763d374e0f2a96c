//! The bookkeeping of [`Drive`](super::Drive): which operation runs, and
//! what a state-machine operation does in each state.

use crate::Instant;
use crate::cia402::types::{Move, Step};
use crate::cia402::words::{Command, State};

/// The state-machine operation in progress.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Goal {
    Enable,
    Disable,
    QuickStop,
    FaultReset,
}

/// A running state-machine operation: its goal, the step it waits in and
/// until when, and its budgets.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sequence {
    pub(super) goal: Goal,
    pub(super) step: Step,
    pub(super) deadline: Instant,
    pub(super) fault_resets: u8,
    pub(super) steps_left: u8,
}

/// What a goal needs in a state.
pub(super) enum Plan {
    Done,
    Wait(Step),
    Send(Command, Step),
    ResetFault,
}

/// The motion operation in progress.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Motion {
    /// None.
    Idle,
    /// A move waits for the previous set-point acknowledge to clear.
    PpRelease { target: i32, options: Move },
    /// Bit 4 sent, waiting for the acknowledge.
    PpAcknowledge,
    /// Acknowledged; `armed` once bit 10 was seen clear.
    PpTarget { armed: bool },
    /// Homing started; `armed` once bits 12 and 13 were seen clear.
    Homing { armed: bool },
}

impl Motion {
    pub(super) fn step(self) -> Option<Step> {
        match self {
            Motion::Idle => None,
            Motion::PpRelease { .. } => Some(Step::SetPointRelease),
            Motion::PpAcknowledge => Some(Step::SetPointAcknowledge),
            Motion::PpTarget { .. } => Some(Step::TargetReached),
            Motion::Homing { .. } => Some(Step::Homing),
        }
    }
}

/// What `goal` needs in `state`.
pub(super) fn plan(goal: Goal, state: Option<State>) -> Plan {
    use State as S;
    let Some(state) = state else {
        return Plan::Wait(Step::Statusword);
    };
    match (goal, state) {
        (Goal::Enable | Goal::FaultReset, S::FaultReactionActive) => {
            Plan::Wait(Step::FaultReaction)
        }
        (Goal::Enable | Goal::FaultReset, S::Fault) => Plan::ResetFault,
        (Goal::FaultReset, _) => Plan::Done,
        (Goal::Enable, S::NotReadyToSwitchOn) => Plan::Wait(Step::StartUp),
        (Goal::Enable, S::SwitchOnDisabled) => Plan::Send(Command::Shutdown, Step::Shutdown),
        (Goal::Enable, S::ReadyToSwitchOn) => Plan::Send(Command::SwitchOn, Step::SwitchOn),
        (Goal::Enable, S::SwitchedOn) => {
            Plan::Send(Command::EnableOperation, Step::EnableOperation)
        }
        (Goal::Enable, S::OperationEnabled) => Plan::Done,
        (Goal::Enable | Goal::Disable, S::QuickStopActive)
        | (Goal::Disable, S::ReadyToSwitchOn | S::SwitchedOn | S::OperationEnabled) => {
            Plan::Send(Command::DisableVoltage, Step::DisableVoltage)
        }
        (Goal::QuickStop, S::ReadyToSwitchOn | S::SwitchedOn | S::OperationEnabled) => {
            Plan::Send(Command::QuickStop, Step::QuickStop)
        }
        // Disable, quick stop: no voltage on the motor already.
        (Goal::Disable | Goal::QuickStop, _) => Plan::Done,
    }
}
