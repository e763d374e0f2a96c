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
//! `eds2rust sim --network BUS --iface IFACE [--fault NODE:KIND[=VALUE]]...`
//! simulates every slave of a bus file instead (`sim/network.rs`), with
//! faults (`sim/fault.rs`).
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
use eds2rust_sim::{Behaviour, Device, DeviceConfig, ObjectTable, SimEvent};

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
    #[arg(required_unless_present = "network", conflicts_with = "network")]
    pub file: Option<PathBuf>,
    /// A YAML overlay table (without `base:`) applied on FILE: names,
    /// defaults, limits, added or deleted objects; may be given several
    /// times, applied in order.
    #[arg(long = "overlay", value_name = "YAML", conflicts_with = "network")]
    pub overlays: Vec<PathBuf>,
    /// Simulates every slave of a network instead of one device: a bus
    /// file (lely dcfgen's YAML), each slave from its device file at the
    /// node id the file gives (docs/sim-cli.md).
    #[arg(long, value_name = "BUS", conflicts_with = "node")]
    pub network: Option<PathBuf>,
    /// With --network: what goes wrong with a node, NODE:KIND[=VALUE]
    /// (NODE a node id or a slave's name): missing, device-type=V,
    /// vendor-id=V, product-code=V, revision=V, serial=V, late-boot=T,
    /// power-loss=AT[+OFF], sdo-abort=INDEX:SUB[:CODE],
    /// heartbeat-stops=AT[+FOR], config-current. May be given several
    /// times.
    #[arg(long = "fault", value_name = "NODE:KIND[=VALUE]")]
    pub faults: Vec<String>,
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
    let file = match (&args.network, &args.file) {
        (Some(bus), _) => return network::run(&args, bus),
        (None, _) if !args.faults.is_empty() => {
            let _ = writeln!(err, "error: --fault goes with --network <BUS> (a bus file)");
            return ExitCode::from(2);
        }
        (None, Some(file)) => file,
        (None, None) => {
            let _ = writeln!(err, "error: give a device FILE or --network BUS");
            return ExitCode::from(2);
        }
    };
    let loaded = file::load_with_overlays(file, &args.overlays);
    let table = match read_input(file, loaded, |t| &t.warnings, args.quiet, &mut err) {
        Ok(table) => table,
        Err(code) => return code,
    };
    let Some(node) = args.node.and_then(NodeId::new).or(table.node) else {
        let _ = writeln!(
            err,
            "error: {} gives no node id (no DCF [DeviceComissioning] NodeID, no YAML \
             network: node_id); pass --node N (1 to 127)",
            file.display()
        );
        return ExitCode::from(2);
    };
    let (bus, stop) = match open(&args.iface, &mut err) {
        Ok(opened) => opened,
        Err(code) => return code,
    };
    simulate(&args, &table, node, bus, &stop, &mut io::stdout(), &mut err)
}

/// The interface `iface`, and the flag Ctrl-C sets; an error (exit 1) when
/// it does not open, said on `err`.
fn open(
    iface: &str,
    err: &mut dyn Write,
) -> Result<(Box<dyn Bus + Send>, std::sync::Arc<AtomicBool>), ExitCode> {
    match bus::open_socketcan(iface) {
        Ok(bus) => Ok((bus, crate::monitor::stop_on_ctrl_c("the simulator", err))),
        Err(message) => {
            let _ = writeln!(err, "error: {message}");
            Err(ExitCode::from(1))
        }
    }
}

/// A file that does not read: its errors (each naming file and line),
/// then what became of it.
/// What `sim` read from `file` (a device file or, with `--network`, a bus
/// file): on errors their lines and `FILE: not simulated: N errors` with
/// exit status 1; else the readers' warnings (unless `--quiet`) and the
/// input.
fn read_input<T>(
    file: &std::path::Path,
    loaded: Result<T, file::LoadError>,
    warnings: impl Fn(&T) -> &[String],
    quiet: bool,
    err: &mut dyn Write,
) -> Result<T, ExitCode> {
    let input = loaded.map_err(|e| {
        not_simulated(file, &e, err);
        ExitCode::from(1)
    })?;
    if !quiet {
        for line in warnings(&input) {
            let _ = writeln!(err, "{line}");
        }
    }
    Ok(input)
}

