//! CiA 402 drives on the blocking [`Master`]: the I/O loop around
//! [`cia402::Session`](crate::cia402::Session). Writes go by SDO download,
//! statuswords come from SDO uploads of 0x6041 (every
//! [`SessionConfig::poll_period`]) and from the statusword TPDO when one
//! is configured; every other core keeps running meanwhile.

use core::fmt;
use core::ops::ControlFlow;
use core::time::Duration;
use std::boxed::Box;
use std::collections::VecDeque;
use std::vec::Vec;

use super::Master;
use crate::blocking::Error;
use crate::cia402::session::{Action, OperationError, Read, Request, Session, SessionConfig};
use crate::cia402::{Event, Move, State, Statusword, object};
use crate::master::MasterEvent;
use crate::od::{self, DataType, Entry, NodeId, ObjectInfo};
use crate::pdo::PdoEvent;
use crate::transport::Bus;
use crate::{CanId, Instant};

/// Events a [`DriveHandle`] without observer keeps for
/// [`DriveHandle::take_events`]; the oldest beyond are dropped.
pub const DRIVE_EVENTS_KEPT: usize = 1024;

/// The UNSIGNED16 objects the loop uploads, as entries for the typed read
/// (length and padding rules of [`Master::read`]).
struct Word<const INDEX: u16>;

impl<const INDEX: u16> Entry for Word<INDEX> {
    const INDEX: u16 = INDEX;
    const SUBINDEX: u8 = 0;
    const NAME: &'static str = "CiA 402 word";
    const DATA_TYPE: DataType = DataType::Unsigned16;
    const PDO_MAPPABLE: bool = true;
    type Access = od::access::Ro;
    type Value = u16;
}

impl<B: Bus> Master<B> {
    /// A CiA 402 drive at `node` whose object table is `objects` (a
    /// generated `od::OBJECTS`). The table is checked for the state
    /// machine's objects and [`SessionConfig::required`] before anything is
    /// sent; each call of the handle checks its own mode's objects.
    ///
    /// ```
    /// # use core::time::Duration;
    /// # use eds2rust_runtime::{blocking::Master, master, od::NodeId};
    /// # use eds2rust_runtime::transport::virtual_bus::VirtualBus;
    /// use eds2rust_runtime::cia402::{Operation, SessionConfig};
    /// use eds2rust_runtime::od::{AccessRight, DataType, ObjectInfo};
    ///
    /// static OBJECTS: [ObjectInfo; 2] = [
    ///     ObjectInfo::new(0x6040, 0, "Controlword", DataType::Unsigned16, AccessRight::Rw, true),
    ///     ObjectInfo::new(0x6041, 0, "Statusword", DataType::Unsigned16, AccessRight::Ro, true),
    /// ];
    /// # let bus = VirtualBus::new();
    /// # let core = master::Master::new(NodeId::new(1).unwrap(), Some(Duration::from_millis(100)));
    /// let mut m = Master::new(bus.attach(), core);
    /// let node = NodeId::new(0x20).unwrap();
    /// let config = SessionConfig::default().with_required(&[Operation::ProfileVelocity]);
    /// let e = m.drive(node, &OBJECTS, config).err().unwrap();
    /// assert_eq!(
    ///     e.to_string(),
    ///     "profile velocity needs 0x6060 Modes of operation, which this device does not have"
    /// );
    /// let mut drive = m.drive(node, &OBJECTS, SessionConfig::default())?;
    /// drive.on_event(|at, event| println!("{at:?} {event:?}"));
    /// // drive.enable()?; drive.quick_stop()?; ...
    /// # Ok::<(), eds2rust_runtime::blocking::Error>(())
    /// ```
    pub fn drive(
        &mut self,
        node: NodeId,
        objects: &'static [ObjectInfo],
        config: SessionConfig,
    ) -> Result<DriveHandle<'_, B>, Error> {
        let session = Session::new(objects, config).map_err(OperationError::Missing)?;
        Ok(DriveHandle::new(self, node, session))
    }

    /// Runs `request` of `session` on `node` to its end, handing each
    /// event of the drive to `on_event` as it happens. On an error the
    /// request is cancelled in the session.
    pub fn run_drive_request(
        &mut self,
        node: NodeId,
        session: &mut Session,
        request: Request,
        on_event: &mut dyn FnMut(Instant, Event),
    ) -> Result<(), Error> {
        session.start(self.now(), request)?;
        let result = self.drive_loop(node, session, on_event);
        if result.is_err() {
            session.cancel();
        }
        result
    }

    /// The loop of [`Master::run_drive_request`].
    fn drive_loop(
        &mut self,
        node: NodeId,
        session: &mut Session,
        on_event: &mut dyn FnMut(Instant, Event),
    ) -> Result<(), Error> {
        loop {
            match next_action(session, self.now(), on_event) {
                Action::Write(write) => {
                    let (index, sub) = (write.index, write.sub);
                    self.download(node, index, sub, &write.value.to_le_bytes())?;
                }
                Action::Read(Read::Statusword) => {
                    let sw = self.read::<Word<{ object::STATUSWORD }>>(node)?;
                    session.on_statusword(self.now(), &sw.to_le_bytes());
                }
                Action::Read(Read::ErrorCode) => {
                    // Best effort: the fault is reported without its code.
                    let code = self.read::<Word<{ object::ERROR_CODE }>>(node).ok();
                    session.on_error_code(code.map(u16::to_le_bytes).as_ref().map(|c| &c[..]));
                }
                Action::Wait(until) => {
                    let pdo = self.run_until(until, |event| match statusword_pdo(session, event) {
                        Some(pdo) => ControlFlow::Break(pdo),
                        None => ControlFlow::Continue(()),
                    });
                    match pdo {
                        Ok(pdo) => pdo.feed(session),
                        Err(Error::DeadlinePassed) => {}
                        Err(e) => return Err(e),
                    }
                }
                Action::Done(result) => return result.map_err(Error::Cia402),
            }
        }
    }
}

