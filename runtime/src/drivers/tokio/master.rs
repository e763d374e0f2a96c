//! The tokio driver of the composite [`crate::master::Master`]: a cheap
//! [`Master`] handle for the calls, and the [`Driver`] future that runs the
//! cores on the bus.

use core::marker::PhantomData;
use std::collections::{BTreeMap, VecDeque};
use std::string::{String, ToString};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::vec::Vec;

use ::tokio::sync::{Notify, oneshot};

mod drive;
mod driver;
mod lss;
mod pdo;
mod sdo;
mod stream;
mod streamed;

pub use crate::blocking::{LssRequestError, MASTER_QUEUE_CAPACITY};
pub use drive::DriveHandle;
pub use driver::Driver;
pub use stream::{Events, PDO_QUEUE_CAPACITY, Pdos};

use super::Error;
use crate::CanId;
use crate::blocking::{Upload, transfer_end};
use crate::boot::{NetworkBoot, NetworkPlan, NetworkReport, ends_boot};
use crate::lss::LssEvent;
use crate::master::{self, MasterEvent};
use crate::nmt::{NmtCommand, NmtTarget};
use crate::od::{self, NodeId};
use crate::pdo::{PdoCobId, PdoEvent, WatchError};
use crate::sdo::typed::LengthNote;
use crate::transport::{AsyncBus, Clock};
use crate::{Instant, Service};
use stream::Queue;

/// A handle to a composite CANopen master run by a [`Driver`].
///
/// ## Why a handle and a driver
///
/// One task must own the bus and poll the cores, both while a caller
/// awaits an SDO transfer and while it only consumes [`Events`] or
/// [`Pdos`]. [`Master::new`] therefore returns the handle and a
/// [`Driver`] that the application runs itself, usually with
/// `tokio::spawn(driver.run())`. Nothing is spawned behind the caller's
/// back: the driver works on any runtime flavour (current-thread,
/// multi-thread, a `LocalSet` for a bus that is not `Send`), its bus
/// errors come back from [`Driver::run`], and its lifetime is the
/// application's to decide. The driver ends when every [`Master`] handle
/// is dropped (after sending the frames the cores still had), on a bus
/// error, or when its future is dropped; pending calls then fail with
/// [`Error::DriverStopped`] and the streams end.
///
/// Unlike the blocking master, whose cores run only during its calls, the
/// cores run for as long as the driver does: heartbeats, SYNC, PDOs and
/// supervision go on between calls too. Calls made before the driver
/// runs wait for it (SDO calls until their bound).
///
/// The handle is `Clone`; its calls take `&self`, so tasks may run SDO
/// transfers with different nodes at the same time. Transfers with one
/// node take turns (the CiA 301 SDO channel carries one at a time), and so
/// do LSS requests.
///
/// ## Cancellation
///
/// Every SDO call ends: the client core bounds each step by its timeout,
/// and the call gives up (aborting with 0x05040000) once the whole
/// transfer took the bound the blocking driver uses. Every call is
/// cancellation-safe. Dropping an SDO future before it
/// completed aborts the transfer (abort 0x05040000 is sent, as for a
/// timeout) and frees the node's channel for the next call. Dropping an
/// LSS future cancels the request on the LSS core. Dropping an NMT or
/// start future leaves its frame queued: the driver still sends it.
///
/// ## Events
///
/// Events a call waits for (the end of its SDO transfer or LSS request) go
/// to that call. All others go to every [`Events`] stream (each a bounded
/// queue of its own; see [`Events`] for what happens when one is full) and
/// PDO receptions also to the [`Pdos`] streams of their COB-ID. Events
/// that come while no [`Events`] stream exists are counted in
/// [`Master::unobserved_events`].
///
/// ## Example
///
/// ```
/// use core::time::Duration;
/// use eds2rust_runtime::master;
/// use eds2rust_runtime::nmt::{NmtCommand, NmtTarget};
/// use eds2rust_runtime::od::NodeId;
/// use eds2rust_runtime::tokio::Master;
/// use eds2rust_runtime::transport::virtual_bus::VirtualBus;
///
/// # #[tokio::main(flavor = "current_thread", start_paused = true)]
/// # async fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let bus = VirtualBus::new();
/// let monitor = bus.attach();
/// let core = master::Master::new(NodeId::new(1).unwrap(), Some(Duration::from_millis(100)));
/// let (m, driver) = Master::new(bus.attach(), core);
/// let driver = tokio::spawn(driver.run());
/// m.start().await?; // boot-up message of node 1
/// let node = NodeId::new(0x20).expect("1 to 127");
/// m.nmt(NmtCommand::Start, NmtTarget::Node(node)).await?;
/// tokio::time::sleep(Duration::from_millis(150)).await; // one heartbeat
/// let seen: Vec<String> = std::iter::from_fn(|| monitor.try_recv())
///     .map(|f| f.to_string())
///     .collect();
/// assert_eq!(seen, ["701#00", "000#0120", "701#7F"]);
/// // Typed SDO calls: m.read::<SomeEntry>(node).await?, m.write::<SomeEntry>(node, value).await?
/// drop(m); // the driver sends what is left and ends
/// driver.await.unwrap()?;
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct Master {
    shared: Arc<Shared>,
}

