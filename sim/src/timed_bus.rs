//! One shared CAN bus in virtual time on which every frame takes its time
//! on the wire: a master and any number of simulated devices, each a
//! sans-IO [`Service`], no threads, no sleeping.
//!
//! The model, as a classic CAN bus behaves:
//! - every station (the master, each device) has a transmit queue; what a
//!   station's core has to send joins its queue at once (the cores' own
//!   processing takes no virtual time);
//! - when the bus is idle, the queue heads arbitrate: the lowest
//!   identifier wins (a base-format frame before an extended one with the
//!   same first 11 bits, a data frame before a remote one), and the frame
//!   occupies the bus for its exact length at the bit rate
//!   ([`frame_bits`]: the stuff bits it really gets, and the 3-bit
//!   intermission);
//! - at the end of a frame every other station receives it, at that time;
//!   timers fire at their instants, during a frame too.
//!
//! So frames go one at a time, and a boot that keeps the bus busy takes
//! the sum of its frames' times; gaps are where every station waits.
//! [`TimedBus::trace`] has each frame with its start and end.

use std::collections::VecDeque;
use std::time::Duration;

use eds2rust_runtime::transport::wire::frame_bits;
use eds2rust_runtime::{CanId, Frame, Instant, Service};

/// A device on the bus: any [`Service`]; its events are dropped.
pub trait Station {
    /// See [`Service::handle_frame`].
    fn handle_frame(&mut self, now: Instant, frame: &Frame);
    /// See [`Service::handle_timeout`].
    fn handle_timeout(&mut self, now: Instant);
    /// See [`Service::poll_transmit`].
    fn poll_transmit(&mut self) -> Option<Frame>;
    /// See [`Service::poll_timeout`].
    fn poll_timeout(&self) -> Option<Instant>;
    /// Drops the events it has.
    fn drop_events(&mut self);
}

impl<S: Service> Station for S {
    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        Service::handle_frame(self, now, frame);
    }
    fn handle_timeout(&mut self, now: Instant) {
        Service::handle_timeout(self, now);
    }
    fn poll_transmit(&mut self) -> Option<Frame> {
        Service::poll_transmit(self)
    }
    fn poll_timeout(&self) -> Option<Instant> {
        Service::poll_timeout(self)
    }
    fn drop_events(&mut self) {
        while self.poll_event().is_some() {}
    }
}

/// One frame on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WireFrame {
    /// When its start of frame went out.
    pub start: Instant,
    /// When its intermission ended (the bus is free again).
    pub end: Instant,
    /// Who sent it: 0 the master, `i + 1` the device added `i`th.
    pub sender: usize,
    /// The frame.
    pub frame: Frame,
    /// Its length on the wire, stuff bits and intermission included.
    pub bits: u32,
}

/// Where the [`TimedBus`]'s host time went.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HostTime {
    /// In the master's calls (frames in, timers, frames and events out).
    pub master: Duration,
    /// In the devices' calls.
    pub devices: Duration,
}

/// The master and the devices on one bus (see the module documentation).
pub struct TimedBus<M: Service> {
    bit_rate: u32,
    now: Instant,
    /// The master core.
    pub master: M,
    /// The master's events not yet taken.
    pub master_events: VecDeque<M::Event>,
    devices: Vec<Box<dyn Station>>,
    /// Transmit queues: 0 the master, `i + 1` device `i`.
    queues: Vec<VecDeque<Frame>>,
    on_wire: Option<WireFrame>,
    /// Every frame sent, in order.
    pub trace: Vec<WireFrame>,
    /// Host time spent in the stations' code.
    pub host: HostTime,
}

/// The most timer rounds at one instant before the bus gives up (a core
/// that never clears its timer would otherwise stop time).
const MAX_ROUNDS_PER_INSTANT: usize = 100_000;

impl<M: Service> TimedBus<M> {
    /// An idle bus at `bit_rate` bit/s from `now`, with `master` on it.
    pub fn new(bit_rate: u32, master: M, now: Instant) -> TimedBus<M> {
        assert!(bit_rate > 0, "a bit rate of 0 bit/s");
        TimedBus {
            bit_rate,
            now,
            master,
            master_events: VecDeque::new(),
            devices: Vec::new(),
            queues: vec![VecDeque::new()],
            on_wire: None,
            trace: Vec::new(),
            host: HostTime::default(),
        }
    }

