//! `eds2rust net check BUS`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use crate::ReadArgs;

#[derive(Args)]
pub(crate) struct CheckArgs {
    #[command(flatten)]
    read: ReadArgs,
    /// The bus file (bus.yml).
    bus: PathBuf,
}

pub(crate) fn run(args: CheckArgs) -> ExitCode {
    let _ = (args.read.options(), args.bus);
    todo!("net-check helper")
}
