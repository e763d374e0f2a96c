//! What the examples share: the command line (`--iface`, `--trace`,
//! `--simulate`, `--time-scale`), a bus for the master, the simulator
//! running in a thread, and the trace of every frame in candump's compact
//! form.
//!
//! Without `--iface` everything runs on an in-process virtual bus
//! ([`eds2rust_runtime::transport::virtual_bus`]): the
//! master gets one port, the simulator another, the tracer a third. With
//! `--iface NAME` the master opens the SocketCAN interface `NAME` (Linux,
//! feature `socketcan`; without it [`Harness::start`] returns an error that
//! says so); the simulator runs there too only with `--simulate` (for a
//! vcan interface), otherwise the real device is expected on the bus.

use std::fmt;
use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{Frame, Instant, Service, blocking};

use crate::{Behaviour, Device, SimEvent};

/// The examples' command line.
#[derive(Debug, Clone, PartialEq)]
pub struct Args {
    /// SocketCAN interface to use instead of the virtual bus.
    pub iface: Option<String>,
    /// Print every frame on the bus, one per line, in candump's compact
    /// form (`720#00`).
    pub trace: bool,
    /// With `iface`: run the simulated device on that interface as well.
    pub simulate: bool,
    /// How much faster than real time the simulated mechanics move (1.0:
    /// as the manual says).
    pub time_scale: f64,
}

impl Default for Args {
    fn default() -> Self {
        Args {
            iface: None,
            trace: false,
            simulate: false,
            time_scale: 1.0,
        }
    }
}

/// A command line that could not be understood.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArgsError(pub String);

impl fmt::Display for ArgsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}\nusage: [--iface NAME [--simulate]] [--trace] [--time-scale FACTOR]",
            self.0
        )
    }
}

impl std::error::Error for ArgsError {}

impl Args {
    /// Parses the arguments after the program name.
    pub fn parse(args: impl IntoIterator<Item = String>) -> Result<Args, ArgsError> {
        let mut out = Args::default();
        let mut args = args.into_iter();
        while let Some(arg) = args.next() {
            match arg.as_str() {
                "--trace" => out.trace = true,
                "--simulate" => out.simulate = true,
                "--iface" => {
                    let name = args
                        .next()
                        .ok_or_else(|| ArgsError("--iface needs an interface name".into()))?;
                    out.iface = Some(name);
                }
                "--time-scale" => {
                    let value = args
                        .next()
                        .ok_or_else(|| ArgsError("--time-scale needs a factor".into()))?;
                    out.time_scale = time_scale(&value)?;
                }
                other => return Err(ArgsError(format!("unknown argument `{other}`"))),
            }
        }
        if out.simulate && out.iface.is_none() {
            return Err(ArgsError(
                "--simulate goes with --iface (the virtual bus always simulates)".into(),
            ));
        }
        Ok(out)
    }

    /// Parses the process's arguments.
    pub fn from_env() -> Result<Args, ArgsError> {
        Args::parse(std::env::args().skip(1))
    }

    /// Whether a simulator runs (always on the virtual bus).
    pub fn simulates(&self) -> bool {
        self.iface.is_none() || self.simulate
    }
}

/// The factor of `--time-scale`: a positive number.
pub fn time_scale(value: &str) -> Result<f64, ArgsError> {
    value
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite() && *v > 0.0)
        .ok_or_else(|| ArgsError(format!("--time-scale {value}: not a positive number")))
}

/// The master's end of the bus. Non-exhaustive: the `SocketCan` variant
/// exists only with the feature `socketcan`, which another crate in the
/// build may turn on.
#[derive(Debug)]
#[non_exhaustive]
pub enum MasterPort {
    /// A port of the in-process virtual bus.
    Virtual(VirtualPort),
    /// A SocketCAN socket (Linux, feature `socketcan`).
    #[cfg(all(feature = "socketcan", target_os = "linux"))]
    SocketCan(eds2rust_runtime::transport::socketcan::SocketCanBus),
}

impl Bus for MasterPort {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        match self {
            MasterPort::Virtual(p) => p.send(frame),
            #[cfg(all(feature = "socketcan", target_os = "linux"))]
            MasterPort::SocketCan(s) => s.send(frame),
        }
    }

    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        match self {
            MasterPort::Virtual(p) => p.recv(timeout),
            #[cfg(all(feature = "socketcan", target_os = "linux"))]
            MasterPort::SocketCan(s) => s.recv(timeout),
        }
    }
}

/// Where the harness attaches simulated devices.
#[derive(Debug)]
enum DevicePorts {
    /// No simulator runs (a real device on a SocketCAN interface).
    None,
    /// The in-process virtual bus.
    Virtual(VirtualBus),
    /// A SocketCAN interface, opened once per device.
    #[cfg(all(feature = "socketcan", target_os = "linux"))]
    SocketCan(String),
}

/// A port on the SocketCAN interface `name`.
#[cfg(all(feature = "socketcan", target_os = "linux"))]
fn open_socketcan(name: &str) -> io::Result<MasterPort> {
    use eds2rust_runtime::transport::socketcan::SocketCanBus;
    SocketCanBus::open(name)
        .map(MasterPort::SocketCan)
        .map_err(|e| io::Error::new(e.kind(), format!("SocketCAN interface `{name}`: {e}")))
}

/// Lines shared between the threads.
type Lines = Arc<Mutex<Vec<String>>>;

fn push(lines: &Lines, line: String) {
    lines
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .push(line);
}

/// A running example setup: bus, simulator thread and tracer thread.
#[derive(Debug)]
pub struct Harness {
    clock: Clock,
    /// Where more simulated devices join ([`Harness::add_device`]).
    devices: DevicePorts,
    port: Option<MasterPort>,
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<io::Result<()>>>,
    trace: Lines,
    device_log: Lines,
}

