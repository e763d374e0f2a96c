//! An in-process CAN bus for simulators and tests.
//!
//! Every port attached to a [`VirtualBus`] receives, in send order, every
//! frame that another port sends (CAN is a broadcast medium); a port attached
//! with loopback also receives its own frames. Each port has a bounded
//! receive queue: when it is full, the oldest frame is dropped and counted in
//! [`VirtualPort::overruns`], as a CAN controller overrun would.
//!
//! Ports implement [`Bus`] (blocking receive with a timeout) and, with the
//! feature `tokio`, `AsyncBus`. [`VirtualPort::try_recv`] is the
//! cheap non-blocking receive for single-threaded loops.
//!
//! With [`VirtualBus::with_bit_rate`] the bus also counts every frame's
//! length on the wire ([`super::wire`]) so that [`VirtualBus::stats`] gives
//! the time the bus was busy. Delivery itself is immediate either way.

use core::time::Duration;
use std::collections::VecDeque;
use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::vec::Vec;

use super::Bus;
use super::wire::frame_bits;
use crate::Frame;

/// Receive-queue length of a port unless [`VirtualBus::with_queue_capacity`]
/// says otherwise.
pub const DEFAULT_QUEUE_CAPACITY: usize = 4096;

/// Frames a new receive queue has room for before it grows (up to its
/// capacity).
const INITIAL_QUEUE_ROOM: usize = 64;

/// Traffic counted by a [`VirtualBus`] since it was created.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BusStats {
    /// Frames sent.
    pub frames: u64,
    /// Bits those frames took on the wire, stuff bits and intermission
    /// included (0 without a bit rate).
    pub bits: u64,
    /// `bits` at the bit rate (zero without a bit rate).
    pub busy: Duration,
    /// Data bytes carried (remote frames carry none).
    pub payload_bytes: u64,
}

impl BusStats {
    /// The share of `elapsed` during which the bus was busy (1.0 = 100 %).
    pub fn load(&self, elapsed: Duration) -> f64 {
        if elapsed.is_zero() {
            return 0.0;
        }
        self.busy.as_secs_f64() / elapsed.as_secs_f64()
    }
}

/// A frame queue that drops its oldest frame when full.
#[derive(Debug)]
struct RxQueue {
    frames: VecDeque<Frame>,
    capacity: usize,
    overruns: u64,
    /// Threads blocked in [`Bus::recv`] on this port (they need a notify).
    sleepers: u32,
}

/// One attached port, shared between the bus (which fills its queue) and
/// the [`VirtualPort`] (which drains it).
#[derive(Debug)]
struct PortState {
    id: u64,
    loopback: AtomicBool,
    queue: Mutex<RxQueue>,
    ready: Condvar,
    #[cfg(feature = "tokio")]
    notify: ::tokio::sync::Notify,
}

impl PortState {
    fn queue(&self) -> MutexGuard<'_, RxQueue> {
        // A panic in another thread cannot leave a queue half-updated (every
        // update is a single push or pop), so a poisoned lock is still good.
        self.queue.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn deliver(&self, frame: Frame) {
        let mut queue = self.queue();
        if queue.frames.len() >= queue.capacity {
            queue.frames.pop_front();
            queue.overruns += 1;
        }
        queue.frames.push_back(frame);
        let wake = queue.sleepers > 0;
        drop(queue);
        if wake {
            self.ready.notify_all();
        }
        #[cfg(feature = "tokio")]
        self.notify.notify_one();
    }
}

/// What the bus shares between its handles and its ports.
#[derive(Debug)]
struct Registry {
    ports: Vec<Arc<PortState>>,
    next_id: u64,
    queue_capacity: usize,
    stats: BusStats,
}

#[derive(Debug)]
struct Shared {
    bit_rate: Option<u32>,
    registry: Mutex<Registry>,
}

