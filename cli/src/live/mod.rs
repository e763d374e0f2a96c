//! The live-bus commands (docs/live-bus.md): `sdo`, `nmt`, `scan`, `od
//! upload|download` and `lss`, over SocketCAN (`--iface can0`), every object
//! named and typed from `--od FILE` when one is given, raw otherwise.
//!
//! Each command runs on a [`bus::LiveBus`] through the runtime's blocking
//! master; the unit tests run them on the virtual bus against the seed-device
//! simulators, `tests/live_vcan.rs` runs the binary over vcan in the VM.
//!
//! Exit status: 0 done, 1 the operation failed (an abort, a timeout, no
//! answer, a value that differed on read-back), 2 usage errors (arguments,
//! unknown objects, values that do not parse, an unreadable `--od` file).

pub mod backup;
pub mod bus;
pub mod lss;
pub mod nmt;
pub mod od;
pub mod sdo;
pub use eds2rust_decode::value as values;

use std::fmt;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::{Args, Subcommand, ValueEnum};

use bus::LiveBus;

/// Why a live command failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LiveError {
    /// The command line, an object name, a value or the `--od` file is
    /// wrong: exit status 2.
    Usage(String),
    /// The bus or a node failed the operation: exit status 1.
    Failed(String),
}

impl fmt::Display for LiveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LiveError::Usage(m) | LiveError::Failed(m) => f.write_str(m),
        }
    }
}

impl LiveError {
    fn exit_code(&self) -> ExitCode {
        match self {
            LiveError::Usage(_) => ExitCode::from(2),
            LiveError::Failed(_) => ExitCode::from(1),
        }
    }
}

/// A failure writing to stdout (a closed pipe is not ours to report).
impl From<std::io::Error> for LiveError {
    fn from(e: std::io::Error) -> LiveError {
        LiveError::Failed(format!("cannot write the output: {e}"))
    }
}

/// `500ms`, `2s`, `1.5s`, `250us`; a bare number is milliseconds.
pub fn parse_duration(text: &str) -> Result<Duration, String> {
    let t = text.trim();
    let (number, scale) = if let Some(n) = t.strip_suffix("ms") {
        (n, 1e-3)
    } else if let Some(n) = t.strip_suffix("us") {
        (n, 1e-6)
    } else if let Some(n) = t.strip_suffix('s') {
        (n, 1.0)
    } else {
        (t, 1e-3)
    };
    number
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0 && *v * scale < 86_400.0)
        .map(|v| Duration::from_secs_f64(v * scale))
        .ok_or_else(|| format!("`{text}` is not a duration (e.g. 500ms, 2s)"))
}

fn node_arg(text: &str) -> Result<u8, String> {
    values::parse_int(text)
        .and_then(|n| u8::try_from(n).ok())
        .filter(|n| (1..=127).contains(n))
        .ok_or_else(|| format!("`{text}` is not a node id (1 to 127)"))
}

/// The bus options of every live command.
#[derive(Args, Debug, Clone)]
pub struct BusArgs {
    /// The SocketCAN interface (can0, vcan0).
    #[arg(long, short = 'i', value_name = "IFACE")]
    pub iface: Option<String>,
    /// Time a node has to answer each SDO frame (500ms, 2s; a bare number
    /// is milliseconds).
    #[arg(long, value_name = "TIME", value_parser = parse_duration, default_value = "500ms")]
    pub timeout: Duration,
}

impl BusArgs {
    fn open(&self) -> Result<LiveBus, LiveError> {
        match &self.iface {
            Some(iface) => LiveBus::open(iface),
            None => Err(LiveError::Usage(
                "--iface IFACE is required (a SocketCAN interface: can0, vcan0)".into(),
            )),
        }
    }
}

#[derive(Subcommand, Debug)]
pub enum SdoCommand {
    /// Reads objects of a node and prints them by their type (with --od:
    /// named, with unit and named values; raw bytes otherwise).
    Read(sdo::ReadArgs),
    /// Writes one object of a node, the value parsed by its type (--od or
    /// --type).
    Write(sdo::WriteArgs),
    /// Downloads a file into a DOMAIN object (a program: 0x1F50.1), by
    /// block transfer, with a progress bar.
    DownloadFile(sdo::DownloadFileArgs),
}

#[derive(Subcommand, Debug)]
pub enum OdCommand {
    /// Reads every readable object of a live node and writes a DCF with
    /// its values as ParameterValue (a configuration backup).
    Upload(backup::UploadArgs),
    /// Writes every writable ParameterValue of a DCF to a live node in a
    /// safe order, reads each back and reports what differed or was
    /// refused.
    Download(backup::DownloadArgs),
}