impl Harness {
    /// Opens the bus and, when [`Args::simulates`], starts the device that
    /// `device` builds (given the power-on time) in a thread.
    ///
    /// `args.iface` needs the feature `socketcan` (and Linux); without it
    /// this is an [`io::ErrorKind::Unsupported`] error naming the feature.
    pub fn start<B, F>(args: &Args, device: F) -> io::Result<Harness>
    where
        B: Behaviour + Send + 'static,
        B::Event: Send,
        F: FnOnce(Instant) -> Device<B>,
    {
        let clock = Clock::new();
        let mut harness = Harness {
            clock: clock.clone(),
            devices: DevicePorts::None,
            port: None,
            stop: Arc::new(AtomicBool::new(false)),
            threads: Vec::new(),
            trace: Lines::default(),
            device_log: Lines::default(),
        };
        match &args.iface {
            None => {
                let bus = VirtualBus::new();
                harness.port = Some(MasterPort::Virtual(bus.attach()));
                harness.spawn_tracer(MasterPort::Virtual(bus.attach()), args.trace);
                harness.devices = DevicePorts::Virtual(bus);
            }
            #[cfg(all(feature = "socketcan", target_os = "linux"))]
            Some(name) => {
                harness.port = Some(open_socketcan(name)?);
                harness.spawn_tracer(open_socketcan(name)?, args.trace);
                if args.simulate {
                    harness.devices = DevicePorts::SocketCan(name.clone());
                }
            }
            #[cfg(all(feature = "socketcan", not(target_os = "linux")))]
            Some(name) => {
                return Err(io::Error::new(
                    io::ErrorKind::Unsupported,
                    format!("SocketCAN interface `{name}`: SocketCAN needs Linux"),
                ));
            }
            #[cfg(not(feature = "socketcan"))]
            Some(name) => {
                return Err(io::Error::new(
                    io::ErrorKind::Unsupported,
                    format!(
                        "SocketCAN interface `{name}`: this build has no SocketCAN support; \
                         enable the feature `socketcan` of eds2rust-sim"
                    ),
                ));
            }
        }
        harness.add_device(device)?;
        Ok(harness)
    }

    /// Starts one more simulated device on the same bus (given the
    /// power-on time), in a thread of its own, when a simulator runs
    /// ([`Args::simulates`]); otherwise the real device is expected on the
    /// bus and `device` is not called.
    pub fn add_device<B, F>(&mut self, device: F) -> io::Result<()>
    where
        B: Behaviour + Send + 'static,
        B::Event: Send,
        F: FnOnce(Instant) -> Device<B>,
    {
        let port = match &self.devices {
            DevicePorts::None => return Ok(()),
            DevicePorts::Virtual(bus) => MasterPort::Virtual(bus.attach()),
            #[cfg(all(feature = "socketcan", target_os = "linux"))]
            DevicePorts::SocketCan(name) => open_socketcan(name)?,
        };
        self.spawn_device(port, device(self.clock.now()))
    }

    fn spawn_tracer(&mut self, mut port: MasterPort, print: bool) {
        let stop = Arc::clone(&self.stop);
        let trace = Arc::clone(&self.trace);
        self.threads.push(std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                if let Some(frame) = port.recv(Duration::from_millis(20))? {
                    let line = frame.to_string();
                    if print {
                        println!("{line}");
                    }
                    push(&trace, line);
                }
            }
            // Frames sent just before the stop.
            while let Some(frame) = port.recv(Duration::from_millis(5))? {
                let line = frame.to_string();
                if print {
                    println!("{line}");
                }
                push(&trace, line);
            }
            Ok(())
        }));
    }

    /// Runs `device` on `port` in a thread. Its boot-up message is sent
    /// before this returns, so that it precedes the master's first frame as
    /// on a bus where the device was powered first.
    fn spawn_device<B>(&mut self, mut port: MasterPort, mut device: Device<B>) -> io::Result<()>
    where
        B: Behaviour + Send + 'static,
        B::Event: Send,
    {
        while let Some(frame) = device.poll_transmit() {
            port.send(&frame)?;
        }
        let stop = Arc::clone(&self.stop);
        let log = Arc::clone(&self.device_log);
        let clock = self.clock.clone();
        self.threads.push(std::thread::spawn(move || {
            blocking::serve(&mut port, &clock, &mut device, &stop, None, |event| {
                if !matches!(event, SimEvent::Sdo(_) | SimEvent::Written { .. }) {
                    push(&log, format!("{event:?}"));
                }
            })
        }));
        Ok(())
    }

    /// The clock master and simulator share.
    pub fn clock(&self) -> Clock {
        self.clock.clone()
    }

    /// The master's port (once).
    pub fn take_port(&mut self) -> io::Result<MasterPort> {
        self.port
            .take()
            .ok_or_else(|| io::Error::other("the master port was already taken"))
    }

    /// The frames traced so far, in candump's compact form.
    pub fn trace(&self) -> Vec<String> {
        self.trace
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    /// The simulator's events so far (Debug form), without SDO and write
    /// events.
    pub fn device_log(&self) -> Vec<String> {
        self.device_log
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    /// Stops the simulator and tracer and returns the whole trace; a thread
    /// that failed (a bus error) is reported.
    pub fn stop(mut self) -> io::Result<Vec<String>> {
        self.stop.store(true, Ordering::Relaxed);
        for thread in self.threads.drain(..) {
            thread
                .join()
                .map_err(|_| io::Error::other("a simulator thread panicked"))??;
        }
        Ok(self.trace())
    }
}

impl Drop for Harness {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}
