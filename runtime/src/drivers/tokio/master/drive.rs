//! CiA 402 drives on the tokio [`Master`]: the async loop around
//! [`cia402::Session`](crate::cia402::Session), the same loop as the
//! blocking master's ([`blocking::Master::drive`](crate::blocking::Master::drive)).
//! Writes go by SDO download, statuswords come from SDO uploads of 0x6041
//! (every [`SessionConfig::poll_period`]) and from the statusword TPDO when
//! one is configured (and watched by the master's PDO receiver).
//!
//! Every call is cancellation-safe in the sense of the master's: dropping
//! it mid-request aborts the SDO transfer in flight and cancels the request
//! in the session, so the next request starts from the drive's state.

use core::fmt;
use std::boxed::Box;
use std::vec::Vec;

use super::Master;
use crate::Instant;
use crate::blocking::Error;
use crate::cia402::session::{Action, OperationError, Read, Request, Session, SessionConfig};
use crate::cia402::{Event, Move, State, Statusword, object};
use crate::od::{NodeId, ObjectInfo};
use crate::tokio::Events;

use crate::blocking::master::drive::{DriveEvents, StatuswordPdo, next_action, statusword_pdo};

impl Master {
    /// A CiA 402 drive at `node` whose object table is `objects` (a
    /// generated `od::OBJECTS`). The table is checked for the state
    /// machine's objects and [`SessionConfig::required`] before anything is
    /// sent; each call of the handle checks its own mode's objects.
    ///
    /// ```no_run
    /// # async fn run(master: eds2rust_runtime::tokio::Master, objects: &'static [eds2rust_runtime::od::ObjectInfo])
    /// # -> Result<(), eds2rust_runtime::tokio::Error> {
    /// use eds2rust_runtime::cia402::{Move, SessionConfig};
    /// let node = eds2rust_runtime::od::NodeId::new(2).unwrap();
    /// let mut drive = master.drive(node, objects, SessionConfig::default())?;
    /// drive.enable().await?;
    /// drive.move_to(10_000, Move::default()).await?;
    /// for (at, event) in drive.take_events() {
    ///     println!("{at:?} {event:?}");
    /// }
    /// # Ok(()) }
    /// ```
    pub fn drive(
        &self,
        node: NodeId,
        objects: &'static [ObjectInfo],
        config: SessionConfig,
    ) -> Result<DriveHandle, Error> {
        let session = Session::new(objects, config).map_err(OperationError::Missing)?;
        Ok(DriveHandle::new(self.clone(), node, session))
    }

    /// Runs `request` of `session` on `node` to its end, handing each event
    /// of the drive to `on_event` as it happens; `pdos` is the event stream
    /// the statusword TPDO comes on (when the session has one). On an error,
    /// or when the future is dropped, the request is cancelled in the
    /// session.
    pub async fn run_drive_request(
        &self,
        node: NodeId,
        session: &mut Session,
        request: Request,
        pdos: Option<&mut Events>,
        on_event: &mut (dyn FnMut(Instant, Event) + Send),
    ) -> Result<(), Error> {
        session.start(self.now(), request)?;
        let mut guard = CancelOnDrop(Some(session));
        let session = guard.0.as_deref_mut().expect("set above");
        let result = self.drive_loop(node, session, pdos, on_event).await;
        if result.is_ok() {
            guard.0 = None;
        }
        result
    }

    async fn drive_loop(
        &self,
        node: NodeId,
        session: &mut Session,
        mut pdos: Option<&mut Events>,
        on_event: &mut (dyn FnMut(Instant, Event) + Send),
    ) -> Result<(), Error> {
        loop {
            match next_action(session, self.now(), on_event) {
                Action::Write(write) => {
                    let (index, sub) = (write.index, write.sub);
                    self.download(node, index, sub, &write.value.to_le_bytes())
                        .await?;
                }
                Action::Read(Read::Statusword) => {
                    let data = self.upload(node, object::STATUSWORD, 0).await?;
                    session.on_statusword(self.now(), &data);
                }
                Action::Read(Read::ErrorCode) => {
                    // Best effort: the fault is reported without its code.
                    let data = self.upload(node, object::ERROR_CODE, 0).await.ok();
                    session.on_error_code(data.as_deref());
                }
                Action::Wait(until) => {
                    let wake = ::tokio::time::Instant::from_std(self.clock().to_std(until));
                    let sleep = ::tokio::time::sleep_until(wake);
                    match pdos.as_deref_mut() {
                        None => sleep.await,
                        Some(events) => {
                            ::tokio::select! {
                                () = sleep => {}
                                pdo = next_statusword_pdo(events, session) => {
                                    if let Some(pdo) = pdo {
                                        pdo.feed(session);
                                    }
                                }
                            }
                        }
                    }
                }
                Action::Done(result) => return result.map_err(Error::Cia402),
            }
        }
    }
}

/// The next statusword TPDO on `events` (`None` when the stream ends).
async fn next_statusword_pdo(events: &mut Events, session: &Session) -> Option<StatuswordPdo> {
    loop {
        let event = events.next().await?;
        if let Some(pdo) = statusword_pdo(session, &event) {
            return Some(pdo);
        }
    }
}

/// Cancels the request in the session unless disarmed: an error, or the
/// future dropped mid-request.
struct CancelOnDrop<'a>(Option<&'a mut Session>);

impl Drop for CancelOnDrop<'_> {
    fn drop(&mut self) {
        if let Some(session) = self.0.take() {
            session.cancel();
        }
    }
}

