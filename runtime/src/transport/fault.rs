//! Fault injection: a link that loses, duplicates, delays and reorders
//! frames, and damages the fields of SDO frames that the protocol is meant to
//! check (toggle bits, block sequence numbers, block CRCs), or replaces a
//! frame by an abort. Everything it does follows from a seed, so a failing
//! scenario is replayed by its seed.
//!
//! [`FaultInjector`] is sans-IO and runs on the caller's (virtual) clock,
//! which makes thousands of scenarios a second possible; [`FaultyBus`] wraps
//! any blocking [`Bus`] with it in real time.

use core::cmp::Ordering;
use core::time::Duration;
use std::collections::BinaryHeap;
use std::io;

use super::Bus;
use super::clock::Clock;
use crate::sdo::AbortCode;
use crate::{Frame, Instant};

/// Probabilities (0.0 to 1.0) of each fault, drawn independently per frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Faults {
    pub drop: f64,
    pub duplicate: f64,
    /// Delay a frame by up to `max_delay`, keeping the order of the link.
    pub delay: f64,
    /// Delay a frame by up to `max_delay`, letting later frames overtake it.
    pub reorder: f64,
    pub max_delay: Duration,
    /// Flip bit 4 of the first byte of SDO frames that start below 0x80:
    /// the toggle bit of segments (an unused bit of initiate frames).
    pub flip_toggle: f64,
    /// Give SDO frames that start with 0x01 to 0x7F another first byte in
    /// that range: in a block transfer these are the segments before the
    /// last, so this is a wrong sequence number. On links that carry
    /// expedited or segmented transfers it rewrites commands; use it only
    /// where block transfers run.
    pub corrupt_sequence: f64,
    /// Damage the CRC of an SDO block end frame.
    pub corrupt_crc: f64,
    /// Replace an SDO frame by an abort with a random CiA 301 code.
    pub inject_abort: f64,
}

impl Faults {
    /// No faults: the link delivers every frame at once, in order.
    pub const NONE: Faults = Faults {
        drop: 0.0,
        duplicate: 0.0,
        delay: 0.0,
        reorder: 0.0,
        max_delay: Duration::ZERO,
        flip_toggle: 0.0,
        corrupt_sequence: 0.0,
        corrupt_crc: 0.0,
        inject_abort: 0.0,
    };
}

/// What the injector did, counted over its lifetime.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FaultCounts {
    pub frames: u64,
    pub dropped: u64,
    pub duplicated: u64,
    pub delayed: u64,
    pub reordered: u64,
    pub toggles_flipped: u64,
    pub sequences_corrupted: u64,
    pub crcs_corrupted: u64,
    pub aborts_injected: u64,
    /// Frames lost because `capacity` frames were already in flight.
    pub overflowed: u64,
}

#[derive(Debug)]
struct Pending {
    at: Instant,
    order: u64,
    frame: Frame,
}

impl PartialEq for Pending {
    fn eq(&self, other: &Self) -> bool {
        (self.at, self.order) == (other.at, other.order)
    }
}
impl Eq for Pending {}
impl PartialOrd for Pending {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Pending {
    /// Reversed, so that the max-heap yields the earliest frame first.
    fn cmp(&self, other: &Self) -> Ordering {
        (other.at, other.order).cmp(&(self.at, self.order))
    }
}

/// A one-way link with faults, on the caller's clock.
#[derive(Debug)]
pub struct FaultInjector {
    rng: fastrand::Rng,
    faults: Faults,
    in_flight: BinaryHeap<Pending>,
    capacity: usize,
    next_order: u64,
    /// Delivery time of the last in-order frame (delays keep the order).
    last_in_order: Instant,
    counts: FaultCounts,
}

/// Whether a frame is on an SDO identifier (0x581..=0x67F).
fn is_sdo(frame: &Frame) -> bool {
    matches!(frame.standard_id(), Some(0x581..=0x67F)) && frame.len() == 8 && !frame.is_remote()
}

impl FaultInjector {
    /// At most `capacity` frames are in flight; more are lost (and counted).
    pub fn new(seed: u64, faults: Faults, capacity: usize) -> FaultInjector {
        FaultInjector {
            rng: fastrand::Rng::with_seed(seed),
            faults,
            in_flight: BinaryHeap::new(),
            capacity,
            next_order: 0,
            last_in_order: Instant::ZERO,
            counts: FaultCounts::default(),
        }
    }

