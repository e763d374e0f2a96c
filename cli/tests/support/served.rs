//! A simulated device served in a thread (`blocking::serve`): what the
//! live and monitor unit tests (on the virtual bus, through `#[path]`) and
//! the vcan tests (tests/vcan) start their devices with.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

use eds2rust_runtime::blocking;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{Instant, Service};
use eds2rust_sim::{Behaviour, Device};

/// A device served on its port in a thread until dropped; dropping it
/// fails the test when the thread panicked or the bus failed (unless the
/// test is failing already).
pub struct Served {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<std::io::Result<()>>>,
}

impl Served {
    /// `device` made at the clock's now, its boot-up frames sent on `port`,
    /// then served on it.
    pub fn start<P, B>(mut port: P, device: impl FnOnce(Instant) -> Device<B>) -> Served
    where
        P: Bus + Send + 'static,
        B: Behaviour + Send + 'static,
        B::Event: Send,
    {
        let clock = Clock::new();
        let mut device = device(clock.now());
        while let Some(frame) = device.poll_transmit() {
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
}

impl Drop for Served {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let r = t.join().expect("the simulator thread panicked");
            if !std::thread::panicking() {
                r.expect("the simulator's bus failed");
            }
        }
    }
}