impl Shared {
    fn registry(&self) -> MutexGuard<'_, Registry> {
        self.registry.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// An in-process CAN bus. Cloning gives another handle to the same bus.
#[derive(Debug, Clone)]
pub struct VirtualBus {
    shared: Arc<Shared>,
}

impl VirtualBus {
    /// A bus without bit-time model: [`BusStats::bits`] and
    /// [`BusStats::busy`] stay zero.
    pub fn new() -> VirtualBus {
        VirtualBus::build(None)
    }

    /// A bus that counts every frame's bits on the wire at `bits_per_second`
    /// (for example 500_000). A rate of 0 counts bits but no busy time.
    pub fn with_bit_rate(bits_per_second: u32) -> VirtualBus {
        VirtualBus::build(Some(bits_per_second))
    }

    fn build(bit_rate: Option<u32>) -> VirtualBus {
        VirtualBus {
            shared: Arc::new(Shared {
                bit_rate,
                registry: Mutex::new(Registry {
                    ports: Vec::new(),
                    next_id: 0,
                    queue_capacity: DEFAULT_QUEUE_CAPACITY,
                    stats: BusStats::default(),
                }),
            }),
        }
    }

    /// Sets the receive-queue length (at least 1) of ports attached from
    /// now on.
    pub fn with_queue_capacity(self, frames: usize) -> VirtualBus {
        self.shared.registry().queue_capacity = frames.max(1);
        self
    }

    /// The bit rate of the bit-time model, if any.
    pub fn bit_rate(&self) -> Option<u32> {
        self.shared.bit_rate
    }

    /// Attaches a new port that does not receive its own frames.
    pub fn attach(&self) -> VirtualPort {
        self.attach_port(false)
    }

    /// Attaches a new port that also receives the frames it sends.
    pub fn attach_with_loopback(&self) -> VirtualPort {
        self.attach_port(true)
    }

    fn attach_port(&self, loopback: bool) -> VirtualPort {
        let mut registry = self.shared.registry();
        let capacity = registry.queue_capacity;
        let state = Arc::new(PortState {
            id: registry.next_id,
            loopback: AtomicBool::new(loopback),
            queue: Mutex::new(RxQueue {
                frames: VecDeque::with_capacity(capacity.min(INITIAL_QUEUE_ROOM)),
                capacity,
                overruns: 0,
                sleepers: 0,
            }),
            ready: Condvar::new(),
            #[cfg(feature = "tokio")]
            notify: ::tokio::sync::Notify::new(),
        });
        registry.next_id += 1;
        registry.ports.push(Arc::clone(&state));
        drop(registry);
        VirtualPort {
            shared: Arc::clone(&self.shared),
            state,
        }
    }

    /// Ports attached now.
    pub fn port_count(&self) -> usize {
        self.shared.registry().ports.len()
    }

    /// Traffic counted so far.
    pub fn stats(&self) -> BusStats {
        self.shared.registry().stats
    }
}

impl Default for VirtualBus {
    /// Same as [`VirtualBus::new`].
    fn default() -> VirtualBus {
        VirtualBus::new()
    }
}

/// A node's connection to a [`VirtualBus`]; dropping it detaches it.
#[derive(Debug)]
pub struct VirtualPort {
    shared: Arc<Shared>,
    state: Arc<PortState>,
}

impl VirtualPort {
    /// Puts `frame` on the bus: every other port (and this one, with
    /// loopback) gets it. Never blocks and never fails.
    pub fn transmit(&self, frame: &Frame) {
        let mut registry = self.shared.registry();
        let stats = &mut registry.stats;
        stats.frames += 1;
        stats.payload_bytes += frame.data().len() as u64;
        if let Some(rate) = self.shared.bit_rate {
            let bits = frame_bits(frame);
            stats.bits += u64::from(bits);
            if rate > 0 {
                stats.busy = busy_time(stats.bits, rate);
            }
        }
        // Delivering under the registry lock keeps every queue in the one
        // global send order.
        for port in &registry.ports {
            if port.id != self.state.id || port.loopback.load(Ordering::Relaxed) {
                port.deliver(*frame);
            }
        }
    }