    pub fn counts(&self) -> FaultCounts {
        self.counts
    }

    /// Frames sent but not yet delivered.
    pub fn in_flight(&self) -> usize {
        self.in_flight.len()
    }

    fn chance(&mut self, p: f64) -> bool {
        p > 0.0 && self.rng.f64() < p
    }

    fn random_delay(&mut self) -> Duration {
        let max = u64::try_from(self.faults.max_delay.as_micros()).unwrap_or(u64::MAX);
        Duration::from_micros(self.rng.u64(0..=max))
    }

    /// Damages the checked fields of an SDO frame, as the fault rates say.
    fn damage(&mut self, frame: Frame) -> Frame {
        if !is_sdo(&frame) {
            return frame;
        }
        let mut d = *frame.data_padded();
        if self.chance(self.faults.inject_abort) {
            self.counts.aborts_injected += 1;
            let codes = AbortCode::ALL;
            let code = codes[self.rng.usize(0..codes.len())];
            d[0] = 0x80;
            d[4..8].copy_from_slice(&code.code().to_le_bytes());
        } else {
            // Below 0x80 bit 4 is the toggle of segments and their
            // requests/responses, an unused bit of initiate frames, or bit 4
            // of a block segment's sequence number; at and above 0x80 it
            // would change the meaning of block and abort frames.
            if d[0] < 0x80 && self.chance(self.faults.flip_toggle) {
                self.counts.toggles_flipped += 1;
                d[0] ^= 0x10;
            }
            // In a block transfer every frame that starts below 0x80 is a
            // segment (not the last); the other frames start at 0x80 or above.
            if (1..0x80).contains(&d[0]) && self.chance(self.faults.corrupt_sequence) {
                self.counts.sequences_corrupted += 1;
                let old = d[0];
                let mut new = self.rng.u8(1..=127);
                if new == old {
                    new = if old == 127 { 1 } else { old + 1 };
                }
                d[0] = new;
            }
            // Block end frames: client's 0xC1-family request, server's 0xC1 response.
            if d[0] & 0xE1 == 0xC1 && self.chance(self.faults.corrupt_crc) {
                self.counts.crcs_corrupted += 1;
                let flip = self.rng.u16(1..=u16::MAX).to_le_bytes();
                d[1] ^= flip[0];
                d[2] ^= flip[1];
            }
        }
        let id = frame.standard_id().unwrap_or(0);
        Frame::standard(id, d, 8)
    }

    fn schedule(&mut self, at: Instant, frame: Frame) {
        if self.in_flight.len() >= self.capacity {
            self.counts.overflowed += 1;
            return;
        }
        self.next_order += 1;
        self.in_flight.push(Pending {
            at,
            order: self.next_order,
            frame,
        });
    }

    /// A frame enters the link at `now`.
    pub fn send(&mut self, now: Instant, frame: Frame) {
        self.counts.frames += 1;
        if self.chance(self.faults.drop) {
            self.counts.dropped += 1;
            return;
        }
        let frame = self.damage(frame);
        let copies = if self.chance(self.faults.duplicate) {
            self.counts.duplicated += 1;
            2
        } else {
            1
        };
        for _ in 0..copies {
            let at = if self.chance(self.faults.reorder) {
                self.counts.reordered += 1;
                now + self.random_delay()
            } else {
                let mut at = now.max(self.last_in_order);
                if self.chance(self.faults.delay) {
                    self.counts.delayed += 1;
                    at += self.random_delay();
                }
                self.last_in_order = at;
                at
            };
            self.schedule(at, frame);
        }
    }

    /// When the next frame is due.
    pub fn next_delivery(&self) -> Option<Instant> {
        self.in_flight.peek().map(|p| p.at)
    }

    /// The next frame due at or before `now`.
    pub fn deliver(&mut self, now: Instant) -> Option<Frame> {
        if self.next_delivery()? <= now {
            self.in_flight.pop().map(|p| p.frame)
        } else {
            None
        }
    }
}

/// A blocking bus whose outgoing and incoming frames pass through fault
/// injectors, in real time.
pub struct FaultyBus<B> {
    inner: B,
    clock: Clock,
    outgoing: FaultInjector,
    incoming: FaultInjector,
}

impl<B: Bus> FaultyBus<B> {
    /// Both directions get `faults`; the incoming one a seed derived from `seed`.
    pub fn new(inner: B, seed: u64, faults: Faults) -> FaultyBus<B> {
        FaultyBus {
            inner,
            clock: Clock::new(),
            outgoing: FaultInjector::new(seed, faults.clone(), 4096),
            incoming: FaultInjector::new(seed ^ 0x9E37_79B9_7F4A_7C15, faults, 4096),
        }
    }