/// What the handles and the driver share.
#[derive(Debug)]
struct Shared {
    state: Mutex<State>,
    /// Wakes the driver: new frames to send, a timer to rearm, or the last
    /// handle gone.
    wake: Notify,
    /// Signalled after every round of frames the driver sent (and when it
    /// stops).
    flushed: Notify,
    /// Signalled after every frame the driver received: a streamed
    /// transfer feeds its source or drains its sink then.
    received: Notify,
    /// LSS requests take turns.
    lss_turn: Arc<::tokio::sync::Mutex<()>>,
    clock: Clock,
}

/// An SDO call waiting for its transfer to end.
#[derive(Debug)]
struct SdoWaiter {
    id: u64,
    object: crate::blocking::Object,
    reply: oneshot::Sender<Result<Upload, Error>>,
}

/// The state behind the lock (never held across an `await`).
#[derive(Debug)]
struct State {
    core: master::Master,
    sdo: BTreeMap<NodeId, SdoWaiter>,
    lss: Option<(u64, oneshot::Sender<LssEvent>)>,
    /// SDO transfers with one node take turns.
    turns: BTreeMap<NodeId, Arc<::tokio::sync::Mutex<()>>>,
    events: Vec<Arc<Queue<MasterEvent>>>,
    pdos: Vec<(CanId, Arc<Queue<PdoEvent>>)>,
    notes: VecDeque<(NodeId, LengthNote)>,
    unobserved: u64,
    handles: usize,
    next_id: u64,
    /// Rounds in which the driver took frames from the cores.
    collected: u64,
    /// The last of those rounds whose frames are all sent.
    sent: u64,
    /// Why the driver stopped, once it did.
    stopped: Option<String>,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        // A panic elsewhere cannot leave the cores half-updated in a way
        // that matters more than stopping would: keep going.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn now(&self) -> Instant {
        self.clock.now()
    }

    /// Marks the driver stopped for `reason`: pending calls fail, streams
    /// end, NMT callers waiting for room wake.
    fn stop(&self, reason: String) {
        let mut state = self.lock();
        if state.stopped.is_none() {
            state.stopped = Some(reason);
        }
        for (_, waiter) in core::mem::take(&mut state.sdo) {
            let _ = waiter.reply.send(Err(state.stopped_error()));
        }
        // The LSS caller sees its sender dropped.
        state.lss = None;
        for queue in state.events.drain(..) {
            queue.close();
        }
        for (_, queue) in state.pdos.drain(..) {
            queue.close();
        }
        drop(state);
        self.flushed.notify_waiters();
    }
}

impl State {
    /// The error of a call made after the driver stopped.
    fn stopped_error(&self) -> Error {
        let reason = self.stopped.as_deref().unwrap_or("it had not stopped");
        Error::DriverStopped {
            reason: reason.to_string(),
        }
    }

    /// `Err` once the driver stopped.
    fn running(&self) -> Result<(), Error> {
        match self.stopped {
            Some(_) => Err(self.stopped_error()),
            None => Ok(()),
        }
    }

    fn next_id(&mut self) -> u64 {
        self.next_id = self.next_id.wrapping_add(1);
        self.next_id
    }

    /// Hands every event of the cores to its waiter or its streams.
    fn pump(&mut self) {
        while let Some(event) = self.core.poll_event() {
            self.route(event);
        }
    }

    fn route(&mut self, event: MasterEvent) {
        match event {
            MasterEvent::Sdo(node, e) => {
                let end = self
                    .sdo
                    .get(&node)
                    .map(|w| transfer_end(e.clone(), w.object));
                if let Some(core::ops::ControlFlow::Break(result)) = end {
                    if let Some(waiter) = self.sdo.remove(&node) {
                        // A caller gone in the meantime no longer cares.
                        let _ = waiter.reply.send(result);
                    }
                    return;
                }
                self.publish(MasterEvent::Sdo(node, e));
            }
            MasterEvent::Lss(e) => match self.lss.take() {
                Some((_, reply)) => {
                    if let Err(e) = reply.send(e) {
                        self.publish(MasterEvent::Lss(e));
                    }
                }
                None => self.publish(MasterEvent::Lss(e)),
            },
            MasterEvent::Pdo(e) => {
                if !matches!(e, PdoEvent::Timeout { .. }) {
                    self.pdos.retain(|(_, q)| Arc::strong_count(q) > 1);
                    for (_, queue) in self.pdos.iter().filter(|(id, _)| *id == e.can_id()) {
                        queue.push(e);
                    }
                }
                self.publish(MasterEvent::Pdo(e));
            }
            other => self.publish(other),
        }
    }