#[derive(Subcommand, Debug)]
pub enum LssCommand {
    /// Finds the LSS slaves without a node id by fastscan and prints their
    /// addresses (optionally assigning node ids).
    Scan(lss::ScanArgs),
    /// Gives one LSS slave a node id.
    SetNodeId(lss::SetNodeIdArgs),
}

/// The NMT commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum NmtVerb {
    /// Start remote node (operational).
    Start,
    /// Stop remote node (stopped).
    Stop,
    /// Enter pre-operational.
    Preop,
    /// Reset node (application and communication).
    Reset,
    /// Reset communication.
    ResetComm,
}

#[derive(Args, Debug)]
pub struct NmtArgs {
    pub verb: NmtVerb,
    #[command(flatten)]
    pub bus: BusArgs,
    /// The node.
    #[arg(long, short = 'n', value_parser = node_arg, required_unless_present = "all")]
    pub node: Option<u8>,
    /// Every node (NMT broadcast, node id 0); instead of --node.
    #[arg(long, conflicts_with = "node")]
    pub all: bool,
    /// Wait (up to 2 s) for the node's boot-up (resets) or a heartbeat in
    /// the new state; exit status 1 when none comes.
    #[arg(long, requires = "node")]
    pub confirm: bool,
}

#[derive(Args, Debug)]
pub struct ScanArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// How long to listen for boot-up and heartbeat messages first.
    #[arg(long, value_name = "TIME", value_parser = parse_duration, default_value = "1s")]
    pub listen: Duration,
    /// Time each node has to answer the probe (an SDO read of 0x1000).
    #[arg(long, value_name = "TIME", value_parser = parse_duration, default_value = "100ms")]
    pub probe_timeout: Duration,
    /// Only listen; probe no node by SDO.
    #[arg(long)]
    pub no_probe: bool,
}

/// Runs `f`, printing to stdout, with the opener of the bus of `args`
/// (called once the command line and the files have been checked); the
/// exit status.
fn on_bus(
    args: &BusArgs,
    f: impl FnOnce(&dyn Fn() -> Result<LiveBus, LiveError>, &mut dyn Write) -> Result<(), LiveError>,
) -> ExitCode {
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    // The last line may sit in the buffer: a failed flush is a failed write.
    let result = f(&|| args.open(), &mut out).and_then(|()| Ok(out.flush()?));
    drop(out);
    finish(result)
}

/// Prints the error (if any) and gives the exit status.
fn finish(result: Result<(), LiveError>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = std::io::stdout().flush();
            let _ = writeln!(std::io::stderr().lock(), "error: {e}");
            e.exit_code()
        }
    }
}

pub fn run_sdo(cmd: SdoCommand) -> ExitCode {
    match cmd {
        SdoCommand::Read(a) => on_bus(&a.to.bus.clone(), |open, out| sdo::read(open, &a, out)),
        SdoCommand::Write(a) => on_bus(&a.to.bus.clone(), |open, out| sdo::write(open, &a, out)),
        SdoCommand::DownloadFile(a) => on_bus(&a.to.bus.clone(), |open, out| {
            sdo::download_file(open, &a, out)
        }),
    }
}

pub fn run_nmt(a: NmtArgs) -> ExitCode {
    on_bus(&a.bus.clone(), |open, out| nmt::command(open, &a, out))
}

pub fn run_scan(a: ScanArgs) -> ExitCode {
    on_bus(&a.bus.clone(), |open, out| nmt::scan(open, &a, out))
}

pub fn run_od(cmd: OdCommand) -> ExitCode {
    match cmd {
        OdCommand::Upload(a) => on_bus(&a.bus.clone(), |open, out| backup::upload(open, &a, out)),
        OdCommand::Download(a) if a.dry_run => {
            let stdout = std::io::stdout();
            finish(backup::download_plan(&a, &mut stdout.lock()))
        }
        OdCommand::Download(a) => {
            on_bus(&a.bus.clone(), |open, out| backup::download(open, &a, out))
        }
    }
}

pub fn run_lss(cmd: LssCommand) -> ExitCode {
    match cmd {
        LssCommand::Scan(a) => on_bus(&a.bus.clone(), |open, out| lss::scan(open, &a, out)),
        LssCommand::SetNodeId(a) => {
            on_bus(&a.bus.clone(), |open, out| lss::set_node_id(open, &a, out))
        }
    }
}

/// The `--od` file, when given.
fn load_od(path: Option<&PathBuf>) -> Result<Option<od::Od>, LiveError> {
    path.map(|p| od::Od::load(p)).transpose()
}

#[cfg(test)]
mod tests;
