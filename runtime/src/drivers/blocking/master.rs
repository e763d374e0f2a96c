//! The blocking driver of the composite [`crate::master::Master`].

use core::ops::ControlFlow;
use core::time::Duration;
use std::collections::VecDeque;
use std::collections::vec_deque;
use std::io;
use std::vec::Vec;

pub(crate) mod drive;
pub(crate) mod lss;
mod pdo;
mod sdo;

pub use drive::{DRIVE_EVENTS_KEPT, DriveHandle};
pub use lss::LssRequestError;

use super::{Error, IDLE_WAIT, RunError};
use crate::boot::{NetworkBoot, NetworkPlan, NetworkReport, ends_boot};
use crate::master::{self, MasterEvent};
use crate::nmt::{NmtCommand, NmtTarget};
use crate::od::NodeId;
use crate::sdo::typed::LengthNote;
use crate::time::Deadline;
use crate::transport::{Bus, Clock};
use crate::{Instant, Service};

/// Events [`Master`] keeps for [`Master::next_event`] by default.
pub const MASTER_QUEUE_CAPACITY: usize = 1024;

/// A composite CANopen master on a bus, run on the calling thread.
///
/// Every blocking call (an SDO transfer, an LSS request, [`Master::run_for`],
/// [`Master::run_until`]) runs all the cores while it waits: the master's
/// heartbeat and SYNC go out on time, PDOs are sent and received, NMT,
/// heartbeat and EMCY frames are taken in. Events that the call does not
/// wait for are queued (at most [`Master::set_queue_capacity`], oldest
/// dropped first and counted) for [`Master::next_event`] and
/// [`Master::drain_events`]. Between calls nothing runs: an application
/// with nothing to do calls [`Master::run_for`] or [`Master::run_until`].
///
/// ```
/// use core::time::Duration;
/// use eds2rust_runtime::blocking::Master;
/// use eds2rust_runtime::master;
/// use eds2rust_runtime::nmt::{NmtCommand, NmtTarget};
/// use eds2rust_runtime::od::NodeId;
/// use eds2rust_runtime::transport::virtual_bus::VirtualBus;
///
/// let bus = VirtualBus::new();
/// let monitor = bus.attach();
/// let core = master::Master::new(NodeId::new(1).unwrap(), Some(Duration::from_millis(100)));
/// let mut m = Master::new(bus.attach(), core);
/// m.start()?; // boot-up message of node 1
/// let node = NodeId::new(0x20).expect("1 to 127");
/// m.nmt(NmtCommand::Start, NmtTarget::Node(node))?;
/// m.run_for(Duration::from_millis(150))?; // one heartbeat
/// let seen: Vec<String> = std::iter::from_fn(|| monitor.try_recv())
///     .map(|f| f.to_string())
///     .collect();
/// assert_eq!(seen, ["701#00", "000#0120", "701#7F"]);
/// // Typed SDO calls: m.read::<SomeEntry>(node)?, m.write::<SomeEntry>(node, value)?
/// # Ok::<(), eds2rust_runtime::blocking::Error>(())
/// ```
///
/// Every call fails with the one [`Error`] of the drivers.
#[derive(Debug)]
pub struct Master<B> {
    bus: B,
    clock: Clock,
    core: master::Master,
    queue: VecDeque<MasterEvent>,
    capacity: usize,
    dropped: u64,
    notes: VecDeque<(NodeId, LengthNote)>,
}

impl<B: Bus> Master<B> {
    /// Runs `core` on `bus`, with a clock starting now.
    pub fn new(bus: B, core: master::Master) -> Master<B> {
        Master::with_clock(bus, core, Clock::new())
    }

    /// Runs `core` on `bus`; the core sees time through `clock`.
    pub fn with_clock(bus: B, core: master::Master, clock: Clock) -> Master<B> {
        Master {
            bus,
            clock,
            core,
            queue: VecDeque::new(),
            capacity: MASTER_QUEUE_CAPACITY,
            dropped: 0,
            notes: VecDeque::new(),
        }
    }

    /// The sans-IO core.
    pub fn core(&self) -> &master::Master {
        &self.core
    }

    /// The sans-IO core, to configure its cores (PDOs, heartbeat consumer,
    /// SDO clients) or to start requests without waiting for them.
    pub fn core_mut(&mut self) -> &mut master::Master {
        &mut self.core
    }

    /// The bus.
    pub fn bus(&self) -> &B {
        &self.bus
    }

    /// The bus, to send other frames.
    pub fn bus_mut(&mut self) -> &mut B {
        &mut self.bus
    }

    /// The clock of the cores.
    pub fn clock(&self) -> &Clock {
        &self.clock
    }

    /// The current time of the cores.
    pub fn now(&self) -> Instant {
        self.clock.now()
    }