/// The session's next action at `now`; the events it has are handed to
/// `on_event` first.
pub(crate) fn next_action(
    session: &mut Session,
    now: Instant,
    on_event: &mut dyn FnMut(Instant, Event),
) -> Action {
    let action = session.poll_action(now);
    while let Some(event) = session.poll_event() {
        on_event(now, event);
    }
    action
}

/// A statusword TPDO the session waits for, as the master received it.
pub(crate) struct StatuswordPdo {
    can_id: CanId,
    data: [u8; 8],
    len: usize,
    at: Instant,
}

impl StatuswordPdo {
    /// Hands the PDO to `session`.
    pub(crate) fn feed(&self, session: &mut Session) {
        let data = self.data.get(..self.len).unwrap_or(&[]);
        session.on_pdo(self.can_id, data, self.at);
    }
}

/// The statusword TPDO of `session` that `event` brings, if it brings one.
pub(crate) fn statusword_pdo(session: &Session, event: &MasterEvent) -> Option<StatuswordPdo> {
    match *event {
        MasterEvent::Pdo(PdoEvent::Received {
            can_id,
            data,
            len,
            at,
        }) if session.is_statusword_pdo(can_id) => Some(StatuswordPdo {
            can_id,
            data,
            len,
            at,
        }),
        _ => None,
    }
}

/// Where the events of a drive handle (blocking or tokio) go: to its
/// observer (`O`, a closure) once one is set, or else into a log of the
/// newest [`DRIVE_EVENTS_KEPT`].
pub(crate) struct DriveEvents<O: ?Sized> {
    observer: Option<Box<O>>,
    log: VecDeque<(Instant, Event)>,
}

impl<O: ?Sized + FnMut(Instant, &Event)> DriveEvents<O> {
    pub(crate) fn new() -> DriveEvents<O> {
        DriveEvents {
            observer: None,
            log: VecDeque::new(),
        }
    }

    /// The `Debug` form of the drive handle of `node` and `session` these
    /// events belong to (whether it has an observer, not the closure).
    pub(crate) fn debug_handle(
        &self,
        f: &mut fmt::Formatter<'_>,
        node: NodeId,
        session: &Session,
    ) -> fmt::Result {
        f.debug_struct("DriveHandle")
            .field("node", &node)
            .field("session", session)
            .field("observer", &self.observer.is_some())
            .finish_non_exhaustive()
    }

    /// Hands every event from now on to `observer`.
    pub(crate) fn set_observer(&mut self, observer: Box<O>) {
        self.observer = Some(observer);
    }

    /// The events kept since the last call.
    pub(crate) fn take(&mut self) -> Vec<(Instant, Event)> {
        self.log.drain(..).collect()
    }

    /// Hands `event`, seen `at`, to the observer, or else keeps it.
    pub(crate) fn deliver(&mut self, at: Instant, event: Event) {
        match &mut self.observer {
            Some(observer) => observer(at, &event),
            None => {
                if self.log.len() >= DRIVE_EVENTS_KEPT {
                    self.log.pop_front();
                }
                self.log.push_back((at, event));
            }
        }
    }
}

/// The observer of a [`DriveHandle`].
type Observer<'a> = dyn FnMut(Instant, &Event) + 'a;

/// One CiA 402 drive on a blocking [`Master`] (see [`Master::drive`]).
///
/// Each call runs one [`Request`] and blocks until the drive reports it
/// done or failed or a step times out (timeouts per
/// [`Step`](crate::cia402::Step) in [`SessionConfig::drive`]). The
/// drive's [`Event`]s (state changes, faults) go to the observer
/// ([`DriveHandle::on_event`]) as they happen, or else are kept for
/// [`DriveHandle::take_events`].
pub struct DriveHandle<'a, B> {
    master: &'a mut Master<B>,
    node: NodeId,
    session: Session,
    events: DriveEvents<Observer<'a>>,
}

impl<B> fmt::Debug for DriveHandle<'_, B> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.events.debug_handle(f, self.node, &self.session)
    }
}

