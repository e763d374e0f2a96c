//! `eds2rust net boot BUS --iface can0`: boots a network as a CiA 302-2
//! master does (`eds2rust::network::boot_plan`, run by the runtime's
//! blocking master over SocketCAN), and prints one row per slave: node id,
//! name, identity check, configuration, state, time taken and, for a
//! failure, the boot error (its status letter A–O with what it means, the
//! object and the expected and found values). `--simulate` boots the
//! network's own simulation in this process, on the virtual bus, with the
//! `--fault`s of `eds2rust sim --network` (`simulate.rs`); `--run` keeps
//! the network running after its boot, one line per slave event
//! (`run.rs`); the table, the summary and the JSON are `report.rs`'s.
//!
//! Exit status: 0 when every mandatory slave is operational (booted, when
//! the network does not start its slaves), 1 when one is not, the boot
//! was not decided within `--timeout`, the bus failed or the bus file has
//! errors, 2 on usage errors.

mod report;
mod run;
pub(crate) mod simulate;

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::{Args, ValueEnum};
use eds2rust_runtime::blocking::{self, Error};
use eds2rust_runtime::boot::{NetworkPlan, SlaveStatus};
use eds2rust_runtime::master;
use eds2rust_runtime::transport::{Bus, Clock};

use crate::ReadArgs;
use crate::live::bus::LiveBus;

pub(crate) use report::{Outcome, render_json, render_summary, render_text};

/// Output forms.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum BootFormat {
    /// A table, one row per slave, and a summary line.
    Text,
    /// One JSON object: the outcome and every slave's report.
    Json,
}

#[derive(Args)]
pub(crate) struct BootArgs {
    #[command(flatten)]
    read: ReadArgs,
    /// The SocketCAN interface the network is on (can0, vcan0).
    #[arg(
        long,
        short = 'i',
        value_name = "IFACE",
        required_unless_present = "simulate"
    )]
    iface: Option<String>,
    /// Boot the network's own simulation instead: every slave simulated
    /// from its device file, in this process, on the virtual bus.
    #[arg(long, conflicts_with = "iface")]
    simulate: bool,
    /// With --simulate: what goes wrong with a simulated slave,
    /// NODE:KIND[=VALUE] as `eds2rust sim --network` takes it (NODE a
    /// node id or a slave's name): missing, device-type=V, vendor-id=V,
    /// product-code=V, revision=V, serial=V, late-boot=T,
    /// power-loss=AT[+OFF], sdo-abort=INDEX:SUB[:CODE],
    /// heartbeat-stops=AT[+FOR], config-current. May be given several
    /// times.
    #[arg(
        long = "fault",
        value_name = "NODE:KIND[=VALUE]",
        requires = "simulate"
    )]
    faults: Vec<String>,
    /// The longest the whole boot may take (seconds: 2, 0.5, or 500ms,
    /// 2s, 1m). Default: the network's boot time (or the master's response
    /// time), plus the longest heartbeat wait, plus one SDO timeout, plus
    /// 20 ms per SDO step of the longest boot.
    #[arg(long, value_name = "SECONDS", value_parser = crate::monitor::parse_seconds)]
    timeout: Option<Duration>,
    /// After the boot, keep the network running (until Ctrl-C, or for
    /// --duration): the master's heartbeat, SYNC and supervision go on, a
    /// slave that resets or comes back is booted again; each such event
    /// is one line. The exit status is then that of the end.
    #[arg(long)]
    run: bool,
    /// With --run: stop after this time (seconds: 2, 0.5, or 500ms, 2s,
    /// 1m). Needed with --simulate (the simulation runs in virtual time).
    #[arg(long, value_name = "SECONDS", requires = "run", value_parser = crate::monitor::parse_seconds)]
    duration: Option<Duration>,
    #[arg(long, value_enum, default_value_t = BootFormat::Text)]
    format: BootFormat,
    /// The bus file (bus.yml).
    bus: PathBuf,
}

/// The SDO client's timeout per step the boot uses (the runtime's
/// default client configuration).
const SDO_TIMEOUT: Duration = Duration::from_millis(500);
/// What one SDO step of a boot is given in the default `--timeout`.
const SDO_STEP: Duration = Duration::from_millis(20);
/// The SDO reads of a boot besides its configuration: device type,
/// identity (4), software version, configuration date and time.
const BOOT_READS: usize = 8;

pub(crate) fn run(args: BootArgs) -> ExitCode {
    let options = match args.read.options() {
        Ok(options) => options,
        Err(message) => return usage(&message),
    };
    let Some(network) = super::load::read_configured(&args.bus, &options, "booted") else {
        return ExitCode::from(1);
    };
    let mut err = std::io::stderr().lock();
    let _ = write!(err, "{}", network.warnings.render());
    let plan = eds2rust::network::boot_plan(&network.bus, &network.configured);
    drop(err);
    if args.simulate {
        if args.run && args.duration.is_none() {
            return usage(
                "--run needs --duration with --simulate (the simulation runs in virtual time): \
                 --run --duration 10s",
            );
        }
        match simulate::simulation(&network, &args.faults) {
            Ok((bus, time)) => go(&args, &plan, bus, time.clock(), true),
            Err(message) => usage(&message),
        }
    } else {
        let iface = args.iface.as_deref().unwrap_or_default();
        match crate::live::bus::open_socketcan(iface) {
            Ok(bus) => go(&args, &plan, LiveBus::new(bus), Clock::new(), false),
            Err(message) => failed(&message),
        }
    }
}