    /// Puts a device on the bus; what it has to send joins its queue.
    pub fn add_device(&mut self, device: Box<dyn Station>) {
        self.devices.push(device);
        self.queues.push(VecDeque::new());
        let i = self.devices.len() - 1;
        self.collect_device(i);
    }

    /// The virtual time.
    pub fn now(&self) -> Instant {
        self.now
    }

    /// The time `bits` take at the bit rate.
    pub fn bit_time(&self, bits: u64) -> Duration {
        Duration::from_nanos(bits * 1_000_000_000 / u64::from(self.bit_rate))
    }

    /// Lets the master act at the current time (after calling its core
    /// from outside): its frames join its queue.
    pub fn master_acted(&mut self) {
        self.collect_master();
    }

    /// Runs until `stop` holds for a master event (which stays queued) or
    /// `limit` passes; returns whether `stop` held.
    pub fn run_until(&mut self, limit: Instant, mut stop: impl FnMut(&M::Event) -> bool) -> bool {
        let mut seen = self.master_events.len();
        if self.master_events.iter().any(&mut stop) {
            return true;
        }
        let mut rounds = 0;
        let mut last = self.now;
        loop {
            if self.master_events.iter().skip(seen).any(&mut stop) {
                return true;
            }
            seen = self.master_events.len();
            if self.on_wire.is_none() {
                self.arbitrate();
            }
            let wire_end = self.on_wire.map(|f| f.end);
            let timer = self.next_timer();
            let Some(next) = [wire_end, timer].into_iter().flatten().min() else {
                self.now = self.now.max(limit);
                return false;
            };
            if next > limit {
                self.now = self.now.max(limit);
                return false;
            }
            self.now = self.now.max(next);
            if self.now == last {
                rounds += 1;
                assert!(
                    rounds < MAX_ROUNDS_PER_INSTANT,
                    "a station's timer does not advance at {:?}",
                    self.now
                );
            } else {
                rounds = 0;
                last = self.now;
            }
            if wire_end.is_some_and(|end| end <= self.now) {
                self.deliver();
            }
            self.fire_timers();
        }
    }

    /// The earliest timer of all stations.
    fn next_timer(&self) -> Option<Instant> {
        let mut at = self.master.poll_timeout();
        for d in &self.devices {
            at = match (at, d.poll_timeout()) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
        }
        at
    }

    /// The queue heads arbitrate; the winner goes on the wire now.
    fn arbitrate(&mut self) {
        let winner = self
            .queues
            .iter()
            .enumerate()
            .filter_map(|(i, q)| q.front().map(|f| (arbitration_key(f), i)))
            .min();
        let Some((_, sender)) = winner else {
            return;
        };
        let Some(frame) = self.queues.get_mut(sender).and_then(VecDeque::pop_front) else {
            return;
        };
        let bits = frame_bits(&frame);
        let end = self.now + self.bit_time(u64::from(bits));
        self.on_wire = Some(WireFrame {
            start: self.now,
            end,
            sender,
            frame,
            bits,
        });
    }

    /// The frame on the wire ends: every other station receives it.
    fn deliver(&mut self) {
        let Some(wire) = self.on_wire.take() else {
            return;
        };
        self.trace.push(wire);
        let now = self.now;
        if wire.sender != 0 {
            let t = std::time::Instant::now();
            self.master.handle_frame(now, &wire.frame);
            self.host.master += t.elapsed();
            self.collect_master();
        }
        let t = std::time::Instant::now();
        for i in 0..self.devices.len() {
            if i + 1 == wire.sender {
                continue;
            }
            if let Some(d) = self.devices.get_mut(i) {
                d.handle_frame(now, &wire.frame);
            }
            self.collect_device(i);
        }
        self.host.devices += t.elapsed();
    }

    /// Fires every timer that is due.
    fn fire_timers(&mut self) {
        let now = self.now;
        if self.master.poll_timeout().is_some_and(|at| at <= now) {
            let t = std::time::Instant::now();
            self.master.handle_timeout(now);
            self.host.master += t.elapsed();
            self.collect_master();
        }
        let t = std::time::Instant::now();
        for i in 0..self.devices.len() {
            let due = self
                .devices
                .get(i)
                .and_then(|d| d.poll_timeout())
                .is_some_and(|at| at <= now);
            if due {
                if let Some(d) = self.devices.get_mut(i) {
                    d.handle_timeout(now);
                }
                self.collect_device(i);
            }
        }
        self.host.devices += t.elapsed();
    }