impl<'a, B: Bus> DriveHandle<'a, B> {
    /// Runs `session` (made or kept by the caller) on `node`.
    pub fn new(master: &'a mut Master<B>, node: NodeId, session: Session) -> DriveHandle<'a, B> {
        DriveHandle {
            master,
            node,
            session,
            events: DriveEvents::new(),
        }
    }

    /// Hands every event from now on to `observer` (with the time it was
    /// seen) instead of keeping it.
    pub fn on_event(&mut self, observer: impl FnMut(Instant, &Event) + 'a) {
        self.events.set_observer(Box::new(observer));
    }

    /// The events kept since the last call (at most [`DRIVE_EVENTS_KEPT`],
    /// the newest), when no observer is set.
    pub fn take_events(&mut self) -> Vec<(Instant, Event)> {
        self.events.take()
    }

    /// Runs one request (every other call is this one).
    pub fn request(&mut self, request: Request) -> Result<(), Error> {
        let events = &mut self.events;
        let mut on_event = |at: Instant, event: Event| events.deliver(at, event);
        self.master
            .run_drive_request(self.node, &mut self.session, request, &mut on_event)
    }

    /// To Operation enabled from any state, resetting a fault (at most
    /// [`DriveConfig::fault_reset_attempts`](crate::cia402::DriveConfig)
    /// times). A fault that stays gives [`OperationError::Fault`] with the
    /// error code read from 0x603F.
    pub fn enable(&mut self) -> Result<(), Error> {
        self.request(Request::Enable)
    }

    /// Disable voltage, to Switch on disabled.
    pub fn disable(&mut self) -> Result<(), Error> {
        self.request(Request::Disable)
    }

    /// Quick stop, to Quick stop active (or Switch on disabled).
    pub fn quick_stop(&mut self) -> Result<(), Error> {
        self.request(Request::QuickStop)
    }

    /// Resets a fault; nothing to do outside the fault states.
    pub fn fault_reset(&mut self) -> Result<(), Error> {
        self.request(Request::FaultReset)
    }

    /// A profile-position move (absolute, relative, immediate per
    /// `options`), until target reached. Needs Operation enabled; writes
    /// mode 1 first when the handle has not set it.
    pub fn move_to(&mut self, target: i32, options: Move) -> Result<(), Error> {
        self.request(Request::Move { target, options })
    }

    /// Profile velocity: writes `target` to 0x60FF (mode 3 first when not
    /// set) and waits for target reached (bit 10) in a later statusword
    /// (the I/O form of [`Drive::set_velocity`](crate::cia402::Drive::set_velocity)).
    pub fn set_velocity(&mut self, target: i32) -> Result<(), Error> {
        self.request(Request::Velocity(target))
    }

    /// Homing with `method` (0x6098; `None`: the drive's), until homing
    /// attained.
    pub fn home(&mut self, method: Option<i8>) -> Result<(), Error> {
        self.request(Request::Home(method))
    }

    /// Writes profile velocity, acceleration and deceleration (0x6081,
    /// 0x6083, 0x6084).
    pub fn set_profile(
        &mut self,
        velocity: u32,
        acceleration: u32,
        deceleration: u32,
    ) -> Result<(), Error> {
        self.request(Request::Profile {
            velocity,
            acceleration,
            deceleration,
        })
    }

    /// One cycle of cyclic synchronous position: writes `target` to 0x607A
    /// (mode 8 first when not set) and takes one statusword (the I/O form
    /// of [`Drive::set_csp_target`](crate::cia402::Drive::set_csp_target)).
    pub fn set_csp_target(&mut self, target: i32) -> Result<(), Error> {
        self.request(Request::CspTarget(target))
    }

    /// Cyclic synchronous position: one target of `targets` every
    /// `period` ([`DriveHandle::set_csp_target`], then the master's cores run
    /// — SYNC included — until the period is over). Stops at the first
    /// error (the drive left Operation enabled, a following error).
    pub fn run_csp(
        &mut self,
        period: Duration,
        targets: impl IntoIterator<Item = i32>,
    ) -> Result<(), Error> {
        for target in targets {
            let next = self.master.now() + period;
            self.set_csp_target(target)?;
            let left = next.saturating_duration_since(self.master.now());
            self.master.run_for(left)?;
        }
        Ok(())
    }

    /// A statusword uploaded now.
    pub fn statusword(&mut self) -> Result<Statusword, Error> {
        self.request(Request::Statusword)?;
        Ok(self.session.drive().statusword().unwrap_or(Statusword(0)))
    }

    /// The state of the last statusword.
    pub fn state(&self) -> Option<State> {
        self.session.drive().state()
    }

    /// The session (the helper, its mode and controlword).
    pub fn session(&self) -> &Session {
        &self.session
    }

    /// The master, for other calls between drive calls.
    pub fn master(&mut self) -> &mut Master<B> {
        self.master
    }

    /// The node.
    pub fn node(&self) -> NodeId {
        self.node
    }

    /// Ends the handle, keeping the session (the helper's state) for a
    /// later [`DriveHandle::new`].
    pub fn into_session(self) -> Session {
        self.session
    }
}