    /// Queues `event` on every [`Events`] stream still held.
    fn publish(&mut self, event: MasterEvent) {
        self.events.retain(|q| Arc::strong_count(q) > 1);
        match self.events.split_last() {
            None => self.unobserved = self.unobserved.saturating_add(1),
            Some((last, others)) => {
                for queue in others {
                    queue.push(event.clone());
                }
                last.push(event);
            }
        }
    }
}

impl Master {
    /// A handle and the driver that runs `core` on `bus`; the cores' clock
    /// starts at tokio's now (the paused clock in tests). Run the driver
    /// (`tokio::spawn(driver.run())`) for anything to happen.
    pub fn new<B: AsyncBus>(bus: B, core: master::Master) -> (Master, Driver<B>) {
        Master::with_clock(bus, core, super::clock())
    }

    /// [`Master::new`] with the cores seeing time through `clock`.
    pub fn with_clock<B: AsyncBus>(
        bus: B,
        core: master::Master,
        clock: Clock,
    ) -> (Master, Driver<B>) {
        let shared = Arc::new(Shared {
            state: Mutex::new(State {
                core,
                sdo: BTreeMap::new(),
                lss: None,
                turns: BTreeMap::new(),
                events: Vec::new(),
                pdos: Vec::new(),
                notes: VecDeque::new(),
                unobserved: 0,
                handles: 1,
                next_id: 0,
                collected: 0,
                sent: 0,
                stopped: None,
            }),
            wake: Notify::new(),
            flushed: Notify::new(),
            received: Notify::new(),
            lss_turn: Arc::new(::tokio::sync::Mutex::new(())),
            clock,
        });
        let driver = Driver::new(bus, Arc::clone(&shared));
        (Master { shared }, driver)
    }

    /// The clock of the cores.
    pub fn clock(&self) -> &Clock {
        &self.shared.clock
    }

    /// The current time of the cores (tokio's clock).
    pub fn now(&self) -> Instant {
        self.shared.now()
    }

    /// Runs `f` on the sans-IO core (to configure its cores: heartbeat
    /// consumer, PDOs, SYNC, SDO clients; or to read their state), then
    /// wakes the driver. Keep `f` short: the driver waits meanwhile; and
    /// do not call this master from `f` (its lock is held: a deadlock).
    pub fn with_core<T>(&self, f: impl FnOnce(&mut master::Master) -> T) -> T {
        let value = f(&mut self.shared.lock().core);
        self.shared.wake.notify_one();
        value
    }

    /// Whether the driver has not stopped (it may not have started).
    pub fn is_running(&self) -> bool {
        self.shared.lock().stopped.is_none()
    }

    /// Starts the core ([`master::Master::start`]) and returns once the
    /// driver sent its boot-up message. Fails once the driver stopped.
    pub async fn start(&self) -> Result<(), Error> {
        let round = {
            let mut state = self.shared.lock();
            state.running()?;
            let now = self.shared.now();
            state.core.start(now);
            state.collected + 1
        };
        self.shared.wake.notify_one();
        self.sent(round).await
    }

    /// Boots `plan`'s network ([`master::Master::boot_network`]: every
    /// slave at once, CiA 302-2) and returns once the boot is decided. The
    /// boot's events are published on the [`Events`] streams as any
    /// others; the master supervises the network from then on. Fails once
    /// the driver stopped.
    pub async fn boot_network(&self, plan: NetworkPlan) -> Result<NetworkReport, Error> {
        let mut events = self.events();
        {
            let mut state = self.shared.lock();
            state.running()?;
            let now = self.shared.now();
            state.core.boot_network(now, plan);
        }
        self.shared.wake.notify_one();
        loop {
            match events.next().await {
                Some(MasterEvent::Network(e)) if ends_boot(&e) => break,
                Some(_) => {}
                None => return Err(self.shared.lock().stopped_error()),
            }
        }
        let state = self.shared.lock();
        match state.core.network().and_then(NetworkBoot::report) {
            Some(report) => Ok(report),
            None => Err(state.stopped_error()),
        }
    }

    /// Returns once the driver sent every frame the cores have ready now.
    pub async fn flush(&self) -> Result<(), Error> {
        let round = self.shared.lock().collected + 1;
        self.shared.wake.notify_one();
        self.sent(round).await
    }

