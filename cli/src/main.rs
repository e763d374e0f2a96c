//! The `eds2rust` command line: check, dump, export and diff CANopen object
//! dictionaries, generate their Rust and list its API; and talk to live
//! nodes over SocketCAN (`sdo`, `nmt`, `scan`, `od upload|download`, `lss`:
//! the `live` module, docs/live-bus.md); simulate a device from its file on
//! SocketCAN (`sim`, docs/sim-cli.md).
//!
//! Exit status: 0 when no input has an error, 1 when one has, 2 on usage errors.
//! `diff`: 0 without changes at the `--fail-on` level, 1 with, 2 on usage or
//! input errors. Live commands: 0 done, 1 the operation failed on the bus,
//! 2 usage errors.
#![forbid(unsafe_code)]

mod decode;
mod live;
mod monitor;
mod net;
mod refusal;
// The unit tests' simulated devices: the rig of the tests crate (and of
// the vcan tests), one file for both crates.
#[cfg(test)]
#[allow(dead_code)] // the tests here use part of it
#[path = "../../tests/src/served.rs"]
mod served;
mod sim;

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};
use eds2rust::diag::Levels;
use eds2rust::input::{Options, read_device};

#[derive(Parser)]
#[command(
    name = "eds2rust",
    version,
    about = "Reads CANopen object dictionaries (EDS/DCF files and YAML object tables), reports on them and generates their Rust; talks to live nodes over SocketCAN"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Reads each file and prints its diagnostics with the source lines.
    Check {
        #[command(flatten)]
        read: ReadArgs,
        /// EDS/DCF files or YAML object tables (.yaml, .yml).
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Prints the object dictionary of one file.
    Dump {
        #[arg(long, value_enum, default_value_t = Format::Json)]
        format: Format,
        /// Resolve `$NODEID` formulas for this node id.
        #[arg(long, value_parser = clap::value_parser!(u8).range(1..=127))]
        node_id: Option<u8>,
        #[command(flatten)]
        read: ReadArgs,
        file: PathBuf,
    },
    /// Writes the object dictionary of one file in another format (a YAML
    /// table as a CiA 306 EDS). Nothing is written when the input has errors.
    Export {
        #[arg(long, value_enum, default_value_t = ExportFormat::Eds)]
        format: ExportFormat,
        /// Export this product variant of the device.
        #[arg(long)]
        variant: Option<String>,
        /// Write here instead of standard output (replaced only when complete).
        #[arg(long, short)]
        output: Option<PathBuf>,
        #[command(flatten)]
        read: ReadArgs,
        file: PathBuf,
    },
    /// Prints the generated Rust of one device (or writes it with -o).
    /// Diagnostics go to stderr; nothing is written when there is an error.
    Generate {
        /// A YAML overlay table (without `base:`) applied on the input; may
        /// be given several times, applied in order.
        #[arg(long = "overlay", value_name = "FILE")]
        overlays: Vec<PathBuf>,
        /// The path of the runtime crate in generated code (default
        /// `::eds2rust_runtime`).
        #[arg(long, value_name = "PATH")]
        runtime_path: Option<String>,
        /// Write here instead of standard output (replaced only when complete).
        #[arg(long, short)]
        output: Option<PathBuf>,
        #[command(flatten)]
        read: ReadArgs,
        /// An EDS/DCF file or a YAML object table.
        file: PathBuf,
    },
    /// Prints a compact listing of the generated API of one device, one
    /// line per public item (docs/api-listing.md), for a snapshot test; of
    /// a bus file, the network's wiring and every node's listing
    /// (docs/network.md). Diagnostics go to stderr; nothing is printed
    /// when there is an error.
    Api {
        /// A YAML overlay table (without `base:`) applied on the input; may
        /// be given several times, applied in order.
        #[arg(long = "overlay", value_name = "FILE")]
        overlays: Vec<PathBuf>,
        #[command(flatten)]
        read: ReadArgs,
        /// An EDS/DCF file, a YAML object table or a bus file.
        file: PathBuf,
    },
    /// Compares two versions of a device: every object, sub, type, access
    /// right, default, limit, name, semantic and default PDO that changed,
    /// each classified breaking, additive or compatible (docs/diff.md).
    /// Two bus files: the wiring and each node's device (docs/network.md).
    Diff {
        /// A YAML overlay applied on OLD; may be given several times, in order.
        #[arg(long = "old-overlay", value_name = "FILE")]
        old_overlays: Vec<PathBuf>,
        /// A YAML overlay applied on NEW; may be given several times, in order.
        #[arg(long = "new-overlay", value_name = "FILE")]
        new_overlays: Vec<PathBuf>,
        #[arg(long, value_enum, default_value_t = DiffFormat::Text)]
        format: DiffFormat,
        /// Exit 1 when a change of this severity or above exists.
        #[arg(long, value_enum, default_value_t = FailOn::Breaking)]
        fail_on: FailOn,
        /// Compare without the YAML-only layer (units, named values, bit
        /// fields, error tables, PDO labels): for an EDS against a YAML table.
        #[arg(long)]
        ignore_semantics: bool,
        #[command(flatten)]
        read: ReadArgs,
        /// The old version: an EDS/DCF file, a YAML object table or a bus file.
        old: PathBuf,
        /// The new version: an EDS/DCF file, a YAML object table or a bus file.
        new: PathBuf,
    },
    /// Decodes a recorded CAN trace into named, typed CANopen values
    /// (docs/decode.md): every frame, every SDO transfer, with the files of
    /// the nodes their PDO fields by name.
    Decode(decode::DecodeArgs),
    /// Decodes a live SocketCAN bus as `decode` decodes a trace: the record
    /// stream, or a table of the nodes (--table), and a chart of PDO fields
    /// (--plot), until --duration ends or Ctrl-C.
    Monitor(monitor::MonitorArgs),
    /// Simulates the device of an EDS/DCF file or YAML table, or every slave
    /// of a bus file (--network, with --fault), on a SocketCAN interface
    /// (docs/sim-cli.md): boot-up, SDO server, NMT, heartbeat, PDOs, CiA 402
    /// drives; one line per NMT change, SDO write and drive state change,
    /// until --duration ends or Ctrl-C.
    Sim(sim::SimArgs),
    /// Reads and writes objects of a live node by SDO (docs/live-bus.md).
    #[command(subcommand)]
    Sdo(live::SdoCommand),
    /// Sends an NMT command to one node or all nodes.
    Nmt(live::NmtArgs),
    /// Lists the nodes on a bus: boot-up and heartbeat messages heard, SDO
    /// probes of 0x1000 answered, with their identity (0x1018).
    Scan(live::ScanArgs),
    /// Backs up a live node's configuration into a DCF and writes it back.
    #[command(subcommand)]
    Od(live::OdCommand),
    /// Layer setting services (CiA 305): fastscan, node ids.
    #[command(subcommand)]
    Lss(live::LssCommand),
    /// Commands on a whole network described by a bus file (bus.yml).
    #[command(subcommand)]
    Net(net::NetCommand),
}

