//! `eds2rust net dcf BUS -o DIR`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use crate::ReadArgs;

#[derive(Args)]
pub(crate) struct DcfArgs {
    #[command(flatten)]
    read: ReadArgs,
    /// Write the master's PDOs as remote PDO mappings (dcfgen's `-r`).
    #[arg(long, short = 'r')]
    remote_pdo: bool,
    /// The directory to write into.
    #[arg(long, short)]
    output: PathBuf,
    /// The bus file (bus.yml).
    bus: PathBuf,
}

pub(crate) fn run(args: DcfArgs) -> ExitCode {
    let _ = (args.read.options(), args.remote_pdo, args.output, args.bus);
    todo!("net-dcf helper")
}