    /// Waits until the frames of collection round `round` are sent.
    async fn sent(&self, round: u64) -> Result<(), Error> {
        loop {
            let flushed = self.shared.flushed.notified();
            let mut flushed = core::pin::pin!(flushed);
            flushed.as_mut().enable();
            {
                let state = self.shared.lock();
                if state.sent >= round {
                    return Ok(());
                }
                state.running()?;
            }
            flushed.await;
        }
    }

    /// Sends NMT `cmd` to `target` (one node, [`NmtTarget::Node`], or
    /// spelled out, every node, [`NmtTarget::All`]) and returns once the
    /// driver sent it. When the NMT queue is full, waits for the driver to
    /// send the queued frames first, then tries once more
    /// ([`Error::NmtQueueFull`] when it is still full).
    pub async fn nmt(&self, cmd: NmtCommand, target: impl Into<NmtTarget>) -> Result<(), Error> {
        let target = target.into();
        let mut tries = 0;
        loop {
            let (queued, round) = {
                let mut state = self.shared.lock();
                state.running()?;
                (state.core.nmt.send(cmd, target), state.collected + 1)
            };
            self.shared.wake.notify_one();
            self.sent(round).await?;
            match queued {
                Ok(()) => return Ok(()),
                Err(_) if tries > 0 => return Err(Error::NmtQueueFull),
                Err(_) => tries += 1,
            }
        }
    }

    /// A new stream of the events no call waits for, from now on, keeping
    /// at most [`MASTER_QUEUE_CAPACITY`] (see [`Events`]).
    pub fn events(&self) -> Events {
        self.events_with_capacity(MASTER_QUEUE_CAPACITY)
    }

    /// [`Master::events`] keeping at most `capacity` events (at least 1).
    pub fn events_with_capacity(&self, capacity: usize) -> Events {
        let queue = Arc::new(Queue::new(capacity));
        let mut state = self.shared.lock();
        if state.stopped.is_some() {
            queue.close();
        } else {
            state.events.push(Arc::clone(&queue));
        }
        Events { queue }
    }

    /// Events that came while no [`Events`] stream existed (they went
    /// nowhere).
    pub fn unobserved_events(&self) -> u64 {
        self.shared.lock().unobserved
    }

    /// A stream of the generated PDO `P` as `node` sends it, on `P`'s
    /// default COB-ID (see [`Pdos`]). The PDO receiver watches it with
    /// length [`od::Pdo::LEN`] unless it already watches that COB-ID (then
    /// its settings stay).
    pub fn pdos<P: od::Pdo>(&self, node: NodeId) -> Result<Pdos<P>, Error> {
        let cob_id = crate::pdo::default_cob_id::<P>(node)?;
        self.pdos_on::<P>(cob_id)
    }

    /// [`Master::pdos`] on the COB-ID entry `cob_id` (bit 30 ignored).
    pub fn pdos_on<P: od::Pdo>(&self, cob_id: PdoCobId) -> Result<Pdos<P>, Error> {
        let id = cob_id.checked_can_id().map_err(WatchError::from)?;
        let queue = Arc::new(Queue::new(PDO_QUEUE_CAPACITY));
        let mut state = self.shared.lock();
        if !state.core.pdo_rx.is_watched(id) {
            state.core.pdo_rx.watch(cob_id, P::LEN, None)?;
        }
        if state.stopped.is_some() {
            queue.close();
        } else {
            state.pdos.push((id, Arc::clone(&queue)));
        }
        drop(state);
        self.shared.wake.notify_one();
        Ok(Pdos {
            can_id: id,
            queue,
            pdo: PhantomData,
        })
    }

    /// The notes typed reads left since the last call, with the node (see
    /// [`crate::blocking::Master::take_length_notes`]).
    pub fn take_length_notes(&self) -> Vec<(NodeId, LengthNote)> {
        self.shared.lock().notes.drain(..).collect()
    }
}

impl Clone for Master {
    /// Another handle to the same master and driver.
    fn clone(&self) -> Master {
        self.shared.lock().handles += 1;
        Master {
            shared: Arc::clone(&self.shared),
        }
    }
}

impl Drop for Master {
    /// The last handle gone ends the driver (after it sent what the cores
    /// had ready).
    fn drop(&mut self) {
        let mut state = self.shared.lock();
        state.handles = state.handles.saturating_sub(1);
        let last = state.handles == 0;
        drop(state);
        if last {
            self.shared.wake.notify_one();
        }
    }
}

/// The reason recorded when the driver ends because every handle is gone.
fn handles_gone() -> String {
    "every Master handle was dropped".to_string()
}