    pub fn counts(&self) -> (FaultCounts, FaultCounts) {
        (self.outgoing.counts(), self.incoming.counts())
    }

    pub fn into_inner(self) -> B {
        self.inner
    }

    fn flush_outgoing(&mut self) -> io::Result<()> {
        let now = self.clock.now();
        while let Some(frame) = self.outgoing.deliver(now) {
            self.inner.send(&frame)?;
        }
        Ok(())
    }
}

impl<B: Bus> Bus for FaultyBus<B> {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        let now = self.clock.now();
        self.outgoing.send(now, *frame);
        self.flush_outgoing()
    }

    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        let end = self.clock.now() + timeout;
        loop {
            self.flush_outgoing()?;
            let now = self.clock.now();
            if let Some(frame) = self.incoming.deliver(now) {
                return Ok(Some(frame));
            }
            if now >= end {
                return Ok(None);
            }
            // Wait for the inner bus, but not past the next delayed frame.
            let mut until = end;
            for due in [self.incoming.next_delivery(), self.outgoing.next_delivery()]
                .into_iter()
                .flatten()
            {
                until = until.min(due);
            }
            let wait = until
                .saturating_duration_since(now)
                .max(Duration::from_micros(100));
            if let Some(frame) = self.inner.recv(wait)? {
                let now = self.clock.now();
                self.incoming.send(now, frame);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sdo(byte0: u8) -> Frame {
        Frame::standard(0x605, [byte0, 0x00, 0x20, 0x01, 1, 2, 3, 4], 8)
    }

    #[test]
    fn clean_link_delivers_in_order_at_once() {
        let mut link = FaultInjector::new(1, Faults::NONE, 16);
        let now = Instant::from_millis(5);
        for b in 0..5u8 {
            link.send(now, sdo(b));
        }
        let got: Vec<u8> = core::iter::from_fn(|| link.deliver(now))
            .map(|f| f.data()[0])
            .collect();
        assert_eq!(got, [0, 1, 2, 3, 4]);
    }

    #[test]
    fn same_seed_same_faults() {
        let faults = Faults {
            drop: 0.2,
            duplicate: 0.2,
            reorder: 0.2,
            max_delay: Duration::from_millis(3),
            flip_toggle: 0.2,
            corrupt_crc: 0.5,
            inject_abort: 0.1,
            ..Faults::NONE
        };
        let run = |seed| {
            let mut link = FaultInjector::new(seed, faults.clone(), 1024);
            let mut out = Vec::new();
            for i in 0..200u64 {
                let now = Instant::from_micros(i * 100);
                link.send(now, sdo(0xC1 | (i as u8 & 0x1C)));
                while let Some(f) = link.deliver(now) {
                    out.push(f);
                }
            }
            (out, link.counts())
        };
        assert_eq!(run(7), run(7));
        assert_ne!(run(7).0, run(8).0);
        let counts = run(7).1;
        assert!(counts.dropped > 0 && counts.duplicated > 0 && counts.crcs_corrupted > 0);
    }

    #[test]
    fn capacity_bounds_the_frames_in_flight() {
        let faults = Faults {
            delay: 1.0,
            max_delay: Duration::from_secs(10),
            ..Faults::NONE
        };
        let mut link = FaultInjector::new(3, faults, 8);
        for _ in 0..100 {
            link.send(Instant::ZERO, sdo(0));
        }
        assert_eq!(link.in_flight(), 8);
        assert_eq!(link.counts().overflowed, 92);
    }

    #[test]
    fn non_sdo_frames_are_never_damaged() {
        let faults = Faults {
            flip_toggle: 1.0,
            corrupt_sequence: 1.0,
            inject_abort: 1.0,
            ..Faults::NONE
        };
        let mut link = FaultInjector::new(3, faults, 8);
        let hb = Frame::standard(0x705, [5, 0, 0, 0, 0, 0, 0, 0], 1);
        link.send(Instant::ZERO, hb);
        assert_eq!(link.deliver(Instant::ZERO), Some(hb));
    }
}
