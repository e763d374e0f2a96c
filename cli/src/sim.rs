//! `eds2rust sim FILE [--overlay YAML]... --iface IFACE [--node N]`: a
//! simulated device from any EDS/DCF file or YAML object table on a
//! SocketCAN interface (docs/sim-cli.md), for developing a master before
//! the hardware arrives.
//!
//! The object table comes from `eds2rust_sim::file::load_with_overlays`
//! (the file and its YAML overlays), the device is
//! `eds2rust_sim::Device` (SDO server, NMT, heartbeat, PDOs per the
//! table), with the generic CiA 402 drive (`eds2rust_sim::cia402`) when
//! the file is a drive. It runs on the calling thread through the
//! runtime's blocking driver; every notable event (NMT state, SDO write
//! with the object's name and value, SDO abort, EMCY, CiA 402 transition,
//! target reached) is one line on stdout, status lines go to stderr.
//!
//! Exit status: 0 stopped by --duration or Ctrl-C, 1 the file does not
//! read, the interface cannot be opened or the bus failed while running,
//! 2 usage errors (including a file without a node id and no --node).

use std::convert::Infallible;
use std::io::{self, Write};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant as WallClock};

use clap::Args;
use eds2rust_runtime::blocking::{self, RunError};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::server::ServerEvent;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{Instant, Service};
use eds2rust_sim::cia402::{self, Cia402, Cia402Event};
use eds2rust_sim::file::{self, LoadedTable};
use eds2rust_sim::{Behaviour, Device, DeviceConfig, SimEvent};

use crate::live::bus;
use crate::live::nmt::state_name;
use crate::live::od::{self, Od};
use crate::live::values;

/// How often the loop looks at Ctrl-C and --duration.
const POLL: Duration = Duration::from_millis(50);
/// Repeated bus errors are reported at most this often.
const ERROR_REPORT: Duration = Duration::from_secs(5);
/// The statusword (CiA 402), shown with the drive's state changes.
const STATUSWORD: u16 = 0x6041;
/// Producer heartbeat time (CiA 301).
const HEARTBEAT_TIME: u16 = 0x1017;

#[derive(Args)]
pub struct SimArgs {
    /// The device: an EDS/DCF file or a YAML object table (.yaml, .yml).
    pub file: PathBuf,
    /// A YAML overlay table (without `base:`) applied on FILE: names,
    /// defaults, limits, added or deleted objects; may be given several
    /// times, applied in order.
    #[arg(long = "overlay", value_name = "YAML")]
    pub overlays: Vec<PathBuf>,
    /// The SocketCAN interface the device is on (can0, vcan0).
    #[arg(long, short = 'i', value_name = "IFACE")]
    pub iface: String,
    /// The node id (1 to 127). Default: the file's (a DCF's
    /// [DeviceComissioning] NodeID, a YAML table's network: node_id).
    #[arg(long, short = 'n', value_name = "N",
          value_parser = clap::value_parser!(u8).range(1..=127))]
    pub node: Option<u8>,
    /// Stop after this time (seconds: 2, 0.5, or 500ms, 2s, 1m); without
    /// it, Ctrl-C stops (SIGINT; SIGTERM and SIGHUP too).
    #[arg(long, value_name = "SECONDS", value_parser = crate::monitor::parse_seconds)]
    pub duration: Option<Duration>,
    /// A CiA 402 drive's mechanics this many times faster than real time
    /// (moves, ramps, homing, the drive's time windows); 1 by default.
    #[arg(long, value_name = "F", default_value_t = 1.0, value_parser = time_scale)]
    pub time_scale: f64,
    /// Print only errors: no event lines, no status lines, no warnings.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

/// `--time-scale F`: a positive, finite factor.
fn time_scale(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|f| f.is_finite() && *f > 0.0)
        .ok_or_else(|| format!("`{text}` is not a positive factor (1, 10, 0.5)"))
}

/// A model event as one line (`None`: not worth one).
pub trait Describe {
    fn describe(&self, statusword: Option<u64>) -> Option<String>;
}

