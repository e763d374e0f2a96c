//! The `eds2rust` command line: check and dump CANopen object dictionaries.
//!
//! Exit status: 0 when no input has an error, 1 when one has, 2 on usage errors.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use eds2rust::input::{Options, read_device};

#[derive(Parser)]
#[command(
    name = "eds2rust",
    version,
    about = "Reads CANopen object dictionaries (EDS/DCF files and YAML object tables) and reports on them"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Reads each file and prints its diagnostics with the source lines.
    Check {
        /// Turn warnings into errors.
        #[arg(long)]
        strict: bool,
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
        /// Turn warnings into errors.
        #[arg(long)]
        strict: bool,
        file: PathBuf,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    Json,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { strict, files } => check(&files, Options { strict }),
        Command::Dump {
            format: Format::Json,
            node_id,
            strict,
            file,
        } => dump(&file, node_id, Options { strict }),
    }
}

fn check(files: &[PathBuf], options: Options) -> ExitCode {
    let mut failed = false;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for path in files {
        let loaded = read_device(path, options);
        let d = &loaded.diagnostics;
        let _ = write!(out, "{}", d.render());
        let objects = loaded.device.as_ref().map_or(0, |dev| dev.objects.len());
        let _ = writeln!(
            out,
            "{}: {} objects, {} errors, {} warnings",
            path.display(),
            objects,
            d.error_count(),
            d.warning_count()
        );
        failed |= d.has_errors();
    }
    if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

fn dump(path: &std::path::Path, node_id: Option<u8>, options: Options) -> ExitCode {
    let loaded = read_device(path, options);
    let name = path.display().to_string();
    let json =
        eds2rust::dump::json::to_json(&name, loaded.device.as_ref(), &loaded.diagnostics, node_id);
    let text = serde_json::to_string_pretty(&json).expect("a serde_json::Value always serialises");
    // A closed pipe (`| head`) is not an error of ours.
    let _ = writeln!(std::io::stdout().lock(), "{text}");
    if loaded.diagnostics.has_errors() {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