/// How strictly to read, and the levels of single rules.
#[derive(Args)]
pub(crate) struct ReadArgs {
    /// Turn warnings into errors (but those of allowed rules).
    #[arg(long)]
    strict: bool,
    /// Drop the warnings of this rule (for example `eds::unlisted-object`);
    /// may be given several times. Wins over a YAML table's `diagnostics:`.
    #[arg(long, value_name = "CODE")]
    allow: Vec<String>,
    /// Make the warnings of this rule errors; may be given several times.
    #[arg(long, value_name = "CODE")]
    deny: Vec<String>,
    /// The largest input file read, in bytes (default 64 MiB); a larger
    /// one is an error.
    #[arg(long, value_name = "BYTES", default_value_t = eds2rust::read::DEFAULT_MAX_INPUT_SIZE)]
    max_input_size: u64,
    /// Let a YAML table's `base:` name files in DIR too (by default only
    /// files under the current directory); may be given several times.
    #[arg(long, value_name = "DIR")]
    allow_base_dir: Vec<PathBuf>,
}

impl ReadArgs {
    /// The reading options, or the usage error of a code that names no rule.
    pub(crate) fn options(&self) -> Result<Options, String> {
        let mut levels = Levels::new();
        for code in &self.allow {
            levels.allow(code, "--allow");
        }
        for code in &self.deny {
            levels.deny(code, "--deny");
        }
        if let Some((code, close)) = levels.unknown().into_iter().next() {
            let mut message = format!("`{code}` is not a diagnostic rule");
            if let Some(close) = close {
                message.push_str(&format!("; did you mean `{close}`?"));
            }
            return Err(message);
        }
        Ok(Options {
            strict: self.strict,
            levels,
            max_input_size: self.max_input_size,
            project_dir: None,
            allow_base_dirs: self.allow_base_dir.clone(),
        })
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    Json,
}

#[derive(Clone, Copy, ValueEnum)]
enum ExportFormat {
    Eds,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum DiffFormat {
    /// One line per change and a summary line.
    Text,
    /// One JSON object.
    Json,
    /// A Markdown table for a review comment.
    Markdown,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum FailOn {
    /// Breaking changes.
    Breaking,
    /// Breaking or additive changes.
    Additive,
    /// Any change.
    Any,
    /// Exit 0 whatever changed.
    Never,
}

impl FailOn {
    /// The lowest severity that fails, `None` for `never`.
    fn threshold(self) -> Option<eds2rust::diff::Severity> {
        use eds2rust::diff::Severity;
        match self {
            FailOn::Breaking => Some(Severity::Breaking),
            FailOn::Additive => Some(Severity::Additive),
            FailOn::Any => Some(Severity::Compatible),
            FailOn::Never => None,
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let read = match &cli.command {
        Command::Check { read, .. }
        | Command::Dump { read, .. }
        | Command::Export { read, .. }
        | Command::Generate { read, .. }
        | Command::Api { read, .. }
        | Command::Diff { read, .. } => read.options(),
        Command::Decode(_)
        | Command::Monitor(_)
        | Command::Sim(_)
        | Command::Sdo(_)
        | Command::Nmt(_)
        | Command::Scan(_)
        | Command::Od(_)
        | Command::Lss(_)
        | Command::Net(_) => Ok(Options::default()),
    };
    let options = match read {
        Ok(options) => options,
        Err(message) => {
            let _ = writeln!(std::io::stderr().lock(), "error: {message}");
            return ExitCode::from(2);
        }
    };
    if let Command::Generate {
        runtime_path: Some(path),
        ..
    } = &cli.command
        && let Err(problem) = eds2rust::r#gen::rust::check_runtime_path(path)
    {
        let _ = writeln!(
            std::io::stderr().lock(),
            "error: --runtime-path `{}` {problem}\n  = {}",
            eds2rust::text::terminal_line(path),
            eds2rust::r#gen::rust::RUNTIME_PATH_HELP
        );
        return ExitCode::from(2);
    }
    match cli.command {
        Command::Decode(args) => decode::run(args),
        Command::Monitor(args) => monitor::run(args),
        Command::Sim(args) => sim::run(args),
        Command::Sdo(cmd) => live::run_sdo(cmd),
        Command::Nmt(args) => live::run_nmt(args),
        Command::Scan(args) => live::run_scan(args),
        Command::Od(cmd) => live::run_od(cmd),
        Command::Lss(cmd) => live::run_lss(cmd),
        Command::Net(cmd) => net::run(cmd),
        Command::Check { files, .. } => check(&files, &options),
        Command::Dump {
            format: Format::Json,
            node_id,
            file,
            ..
        } => dump(&file, node_id, &options),
        Command::Export {
            format: ExportFormat::Eds,
            variant,
            output,
            file,
            ..
        } => export(&file, variant.as_deref(), output.as_deref(), &options),
        Command::Generate {
            overlays,
            runtime_path,
            output,
            file,
            ..
        } => generate(
            &file,
            &overlays,
            output.as_deref(),
            &eds2rust::r#gen::rust::Options {
                runtime_path: runtime_path
                    .unwrap_or_else(|| eds2rust::r#gen::rust::Options::default().runtime_path),
                strict: options.strict,
            },
            &options,
        ),
        Command::Api { overlays, file, .. } => api(&file, &overlays, &options),
        Command::Diff {
            old_overlays,
            new_overlays,
            format,
            fail_on,
            ignore_semantics,
            old,
            new,
            ..
        } => diff(
            (&old, &old_overlays),
            (&new, &new_overlays),
            format,
            fail_on,
            &eds2rust::diff::Options { ignore_semantics },
            &options,
        ),
    }
}

/// Reads one side of a diff; `None` (its diagnostics printed) on errors.
fn diff_side(
    path: &std::path::Path,
    overlays: &[PathBuf],
    options: &Options,
) -> Option<eds2rust::ir::Device> {
    let err = &mut std::io::stderr().lock();
    refusal::device_or_refuse(path, overlays, options, "compared", err)
}

fn diff(
    (old, old_overlays): (&std::path::Path, &[PathBuf]),
    (new, new_overlays): (&std::path::Path, &[PathBuf]),
    format: DiffFormat,
    fail_on: FailOn,
    diff_options: &eds2rust::diff::Options,
    options: &Options,
) -> ExitCode {
    use eds2rust::diff::render;
    if eds2rust::network::is_bus_file(old) || eds2rust::network::is_bus_file(new) {
        let sides = ((old, old_overlays), (new, new_overlays));
        return net::review::diff(sides.0, sides.1, format, fail_on, diff_options, options);
    }
    let old_device = diff_side(old, old_overlays, options);
    let new_device = diff_side(new, new_overlays, options);
    let (Some(old_device), Some(new_device)) = (old_device, new_device) else {
        return ExitCode::from(2);
    };
    let changes = eds2rust::diff::diff_with(&old_device, &new_device, diff_options);
    let (old_name, new_name) = (old.display().to_string(), new.display().to_string());
    let text = match format {
        DiffFormat::Text => render::text(&changes),
        DiffFormat::Json => render::json(&old_name, &new_name, &changes),
        DiffFormat::Markdown => render::markdown(&old_name, &new_name, &changes),
    };
    if let Err(code) = print(&text) {
        return code;
    }
    let threshold = fail_on.threshold();
    let fails = threshold.is_some_and(|t| changes.iter().any(|c| c.severity >= t));
    if fails {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

fn check(files: &[PathBuf], options: &Options) -> ExitCode {
    let mut failed = false;
    for path in files {
        let loaded = read_device(path, options);
        let d = &loaded.diagnostics;
        let objects = loaded.device.as_ref().map_or(0, |dev| dev.objects.len());
        let text = format!(
            "{}{}: {} objects, {} errors, {} warnings\n",
            d.render(),
            eds2rust::text::terminal_line(&path.display().to_string()),
            objects,
            d.error_count(),
            d.warning_count()
        );
        if let Err(code) = print(&text) {
            return code;
        }
        failed |= d.has_errors();
    }
    if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

fn dump(path: &std::path::Path, node_id: Option<u8>, options: &Options) -> ExitCode {
    let mut loaded = read_device(path, options);
    if let (Some(n), Some(device)) = (node_id, &loaded.device) {
        let errors = eds2rust::dump::json::node_id_diagnostics(device, n);
        loaded.diagnostics.extend(errors);
    }
    let name = path.display().to_string();
    let text = eds2rust::dump::json::to_json_pretty(
        &name,
        loaded.device.as_ref(),
        &loaded.diagnostics,
        node_id,
    );
    if let Err(code) = print(&format!("{text}\n")) {
        return code;
    }
    if loaded.diagnostics.has_errors() {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

fn export(
    path: &std::path::Path,
    variant: Option<&str>,
    output: Option<&std::path::Path>,
    options: &Options,
) -> ExitCode {
    let loaded = read_device(path, options);
    let d = &loaded.diagnostics;
    // Diagnostics go to stderr so that stdout holds only the export.
    let _ = write!(std::io::stderr().lock(), "{}", d.render());
    let device = match (&loaded.device, d.has_errors()) {
        (Some(device), false) => device,
        _ => {
            let _ = writeln!(
                std::io::stderr().lock(),
                "{}: not exported: {} errors",
                path.display(),
                d.error_count()
            );
            return ExitCode::from(1);
        }
    };
    let text = match variant {
        None => eds2rust::r#gen::to_eds(device),
        Some(name) => match eds2rust::r#gen::to_eds_variant(device, name) {
            Ok(text) => text,
            Err(message) => {
                let _ = writeln!(std::io::stderr().lock(), "{}: {message}", path.display());
                return ExitCode::from(1);
            }
        },
    };
    write_output(output, &text)
}

fn generate(
    path: &std::path::Path,
    overlays: &[PathBuf],
    output: Option<&std::path::Path>,
    options: &eds2rust::r#gen::rust::Options,
    read: &Options,
) -> ExitCode {
    let generated = eds2rust::build::generate_device_reading(path, overlays, options, read);
    let code = match generated.result {
        Ok(out) => {
            let _ = write!(std::io::stderr().lock(), "{}", out.warnings.render());
            out.code
        }
        Err(diagnostics) => return refusal::failed(path, diagnostics, "generated"),
    };
    write_output(output, &code)
}

fn api(path: &std::path::Path, overlays: &[PathBuf], options: &Options) -> ExitCode {
    if eds2rust::network::is_bus_file(path) {
        return net::review::api(path, overlays, options);
    }
    match eds2rust::build::api_listing_files(path, overlays, options) {
        Ok(listing) => {
            let _ = write!(std::io::stderr().lock(), "{}", listing.warnings.render());
            match print(&listing.text) {
                Ok(()) => ExitCode::SUCCESS,
                Err(code) => code,
            }
        }
        Err(diagnostics) => refusal::failed(path, diagnostics, "listed"),
    }
}

/// Writes `text` to standard output and flushes it. A reader that left
/// (`| head`: a broken pipe) is not an error of ours: the rest is dropped
/// quietly. Any other failure (`> /dev/full`: no space) is printed, with
/// exit status 1 as `Err`.
pub(crate) fn print(text: &str) -> Result<(), ExitCode> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => {
            drop(out);
            let _ = writeln!(
                std::io::stderr().lock(),
                "error: cannot write to standard output: {e}"
            );
            Err(ExitCode::from(1))
        }
    }
}

/// Writes `text` to standard output ([`print`]), or whole to `output`
/// ([`eds2rust::build::write_whole`]: atomically, through a symlink, never
/// over a device, FIFO or directory).
fn write_output(output: Option<&std::path::Path>, text: &str) -> ExitCode {
    match output {
        None => match print(text) {
            Ok(()) => ExitCode::SUCCESS,
            Err(code) => code,
        },
        Some(out) => match eds2rust::build::write_whole(out, text.as_bytes()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(err) => {
                let _ = writeln!(
                    std::io::stderr().lock(),
                    "cannot write {}: {err}",
                    out.display()
                );
                ExitCode::from(1)
            }
        },
    }
}
