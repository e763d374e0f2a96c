//! Tests of the tokio free functions: timers, deadlines and shutdown.

use core::time::Duration;

use super::*;
use crate::transport::virtual_bus::VirtualBus;
use crate::{CanId, Frame};

/// A test core: reports frames with id 0x200 and a tick every 10 ms.
struct Ticker {
    next: Instant,
    events: Vec<Result<Frame, Instant>>,
}

impl Service for Ticker {
    type Event = Result<Frame, Instant>;
    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        if frame.standard_id() == Some(0x200) {
            self.events.push(Ok(*frame));
        }
    }
    fn handle_timeout(&mut self, now: Instant) {
        self.events.push(Err(now));
        self.next = now + Duration::from_millis(10);
    }
    fn poll_transmit(&mut self) -> Option<Frame> {
        None
    }
    fn poll_event(&mut self) -> Option<Self::Event> {
        (!self.events.is_empty()).then(|| self.events.remove(0))
    }
    fn poll_timeout(&self) -> Option<Instant> {
        Some(self.next)
    }
}

fn ticker() -> Ticker {
    Ticker {
        next: Instant::from_millis(10),
        events: Vec::new(),
    }
}

#[::tokio::test(start_paused = true)]
async fn run_runs_timers_until_the_deadline() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let clock = clock();
    let mut core = ticker();
    let mut ticks = Vec::new();
    let start = ::tokio::time::Instant::now();
    let result = run(
        &mut port,
        &clock,
        &mut core,
        start + Duration::from_millis(55),
        |event| {
            if let Err(at) = event {
                ticks.push(at);
            }
            ControlFlow::<()>::Continue(())
        },
    )
    .await;
    assert!(matches!(result, Err(RunError::Deadline)));
    // Paused time: the ticks come exactly on time.
    let expected: Vec<Instant> = (1..=5).map(|i| Instant::from_millis(10 * i)).collect();
    assert_eq!(ticks, expected);
}

#[::tokio::test(start_paused = true)]
async fn run_and_serve_take_deadlines_in_the_cores_time() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let clock = clock();
    let mut core = ticker();
    let mut ticks = Vec::new();
    let deadline = clock.now() + Duration::from_millis(55);
    let result = run(&mut port, &clock, &mut core, deadline, |event| {
        if let Err(at) = event {
            ticks.push(at);
        }
        ControlFlow::<()>::Continue(())
    })
    .await;
    assert!(matches!(result, Err(RunError::Deadline)));
    // Paused time: the deadline is met exactly, after five ticks.
    assert_eq!(clock.now(), deadline);
    assert_eq!(ticks.len(), 5);

    let mut seen = 0;
    let deadline = clock.now() + Duration::from_millis(30);
    serve(
        &mut port,
        &clock,
        &mut core,
        core::future::pending(),
        deadline,
        |_| seen += 1,
    )
    .await
    .unwrap();
    assert_eq!(clock.now(), deadline);
    // Ticks at 60, 70 and 80 ms.
    assert_eq!(seen, 3);
    // No deadline and a shutdown that has come: returns at once.
    serve(
        &mut port,
        &clock,
        &mut core,
        async {},
        Deadline::NEVER,
        |_| {},
    )
    .await
    .unwrap();
    assert_eq!(clock.now(), deadline);
}

#[::tokio::test(start_paused = true)]
async fn run_breaks_on_a_frame_and_serve_stops_on_shutdown() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let peer = bus.attach();
    let clock = clock();
    let mut core = ticker();
    peer.transmit(&Frame::new(CanId::Standard(0x200), &[1]).unwrap());
    let got = run(
        &mut port,
        &clock,
        &mut core,
        ::tokio::time::Instant::now() + Duration::from_secs(1),
        |event| match event {
            Ok(frame) => ControlFlow::Break(frame),
            Err(_) => ControlFlow::Continue(()),
        },
    )
    .await
    .unwrap();
    assert_eq!(got.data(), [1]);

    let mut seen = 0;
    let shutdown = ::tokio::time::sleep(Duration::from_millis(35));
    serve(&mut port, &clock, &mut core, shutdown, None, |_| seen += 1)
        .await
        .unwrap();
    // Ticks at 10, 20 and 30 ms.
    assert_eq!(seen, 3);
}
