//! `eds2rust sim --network BUS --iface IFACE [--fault NODE:KIND[=VALUE]]...`:
//! every slave of a bus file simulated on one interface
//! (`eds2rust_sim::network`), each from its device file at the node id the
//! bus file gives, CiA 402 drives with the generic drive; the faults make
//! nodes go missing, answer with a wrong identity, boot late, lose power,
//! refuse a configuration write or stop their heartbeat. One line per
//! notable event, prefixed with the node and its name.

use std::io::{self, Write};
use std::path::Path;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

use eds2rust_runtime::transport::Bus;
use eds2rust_sim::network::{Event, Network, NodeFault, Simulation};

use super::{Labels, Runner, SimArgs, event_line, fault, open, read_input};
use crate::live::od::Od;

/// Runs `--network BUS`; the exit status (as `eds2rust sim FILE`).
pub fn run(args: &SimArgs, bus_file: &Path) -> ExitCode {
    let mut err = io::stderr();
    let loaded = Network::load(bus_file);
    let network = match read_input(bus_file, loaded, |n| &n.warnings, args.quiet, &mut err) {
        Ok(network) => network,
        Err(code) => return code,
    };
    let faults = match faults(args, &network) {
        Ok(faults) => faults,
        Err(message) => {
            let _ = writeln!(err, "error: {message}");
            return ExitCode::from(2);
        }
    };
    let (bus, stop) = match open(&args.iface, &mut err) {
        Ok(opened) => opened,
        Err(code) => return code,
    };
    simulate(
        args,
        &network,
        &faults,
        bus,
        &stop,
        &mut io::stdout(),
        &mut err,
    )
}

/// The `--fault` arguments, parsed against `network`.
pub fn faults(args: &SimArgs, network: &Network) -> Result<Vec<NodeFault>, String> {
    fault::parse_all(&args.faults, network)
}

/// Simulates `network` with `faults` on `bus` until `stop` is set or
/// `args.duration` ends: event lines to `out`, status lines and errors to
/// `err`; the exit status.
pub fn simulate(
    args: &SimArgs,
    network: &Network,
    faults: &[NodeFault],
    bus: Box<dyn Bus + Send>,
    stop: &AtomicBool,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> ExitCode {
    let mut runner = Runner::new(bus, &args.iface, args.duration, args.quiet, stop, out, err);
    let mut network = network.clone();
    network.time_scale = args.time_scale;
    let mut sim = match network.simulation(faults, runner.clock().now()) {
        Ok(sim) => sim,
        Err(e) => {
            let _ = writeln!(runner.err, "error: {e}");
            return ExitCode::from(2);
        }
    };
    // Names and types of each slave's entries for the event lines.
    let ods: Vec<Option<Od>> = network
        .slaves
        .iter()
        .map(|s| Od::load_with_overlays(&s.table.path, &[]).ok())
        .collect();
    if let Err(code) = runner.send_ready(&mut sim) {
        return code;
    }
    if !args.quiet {
        let _ = writeln!(
            runner.err,
            "sim: {}: {} slaves on {}; {}",
            network.file.display(),
            network.slaves.len(),
            args.iface,
            runner.until()
        );
        for slave in &network.slaves {
            let what = if slave.drive {
                "a CiA 402 drive"
            } else {
                "a generic device"
            };
            let mut line = format!(
                "sim:   node {} {}: {} ({what})",
                slave.node,
                slave.name,
                slave.table.path.display()
            );
            for f in faults.iter().filter(|f| f.node == slave.node) {
                line.push_str(&format!("; fault: {}", f.fault));
            }
            let _ = writeln!(runner.err, "{line}");
        }
    }
    runner.run(&mut sim, |sim: &Simulation, event: Event| {
        let (node, text) = match event {
            Event::Device(node, e) => {
                let i = network.slaves.iter().position(|s| s.node == node)?;
                let labels = Labels {
                    table: &network.slaves[i].table,
                    od: ods[i].as_ref(),
                };
                (node, event_line(&labels, sim.table(node)?, e)?)
            }
            Event::PoweredOn(node) => (node, "power on".to_string()),
            Event::PoweredOff(node) => (node, "power lost (fault)".to_string()),
            Event::HeartbeatStopped(node) => (node, "heartbeat stops (fault)".to_string()),
            Event::HeartbeatResumed(node) => (node, "heartbeat comes back".to_string()),
        };
        Some(format!(
            "node {node} {}: {text}",
            sim.name(node).unwrap_or("?")
        ))
    })
}

#[cfg(test)]
mod tests;
