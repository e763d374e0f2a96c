//! Any CiA 402 drive from its file: loads an EDS/DCF/YAML at run time,
//! simulates it with the generic CiA 402 behaviour on the in-process
//! virtual bus (in a thread), and drives it with the runtime's CiA 402
//! helper on the blocking master (`blocking::Master::drive`) or, with
//! `--async`, on the tokio master (`tokio::Master::drive`): enable (with
//! fault reset), a profile-position move to a target and back, a quick
//! stop. Every state transition is printed, and `target reached at
//! <position>` after each move; both masters print the same lines.
//!
//! `cargo run -p eds2rust-sim --example cia402 -- FILE [--overlay YAML]...
//! [--node N] [--time-scale F] [--trace] [--async]`
//!
//! Exit 0 when all of it worked; 1 with one message naming what the file
//! lacks (not a CiA 402 drive, no target position, ...) or what failed;
//! 2 for a bad command line. The objects a request needs are checked
//! against the file's table before any frame is sent.

use std::fmt;
use std::path::PathBuf;
use std::time::Duration;

use eds2rust_runtime::blocking;
use eds2rust_runtime::cia402::requirements::Operation;
use eds2rust_runtime::cia402::{Event, Move, Request, SessionConfig, State, object};
use eds2rust_runtime::od::{NodeId, Number, ObjectInfo};
use eds2rust_sim::DeviceConfig;
use eds2rust_sim::cia402::{self, Cia402};
use eds2rust_sim::file::{self, LoadedTable};
use eds2rust_sim::harness::{self, Harness, MasterPort};

mod rig;
use rig::{BlockingRig, Rig, TokioRig};

/// The node id when neither `--node` nor the file gives one.
const DEFAULT_NODE: u8 = 2;
/// The move: this far from the start (units), unless the software
/// position limits leave less room.
pub const DISTANCE: i64 = 10_000;
/// Profile velocity (units/s) and acceleration/deceleration (units/s²):
/// the move takes DISTANCE/VELOCITY + VELOCITY/RAMP = 2.1 s at time scale 1.
pub const VELOCITY: u32 = 5_000;
/// See [`VELOCITY`].
pub const RAMP: u32 = 50_000;
/// Max profile velocity (CiA 402), which limits the profile velocity.
const MAX_PROFILE_VELOCITY: u16 = 0x607F;
/// How often the statusword is read.
const POLL: Duration = Duration::from_millis(5);

/// The command line.
#[derive(Debug, Clone, PartialEq)]
pub struct Args {
    /// The device file.
    pub file: PathBuf,
    /// `--overlay YAML`, in order: YAML overlays applied on the file.
    pub overlays: Vec<PathBuf>,
    /// `--node N`.
    pub node: Option<u8>,
    /// `--time-scale F`: the simulated mechanics F times faster.
    pub time_scale: f64,
    /// `--trace`: print every frame.
    pub trace: bool,
    /// `--async`: the tokio master instead of the blocking one.
    pub asynchronous: bool,
}

/// What went wrong, in one line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failure(pub String);

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Failure {}

impl From<std::io::Error> for Failure {
    fn from(e: std::io::Error) -> Failure {
        Failure(e.to_string())
    }
}

const USAGE: &str =
    "usage: cia402 FILE [--overlay YAML]... [--node N] [--time-scale F] [--trace] [--async]";

/// Parses the arguments after the program name.
pub fn parse(args: impl IntoIterator<Item = String>) -> Result<Args, Failure> {
    let mut file = None;
    let mut out = Args {
        file: PathBuf::new(),
        overlays: Vec::new(),
        node: None,
        time_scale: 1.0,
        trace: false,
        asynchronous: false,
    };
    let mut args = args.into_iter();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--trace" => out.trace = true,
            "--async" => out.asynchronous = true,
            "--overlay" => match args.next() {
                Some(path) => out.overlays.push(PathBuf::from(path)),
                None => return Err(Failure(format!("--overlay needs a YAML file\n{USAGE}"))),
            },
            "--node" => {
                let value = args.next().unwrap_or_default();
                let node = value
                    .parse::<u8>()
                    .ok()
                    .filter(|n| NodeId::new(*n).is_some())
                    .ok_or_else(|| Failure(format!("--node {value}: not a node id 1..=127")))?;
                out.node = Some(node);
            }
            "--time-scale" => {
                let value = args.next().unwrap_or_default();
                out.time_scale = harness::time_scale(&value).map_err(|e| Failure(e.0))?;
            }
            other if other.starts_with("--") => {
                return Err(Failure(format!("unknown argument `{other}`\n{USAGE}")));
            }
            path if file.is_none() => file = Some(PathBuf::from(path)),
            extra => {
                return Err(Failure(format!(
                    "one FILE only, not also `{extra}`\n{USAGE}"
                )));
            }
        }
    }
    out.file = file.ok_or_else(|| Failure(format!("no FILE given\n{USAGE}")))?;
    Ok(out)
}