    /// Gives the bus and the core back (queued events are dropped).
    pub fn into_parts(self) -> (B, master::Master) {
        (self.bus, self.core)
    }

    /// Starts the core ([`master::Master::start`]) and sends its boot-up
    /// message.
    pub fn start(&mut self) -> Result<(), Error> {
        let now = self.now();
        self.core.start(now);
        self.flush()
    }

    /// Sends every frame the cores have ready.
    pub fn flush(&mut self) -> Result<(), Error> {
        self.send_ready().map_err(Error::Io)
    }

    /// Sends every frame the cores have ready.
    fn send_ready(&mut self) -> io::Result<()> {
        while let Some(frame) = self.core.poll_transmit() {
            self.bus.send(&frame)?;
        }
        Ok(())
    }

    /// Takes in the frames already received and the timers already due,
    /// without waiting, and sends what the cores have ready.
    pub fn poll(&mut self) -> Result<(), Error> {
        loop {
            let now = self.clock.now();
            if self.core.poll_timeout().is_some_and(|at| at <= now) {
                self.core.handle_timeout(now);
            }
            self.flush()?;
            self.pump();
            match self.bus.recv(Duration::ZERO)? {
                Some(frame) => self.core.handle_frame(self.clock.now(), &frame),
                None => return Ok(()),
            }
        }
    }

    /// Runs all cores for `duration`, queueing their events.
    pub fn run_for(&mut self, duration: Duration) -> Result<(), Error> {
        let deadline = self.now() + duration;
        match self.wait(Some(deadline), &mut Err::<(), _>) {
            Ok(()) | Err(RunError::Deadline | RunError::Stopped) => Ok(()),
            Err(RunError::Io(e)) => Err(Error::Io(e)),
        }
    }

    /// Runs all cores until `until` breaks on an event or `deadline`
    /// passes ([`Error::DeadlinePassed`]). Queued events are offered first,
    /// oldest first. The event `until` breaks on is removed; the others
    /// stay queued.
    ///
    /// `deadline` is a point in time: an [`Instant`] of the cores
    /// (`master.now() + Duration::from_millis(50)`), a `std::time::Instant`
    /// or [`Deadline::NEVER`] (see [`Deadline`]).
    pub fn run_until<T>(
        &mut self,
        deadline: impl Into<Deadline>,
        mut until: impl FnMut(&MasterEvent) -> ControlFlow<T>,
    ) -> Result<T, Error> {
        let deadline = deadline.into().on(&self.clock);
        for i in 0..self.queue.len() {
            let Some(event) = self.queue.get(i) else {
                break;
            };
            if let ControlFlow::Break(value) = until(event) {
                self.queue.remove(i);
                return Ok(value);
            }
        }
        let result = self.wait(deadline, &mut |event| match until(&event) {
            ControlFlow::Break(value) => Ok(value),
            ControlFlow::Continue(()) => Err(event),
        });
        result.map_err(|e| match e {
            RunError::Io(e) => Error::Io(e),
            RunError::Deadline | RunError::Stopped => Error::DeadlinePassed,
        })
    }

    /// The oldest queued event, or the next one before `deadline`
    /// (`Ok(None)` when none came). `deadline` is a [`Deadline`], as for
    /// [`Master::run_until`].
    pub fn wait_event(
        &mut self,
        deadline: impl Into<Deadline>,
    ) -> Result<Option<MasterEvent>, Error> {
        if let Some(event) = self.queue.pop_front() {
            return Ok(Some(event));
        }
        let deadline = deadline.into().on(&self.clock);
        match self.wait(deadline, &mut Ok) {
            Ok(event) => Ok(Some(event)),
            Err(RunError::Io(e)) => Err(Error::Io(e)),
            Err(RunError::Deadline | RunError::Stopped) => Ok(None),
        }
    }

    /// The oldest queued event (taken in by earlier calls; see
    /// [`Master::poll`] to take in new frames without waiting).
    pub fn next_event(&mut self) -> Option<MasterEvent> {
        self.queue.pop_front()
    }

