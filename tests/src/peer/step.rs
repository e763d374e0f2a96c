//! Stepping sans-IO cores over a bus, for the interop tests (the runtime's
//! [`run`] does the waiting; [`step`] gives frame-by-frame control).

use std::fmt;
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use eds2rust_runtime::Service;
use eds2rust_runtime::blocking::{RunError, run};
use eds2rust_runtime::transport::{Bus, Clock};

/// Drives a sans-IO core over `bus` for one step: sends what it has
/// queued, waits up to `max_wait` (less when its deadline comes first) for
/// one frame, feeds that frame or the due timeout, sends what it queued in
/// answer, and returns its events.
pub fn step<S: Service>(
    bus: &mut impl Bus,
    clock: &Clock,
    service: &mut S,
    max_wait: Duration,
) -> Result<Vec<S::Event>, String> {
    flush(bus, service)?;
    let now = clock.now();
    let wait = match service.poll_timeout() {
        Some(deadline) => max_wait.min(deadline.saturating_duration_since(now)),
        None => max_wait,
    };
    let received = bus
        .recv(wait)
        .map_err(|e| format!("receiving from the bus: {e}"))?;
    let now = clock.now();
    if let Some(frame) = received {
        service.handle_frame(now, &frame);
    }
    if service
        .poll_timeout()
        .is_some_and(|deadline| deadline <= now)
    {
        service.handle_timeout(now);
    }
    flush(bus, service)?;
    let mut events = Vec::new();
    while let Some(event) = service.poll_event() {
        events.push(event);
    }
    Ok(events)
}

/// Sends every frame `service` has queued.
pub fn flush<S: Service>(bus: &mut impl Bus, service: &mut S) -> Result<(), String> {
    while let Some(frame) = service.poll_transmit() {
        bus.send(&frame)
            .map_err(|e| format!("sending {frame}: {e}"))?;
    }
    Ok(())
}

/// Runs `service` with the runtime's [`run`] until `pick` accepts one of
/// its events, for at most `timeout`; the error names the events seen.
pub fn run_until<S: Service, T>(
    bus: &mut impl Bus,
    clock: &Clock,
    service: &mut S,
    timeout: Duration,
    mut pick: impl FnMut(S::Event) -> Option<T>,
) -> Result<T, String>
where
    S::Event: fmt::Debug,
{
    let mut seen = Vec::new();
    let until = |event: S::Event| {
        let text = format!("{event:?}");
        match pick(event) {
            Some(found) => ControlFlow::Break(found),
            None => {
                if seen.len() < 32 {
                    seen.push(text);
                }
                ControlFlow::Continue(())
            }
        }
    };
    run(bus, clock, service, Instant::now() + timeout, until).map_err(|e| match e {
        RunError::Deadline => {
            format!("no awaited event within {timeout:?}; events seen: {seen:?}")
        }
        other => format!("{other}; events seen: {seen:?}"),
    })
}