fn main() {
    let args = match parse(std::env::args().skip(1)) {
        Ok(args) => args,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut out = std::io::stdout();
    if let Err(e) = run(&args, &mut out) {
        eprintln!("{e}");
        std::process::exit(1);
    }
}

/// What a run ended with.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// The positions read at the two targets.
    pub reached: Vec<i64>,
    /// The two targets.
    pub targets: Vec<i64>,
    /// The last state seen.
    pub state: Option<State>,
}

/// Whether the file is a CiA 402 drive at all (one rule:
/// `eds2rust::profiles::is_cia402`, through the loader). What profile
/// position needs is the runtime's rule, checked when the drive handle is
/// made ([`SessionConfig::required`]).
pub fn check(table: &LoadedTable) -> Result<(), Failure> {
    let lacks = table.cia402_lacks();
    if table.cia402 && lacks.is_empty() {
        return Ok(());
    }
    let what = if lacks.is_empty() {
        let device_type = table
            .device_type
            .map_or("no 0x1000 Device type".to_string(), |t| {
                format!("0x1000 Device type {t:#010X} names profile {}", t & 0xFFFF)
            });
        format!("{device_type}, and 0x6040/0x6041 are not UNSIGNED16 variables")
    } else {
        lacks
            .iter()
            .map(|(index, name)| format!("no {index:#06X} {name}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    Err(Failure(format!(
        "{}: not a CiA 402 drive: {what}",
        table.path.display()
    )))
}

/// The helper's configuration: profile position is checked up front.
fn session_config() -> SessionConfig {
    SessionConfig::default()
        .with_poll_period(Some(POLL))
        .with_required(&[Operation::ProfilePosition])
}

/// Runs the scenario on the file `args.file`, printing to `out`.
pub fn run(args: &Args, out: &mut dyn std::io::Write) -> Result<Summary, Failure> {
    let table =
        file::load_with_overlays(&args.file, &args.overlays).map_err(|e| Failure(e.to_string()))?;
    check(&table)?;
    let file = table.path.display().to_string();
    let node = args
        .node
        .and_then(NodeId::new)
        .or(table.node)
        .or(NodeId::new(DEFAULT_NODE))
        .ok_or_else(|| Failure("no node id".into()))?;
    let me = NodeId::new(if node.get() == 127 { 126 } else { 127 })
        .ok_or_else(|| Failure("no master node id".into()))?;
    let hargs = harness::Args {
        trace: args.trace,
        time_scale: args.time_scale,
        ..harness::Args::default()
    };
    let objects = table.objects;
    let scale = args.time_scale;
    let mut harness = Harness::start(&hargs, move |now| {
        let model = Cia402::new().with_time_scale(scale);
        cia402::simulator(objects, DeviceConfig::node(node), model, now)
    })?;
    let port = harness.take_port()?;
    let fail = |e: String| Failure(format!("{file}: {e}"));
    let result = if args.asynchronous {
        let MasterPort::Virtual(port) = port else {
            return Err(Failure("the tokio rig runs on the virtual bus".into()));
        };
        let mut rig = TokioRig::new(port, harness.clock(), me, node, objects, session_config())
            .map_err(fail)?;
        let result = scenario(&mut rig, &table, node, out, args.time_scale);
        rig.finish().map_err(fail).and(result)
    } else {
        let mut master = blocking::Master::with_clock(port, rig::core(me), harness.clock());
        let mut rig =
            BlockingRig::new(&mut master, node, objects, session_config()).map_err(fail)?;
        scenario(&mut rig, &table, node, out, args.time_scale)
    };
    harness.stop()?;
    result
}