/// Boots on `bus`, runs on with `--run`, prints; the exit status.
fn go<B: Bus>(
    args: &BootArgs,
    plan: &NetworkPlan,
    bus: B,
    clock: Clock,
    simulated: bool,
) -> ExitCode {
    let timeout = args.timeout.unwrap_or_else(|| default_timeout(plan));
    let (mut m, mut outcome) = match boot(bus, clock, plan, timeout) {
        Ok(booted) => booted,
        Err(message) => return failed(&message),
    };
    outcome.simulated = simulated;
    let name = args.bus.display().to_string();
    let duration = args.duration;
    if !args.run {
        let text = match args.format {
            BootFormat::Text => render_text(&name, plan, &outcome),
            BootFormat::Json => render_json(&name, plan, &outcome, &[]),
        };
        return exit(&text, plan, &outcome);
    }
    if args.format == BootFormat::Text
        && let Err(code) = crate::print(&render_text(&name, plan, &outcome))
    {
        return code;
    }
    let mut err = std::io::stderr();
    let stop = crate::monitor::stop_on_ctrl_c("net boot --run", &mut err);
    let until = match duration {
        Some(d) => format!("for {:.1} s", d.as_secs_f64()),
        None => "until Ctrl-C".into(),
    };
    let _ = writeln!(err, "net boot: running the network {until}");
    let lines = args.format == BootFormat::Text;
    let events = match run::supervise(&mut m, plan, &mut outcome, duration, &stop, lines) {
        Ok(events) => events,
        Err(message) => return failed(&message),
    };
    let text = match args.format {
        BootFormat::Text => render_summary(&name, plan, &outcome),
        BootFormat::Json => render_json(&name, plan, &outcome, &events),
    };
    exit(&text, plan, &outcome)
}

/// Prints `text`; 0 when the network runs, else 1.
fn exit(text: &str, plan: &NetworkPlan, outcome: &Outcome) -> ExitCode {
    if let Err(code) = crate::print(text) {
        return code;
    }
    if outcome.running(plan) {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

fn failed(message: &str) -> ExitCode {
    let _ = writeln!(std::io::stderr().lock(), "error: {message}");
    ExitCode::from(1)
}

/// The default `--timeout` (see [`BootArgs::timeout`]): the core's own
/// waits decide every boot before it; it only bounds a boot that hangs.
pub(crate) fn default_timeout(plan: &NetworkPlan) -> Duration {
    let wait = plan.boot_time.unwrap_or(plan.response_time);
    let heartbeat = plan
        .slaves
        .iter()
        .filter_map(|s| match s.supervision {
            eds2rust_runtime::boot::Supervision::Heartbeat(time) => Some(time),
            _ => None,
        })
        .fold(plan.response_time, Duration::max);
    let steps = plan
        .slaves
        .iter()
        .map(|s| BOOT_READS + s.plan.configuration.len())
        .max()
        .unwrap_or(0);
    wait + heartbeat + SDO_TIMEOUT + SDO_STEP * u32::try_from(steps).unwrap_or(u32::MAX)
}

/// Boots `plan`'s network on `bus` with the blocking master on `clock`
/// (its own boot-up message first), waiting at most `timeout` for the
/// boot to be decided. `Err` when the plan's master part cannot be set up
/// or the bus fails.
pub(crate) fn boot<B: Bus>(
    bus: B,
    clock: Clock,
    plan: &NetworkPlan,
    timeout: Duration,
) -> Result<(blocking::Master<B>, Outcome), String> {
    let core = master::Master::for_network(plan).map_err(|e| e.to_string())?;
    let mut m = blocking::Master::with_clock(bus, core, clock);
    m.start().map_err(|e| e.to_string())?;
    let started = m.now();
    let result = m.boot_network(plan.clone(), started + timeout);
    // The start commands of the boot's end are queued on the core.
    let flushed = m.flush();
    let ended = m.now();
    let (decided, slaves) = match result {
        Ok(report) => (Some(report.booted), report.slaves),
        Err(Error::DeadlinePassed) => {
            let slaves: Vec<SlaveStatus> = m
                .core()
                .network()
                .map(|n| n.slaves().cloned().collect())
                .unwrap_or_default();
            (None, slaves)
        }
        Err(e) => return Err(e.to_string()),
    };
    flushed.map_err(|e| e.to_string())?;
    let outcome = Outcome {
        decided,
        slaves,
        started,
        ended,
        timeout,
        simulated: false,
        ran: None,
    };
    Ok((m, outcome))
}

fn usage(message: &str) -> ExitCode {
    let _ = writeln!(std::io::stderr().lock(), "error: {message}");
    ExitCode::from(2)
}

#[cfg(test)]
mod tests;
