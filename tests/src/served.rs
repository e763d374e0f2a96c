//! A simulated device (any [`Service`]) served on a bus port in a thread
//! (`blocking::serve`): the rig of the python-canopen sessions and interop
//! tests here, and of the command line's live, monitor and vcan tests
//! (cli/ includes this file by path: one rig for both crates).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

use eds2rust_runtime::blocking;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{Instant, Service};

/// A simulator served in a thread until [`Served::finish`] or drop;
/// dropping it fails the test when the thread panicked or the bus failed
/// (unless the test is failing already).
pub struct Served {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<std::io::Result<()>>>,
}

impl Served {
    /// The simulator `make` gives at the clock's now, served on `port`.
    pub fn start<P, S>(port: P, make: impl FnOnce(Instant) -> S) -> Served
    where
        P: Bus + Send + 'static,
        S: Service + Send + 'static,
    {
        Served::spawn(port, Clock::new(), make, false)
    }

    /// [`Served::start`] with the simulator's first frames (its boot-up)
    /// sent on `port` before this returns.
    pub fn booted<P, S>(port: P, make: impl FnOnce(Instant) -> S) -> Served
    where
        P: Bus + Send + 'static,
        S: Service + Send + 'static,
    {
        Served::booted_on(port, Clock::new(), make)
    }

    /// [`Served::booted`] on `clock` (a clone of the test's own clock).
    pub fn booted_on<P, S>(port: P, clock: Clock, make: impl FnOnce(Instant) -> S) -> Served
    where
        P: Bus + Send + 'static,
        S: Service + Send + 'static,
    {
        Served::spawn(port, clock, make, true)
    }

    fn spawn<P, S>(mut port: P, clock: Clock, make: impl FnOnce(Instant) -> S, boot: bool) -> Served
    where
        P: Bus + Send + 'static,
        S: Service + Send + 'static,
    {
        let mut device = make(clock.now());
        while boot && let Some(frame) = device.poll_transmit() {
            port.send(&frame).unwrap();
        }
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            blocking::serve(&mut port, &clock, &mut device, &flag, None, |_| {})
        });
        Served {
            stop,
            thread: Some(thread),
        }
    }

    /// Stops the simulator: an error when its thread panicked or its bus
    /// failed.
    pub fn finish(mut self) -> Result<(), String> {
        self.stop.store(true, Ordering::Relaxed);
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(Ok(()))) | None => Ok(()),
            Some(Ok(Err(e))) => Err(format!("the simulator's bus failed: {e}")),
            Some(Err(_)) => Err("the simulator thread panicked".to_string()),
        }
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let result = thread.join().expect("the simulator thread panicked");
            if !std::thread::panicking() {
                result.expect("the simulator's bus failed");
            }
        }
    }
}