impl Describe for Infallible {
    fn describe(&self, _: Option<u64>) -> Option<String> {
        match *self {}
    }
}

impl Describe for Cia402Event {
    fn describe(&self, statusword: Option<u64>) -> Option<String> {
        Some(match self {
            Cia402Event::StateChanged {
                transition,
                from,
                to,
            } => {
                let from = from.map_or("power-on", |s| s.name());
                let sw = statusword.map_or(String::new(), |sw| format!(", statusword {sw:#06X}"));
                format!("CiA 402: {from} -> {to} (transition {transition}{sw})")
            }
            Cia402Event::SetPointAccepted {
                target,
                relative,
                immediate,
            } => format!(
                "CiA 402: new set-point {target}{}{}",
                if *relative { ", relative" } else { "" },
                if *immediate { ", immediately" } else { "" }
            ),
            Cia402Event::TargetLimited { requested, limited } => {
                format!(
                    "CiA 402: target {requested} limited to {limited} (software position limits)"
                )
            }
            Cia402Event::TargetReached { position } => {
                format!("CiA 402: target reached at {position}")
            }
            Cia402Event::HomingAttained { position } => {
                format!("CiA 402: homing attained at {position}")
            }
            Cia402Event::FollowingError { error } => {
                format!("CiA 402: following error {error}")
            }
            Cia402Event::Fault(code) => format!("CiA 402: fault {code:#06X}"),
        })
    }
}

/// Runs the command; the exit status (see the module documentation).
pub fn run(args: SimArgs) -> ExitCode {
    let mut err = io::stderr();
    let table = match file::load_with_overlays(&args.file, &args.overlays) {
        Ok(table) => table,
        Err(e) => {
            for line in &e.errors {
                let _ = writeln!(err, "{line}");
            }
            if e.errors.is_empty() {
                let _ = writeln!(err, "{e}");
            }
            let _ = writeln!(
                err,
                "{}: not simulated: {} errors",
                args.file.display(),
                e.errors.len().max(1)
            );
            return ExitCode::from(1);
        }
    };
    if !args.quiet {
        for line in &table.warnings {
            let _ = writeln!(err, "{line}");
        }
    }
    let Some(node) = args.node.and_then(NodeId::new).or(table.node) else {
        let _ = writeln!(
            err,
            "error: {} gives no node id (no DCF [DeviceComissioning] NodeID, no YAML \
             network: node_id); pass --node N (1 to 127)",
            args.file.display()
        );
        return ExitCode::from(2);
    };
    let bus = match bus::open_socketcan(&args.iface) {
        Ok(bus) => bus,
        Err(message) => {
            let _ = writeln!(err, "error: {message}");
            return ExitCode::from(1);
        }
    };
    let stop = crate::monitor::stop_on_ctrl_c("the simulator", &mut err);
    let mut out = io::stdout();
    simulate(&args, &table, node, bus, &stop, &mut out, &mut err)
}

/// Simulates `table` as `node` on `bus` until `stop` is set or
/// `args.duration` ends: event lines to `out`, status lines and errors to
/// `err`; the exit status.
pub fn simulate(
    args: &SimArgs,
    table: &LoadedTable,
    node: NodeId,
    bus: Box<dyn Bus + Send>,
    stop: &AtomicBool,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> ExitCode {
    // Names and types of the entries for the event lines (the file read
    // once more, into the IR; `file::load_with_overlays` keeps only the
    // table).
    let od = Od::load_with_overlays(&args.file, &args.overlays).ok();
    let drive = table.cia402 && table.cia402_lacks().is_empty();
    let clock = Clock::new();
    let config = DeviceConfig::node(node);
    let mut session = Session {
        args,
        table,
        od: od.as_ref(),
        node,
        bus,
        clock: clock.clone(),
        stop,
        out,
        err,
        out_failed: None,
    };
    if drive {
        let model = Cia402::new().with_time_scale(args.time_scale);
        let device = cia402::simulator(table.objects, config, model, clock.now());
        session.run(device, "a CiA 402 drive")
    } else {
        let device = Device::new(table.objects, config, (), clock.now());
        let what = if table.cia402 {
            "a generic device (0x1000 says CiA 402, but it lacks 0x6040/0x6041)"
        } else {
            "a generic device"
        };
        session.run(device, what)
    }
}

/// One run: the file, its names, the bus.
struct Session<'a> {
    args: &'a SimArgs,
    table: &'a LoadedTable,
    od: Option<&'a Od>,
    node: NodeId,
    bus: Box<dyn Bus + Send>,
    clock: Clock,
    stop: &'a AtomicBool,
    out: &'a mut dyn Write,
    err: &'a mut dyn Write,
    /// The first failed write to `out` other than a closed pipe: the run
    /// stops and exits 1.
    out_failed: Option<io::Error>,
}

