//! A simulation behind a master's own bus, on the master's thread: what
//! the master sends goes into the simulated service, what the service
//! sends comes back, and the service's timers run on the master's clock.
//! No threads, no second port; with a [`ManualClock`] it runs in virtual
//! time, as fast as the CPU goes.
//!
//! On a manual clock a blocking driver asks for frames without waiting
//! and, when none is there, jumps the clock to the end of its wait. A
//! simulated node's timer (a heartbeat, a late boot-up) may fall before
//! that end, so the bus never leaves the driver without a frame: it moves
//! the clock itself to the service's next timer, but at most one
//! [`InlineBus::step`] at a time, and hands out the service's frames, or
//! a [`TICK`] when there are none. Times are exact to one step: the
//! driver's own timers run at the first step at or after they are due.

use std::collections::VecDeque;
use std::io;
use std::time::Duration;

use eds2rust_runtime::transport::virtual_bus::VirtualPort;
use eds2rust_runtime::transport::{Bus, Clock, ManualClock};
use eds2rust_runtime::{CanId, Frame, Instant, Service};

/// The frame a [`InlineBus`] on a manual clock hands out when the time
/// moved and the service sent nothing: a remote frame of length 0 on the
/// highest 29-bit identifier, which no CANopen service uses. Only the
/// master sees it (it is not in the trace).
pub const TICK: Frame = Frame::with_id(CanId::Extended(0x1FFF_FFFF), [0; 8], 0);

/// The most timer rounds of the service at one instant (a timer that
/// never moves on would otherwise hang the master).
const MAX_ROUNDS: usize = 10_000;

/// The time the service runs on.
#[derive(Debug, Clone)]
enum Time {
    /// A real clock: waits sleep.
    Real(Clock),
    /// Virtual time the bus moves.
    Manual(ManualClock),
}

/// A bus for a master with `S` behind it (see the module documentation).
#[derive(Debug)]
pub struct InlineBus<S: Service> {
    service: S,
    time: Time,
    step: Duration,
    /// Frames of the service not yet received by the master.
    inbox: VecDeque<Frame>,
    events: Vec<S::Event>,
    trace: Option<Vec<(Instant, Frame)>>,
    mirror: Option<VirtualPort>,
}

impl<S: Service> InlineBus<S> {
    /// `service` on the real time of `clock` (give the master the same
    /// clock).
    pub fn new(service: S, clock: Clock) -> InlineBus<S> {
        InlineBus::with_time(service, Time::Real(clock))
    }

    /// `service` in virtual time: give the master `time.clock()`
    /// (`blocking::Master::with_clock`).
    pub fn manual(service: S, time: ManualClock) -> InlineBus<S> {
        InlineBus::with_time(service, Time::Manual(time))
    }

    fn with_time(service: S, time: Time) -> InlineBus<S> {
        let mut bus = InlineBus {
            service,
            time,
            step: Duration::from_millis(1),
            inbox: VecDeque::new(),
            events: Vec::new(),
            trace: None,
            mirror: None,
        };
        let now = bus.now();
        bus.collect(now);
        bus
    }

    /// The longest a manual clock moves at once (1 ms by default).
    pub fn with_step(mut self, step: Duration) -> InlineBus<S> {
        self.step = step.max(Duration::from_micros(1));
        self
    }

    /// Records every frame on the bus (both ways) with its time.
    pub fn with_trace(mut self) -> InlineBus<S> {
        self.trace = Some(Vec::new());
        self
    }

    /// Sends every frame on the bus (both ways) to `port` too, for a
    /// tracer or a monitor on its virtual bus.
    pub fn with_mirror(mut self, port: VirtualPort) -> InlineBus<S> {
        self.mirror = Some(port);
        self
    }

    /// The longest a manual clock moves at once.
    pub fn step(&self) -> Duration {
        self.step
    }

    /// The service.
    pub fn service(&self) -> &S {
        &self.service
    }

    /// The service, to change it between calls of the master.
    pub fn service_mut(&mut self) -> &mut S {
        &mut self.service
    }

    /// The service's events so far, taken.
    pub fn take_events(&mut self) -> Vec<S::Event> {
        std::mem::take(&mut self.events)
    }

    /// The frames on the bus so far with their times (empty without
    /// [`InlineBus::with_trace`]).
    pub fn trace(&self) -> &[(Instant, Frame)] {
        self.trace.as_deref().unwrap_or(&[])
    }

    /// The trace in candump's compact form, one frame a line.
    pub fn trace_lines(&self) -> Vec<String> {
        self.trace().iter().map(|(_, f)| f.to_string()).collect()
    }

    fn now(&self) -> Instant {
        match &self.time {
            Time::Real(clock) => clock.now(),
            Time::Manual(time) => time.now(),
        }
    }

    fn record(&mut self, at: Instant, frame: &Frame) -> io::Result<()> {
        if let Some(trace) = &mut self.trace {
            trace.push((at, *frame));
        }
        if let Some(port) = &mut self.mirror {
            port.send(frame)?;
        }
        Ok(())
    }

    /// Takes the service's frames and events at `at`.
    fn collect(&mut self, at: Instant) {
        while let Some(frame) = self.service.poll_transmit() {
            // A mirror that fails loses a trace line, not the simulation.
            let _ = self.record(at, &frame);
            self.inbox.push_back(frame);
        }
        while let Some(event) = self.service.poll_event() {
            self.events.push(event);
        }
    }

    /// Runs the service's timers due at `now`, each at its own time.
    fn catch_up(&mut self, now: Instant) {
        for _ in 0..MAX_ROUNDS {
            match self.service.poll_timeout() {
                Some(at) if at <= now => {
                    self.service.handle_timeout(at);
                    self.collect(at);
                }
                _ => return,
            }
        }
    }
}

impl<S: Service> Bus for InlineBus<S> {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        let now = self.now();
        self.catch_up(now);
        self.record(now, frame)?;
        self.service.handle_frame(now, frame);
        self.collect(now);
        Ok(())
    }

    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        let now = self.now();
        self.catch_up(now);
        if let Some(frame) = self.inbox.pop_front() {
            return Ok(Some(frame));
        }
        match self.time.clone() {
            Time::Manual(time) => {
                let mut to = now + self.step;
                if let Some(at) = self.service.poll_timeout() {
                    // Time moves on, even past a timer that does not.
                    to = to.min(at.max(now + Duration::from_micros(1)));
                }
                time.advance_to(to);
                self.catch_up(to);
                Ok(Some(self.inbox.pop_front().unwrap_or(TICK)))
            }
            Time::Real(clock) => {
                let end = now + timeout;
                loop {
                    let now = clock.now();
                    self.catch_up(now);
                    if let Some(frame) = self.inbox.pop_front() {
                        return Ok(Some(frame));
                    }
                    if now >= end {
                        return Ok(None);
                    }
                    let wake = self.service.poll_timeout().map_or(end, |at| at.min(end));
                    std::thread::sleep(
                        clock
                            .to_std(wake)
                            .saturating_duration_since(std::time::Instant::now()),
                    );
                }
            }
        }
    }
}