    /// All queued events, oldest first.
    pub fn drain_events(&mut self) -> vec_deque::Drain<'_, MasterEvent> {
        self.queue.drain(..)
    }

    /// Number of queued events.
    pub fn queued_events(&self) -> usize {
        self.queue.len()
    }

    /// Sets how many events the queue keeps (default
    /// [`MASTER_QUEUE_CAPACITY`]); the oldest beyond that are dropped.
    pub fn set_queue_capacity(&mut self, capacity: usize) {
        self.capacity = capacity;
        while self.queue.len() > capacity {
            self.queue.pop_front();
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    /// Events dropped because the queue was full.
    pub fn dropped_events(&self) -> u64 {
        self.dropped
    }

    /// The notes typed reads left since the last call (at most
    /// [`NOTES_KEPT`](crate::sdo::typed::NOTES_KEPT), the newest), with
    /// the node: values a server sent longer than their data type, of which
    /// the leading bytes were taken. Empty for nodes whose client has
    /// [`strict_lengths`](crate::sdo::client::ClientConfig::strict_lengths),
    /// which refuses them instead.
    pub fn take_length_notes(&mut self) -> Vec<(NodeId, LengthNote)> {
        self.notes.drain(..).collect()
    }

    fn push(&mut self, event: MasterEvent) {
        if self.queue.len() >= self.capacity {
            self.dropped = self.dropped.saturating_add(1);
            if self.queue.pop_front().is_none() {
                return;
            }
        }
        self.queue.push_back(event);
    }

    /// Moves the cores' events into the queue.
    fn pump(&mut self) {
        while let Some(event) = self.core.poll_event() {
            self.push(event);
        }
    }

    /// The loop behind every call: runs the cores, handing each event to
    /// `until`, which takes it (`Ok`, the call is done) or gives it back
    /// to be queued (`Err`), until `deadline` (on the cores' clock; `None`:
    /// none).
    fn wait<T>(
        &mut self,
        deadline: Option<Instant>,
        until: &mut dyn FnMut(MasterEvent) -> Result<T, MasterEvent>,
    ) -> Result<T, RunError> {
        self.wait_with(deadline, until, &mut |_, _| ControlFlow::Continue(()))
    }

    /// [`Master::wait`] with `hook` run first in every round (streamed
    /// transfers feed and take their data there); breaking from it stops
    /// with [`RunError::Stopped`].
    pub(super) fn wait_with<T>(
        &mut self,
        deadline: Option<Instant>,
        until: &mut dyn FnMut(MasterEvent) -> Result<T, MasterEvent>,
        hook: &mut dyn FnMut(&mut master::Master, Instant) -> ControlFlow<()>,
    ) -> Result<T, RunError> {
        loop {
            if hook(&mut self.core, self.clock.now()).is_break() {
                return Err(RunError::Stopped);
            }
            self.send_ready().map_err(RunError::Io)?;
            while let Some(event) = self.core.poll_event() {
                match until(event) {
                    Ok(value) => {
                        // Best effort: a bus error shows again on the next call.
                        let _ = self.send_ready();
                        self.pump();
                        return Ok(value);
                    }
                    Err(event) => self.push(event),
                }
            }
            // The cores may act on their events as they hand them out (the
            // network boot starts a slave's next SDO request there): send
            // that before waiting for the bus.
            self.send_ready().map_err(RunError::Io)?;
            let now = self.clock.now();
            if deadline.is_some_and(|deadline| now >= deadline) {
                return Err(RunError::Deadline);
            }
            let timer = self.core.poll_timeout();
            if let Some(at) = timer
                && at <= now
            {
                self.core.handle_timeout(now);
                continue;
            }
            let mut wake = now + IDLE_WAIT;
            for limit in [deadline, timer].into_iter().flatten() {
                wake = wake.min(limit);
            }
            let received = super::recv_until(&mut self.bus, &self.clock, now, wake);
            if let Some(frame) = received.map_err(RunError::Io)? {
                self.core.handle_frame(self.clock.now(), &frame);
            }
        }
    }

    /// Boots `plan`'s network ([`master::Master::boot_network`]: every
    /// slave at once, CiA 302-2) and runs the bus until the boot is decided
    /// or `deadline` passes ([`Error::DeadlinePassed`]). The boot's events
    /// stay queued, but for the last; the master supervises the network
    /// from then on (a slave that resets or returns is booted again while
    /// the others run).
    pub fn boot_network(
        &mut self,
        plan: NetworkPlan,
        deadline: impl Into<Deadline>,
    ) -> Result<NetworkReport, Error> {
        let now = self.clock.now();
        self.core.boot_network(now, plan);
        self.run_until(deadline, |event| match event {
            MasterEvent::Network(e) if ends_boot(e) => ControlFlow::Break(()),
            _ => ControlFlow::Continue(()),
        })?;
        self.core
            .network()
            .and_then(NetworkBoot::report)
            .ok_or(Error::DeadlinePassed)
    }

    /// Sends NMT `cmd` to `target`: one node ([`NmtTarget::Node`]) or,
    /// spelled out, every node ([`NmtTarget::All`]). A full NMT queue is
    /// sent first; [`Error::NmtQueueFull`] when it stays full.
    pub fn nmt(&mut self, cmd: NmtCommand, target: impl Into<NmtTarget>) -> Result<(), Error> {
        let target = target.into();
        if self.core.nmt.send(cmd, target).is_err() {
            self.flush()?;
            self.core
                .nmt
                .send(cmd, target)
                .map_err(|_| Error::NmtQueueFull)?;
        }
        self.flush()
    }
}

#[cfg(test)]
mod tests;
