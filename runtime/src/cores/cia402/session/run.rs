//! How a [`Session`] follows the running request: its phases, what it
//! starts on the [`Drive`](crate::cia402::Drive) and when it is done.

use super::{Action, OperationError, Read, Request, Session};
use crate::Instant;
use crate::cia402::types::{DriveError, Event, Step};
use crate::cia402::words::State;

/// Where the running request is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Phase {
    /// No request.
    Idle,
    /// Waiting for a statusword taken at or after `since`, fed after
    /// [`Session::statuswords`] was `seen`.
    Fresh {
        since: Instant,
        seen: u32,
        deadline: Instant,
    },
    /// Handed to the helper: a state-machine operation, a move or homing.
    Running,
    /// Target velocity queued; `since` (time and statusword count) is set
    /// once it was written.
    Velocity {
        since: Option<(Instant, u32)>,
        deadline: Instant,
    },
    /// CSP target queued; `since` is set once it was written.
    Cycle {
        since: Option<(Instant, u32)>,
        deadline: Instant,
    },
    /// Failed in a fault state; 0x603F is to be read (`asked`: the read
    /// was handed out).
    ErrorCode {
        step: Step,
        state: State,
        asked: bool,
    },
    /// Ended; reported by the next [`Action::Done`].
    Finished(Result<(), OperationError>),
}

impl Phase {
    /// The deadline the session itself keeps (the helper keeps its own).
    pub(super) const fn deadline(&self) -> Option<Instant> {
        match *self {
            Phase::Fresh { deadline, .. }
            | Phase::Velocity { deadline, .. }
            | Phase::Cycle { deadline, .. } => Some(deadline),
            _ => None,
        }
    }
}

impl Session {
    /// Advances the phase at `now`: `Some` action for the caller, or
    /// `None` when the phase changed (ask again).
    pub(super) fn step(&mut self, now: Instant) -> Option<Action> {
        let statuswords = self.statuswords;
        let fresh_since = |since: Instant, seen: u32| {
            statuswords != seen && self.statusword_at.is_some_and(|at| at >= since)
        };
        match self.phase {
            Phase::Idle => return Some(Action::Done(Ok(()))),
            Phase::Fresh {
                since,
                seen,
                deadline,
            } => {
                if fresh_since(since, seen) {
                    self.begin(now);
                } else if now >= deadline {
                    self.fail(Step::Statusword, self.drive.state(), true);
                } else {
                    return Some(self.wait_or_poll(now));
                }
            }
            Phase::Running => {
                let ended = match self.request {
                    Some(Request::Move { .. } | Request::Home(_)) => {
                        self.drive.motion_step().is_none()
                    }
                    _ => self.drive.sequence_step().is_none(),
                };
                if !ended {
                    return Some(self.wait_or_poll(now));
                }
                if matches!(self.request, Some(Request::Move { .. } | Request::Home(_))) {
                    // A motion end is always judged by its event first.
                    self.fail(Step::TargetReached, self.drive.state(), false);
                } else {
                    self.finish(Ok(()));
                }
            }
            Phase::Velocity { since, deadline } | Phase::Cycle { since, deadline } => {
                let velocity = matches!(self.phase, Phase::Velocity { .. });
                let step = if velocity {
                    Step::VelocityReached
                } else {
                    Step::Statusword
                };
                let Some((since, seen)) = since else {
                    // Every write went out: from now on statuswords count.
                    let since = Some((now, statuswords));
                    self.phase = if velocity {
                        Phase::Velocity { since, deadline }
                    } else {
                        Phase::Cycle { since, deadline }
                    };
                    return Some(self.wait_or_poll(now));
                };
                let state = self.drive.state();
                let reached = self
                    .drive
                    .statusword()
                    .is_some_and(|sw| sw.target_reached());
                if state != Some(State::OperationEnabled) {
                    self.fail(step, state, false);
                } else if fresh_since(since, seen) && (reached || !velocity) {
                    self.finish(Ok(()));
                } else if now >= deadline {
                    self.fail(step, state, true);
                } else {
                    return Some(self.wait_or_poll(now));
                }
            }
            Phase::ErrorCode {
                step,
                state,
                asked: false,
            } => {
                self.phase = Phase::ErrorCode {
                    step,
                    state,
                    asked: true,
                };
                return Some(Action::Read(Read::ErrorCode));
            }
            Phase::ErrorCode { asked: true, .. } => self.finish_fault(None),
            Phase::Finished(result) => {
                self.request = None;
                self.phase = Phase::Idle;
                return Some(Action::Done(result));
            }
        }
        None
    }