/// Enable, there and back in profile position, quick stop: the same calls
/// of the drive helper on either master.
fn scenario(
    rig: &mut dyn Rig,
    table: &LoadedTable,
    node: NodeId,
    out: &mut dyn std::io::Write,
    time_scale: f64,
) -> Result<Summary, Failure> {
    let file = table.path.display().to_string();
    writeln!(
        out,
        "{file}: {} as node {node}, driven by the {}",
        table.product.as_deref().unwrap_or("CiA 402 drive"),
        rig.name()
    )?;
    let step = |rig: &mut dyn Rig, out: &mut dyn std::io::Write, what: &str, request| {
        let result = rig.request(request);
        print_transitions(rig, out)?;
        result.map_err(|e| Failure(format!("{file}: {what}: {e}")))
    };
    writeln!(
        out,
        "enable: fault reset, Shutdown, Switch on, Enable operation"
    )?;
    step(rig, out, "enable", Request::Enable)?;
    let velocity = clamp(table, object::PROFILE_VELOCITY, VELOCITY);
    let acceleration = clamp(table, object::PROFILE_ACCELERATION, RAMP);
    let deceleration = clamp(table, object::PROFILE_DECELERATION, RAMP);
    match Operation::MotionProfile.check(table.objects) {
        Ok(()) => {
            let profile = Request::Profile {
                velocity,
                acceleration,
                deceleration,
            };
            step(rig, out, "setting the motion profile", profile)?;
        }
        Err(e) => writeln!(out, "motion profile left as the drive has it: {e}")?,
    }
    if let Some(max) = read_int(rig, table, MAX_PROFILE_VELOCITY)?
        && max > 0
        && max < i64::from(velocity)
    {
        writeln!(
            out,
            "note: {MAX_PROFILE_VELOCITY:#06X} Max profile velocity = {max} limits the profile velocity"
        )?;
    }
    let start = read_int(rig, table, object::POSITION_ACTUAL_VALUE)?.unwrap_or(0);
    let target = pick_target(rig, table, start);
    let mut summary = Summary {
        reached: Vec::new(),
        targets: Vec::new(),
        state: None,
    };
    for goal in [target, start] {
        writeln!(
            out,
            "profile position: move to {goal} at {velocity} units/s, {acceleration} units/s²"
        )?;
        let target =
            i32::try_from(goal).map_err(|_| Failure(format!("target {goal} is out of range")))?;
        let begun = rig.now();
        let request = Request::Move {
            target,
            options: Move::default(),
        };
        step(rig, out, &format!("moving to {goal}"), request)?;
        let took = rig.now().saturating_duration_since(begun);
        let position = read_int(rig, table, object::POSITION_ACTUAL_VALUE)?;
        match position {
            Some(p) => writeln!(
                out,
                "target reached at {p} (after {:.2} s of drive time)",
                took.as_secs_f64() * time_scale
            )?,
            None => writeln!(
                out,
                "target reached at an unknown position (the device has no {:#06X} Position actual value)",
                object::POSITION_ACTUAL_VALUE
            )?,
        }
        summary.targets.push(goal);
        summary.reached.extend(position);
    }
    writeln!(out, "quick stop")?;
    step(rig, out, "quick stop", Request::QuickStop)?;
    summary.state = rig.state();
    writeln!(
        out,
        "quick stopped in state {}",
        summary.state.map_or("unknown", State::name)
    )?;
    Ok(summary)
}

/// Prints the state transitions the drive reported since the last call.
fn print_transitions(rig: &mut dyn Rig, out: &mut dyn std::io::Write) -> Result<(), Failure> {
    for (_, event) in rig.take_events() {
        if let Event::StateChanged { from, to } = event {
            writeln!(
                out,
                "state: {} -> {}",
                from.map_or("unknown", State::name),
                to.map_or("unknown", State::name)
            )?;
        }
    }
    Ok(())
}

/// `value` within the file's limits of (index, 0).
fn clamp(table: &LoadedTable, index: u16, value: u32) -> u32 {
    let Some(info) = table.entry(index, 0) else {
        return value;
    };
    let int = |n: Option<Number>| match n {
        Some(Number::Int(v)) => Some(v),
        Some(Number::Real(v)) => Some(v as i128),
        None => None,
    };
    let mut v = i128::from(value);
    if let Some(high) = int(info.high_limit) {
        v = v.min(high);
    }
    if let Some(low) = int(info.low_limit) {
        v = v.max(low);
    }
    u32::try_from(v.max(1)).unwrap_or(value)
}

/// [`DISTANCE`] away from `start`, towards the side with room when the
/// software position limits 0x607D are active.
fn pick_target(rig: &mut dyn Rig, table: &LoadedTable, start: i64) -> i64 {
    let limit = |sub| table.entry(0x607D, sub).is_some();
    if limit(1) && limit(2) {
        let min = read_sub(rig, table, 0x607D, 1).unwrap_or(i64::MIN);
        let max = read_sub(rig, table, 0x607D, 2).unwrap_or(i64::MAX);
        if min < max {
            if max.saturating_sub(start) >= DISTANCE {
                return start + DISTANCE;
            }
            if start.saturating_sub(min) >= DISTANCE {
                return start - DISTANCE;
            }
            return min / 2 + max / 2;
        }
    }
    start + DISTANCE
}

/// (index, sub) by SDO as an integer of the file's type; `None` when the
/// upload fails or the type has no fixed size.
fn read_sub(rig: &mut dyn Rig, table: &LoadedTable, index: u16, sub: u8) -> Option<i64> {
    let info: &ObjectInfo = table.entry(index, sub)?;
    let data = rig.upload(index, sub).ok()?;
    let size = info.data_type.size()?.min(8);
    let mut raw = [0u8; 8];
    let len = data.len().min(size);
    raw.get_mut(..len)?.copy_from_slice(data.get(..len)?);
    let v = i64::from_le_bytes(raw);
    if info.data_type.is_signed() && size < 8 {
        let shift = 64 - 8 * size as u32;
        Some((v << shift) >> shift)
    } else {
        Some(v)
    }
}

/// (index, 0) by SDO, `None` when the file lacks it.
fn read_int(rig: &mut dyn Rig, table: &LoadedTable, index: u16) -> Result<Option<i64>, Failure> {
    if table.entry(index, 0).is_none() {
        return Ok(None);
    }
    read_sub(rig, table, index, 0).map(Some).ok_or_else(|| {
        Failure(format!(
            "{}: reading {index:#06X} by SDO failed",
            table.path.display()
        ))
    })
}

#[cfg(test)]
mod tests;
