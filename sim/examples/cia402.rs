//! Any CiA 402 drive from its file: loads an EDS/DCF/YAML at run time,
//! simulates it with the generic CiA 402 behaviour on the in-process
//! virtual bus (in a thread), and drives it from a blocking master with
//! the runtime's `cia402::Drive`: enable (with fault reset), a profile
//! position move to a target and back, a quick stop. Every state
//! transition is printed, and `target reached at <position>` after each
//! move.
//!
//! `cargo run -p eds2rust-sim --example cia402 -- FILE [--node N]
//! [--time-scale F] [--trace] [--async]`
//!
//! Exit 0 when all of it worked; 1 with one message naming what the file
//! lacks (not a CiA 402 drive, no target position, ...) or what failed;
//! 2 for a bad command line.
//!
//! Writes go by SDO download (writes of objects the file lacks are skipped
//! and said so); the statusword is read by SDO upload every few
//! milliseconds. The glue between `Drive` and the master is
//! [`Session::drive_until`], one function, to be swapped for the runtime's
//! helper once it exists.

use std::fmt;
use std::path::PathBuf;
use std::time::{Duration, Instant as WallClock};

use eds2rust_runtime::blocking;
use eds2rust_runtime::cia402::{
    Drive, DriveConfig, Event, ModeOfOperation, Move, State, Statusword, Write, object,
};
use eds2rust_runtime::master;
use eds2rust_runtime::od::{NodeId, Number, ObjectInfo};
use eds2rust_sim::DeviceConfig;
use eds2rust_sim::cia402::{self, Cia402};
use eds2rust_sim::file::{self, LoadedTable};
use eds2rust_sim::harness::{self, Harness, MasterPort};

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
    /// `--node N`.
    pub node: Option<u8>,
    /// `--time-scale F`: the simulated mechanics F times faster.
    pub time_scale: f64,
    /// `--trace`: print every frame.
    pub trace: bool,
    /// `--async`: the tokio master (not yet).
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

const USAGE: &str = "usage: cia402 FILE [--node N] [--time-scale F] [--trace] [--async]";