fn not_simulated(file: &std::path::Path, e: &file::LoadError, err: &mut dyn Write) {
    for line in &e.errors {
        let _ = writeln!(err, "{line}");
    }
    if e.errors.is_empty() {
        let _ = writeln!(err, "{e}");
    }
    let _ = writeln!(
        err,
        "{}: not simulated: {} errors",
        file.display(),
        e.errors.len().max(1)
    );
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
    let od = Od::load_with_overlays(&table.path, &args.overlays).ok();
    let drive = table.cia402 && table.cia402_lacks().is_empty();
    let config = DeviceConfig::node(node);
    let session = Session {
        args,
        table,
        od: od.as_ref(),
    };
    let mut runner = Runner::new(bus, &args.iface, args.duration, args.quiet, stop, out, err);
    let clock = runner.clock().clone();
    if drive {
        let model = Cia402::new().with_time_scale(args.time_scale);
        let device = cia402::simulator(table.objects, config, model, clock.now());
        session.run(&mut runner, device, node, "a CiA 402 drive")
    } else {
        let device = Device::new(table.objects, config, (), clock.now());
        let what = if table.cia402 {
            "a generic device (0x1000 says CiA 402, but it lacks 0x6040/0x6041)"
        } else {
            "a generic device"
        };
        session.run(&mut runner, device, node, what)
    }
}

/// One device's run: the file and its names.
struct Session<'a> {
    args: &'a SimArgs,
    table: &'a LoadedTable,
    od: Option<&'a Od>,
}

impl Session<'_> {
    fn run<B>(
        &self,
        runner: &mut Runner<'_>,
        mut device: Device<B>,
        node: NodeId,
        what: &str,
    ) -> ExitCode
    where
        B: Behaviour,
        B::Event: Describe,
    {
        // The boot-up message first, before the status line: a master
        // started on that line sees the device booted.
        if let Err(code) = runner.send_ready(&mut device) {
            return code;
        }
        if !self.args.quiet {
            let heartbeat = match device.table().get_uint(HEARTBEAT_TIME, 0) {
                Some(ms) if ms > 0 => format!("heartbeat every {ms} ms"),
                _ => "no heartbeat (0x1017 is 0)".to_string(),
            };
            let _ = writeln!(
                runner.err,
                "sim: {}: {} as node {} on {}, {what}; {heartbeat}; {}",
                self.table.path.display(),
                self.table.product.as_deref().unwrap_or("device"),
                node,
                self.args.iface,
                runner.until()
            );
        }
        runner.run(&mut device, |device, event| self.describe(device, event))
    }

    /// The line of one device event, if it is notable.
    fn describe<B>(&self, device: &Device<B>, event: SimEvent<B::Event>) -> Option<String>
    where
        B: Behaviour,
        B::Event: Describe,
    {
        let labels = Labels {
            table: self.table,
            od: self.od,
        };
        event_line(&labels, device.table(), event)
    }
}

/// Names and values of a device's entries for the event lines: from its
/// file read into the IR when it reads, else from its table.
pub(crate) struct Labels<'a> {
    pub(crate) table: &'a LoadedTable,
    pub(crate) od: Option<&'a Od>,
}

impl Labels<'_> {
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

/// The line of one event of a device whose table holds `table` now, if it
/// is notable.
pub(crate) fn event_line<E: Describe>(
    labels: &Labels<'_>,
    table: &ObjectTable,
    event: SimEvent<E>,
) -> Option<String> {
    Some(match event {
        SimEvent::Nmt { from, to } => {
            format!("NMT: {} -> {}", state_name(from), state_name(to))
        }
        SimEvent::Sdo(ServerEvent::Downloaded { index, sub, .. }) => {
            let value = table.get(index, sub).unwrap_or(&[]);
            format!(
                "SDO write {} := {}",
                labels.label(index, sub),
                labels.value(index, sub, value)
            )
        }
        SimEvent::Sdo(ServerEvent::Failed { index, sub, error }) => {
            format!("SDO {}: {error}", labels.label(index, sub))
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
        SimEvent::Model(e) => e.describe(table.get_uint(STATUSWORD, 0))?,
    })
}

/// The loop both simulations run (one device, a network): the service on
/// the bus until Ctrl-C or the duration, each notable event one line on
/// `out` with the seconds since the start, status lines and errors on
/// `err`.
pub(crate) struct Runner<'a> {
    bus: Box<dyn Bus + Send>,
    clock: Clock,
    iface: &'a str,
    duration: Option<Duration>,
    quiet: bool,
    stop: &'a AtomicBool,
    out: &'a mut dyn Write,
    pub(crate) err: &'a mut dyn Write,
    start: WallClock,
    /// The first failed write to `out` other than a closed pipe: the run
    /// stops and exits 1.
    out_failed: Option<io::Error>,
}

