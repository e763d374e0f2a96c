//! `eds2rust net`: commands on a whole network, described by a bus file
//! (lely dcfgen's YAML, as ros2_canopen users write it).

pub(crate) mod boot;
mod check;
mod dcf;
pub(crate) mod load;
pub(crate) mod review;

use std::process::ExitCode;

use clap::Subcommand;

#[derive(Subcommand)]
pub(crate) enum NetCommand {
    /// Checks a whole bus: node ids, COB-IDs, PDO mappings, SDO writes,
    /// heartbeat times, bus load.
    Check(check::CheckArgs),
    /// Writes master.dcf and the concise DCFs (.bin) that dcfgen writes.
    Dcf(dcf::DcfArgs),
    /// Boots the network as a CiA 302-2 master (identity check,
    /// configuration, start) over SocketCAN, or its own simulation with
    /// --simulate; one row per slave.
    Boot(boot::BootArgs),
}

pub(crate) fn run(command: NetCommand) -> ExitCode {
    match command {
        NetCommand::Check(args) => check::run(args),
        NetCommand::Dcf(args) => dcf::run(args),
        NetCommand::Boot(args) => boot::run(args),
    }
}