    /// The next received frame, without waiting.
    pub fn try_recv(&self) -> Option<Frame> {
        self.state.queue().frames.pop_front()
    }

    /// Waits up to `timeout` for the next frame.
    pub fn recv_timeout(&self, timeout: Duration) -> Option<Frame> {
        let mut queue = self.state.queue();
        if let Some(frame) = queue.frames.pop_front() {
            return Some(frame);
        }
        if timeout.is_zero() {
            return None;
        }
        let deadline = std::time::Instant::now().checked_add(timeout);
        queue.sleepers += 1;
        let frame = loop {
            if let Some(frame) = queue.frames.pop_front() {
                break Some(frame);
            }
            let now = std::time::Instant::now();
            let left = match deadline {
                Some(deadline) if deadline <= now => break None,
                Some(deadline) => deadline - now,
                // A timeout beyond the clock's range: wait in long slices.
                None => Duration::from_secs(3600),
            };
            queue = match self.state.ready.wait_timeout(queue, left) {
                Ok((guard, _)) => guard,
                Err(poisoned) => poisoned.into_inner().0,
            };
        };
        queue.sleepers -= 1;
        frame
    }

    /// Frames waiting in the receive queue.
    pub fn pending(&self) -> usize {
        self.state.queue().frames.len()
    }

    /// Frames dropped because the receive queue was full.
    pub fn overruns(&self) -> u64 {
        self.state.queue().overruns
    }

    /// Whether this port receives its own frames.
    pub fn loopback(&self) -> bool {
        self.state.loopback.load(Ordering::Relaxed)
    }

    /// Turns receiving its own frames on or off (for frames sent from now).
    pub fn set_loopback(&self, on: bool) {
        self.state.loopback.store(on, Ordering::Relaxed);
    }

    /// Another handle to the bus this port is attached to.
    pub fn bus(&self) -> VirtualBus {
        VirtualBus {
            shared: Arc::clone(&self.shared),
        }
    }

    /// Waits until the receive queue is not empty (for [`super::AsyncBus`]).
    #[cfg(feature = "tokio")]
    async fn wait_frame(&self) -> Frame {
        loop {
            // Register interest before looking, so that a frame delivered
            // between the look and the wait still wakes this task.
            let notified = self.state.notify.notified();
            let mut notified = core::pin::pin!(notified);
            notified.as_mut().enable();
            if let Some(frame) = self.try_recv() {
                return frame;
            }
            notified.await;
        }
    }
}

impl Drop for VirtualPort {
    fn drop(&mut self) {
        let id = self.state.id;
        self.shared.registry().ports.retain(|port| port.id != id);
    }
}

/// `bits` at `rate` bits per second.
fn busy_time(bits: u64, rate: u32) -> Duration {
    let rate = u64::from(rate);
    let secs = bits / rate;
    let rest = bits % rate;
    // rest < rate <= u32::MAX, so rest * 1e9 fits in u64.
    let nanos = rest * 1_000_000_000 / rate;
    Duration::from_secs(secs) + Duration::from_nanos(nanos)
}

impl Bus for VirtualPort {
    /// Never fails: see [`VirtualPort::transmit`].
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        self.transmit(frame);
        Ok(())
    }

    /// Waits on a condition variable up to `timeout`.
    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        Ok(self.recv_timeout(timeout))
    }
}

/// `recv` is cancel-safe: a frame leaves the queue only in the same poll
/// that returns it.
#[cfg(feature = "tokio")]
impl super::AsyncBus for VirtualPort {
    /// Never fails and never waits: see [`VirtualPort::transmit`].
    fn send(&mut self, frame: &Frame) -> impl Future<Output = io::Result<()>> + Send {
        let frame = *frame;
        async move {
            self.transmit(&frame);
            Ok(())
        }
    }

    /// Waits on a `tokio::sync::Notify` for the next frame.
    async fn recv(&mut self) -> io::Result<Frame> {
        Ok(self.wait_frame().await)
    }
}

#[cfg(test)]
mod tests;