    /// Starts the request on the helper once a fresh statusword came.
    fn begin(&mut self, now: Instant) {
        let Some(request) = self.request else {
            self.phase = Phase::Idle;
            return;
        };
        self.phase = Phase::Running;
        let started = match request {
            Request::Enable => {
                self.drive.enable(now);
                Ok(())
            }
            Request::Disable => {
                self.drive.disable(now);
                Ok(())
            }
            Request::QuickStop => {
                self.drive.quick_stop(now);
                Ok(())
            }
            Request::FaultReset => {
                self.drive.fault_reset(now);
                Ok(())
            }
            Request::Move { target, options } => self
                .enter_mode(request)
                .and_then(|()| self.drive.move_to(now, target, options)),
            Request::Home(method) => self.drive.home(now, method),
            Request::Velocity(velocity) => self
                .enter_mode(request)
                .and_then(|()| self.drive.set_velocity(velocity)),
            Request::CspTarget(target) => self.enter_mode(request).map(|()| {
                self.drive.set_csp_target(target);
            }),
            Request::Profile {
                velocity,
                acceleration,
                deceleration,
            } => {
                self.drive.set_profile(velocity, acceleration, deceleration);
                Ok(())
            }
            Request::Statusword => Ok(()),
        };
        if let Err(e) = started {
            self.finish(Err(OperationError::Refused(e)));
            return;
        }
        self.phase = match request {
            Request::Velocity(_) => Phase::Velocity {
                since: None,
                deadline: now + self.config.drive.timeout(Step::VelocityReached),
            },
            Request::CspTarget(_) => Phase::Cycle {
                since: None,
                deadline: now + self.config.drive.timeout(Step::Statusword),
            },
            Request::Profile { .. } | Request::Statusword => Phase::Finished(Ok(())),
            _ => Phase::Running,
        };
        self.pump();
    }

    /// Operation enabled is needed, and the request's mode is written
    /// when the helper has not set it.
    fn enter_mode(&mut self, request: Request) -> Result<(), DriveError> {
        let state = self.drive.state();
        if state != Some(State::OperationEnabled) {
            return Err(DriveError::NotEnabled { state });
        }
        match request.mode() {
            Some(mode) if self.drive.mode() != Some(mode) => self.drive.set_mode(mode),
            _ => Ok(()),
        }
    }

    /// Judges the running request by an event of the helper.
    pub(super) fn judge(&mut self, event: Event) {
        if !matches!(
            self.phase,
            Phase::Running | Phase::Velocity { .. } | Phase::Cycle { .. }
        ) {
            return;
        }
        let request = self.request;
        let motion = |r: Option<Request>| matches!(r, Some(Request::Move { .. }));
        match event {
            Event::Timeout { step, state } => self.fail(step, state, true),
            Event::Failed { step, state } => self.fail(step, state, false),
            Event::TargetReached if motion(request) => self.finish(Ok(())),
            Event::HomingAttained if request.is_some_and(|r| matches!(r, Request::Home(_))) => {
                self.finish(Ok(()));
            }
            Event::HomingError if request.is_some_and(|r| matches!(r, Request::Home(_))) => {
                self.finish(Err(OperationError::HomingError));
            }
            Event::FollowingError
                if motion(request) || matches!(request, Some(Request::CspTarget(_))) =>
            {
                self.drive.cancel_motion();
                self.finish(Err(OperationError::FollowingError));
            }
            _ => {}
        }
    }

    /// Ends the request with a failure in `step`: in a fault state the
    /// error code is read first (when the device has 0x603F).
    fn fail(&mut self, step: Step, state: Option<State>, timed_out: bool) {
        if matches!(self.phase, Phase::Finished(_) | Phase::ErrorCode { .. }) {
            return;
        }
        self.drive.cancel_motion();
        match state {
            Some(state) if state.is_fault() && self.error_code => {
                self.phase = Phase::ErrorCode {
                    step,
                    state,
                    asked: false,
                };
            }
            Some(state) if state.is_fault() => self.finish(Err(OperationError::Fault {
                step,
                state,
                code: None,
            })),
            _ if timed_out => self.finish(Err(OperationError::Timeout { step, state })),
            _ => self.finish(Err(OperationError::Failed { step, state })),
        }
    }

    /// Ends the request with `result`, unless it has already ended.
    pub(super) fn finish(&mut self, result: Result<(), OperationError>) {
        if self.request.is_some()
            && !matches!(self.phase, Phase::Finished(_) | Phase::ErrorCode { .. })
        {
            self.phase = Phase::Finished(result);
        }
    }

    /// Ends a request that failed in a fault state with the error code.
    pub(super) fn finish_fault(&mut self, code: Option<u16>) {
        if let Phase::ErrorCode { step, state, .. } = self.phase {
            self.phase = Phase::Finished(Err(OperationError::Fault { step, state, code }));
        }
    }
}