/// Parses the arguments after the program name.
pub fn parse(args: impl IntoIterator<Item = String>) -> Result<Args, Failure> {
    let mut file = None;
    let mut out = Args {
        file: PathBuf::new(),
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
                out.time_scale = value
                    .parse()
                    .ok()
                    .filter(|v: &f64| v.is_finite() && *v > 0.0)
                    .ok_or_else(|| {
                        Failure(format!("--time-scale {value}: not a positive number"))
                    })?;
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

/// Whether the drive can run this example: 0x6040/0x6041, and what
/// profile position needs (one rule: `cia402::mode_needs`).
pub fn check(table: &LoadedTable) -> Result<(), Failure> {
    let file = table.path.display();
    let lacks = table.cia402_lacks();
    if !table.cia402 || !lacks.is_empty() {
        let what = if lacks.is_empty() {
            "0x1000 does not say 402 and 0x6040/0x6041 are missing".to_string()
        } else {
            lacks
                .iter()
                .map(|(index, name)| format!("no {index:#06X} {name}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        return Err(Failure(format!("{file}: not a CiA 402 drive: {what}")));
    }
    for (index, name) in cia402::mode_needs(ModeOfOperation::ProfilePosition) {
        if table.entry(*index, 0).is_none() {
            return Err(Failure(format!(
                "{file}: profile position needs {index:#06X} {name}, which this device does not have"
            )));
        }
    }
    Ok(())
}

/// Runs the scenario on the file `args.file`, printing to `out`.
pub fn run(args: &Args, out: &mut dyn std::io::Write) -> Result<Summary, Failure> {
    if args.asynchronous {
        return Err(Failure(
            "--async: not yet (the tokio master is being written); run without --async".into(),
        ));
    }
    let table = file::load(&args.file).map_err(|e| Failure(e.to_string()))?;
    check(&table)?;
    let node = args
        .node
        .and_then(NodeId::new)
        .or(table.node)
        .or(NodeId::new(DEFAULT_NODE))
        .ok_or_else(|| Failure("no node id".into()))?;
    let me = NodeId::new(if node.get() == 127 { 126 } else { 127 })
        .ok_or_else(|| Failure("no master node id".into()))?;
    writeln!(
        out,
        "{}: {} as node {node}",
        table.path.display(),
        table.product.as_deref().unwrap_or("CiA 402 drive")
    )
    .map_err(Failure::from)?;
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
    let core = master::Master::new(me, Duration::ZERO);
    let mut session = Session {
        master: blocking::Master::with_clock(harness.take_port()?, core, harness.clock()),
        drive: Drive::new(DriveConfig::default()),
        table: &table,
        node,
        out,
        time_scale: args.time_scale,
    };
    let result = session.scenario();
    harness.stop()?;
    result
}

/// The master, the CiA 402 helper and the file's table.
struct Session<'a> {
    master: blocking::Master<MasterPort>,
    drive: Drive,
    table: &'a LoadedTable,
    node: NodeId,
    out: &'a mut dyn std::io::Write,
    time_scale: f64,
}

impl Session<'_> {
    fn say(&mut self, line: String) -> Result<(), Failure> {
        writeln!(self.out, "{line}").map_err(Failure::from)
    }

    fn scenario(&mut self) -> Result<Summary, Failure> {
        self.say("enable: fault reset, Shutdown, Switch on, Enable operation".into())?;
        let now = self.master.now();
        self.drive.enable(now);
        self.drive_until("Operation enabled", |e| matches!(e, Event::Enabled))?;
        self.drive
            .set_mode(ModeOfOperation::ProfilePosition)
            .map_err(drive_error)?;
        let (velocity, ramp) = (
            self.clamp(object::PROFILE_VELOCITY, VELOCITY),
            self.clamp(object::PROFILE_ACCELERATION, RAMP),
        );
        let deceleration = self.clamp(object::PROFILE_DECELERATION, RAMP);
        self.drive.set_profile(velocity, ramp, deceleration);
        if let Some(max) = self.read_int(MAX_PROFILE_VELOCITY)?
            && max > 0
            && max < i64::from(velocity)
        {
            self.say(format!(
                "note: {MAX_PROFILE_VELOCITY:#06X} Max profile velocity = {max} limits the profile velocity"
            ))?;
        }
        let start = self.read_int(object::POSITION_ACTUAL_VALUE)?.unwrap_or(0);
        let target = self.pick_target(start);
        let mut summary = Summary {
            reached: Vec::new(),
            targets: Vec::new(),
            state: None,
        };
        for goal in [target, start] {
            self.say(format!(
                "profile position: move to {goal} at {velocity} units/s, {ramp} units/s²"
            ))?;
            let begun = self.master.now();
            let now = self.master.now();
            let goal32 = i32::try_from(goal)
                .map_err(|_| Failure(format!("target {goal} is out of range")))?;
            self.drive
                .move_to(now, goal32, Move::default())
                .map_err(drive_error)?;
            self.drive_until("target reached", |e| matches!(e, Event::TargetReached))?;
            let took = self.master.now().saturating_duration_since(begun);
            let position = self.read_int(object::POSITION_ACTUAL_VALUE)?;
            match position {
                Some(p) => self.say(format!(
                    "target reached at {p} (after {:.2} s of drive time)",
                    took.as_secs_f64() * self.time_scale
                ))?,
                None => self.say(format!(
                    "target reached at an unknown position (the device has no {:#06X} Position actual value)",
                    object::POSITION_ACTUAL_VALUE
                ))?,
            }
            summary.targets.push(goal);
            summary.reached.extend(position);
        }
        self.say("quick stop".into())?;
        let now = self.master.now();
        self.drive.quick_stop(now);
        self.drive_until("quick stop", |e| matches!(e, Event::QuickStopped))?;
        self.say(format!(
            "quick stopped in state {}",
            self.drive.state().map_or("unknown", State::name)
        ))?;
        summary.state = self.drive.state();
        Ok(summary)
    }

    /// `value` within the file's limits of (index, 0).
    fn clamp(&self, index: u16, value: u32) -> u32 {
        let Some(info) = self.table.entry(index, 0) else {
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
    fn pick_target(&mut self, start: i64) -> i64 {
        let limit = |sub| self.table.entry(0x607D, sub).is_some();
        if limit(1) && limit(2) {
            let min = self.read_sub(0x607D, 1).unwrap_or(i64::MIN);
            let max = self.read_sub(0x607D, 2).unwrap_or(i64::MAX);
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

    fn read_sub(&mut self, index: u16, sub: u8) -> Option<i64> {
        let info: &ObjectInfo = self.table.entry(index, sub)?;
        let data = self.master.upload(self.node, index, sub).ok()?;
        let size = info.data_type.size()?.min(8);
        let mut raw = [0u8; 8];
        raw.get_mut(..data.len().min(size))?
            .copy_from_slice(data.get(..data.len().min(size))?);
        let v = i64::from_le_bytes(raw);
        if info.data_type.is_signed() && size < 8 {
            let shift = 64 - 8 * size as u32;
            Some((v << shift) >> shift)
        } else {
            Some(v)
        }
    }

    /// (index, 0) by SDO, `None` when the file lacks it.
    fn read_int(&mut self, index: u16) -> Result<Option<i64>, Failure> {
        if self.table.entry(index, 0).is_none() {
            return Ok(None);
        }
        self.read_sub(index, 0)
            .map(Some)
            .ok_or_else(|| Failure(format!("node {}: reading {index:#06X} failed", self.node)))
    }

    /// Performs one of the helper's writes by SDO; a write of an object
    /// the file lacks is skipped.
    fn write(&mut self, w: Write) -> Result<(), Failure> {
        let Some(info) = self.table.entry(w.index, w.sub) else {
            return self.say(format!(
                "skipped: writing {:#06X} ({:?}): the device has no such object",
                w.index, w.value
            ));
        };
        self.master
            .download(self.node, w.index, w.sub, &w.value.to_le_bytes())
            .map_err(|e| {
                Failure(format!(
                    "{}: writing {:#06X} {} = {:?}: {e}",
                    self.table.path.display(),
                    w.index,
                    info.name,
                    w.value
                ))
            })
    }

    /// The glue between `Drive` and the master, in one place: the helper's
    /// writes by SDO download, the statusword by SDO upload into
    /// `Drive::update_statusword`, `Drive::handle_timeout` at its
    /// deadlines, until `done` accepts an event. A timeout, a failed
    /// operation or a fault ends it with an error naming what was awaited.
    fn drive_until(&mut self, what: &str, done: impl Fn(&Event) -> bool) -> Result<(), Failure> {
        let wall_limit = WallClock::now() + Duration::from_secs(120);
        loop {
            while let Some(w) = self.drive.poll_write() {
                self.write(w)?;
            }
            let sw = self
                .master
                .upload(self.node, object::STATUSWORD, 0)
                .map_err(|e| {
                    Failure(format!(
                        "node {}: reading the statusword 0x6041: {e}",
                        self.node
                    ))
                })?;
            let sw = Statusword(u16::from_le_bytes([
                sw.first().copied().unwrap_or(0),
                sw.get(1).copied().unwrap_or(0),
            ]));
            let now = self.master.now();
            self.drive.update_statusword(now, sw);
            if self.drive.poll_timeout().is_some_and(|at| at <= now) {
                self.drive.handle_timeout(now);
            }
            while let Some(event) = self.drive.poll_event() {
                match event {
                    Event::StateChanged { from, to } => self.say(format!(
                        "state: {} -> {} (statusword {:#06X})",
                        from.map_or("unknown", State::name),
                        to.map_or("unknown", State::name),
                        sw.0
                    ))?,
                    Event::Timeout { step, state } | Event::Failed { step, state } => {
                        return Err(Failure(format!(
                            "{}: waiting for {what}: the drive gave up in step {step:?} in state {}",
                            self.table.path.display(),
                            state.map_or("unknown", State::name)
                        )));
                    }
                    Event::FaultDetected if what != "Operation enabled" => {
                        return Err(Failure(format!(
                            "{}: fault while waiting for {what}",
                            self.table.path.display()
                        )));
                    }
                    _ => {}
                }
                if done(&event) {
                    while let Some(w) = self.drive.poll_write() {
                        self.write(w)?;
                    }
                    return Ok(());
                }
            }
            if WallClock::now() >= wall_limit {
                return Err(Failure(format!("no {what} within 120 s")));
            }
            self.master.run_for(POLL)?;
        }
    }
}

fn drive_error(e: eds2rust_runtime::cia402::DriveError) -> Failure {
    Failure(format!("drive helper: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn corpus(name: &str) -> Option<PathBuf> {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../shared/eds-corpus/files")
            .join(name);
        if path.exists() {
            Some(path)
        } else {
            use std::io::Write as _;
            let _ = writeln!(
                std::io::stderr(),
                "NOT RUN: cia402 example on {name}: ../shared/eds-corpus is not beside this checkout"
            );
            None
        }
    }

    fn table_has_position(path: &Path) -> bool {
        file::load(path).is_ok_and(|t| t.has(object::POSITION_ACTUAL_VALUE))
    }

    /// Every CiA 402 drive of the corpus moves there and back and
    /// quick-stops, or the example says which object the file lacks.
    #[test]
    fn every_corpus_drive_moves_or_names_what_it_lacks() {
        let Some(dir) = corpus("") else {
            return;
        };
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .expect("the corpus")
            .map(|e| e.expect("an entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "eds" || e == "dcf"))
            .collect();
        files.sort();
        let (mut reached, mut lacking) = (Vec::new(), Vec::new());
        for path in files {
            let Ok(table) = file::load(&path) else { continue };
            if !table.cia402 {
                continue;
            }
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let mut out = Vec::new();
            let mut a = args(path);
            a.time_scale = 50.0;
            match run(&a, &mut out) {
                Ok(summary) => {
                    let text = String::from_utf8_lossy(&out);
                    // A drive without 0x6064 reaches its targets without
                    // a position to read back.
                    if table_has_position(&a.file) {
                        assert_eq!(summary.reached, summary.targets, "{name}: {text}");
                    }
                    assert!(text.matches("target reached").count() == 2, "{name}: {text}");
                    reached.push(name);
                }
                Err(e) => {
                    assert!(e.0.contains("which this device does not have"), "{name}: {e}");
                    lacking.push(format!("{name}: {e}"));
                }
            }
        }
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "cia402 example: {} corpus drives reached their targets; {} lack an object: {lacking:?}",
            reached.len(),
            lacking.len()
        );
        assert!(reached.len() >= 20, "{reached:?}");
    }

    fn args(file: PathBuf) -> Args {
        Args {
            file,
            node: None,
            time_scale: 20.0,
            trace: false,
            asynchronous: false,
        }
    }

    #[test]
    fn moves_a_corpus_drive_there_and_back() {
        let Some(file) = corpus("ros2-canopen_cia402-slave.eds") else {
            return;
        };
        let mut out = Vec::new();
        let summary = run(&args(file), &mut out);
        let text = String::from_utf8_lossy(&out);
        let summary = summary.unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(summary.reached, summary.targets, "{text}");
        assert!(
            text.contains("state: Switched on -> Operation enabled"),
            "{text}"
        );
        assert!(
            text.contains(&format!("target reached at {}", summary.targets[0])),
            "{text}"
        );
        assert!(matches!(
            summary.state,
            Some(State::QuickStopActive | State::SwitchOnDisabled)
        ));
    }

    #[test]
    fn a_file_that_is_no_drive_says_so() {
        let Some(file) = corpus("cia401_sample.eds") else {
            return;
        };
        let e = run(&args(file), &mut Vec::new()).expect_err("refused");
        assert!(
            e.0.contains("not a CiA 402 drive: no 0x6040 Controlword"),
            "{e}"
        );
    }

    #[test]
    fn the_command_line() {
        let a = parse(["f.eds", "--node", "9", "--async"].map(String::from)).expect("parses");
        assert_eq!((a.node, a.asynchronous), (Some(9), true));
        assert!(
            run(&a, &mut Vec::new())
                .expect_err("not yet")
                .0
                .contains("not yet")
        );
        assert!(parse(["--node", "0", "f.eds"].map(String::from)).is_err());
        assert!(parse(Vec::<String>::new()).is_err());
    }
}
