//! [`Driver`]: the future that runs the composite master's cores on the bus.

use std::io;
use std::string::ToString;
use std::sync::Arc;
use std::vec::Vec;

use super::{Shared, handles_gone};
use crate::transport::AsyncBus;
use crate::{Frame, Service};

/// Runs the cores of a tokio [`super::Master`] on its bus: run
/// [`Driver::run`] on a task of its own (see [`super::Master`] for why
/// the driver is the application's to run).
///
/// Dropping the driver (or its `run` future) stops the master: pending
/// calls fail with [`super::Error::DriverStopped`], the streams end, and
/// later calls fail at once.
#[derive(Debug)]
pub struct Driver<B> {
    bus: B,
    shared: Arc<Shared>,
}

impl<B: AsyncBus> Driver<B> {
    pub(super) fn new(bus: B, shared: Arc<Shared>) -> Driver<B> {
        Driver { bus, shared }
    }

    /// Runs the cores until every [`super::Master`] handle is dropped
    /// (`Ok`, after sending the frames the cores had ready) or the bus
    /// fails (that error). Either way the master is stopped afterwards.
    ///
    /// Each round sends what the cores have ready, hands their events to
    /// the waiting calls and the streams, then waits (`select!`) for a
    /// received frame, the cores' next deadline or a call's wake-up.
    pub async fn run(mut self) -> io::Result<()> {
        let result = self.rounds().await;
        let reason = match &result {
            Ok(()) => handles_gone(),
            Err(e) => std::format!("the bus failed: {e}"),
        };
        self.shared.stop(reason);
        result
    }

    async fn rounds(&mut self) -> io::Result<()> {
        let mut out: Vec<Frame> = Vec::new();
        loop {
            let (timer, last) = {
                let mut state = self.shared.lock();
                let now = self.shared.now();
                if state.core.poll_timeout().is_some_and(|at| at <= now) {
                    state.core.handle_timeout(now);
                }
                state.pump();
                while let Some(frame) = state.core.poll_transmit() {
                    out.push(frame);
                }
                // Sending a SYNC can report one.
                state.pump();
                if !out.is_empty() {
                    state.collected += 1;
                }
                (state.core.poll_timeout(), state.handles == 0)
            };
            if !out.is_empty() {
                for frame in out.drain(..) {
                    self.bus.send(&frame).await?;
                }
                let mut state = self.shared.lock();
                state.sent = state.collected;
                drop(state);
                self.shared.flushed.notify_waiters();
            }
            if last {
                return Ok(());
            }
            if timer.is_some_and(|at| at <= self.shared.now()) {
                continue;
            }
            let sleep = crate::tokio::sleep_until(&self.shared.clock, timer);
            // `recv` is cancel-safe (AsyncBus), and so is `notified`: a
            // wake-up that comes before the wait is kept as a permit.
            ::tokio::select! {
                biased;
                () = self.shared.wake.notified() => {}
                received = self.bus.recv() => {
                    let frame = received?;
                    let mut state = self.shared.lock();
                    let now = self.shared.now();
                    state.core.handle_frame(now, &frame);
                    drop(state);
                    self.shared.received.notify_waiters();
                }
                () = sleep => {}
            }
        }
    }

    /// The bus.
    pub fn bus(&self) -> &B {
        &self.bus
    }
}

impl<B> Drop for Driver<B> {
    /// A driver that did not finish `run` stops the master too.
    fn drop(&mut self) {
        self.shared.stop("the driver was dropped".to_string());
    }
}