    /// Takes the master's frames and events. A core may act while handing
    /// out its events (the composite master's network boot does: it takes
    /// the end of its own SDO transfer, reports nothing, and has the
    /// slave's next request ready), so frames are taken again after the
    /// events until there are none.
    fn collect_master(&mut self) {
        let t = std::time::Instant::now();
        loop {
            while let Some(frame) = self.master.poll_transmit() {
                if let Some(q) = self.queues.get_mut(0) {
                    q.push_back(frame);
                }
            }
            while let Some(event) = self.master.poll_event() {
                self.master_events.push_back(event);
            }
            match self.master.poll_transmit() {
                Some(frame) => {
                    if let Some(q) = self.queues.get_mut(0) {
                        q.push_back(frame);
                    }
                }
                None => break,
            }
        }
        self.host.master += t.elapsed();
    }

    /// Takes a device's frames and drops its events (as for the master,
    /// until a round gives no frame).
    fn collect_device(&mut self, i: usize) {
        let (Some(d), Some(q)) = (self.devices.get_mut(i), self.queues.get_mut(i + 1)) else {
            return;
        };
        loop {
            while let Some(frame) = d.poll_transmit() {
                q.push_back(frame);
            }
            d.drop_events();
            match d.poll_transmit() {
                Some(frame) => q.push_back(frame),
                None => break,
            }
        }
    }
}

/// The order of arbitration: identifier bits as they go out (the first
/// 11, then base before extended format, then the extension), data before
/// remote.
fn arbitration_key(frame: &Frame) -> (u32, bool, u32, bool) {
    match frame.id() {
        CanId::Standard(id) => (u32::from(id), false, 0, frame.is_remote()),
        CanId::Extended(id) => (id >> 18, true, id & 0x3_FFFF, frame.is_remote()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A station that sends the frames it is given at its instants.
    struct Sender(Vec<(Instant, Frame)>, VecDeque<Frame>);

    impl Service for Sender {
        type Event = ();
        fn handle_frame(&mut self, _: Instant, _: &Frame) {}
        fn handle_timeout(&mut self, now: Instant) {
            while self.0.first().is_some_and(|(at, _)| *at <= now) {
                let (_, f) = self.0.remove(0);
                self.1.push_back(f);
            }
        }
        fn poll_transmit(&mut self) -> Option<Frame> {
            self.1.pop_front()
        }
        fn poll_event(&mut self) -> Option<()> {
            None
        }
        fn poll_timeout(&self) -> Option<Instant> {
            self.0.first().map(|(at, _)| *at)
        }
    }

    fn frame(id: u16, data: &[u8]) -> Frame {
        Frame::new(CanId::Standard(id), data).unwrap()
    }

    #[test]
    fn frames_take_their_bit_time_one_at_a_time_lowest_id_first() {
        let a = frame(0x601, &[0x40, 0, 0x10, 0, 0, 0, 0, 0]);
        let b = frame(0x581, &[0x43, 0, 0x10, 0, 0x92, 1, 2, 0]);
        let c = frame(0x000, &[0x01, 0x00]);
        let master = Sender(vec![(Instant::ZERO, a)], VecDeque::new());
        let mut bus = TimedBus::new(1_000_000, master, Instant::ZERO);
        // Both devices have a frame ready at 10 µs, while `a` is on the wire.
        let t = Instant::from_micros(10);
        bus.add_device(Box::new(Sender(vec![(t, b)], VecDeque::new())));
        bus.add_device(Box::new(Sender(vec![(t, c)], VecDeque::new())));
        assert!(!bus.run_until(Instant::from_millis(10), |_| false));
        let order: Vec<(Frame, u64, u64)> = bus
            .trace
            .iter()
            .map(|w| (w.frame, w.start.as_micros(), w.end.as_micros()))
            .collect();
        let (ba, bc) = (u64::from(frame_bits(&a)), u64::from(frame_bits(&c)));
        let bb = u64::from(frame_bits(&b));
        // `a` first (alone at 0), then NMT 0x000 before 0x581, back to back.
        assert_eq!(
            order,
            [(a, 0, ba), (c, ba, ba + bc), (b, ba + bc, ba + bc + bb)]
        );
        assert_eq!(bus.bit_time(111), Duration::from_micros(111));
    }
}