/// The observer of a [`DriveHandle`].
type Observer = dyn FnMut(Instant, &Event) + Send;

/// One CiA 402 drive on the tokio [`Master`] (see [`Master::drive`]): the
/// async counterpart of [`blocking::DriveHandle`](crate::blocking::DriveHandle),
/// with the same calls. The drive's [`Event`]s (state changes, faults) go
/// to the observer ([`DriveHandle::on_event`]) as they happen, or else are
/// kept for [`DriveHandle::take_events`] (the newest
/// [`DRIVE_EVENTS_KEPT`](crate::blocking::DRIVE_EVENTS_KEPT)).
pub struct DriveHandle {
    master: Master,
    node: NodeId,
    session: Session,
    pdos: Option<Events>,
    events: DriveEvents<Observer>,
}

impl fmt::Debug for DriveHandle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.events.debug_handle(f, self.node, &self.session)
    }
}

impl DriveHandle {
    /// Runs `session` (made or kept by the caller) on `node`. When the
    /// session has a statusword TPDO, the handle listens to the master's
    /// events for it.
    pub fn new(master: Master, node: NodeId, session: Session) -> DriveHandle {
        let pdos = session.config().statusword_pdo.map(|_| master.events());
        DriveHandle {
            master,
            node,
            session,
            pdos,
            events: DriveEvents::new(),
        }
    }

    /// Hands every event from now on to `observer` (with the time it was
    /// seen) instead of keeping it.
    pub fn on_event(&mut self, observer: impl FnMut(Instant, &Event) + Send + 'static) {
        self.events.set_observer(Box::new(observer));
    }

    /// The events kept since the last call (at most
    /// [`DRIVE_EVENTS_KEPT`](crate::blocking::DRIVE_EVENTS_KEPT), the
    /// newest), each with the time it was seen, when no observer is set.
    pub fn take_events(&mut self) -> Vec<(Instant, Event)> {
        self.events.take()
    }

    /// Runs one request (every other call is this one).
    pub async fn request(&mut self, request: Request) -> Result<(), Error> {
        let events = &mut self.events;
        let mut on_event = |at: Instant, event: Event| events.deliver(at, event);
        self.master
            .run_drive_request(
                self.node,
                &mut self.session,
                request,
                self.pdos.as_mut(),
                &mut on_event,
            )
            .await
    }

    /// To Operation enabled from any state, resetting a fault.
    pub async fn enable(&mut self) -> Result<(), Error> {
        self.request(Request::Enable).await
    }

    /// Disable voltage, to Switch on disabled.
    pub async fn disable(&mut self) -> Result<(), Error> {
        self.request(Request::Disable).await
    }

    /// Quick stop, to Quick stop active (or Switch on disabled).
    pub async fn quick_stop(&mut self) -> Result<(), Error> {
        self.request(Request::QuickStop).await
    }

    /// Resets a fault; nothing to do outside the fault states.
    pub async fn fault_reset(&mut self) -> Result<(), Error> {
        self.request(Request::FaultReset).await
    }

    /// A profile-position move (absolute, relative, immediate per
    /// `options`), until target reached.
    pub async fn move_to(&mut self, target: i32, options: Move) -> Result<(), Error> {
        self.request(Request::Move { target, options }).await
    }

    /// Profile velocity: `target` to 0x60FF, until target reached.
    pub async fn set_velocity(&mut self, target: i32) -> Result<(), Error> {
        self.request(Request::Velocity(target)).await
    }

    /// Homing with `method` (0x6098; `None`: the drive's), until homing
    /// attained.
    pub async fn home(&mut self, method: Option<i8>) -> Result<(), Error> {
        self.request(Request::Home(method)).await
    }

    /// Profile velocity, acceleration and deceleration (0x6081, 0x6083,
    /// 0x6084) for the next moves.
    pub async fn set_profile(
        &mut self,
        velocity: u32,
        acceleration: u32,
        deceleration: u32,
    ) -> Result<(), Error> {
        let request = Request::Profile {
            velocity,
            acceleration,
            deceleration,
        };
        self.request(request).await
    }

    /// One cyclic synchronous position target (0x607A, mode 8 first when
    /// not set).
    pub async fn set_csp_target(&mut self, target: i32) -> Result<(), Error> {
        self.request(Request::CspTarget(target)).await
    }

    /// Cyclic synchronous position: one target of `targets` every
    /// `period` ([`DriveHandle::set_csp_target`], then a sleep until the period
    /// is over; the driver keeps the cores, SYNC included, running). Stops
    /// at the first error (the drive left Operation enabled, a following
    /// error).
    pub async fn run_csp(
        &mut self,
        period: core::time::Duration,
        targets: impl IntoIterator<Item = i32>,
    ) -> Result<(), Error> {
        let mut next = ::tokio::time::Instant::now();
        for target in targets {
            next += period;
            self.set_csp_target(target).await?;
            ::tokio::time::sleep_until(next).await;
        }
        Ok(())
    }

    /// A fresh statusword.
    pub async fn statusword(&mut self) -> Result<Statusword, Error> {
        self.request(Request::Statusword).await?;
        Ok(self.session.drive().statusword().unwrap_or(Statusword(0)))
    }

    /// The state of the last statusword seen.
    pub fn state(&self) -> Option<State> {
        self.session.drive().state()
    }

    /// The session (its drive, table and configuration).
    pub fn session(&self) -> &Session {
        &self.session
    }

    /// The master.
    pub fn master(&self) -> &Master {
        &self.master
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