impl Session<'_> {
    fn run<B>(&mut self, mut device: Device<B>, what: &str) -> ExitCode
    where
        B: Behaviour,
        B::Event: Describe,
    {
        let start = WallClock::now();
        // The boot-up message first, before the status line: a master
        // started on that line sees the device booted.
        let mut failures = Failures::default();
        while let Some(frame) = device.poll_transmit() {
            if let Err(e) = self.bus.send(&frame) {
                let _ = writeln!(
                    self.err,
                    "error: {}: sending the boot-up message: {e}",
                    self.args.iface
                );
                return ExitCode::from(1);
            }
        }
        if !self.args.quiet {
            let heartbeat = match device.table().get_uint(HEARTBEAT_TIME, 0) {
                Some(ms) if ms > 0 => format!("heartbeat every {ms} ms"),
                _ => "no heartbeat (0x1017 is 0)".to_string(),
            };
            let until = match self.args.duration {
                Some(d) => format!("for {:.1} s", d.as_secs_f64()),
                None => "until Ctrl-C".into(),
            };
            let _ = writeln!(
                self.err,
                "sim: {}: {} as node {} on {}, {what}; {heartbeat}; {until}",
                self.table.path.display(),
                self.table.product.as_deref().unwrap_or("device"),
                self.node,
                self.args.iface
            );
        }
        let deadline = self.args.duration.map(|d| start + d);
        while !self.stop.load(Ordering::Relaxed)
            && self.out_failed.is_none()
            && deadline.is_none_or(|d| WallClock::now() < d)
        {
            let until: Instant = self.clock.now() + POLL;
            match blocking::run(
                &mut *self.bus,
                &self.clock,
                &mut device,
                until,
                ControlFlow::Break,
            ) {
                Ok(event) => self.print(&device, event, start),
                Err(RunError::Io(e)) => {
                    failures.report(&self.args.iface, &e, &mut *self.err);
                    std::thread::sleep(POLL);
                }
                // The deadline of this round passed.
                Err(_) => {}
            }
        }
        // Events of the last frame handled (one frame can give several,
        // and the loop stops between them).
        while let Some(event) = device.poll_event() {
            self.print(&device, event, start);
        }
        let _ = self.out.flush();
        if !self.args.quiet {
            let _ = writeln!(
                self.err,
                "sim: stopped after {:.1} s",
                start.elapsed().as_secs_f64()
            );
        }
        if let Some(e) = &self.out_failed {
            let _ = writeln!(self.err, "error: cannot write to standard output: {e}");
            return ExitCode::from(1);
        }
        if failures.count > 0 {
            let _ = writeln!(
                self.err,
                "error: {}: {} bus errors while running",
                self.args.iface, failures.count
            );
            return ExitCode::from(1);
        }
        ExitCode::SUCCESS
    }

    /// Prints the line of `event`, if it is notable, with the seconds since
    /// `start`.
    fn print<B>(&mut self, device: &Device<B>, event: SimEvent<B::Event>, start: WallClock)
    where
        B: Behaviour,
        B::Event: Describe,
    {
        if let Some(line) = self.describe(device, event)
            && !self.args.quiet
        {
            let t = start.elapsed().as_secs_f64();
            if let Err(e) = writeln!(self.out, "{t:9.3} {line}").and_then(|()| self.out.flush()) {
                // `| head` leaves: the simulator goes on without its log.
                if e.kind() != io::ErrorKind::BrokenPipe && self.out_failed.is_none() {
                    self.out_failed = Some(e);
                }
            }
        }
    }

    /// The line of one device event, if it is notable.
    fn describe<B>(&self, device: &Device<B>, event: SimEvent<B::Event>) -> Option<String>
    where
        B: Behaviour,
        B::Event: Describe,
    {
        Some(match event {
            SimEvent::Nmt { from, to } => {
                format!("NMT: {} -> {}", state_name(from), state_name(to))
            }
            SimEvent::Sdo(ServerEvent::Downloaded { index, sub, .. }) => {
                let value = device.table().get(index, sub).unwrap_or(&[]);
                format!(
                    "SDO write {} := {}",
                    self.label(index, sub),
                    self.value(index, sub, value)
                )
            }
            SimEvent::Sdo(ServerEvent::Failed { index, sub, error }) => {
                format!("SDO {}: {error}", self.label(index, sub))
            }
            // Reads are the master's business; RPDO writes come at the
            // PDO rate (their effect on a drive is shown by its events).
            SimEvent::Sdo(_) | SimEvent::Written { .. } => return None,
            SimEvent::HeartbeatLost(n) => format!("heartbeat of node {n} lost"),
            SimEvent::HeartbeatResumed(n) => format!("heartbeat of node {n} resumed"),
            SimEvent::Emcy(code) => format!("EMCY {code:#06X}"),
            SimEvent::LssNodeId(n) => format!("LSS: pending node id {}", node_text(n)),
            SimEvent::LssStored(n) => format!("LSS: stored node id {}", node_text(n)),
            SimEvent::ModelError(e) => format!("model error: {e}"),
            SimEvent::Model(e) => e.describe(device.table().get_uint(STATUSWORD, 0))?,
        })
    }

    /// `0x1017 Producer Heartbeat Time`, `0x1018.1 Identity Object.Vendor Id`.
    fn label(&self, index: u16, sub: u8) -> String {
        match self.od {
            Some(od) => od.label(index, sub),
            None => match self.table.entry(index, sub) {
                Some(info) => format!("{} {}", od::key(index, sub), info.name),
                None => od::key(index, sub),
            },
        }
    }

    /// The value by the entry's type and semantics (raw bytes without).
    fn value(&self, index: u16, sub: u8, data: &[u8]) -> String {
        let entry = self.od.and_then(|od| od.entry(index, sub)).map(|(_, e)| e);
        match entry.map(|e| (e, values::decode(e.data_type, data))) {
            Some((e, Ok((value, _)))) => values::describe(e.data_type, &e.semantics, &value),
            _ => values::hex_bytes(data),
        }
    }
}

fn node_text(node: Option<NodeId>) -> String {
    node.map_or("none (unconfigured)".into(), |n| n.to_string())
}

/// Bus errors while running: the first of a kind at once, then at most
/// one report every [`ERROR_REPORT`].
#[derive(Default)]
struct Failures {
    count: usize,
    last: Option<(String, WallClock)>,
    /// Errors since the last report, not reported.
    suppressed: usize,
}

impl Failures {
    fn report(&mut self, iface: &str, e: &io::Error, err: &mut dyn Write) {
        self.count += 1;
        let text = e.to_string();
        let due = match &self.last {
            Some((last, at)) => *last != text || at.elapsed() >= ERROR_REPORT,
            None => true,
        };
        if !due {
            self.suppressed += 1;
            return;
        }
        let more = match self.suppressed {
            0 => String::new(),
            n => format!(" ({n} more since the last report)"),
        };
        let _ = writeln!(err, "warning: {iface}: {text}{more}; the simulator goes on");
        self.last = Some((text, WallClock::now()));
        self.suppressed = 0;
    }
}

#[cfg(test)]
mod tests;
