//! The I/O-free loop that runs one [`Drive`] operation after another over
//! object reads and writes: the part of a blocking or async CiA 402 runner
//! that is not I/O.
//!
//! A [`Session`] owns a [`Drive`] and the device's object table. The caller
//! [starts](Session::start) a [`Request`] (checked against the table first:
//! a missing object is an error before anything is sent), then asks
//! [`Session::poll_action`] what to do until it says [`Action::Done`]:
//!
//! - [`Action::Write`]: download the value (SDO, or an RPDO), then ask
//!   again;
//! - [`Action::Read`]: upload the object (0x6041 or 0x603F) and feed the
//!   bytes to [`Session::on_statusword`] or [`Session::on_error_code`];
//! - [`Action::Wait`]: wait until that time, feeding TPDOs to
//!   [`Session::on_pdo`] (a statusword TPDO shortens the wait);
//! - [`Action::Done`]: the request ended with this result.
//!
//! [`Session::poll_event`] yields the [`Event`]s of the drive (state
//! changes, faults, ...) as they happen; drain it after each action.
//!
//! The same loop, async (the shape of a tokio runner; `sdo_download`,
//! `sdo_upload`, `next_tpdo` stand for the async master's calls):
//!
//! ```ignore
//! session.start(now(), Request::Move { target: 1000, options: Move::default() })?;
//! loop {
//!     let action = session.poll_action(now());
//!     while let Some(event) = session.poll_event() { println!("{event:?}"); }
//!     match action {
//!         Action::Write(w) => sdo_download(node, w.index, w.sub, &w.value.to_le_bytes()).await?,
//!         Action::Read(Read::Statusword) => {
//!             let data = sdo_upload(node, 0x6041, 0).await?;
//!             session.on_statusword(now(), &data);
//!         }
//!         Action::Read(Read::ErrorCode) => {
//!             let data = sdo_upload(node, 0x603F, 0).await.ok();
//!             session.on_error_code(data.as_deref());
//!         }
//!         Action::Wait(until) => {
//!             if let Ok(Some((can_id, data, at))) = timeout_at(until, next_tpdo()).await {
//!                 session.on_pdo(can_id, &data, at);
//!             }
//!         }
//!         Action::Done(result) => break result,
//!     }
//! }
//! ```
//!
//! The blocking master runs exactly this loop
//! ([`blocking::Master::drive`](crate::blocking::Master::drive)). Here the
//! device is a [`DeviceStateMachine`](super::DeviceStateMachine) called
//! directly:
//!
//! ```
//! use eds2rust_runtime::Instant;
//! use eds2rust_runtime::cia402::session::{Action, Read, Request, Session, SessionConfig};
//! use eds2rust_runtime::cia402::{Controlword, DeviceConfig, DeviceStateMachine, State};
//! use eds2rust_runtime::od::{AccessRight, DataType, ObjectInfo};
//!
//! static OBJECTS: [ObjectInfo; 2] = [
//!     ObjectInfo::new(0x6040, 0, "Controlword", DataType::Unsigned16, AccessRight::Rw, true),
//!     ObjectInfo::new(0x6041, 0, "Statusword", DataType::Unsigned16, AccessRight::Ro, true),
//! ];
//! let now = Instant::from_millis(1);
//! let mut device = DeviceStateMachine::new(now, DeviceConfig::default());
//! let mut session = Session::new(&OBJECTS, SessionConfig::default())?;
//! session.start(now, Request::Enable)?;
//! let result = loop {
//!     match session.poll_action(now) {
//!         Action::Write(w) => {
//!             let bytes = w.value.to_le_bytes();
//!             let cw = u16::from_le_bytes([bytes[0], bytes[1]]);
//!             device.apply_controlword(now, Controlword(cw));
//!         }
//!         Action::Read(Read::Statusword) => {
//!             session.on_statusword(now, &device.statusword().0.to_le_bytes());
//!         }
//!         Action::Read(Read::ErrorCode) => session.on_error_code(None),
//!         Action::Wait(_) => session.on_statusword(now, &device.statusword().0.to_le_bytes()),
//!         Action::Done(result) => break result,
//!     }
//! };
//! assert_eq!(result, Ok(()));
//! assert_eq!(device.state(), State::OperationEnabled);
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```

use core::fmt;
use core::time::Duration;

use super::requirements::{MissingObject, Operation, has_error_code};
use super::types::{DriveConfig, DriveError, Event, Move, Step, Write};
use super::words::{ModeOfOperation, State, Statusword};
use super::{Drive, object};
use crate::od::ObjectInfo;
use crate::queue::Ring;
use crate::time::earliest;
use crate::{CanId, Instant};

mod run;
use run::Phase;

/// The longest [`Action::Wait`] when nothing else limits it.
pub const IDLE_WAIT: Duration = Duration::from_secs(1);

/// A TPDO that carries the statusword.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct StatuswordPdo {
    /// The TPDO's identifier.
    pub can_id: CanId,
    /// The byte offset of 0x6041 in the TPDO data.
    pub offset: usize,
}

/// How a [`Session`] runs: [`SessionConfig::default`], then the `with_*`
/// methods (or field assignments) for what differs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct SessionConfig {
    /// The helper's timeouts and fault-reset attempts.
    pub drive: DriveConfig,
    /// How often 0x6041 is uploaded while a request runs; `None`: the
    /// statusword comes only from [`SessionConfig::statusword_pdo`].
    pub poll_period: Option<Duration>,
    /// A TPDO carrying the statusword, fed through [`Session::on_pdo`].
    pub statusword_pdo: Option<StatuswordPdo>,
    /// Operations checked against the object table by [`Session::new`]
    /// besides [`Operation::StateMachine`] (each request checks its own
    /// anyway).
    pub required: &'static [Operation],
}

impl Default for SessionConfig {
    /// Default helper configuration, statusword polled every 10 ms, no
    /// statusword TPDO, nothing required up front.
    fn default() -> SessionConfig {
        SessionConfig {
            drive: DriveConfig::default(),
            poll_period: Some(Duration::from_millis(10)),
            statusword_pdo: None,
            required: &[],
        }
    }
}

impl SessionConfig {
    /// This configuration with the helper's timeouts and attempts `drive`.
    pub const fn with_drive(mut self, drive: DriveConfig) -> SessionConfig {
        self.drive = drive;
        self
    }

    /// This configuration polling 0x6041 every `period` (`None`: only the
    /// statusword TPDO).
    pub const fn with_poll_period(mut self, period: Option<Duration>) -> SessionConfig {
        self.poll_period = period;
        self
    }

    /// This configuration taking the statusword from `pdo` too.
    pub const fn with_statusword_pdo(mut self, pdo: StatuswordPdo) -> SessionConfig {
        self.statusword_pdo = Some(pdo);
        self
    }

    /// This configuration checking `operations` when the session is made.
    pub const fn with_required(mut self, operations: &'static [Operation]) -> SessionConfig {
        self.required = operations;
        self
    }
}

/// What a [`Session`] is asked to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Request {
    /// [`Drive::enable`]: to Operation enabled, resetting a fault.
    Enable,
    /// [`Drive::disable`]: to Switch on disabled.
    Disable,
    /// [`Drive::quick_stop`].
    QuickStop,
    /// [`Drive::fault_reset`].
    FaultReset,
    /// A profile-position move (mode 1 is written when not set); done when
    /// the target is reached.
    Move {
        /// Target position (0x607A).
        target: i32,
        /// Relative, immediate.
        options: Move,
    },
    /// Profile velocity (mode 3 written when not set): writes 0x60FF and
    /// waits for target reached (bit 10) in a statusword taken after the
    /// write ([`Step::VelocityReached`]).
    Velocity(i32),
    /// [`Drive::home`] with the homing method, if given; done when homing
    /// is attained.
    Home(Option<i8>),
    /// [`Drive::set_profile`]: velocity, acceleration, deceleration.
    Profile {
        /// 0x6081.
        velocity: u32,
        /// 0x6083.
        acceleration: u32,
        /// 0x6084.
        deceleration: u32,
    },
    /// One cycle of cyclic synchronous position (mode 8 written when not
    /// set): writes 0x607A, then takes one statusword; fails when the drive
    /// left Operation enabled or reports a following error.
    CspTarget(i32),
    /// Takes a fresh statusword only.
    Statusword,
}

impl Request {
    /// The operation whose objects the request needs.
    pub const fn operation(self) -> Operation {
        match self {
            Request::Enable
            | Request::Disable
            | Request::QuickStop
            | Request::FaultReset
            | Request::Statusword => Operation::StateMachine,
            Request::Move { .. } => Operation::ProfilePosition,
            Request::Velocity(_) => Operation::ProfileVelocity,
            Request::Home(_) => Operation::Homing,
            Request::Profile { .. } => Operation::MotionProfile,
            Request::CspTarget(_) => Operation::CyclicSynchronousPosition,
        }
    }

    /// The mode of operation the request runs in, if it needs one.
    pub const fn mode(self) -> Option<ModeOfOperation> {
        match self {
            Request::Move { .. } => Some(ModeOfOperation::ProfilePosition),
            Request::Velocity(_) => Some(ModeOfOperation::ProfileVelocity),
            Request::Home(_) => Some(ModeOfOperation::Homing),
            Request::CspTarget(_) => Some(ModeOfOperation::CyclicSynchronousPosition),
            _ => None,
        }
    }
}

/// An object the caller uploads for [`Action::Read`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Read {
    /// 0x6041, fed to [`Session::on_statusword`].
    Statusword,
    /// 0x603F, fed to [`Session::on_error_code`].
    ErrorCode,
}

impl Read {
    /// The object index.
    pub const fn index(self) -> u16 {
        match self {
            Read::Statusword => object::STATUSWORD,
            Read::ErrorCode => object::ERROR_CODE,
        }
    }
}

/// What the caller does next (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Download this value, then call [`Session::poll_action`] again.
    Write(Write),
    /// Upload this object (sub-index 0) and feed it back.
    Read(Read),
    /// Wait until this time, feeding TPDOs to [`Session::on_pdo`].
    Wait(Instant),
    /// The request ended (also the answer when none runs: `Ok(())`).
    Done(Result<(), OperationError>),
}

/// Why a request failed (besides I/O, which is the caller's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum OperationError {
    /// The device lacks an object the request needs; nothing was sent.
    Missing(MissingObject),
    /// The helper refused the request (state, mode, another request).
    Refused(DriveError),
    /// The drive did not answer within the timeout of `step`.
    Timeout {
        /// The step that timed out.
        step: Step,
        /// The state reached.
        state: Option<State>,
    },
    /// The request gave up in `step` (see [`Event::Failed`]).
    Failed {
        /// The step.
        step: Step,
        /// The state reached.
        state: Option<State>,
    },
    /// The drive is in a fault state; `code` is 0x603F read back (`None`:
    /// the device has no 0x603F or the read failed).
    Fault {
        /// The step the request was in.
        step: Step,
        /// The fault state.
        state: State,
        /// The error code.
        code: Option<u16>,
    },
    /// Homing ended with homing error (statusword bit 13).
    HomingError,
    /// Following error (statusword bit 13 in pp or csp).
    FollowingError,
    /// An uploaded or received statusword was not 2 bytes long.
    BadStatusword {
        /// Its length.
        len: usize,
    },
}

/// ", the drive is in STATE" or ", the drive state is unknown".
struct InState(Option<State>);

impl fmt::Display for InState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(state) => write!(f, "; the drive is in {state}"),
            None => f.write_str("; the drive state is unknown"),
        }
    }
}

impl fmt::Display for OperationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            OperationError::Missing(e) => e.fmt(f),
            OperationError::Refused(e) => e.fmt(f),
            OperationError::Timeout { step, state } => {
                write!(f, "timed out {step}{}", InState(state))
            }
            OperationError::Failed { step, state } => {
                write!(f, "gave up {step}{}", InState(state))
            }
            OperationError::Fault { step, state, code } => {
                write!(f, "drive in {state}")?;
                match code {
                    Some(code) => write!(f, " with error code {code:#06X}")?,
                    None => f.write_str(" (error code unknown)")?,
                }
                write!(f, " while {step}")
            }
            OperationError::HomingError => {
                f.write_str("homing ended with a homing error (statusword bit 13)")
            }
            OperationError::FollowingError => f.write_str("following error (statusword bit 13)"),
            OperationError::BadStatusword { len } => {
                write!(f, "the statusword (0x6041) came with {len} bytes, not 2")
            }
        }
    }
}

impl core::error::Error for OperationError {}

impl From<MissingObject> for OperationError {
    fn from(e: MissingObject) -> OperationError {
        OperationError::Missing(e)
    }
}

/// Runs [`Request`]s on a [`Drive`] (see the module documentation).
#[derive(Debug, Clone)]
pub struct Session {
    drive: Drive,
    objects: &'static [ObjectInfo],
    config: SessionConfig,
    error_code: bool,
    request: Option<Request>,
    phase: Phase,
    last_poll: Option<Instant>,
    statusword_at: Option<Instant>,
    /// Statuswords fed so far (wrapping).
    statuswords: u32,
    events: Ring<Event, 32>,
}

impl Session {
    /// A session for a device with `objects` (a generated `od::OBJECTS`),
    /// after checking [`Operation::StateMachine`] and
    /// [`SessionConfig::required`].
    pub fn new(
        objects: &'static [ObjectInfo],
        config: SessionConfig,
    ) -> Result<Session, MissingObject> {
        Operation::StateMachine.check(objects)?;
        for operation in config.required {
            operation.check(objects)?;
        }
        Ok(Session {
            drive: Drive::new(config.drive),
            objects,
            config,
            error_code: has_error_code(objects),
            request: None,
            phase: Phase::Idle,
            last_poll: None,
            statusword_at: None,
            statuswords: 0,
            events: Ring::new(),
        })
    }

    /// The helper (statusword, state, mode, controlword).
    pub const fn drive(&self) -> &Drive {
        &self.drive
    }

    /// The device's object table.
    pub const fn objects(&self) -> &'static [ObjectInfo] {
        self.objects
    }

    /// The configuration.
    pub const fn config(&self) -> &SessionConfig {
        &self.config
    }

    /// The request running, if any.
    pub const fn request(&self) -> Option<Request> {
        self.request
    }

    /// Checks `operation`'s objects against the table.
    pub const fn check(&self, operation: Operation) -> Result<(), MissingObject> {
        operation.check(self.objects)
    }

    /// Starts `request` at `now`. Refused, with nothing to send, when the
    /// device lacks an object it needs or another request runs. The
    /// request begins once a statusword newer than `now` came in (the
    /// first action is that upload, when polling).
    pub fn start(&mut self, now: Instant, request: Request) -> Result<(), OperationError> {
        if self.request.is_some() {
            return Err(OperationError::Refused(DriveError::Busy));
        }
        self.check(request.operation())?;
        self.request = Some(request);
        self.last_poll = None;
        let deadline = now + self.config.drive.timeout(Step::Statusword);
        self.phase = Phase::Fresh {
            since: now,
            seen: self.statuswords,
            deadline,
        };
        Ok(())
    }

    /// Ends the running request without a result, for a caller whose read
    /// or write failed: the writes still queued are dropped, a move or
    /// homing is no longer followed (the drive is not told).
    pub fn cancel(&mut self) {
        self.drive.cancel_motion();
        self.drive.discard_writes();
        self.request = None;
        self.phase = Phase::Idle;
    }

    /// The next action (see [`Action`]).
    pub fn poll_action(&mut self, now: Instant) -> Action {
        for _ in 0..8 {
            if let Some(write) = self.drive.poll_write() {
                return Action::Write(write);
            }
            if self.drive.poll_timeout().is_some_and(|at| at <= now) {
                self.drive.handle_timeout(now);
                self.pump();
                continue;
            }
            match self.step(now) {
                Some(action) => return action,
                // The phase changed: writes may be queued.
                None => continue,
            }
        }
        self.wait_or_poll(now)
    }

    /// The next event of the drive, if any.
    pub fn poll_event(&mut self) -> Option<Event> {
        self.events.pop()
    }

    /// An uploaded or received statusword (0x6041, 2 bytes little-endian)
    /// taken at `at`.
    pub fn on_statusword(&mut self, at: Instant, data: &[u8]) {
        let Ok(bytes) = <[u8; 2]>::try_from(data) else {
            if self.request.is_some() {
                self.finish(Err(OperationError::BadStatusword { len: data.len() }));
            }
            return;
        };
        self.drive
            .update_statusword(at, Statusword(u16::from_le_bytes(bytes)));
        self.statusword_at = Some(self.statusword_at.map_or(at, |t| t.max(at)));
        self.statuswords = self.statuswords.wrapping_add(1);
        self.pump();
    }

    /// The uploaded error code (0x603F) after [`Read::ErrorCode`]; `None`
    /// when the upload failed.
    pub fn on_error_code(&mut self, data: Option<&[u8]>) {
        let code = data
            .and_then(|d| <[u8; 2]>::try_from(d).ok())
            .map(u16::from_le_bytes);
        self.finish_fault(code);
    }

    /// Whether `can_id` is the statusword TPDO.
    pub fn is_statusword_pdo(&self, can_id: CanId) -> bool {
        self.config
            .statusword_pdo
            .is_some_and(|pdo| pdo.can_id == can_id)
    }

    /// A received TPDO; takes the statusword from the statusword TPDO and
    /// returns whether it was that one.
    pub fn on_pdo(&mut self, can_id: CanId, data: &[u8], at: Instant) -> bool {
        let Some(pdo) = self.config.statusword_pdo.filter(|p| p.can_id == can_id) else {
            return false;
        };
        let end = pdo.offset.saturating_add(2);
        self.on_statusword(at, data.get(pdo.offset..end).unwrap_or(&[]));
        true
    }

    /// The next statusword upload when polling is due, otherwise a wait
    /// until the next poll or deadline.
    fn wait_or_poll(&mut self, now: Instant) -> Action {
        let next_poll = self
            .config
            .poll_period
            .map(|period| self.last_poll.map_or(now, |last| last + period));
        if next_poll.is_some_and(|at| at <= now) {
            self.last_poll = Some(now);
            return Action::Read(Read::Statusword);
        }
        let until = earliest(
            earliest(next_poll, self.drive.poll_timeout()),
            self.phase.deadline(),
        );
        Action::Wait(until.unwrap_or(now + IDLE_WAIT).max(now))
    }

    /// Moves the drive's events into the queue, judging the request by
    /// them.
    fn pump(&mut self) {
        while let Some(event) = self.drive.poll_event() {
            self.events.push(event);
            self.judge(event);
        }
    }
}

#[cfg(test)]
mod tests;