impl<'a> Runner<'a> {
    pub(crate) fn new(
        bus: Box<dyn Bus + Send>,
        iface: &'a str,
        duration: Option<Duration>,
        quiet: bool,
        stop: &'a AtomicBool,
        out: &'a mut dyn Write,
        err: &'a mut dyn Write,
    ) -> Runner<'a> {
        Runner {
            bus,
            clock: Clock::new(),
            iface,
            duration,
            quiet,
            stop,
            out,
            err,
            start: WallClock::now(),
            out_failed: None,
        }
    }

    /// The clock of the run.
    pub(crate) fn clock(&self) -> &Clock {
        &self.clock
    }

    /// "for 2.0 s" or "until Ctrl-C".
    pub(crate) fn until(&self) -> String {
        match self.duration {
            Some(d) => format!("for {:.1} s", d.as_secs_f64()),
            None => "until Ctrl-C".into(),
        }
    }

    /// Sends what `service` has ready now (the boot-up messages).
    pub(crate) fn send_ready<S: Service>(&mut self, service: &mut S) -> Result<(), ExitCode> {
        while let Some(frame) = service.poll_transmit() {
            if let Err(e) = self.bus.send(&frame) {
                let _ = writeln!(
                    self.err,
                    "error: {}: sending the boot-up message: {e}",
                    self.iface
                );
                return Err(ExitCode::from(1));
            }
        }
        Ok(())
    }

    /// Runs `service` until stopped; `line` gives the line of an event.
    pub(crate) fn run<S: Service>(
        &mut self,
        service: &mut S,
        mut line: impl FnMut(&S, S::Event) -> Option<String>,
    ) -> ExitCode {
        let mut failures = Failures::default();
        let deadline = self.duration.map(|d| self.start + d);
        while !self.stop.load(Ordering::Relaxed)
            && self.out_failed.is_none()
            && deadline.is_none_or(|d| WallClock::now() < d)
        {
            let until: Instant = self.clock.now() + POLL;
            match blocking::run(
                &mut *self.bus,
                &self.clock,
                service,
                until,
                ControlFlow::Break,
            ) {
                Ok(event) => {
                    let text = line(service, event);
                    self.print(text);
                }
                Err(RunError::Io(e)) => {
                    failures.report(self.iface, &e, &mut *self.err);
                    std::thread::sleep(POLL);
                }
                // The deadline of this round passed.
                Err(_) => {}
            }
        }
        // Events of the last frame handled (one frame can give several,
        // and the loop stops between them).
        while let Some(event) = service.poll_event() {
            let text = line(service, event);
            self.print(text);
        }
        let _ = self.out.flush();
        if !self.quiet {
            let _ = writeln!(
                self.err,
                "sim: stopped after {:.1} s",
                self.start.elapsed().as_secs_f64()
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
                self.iface, failures.count
            );
            return ExitCode::from(1);
        }
        ExitCode::SUCCESS
    }

    /// Prints `line`, if any, with the seconds since the start.
    fn print(&mut self, line: Option<String>) {
        if let Some(line) = line
            && !self.quiet
        {
            let t = self.start.elapsed().as_secs_f64();
            if let Err(e) = writeln!(self.out, "{t:9.3} {line}").and_then(|()| self.out.flush()) {
                // `| head` leaves: the simulator goes on without its log.
                if e.kind() != io::ErrorKind::BrokenPipe && self.out_failed.is_none() {
                    self.out_failed = Some(e);
                }
            }
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

pub(crate) mod fault;
mod network;
#[cfg(test)]
mod tests;
