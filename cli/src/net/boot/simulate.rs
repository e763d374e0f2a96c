//! `net boot --simulate`: the network's own simulation
//! (`eds2rust_sim::network`: every slave from its device file, at its node
//! id, with the generic CiA 402 drive where the device is a drive, and the
//! `--fault`s of `eds2rust sim --network`) behind the master's bus in this
//! process (`InlineBus`), in virtual time: a manual clock the simulation
//! moves, so the boot takes as long as the CPU needs and the times shown
//! are the simulated ones.

use eds2rust_runtime::transport::ManualClock;
use eds2rust_sim::network::{InlineBus, Network, Simulation};
use std::io::Write;

use crate::net::load;

/// The simulation of `network` with the faults of `fault_texts`
/// (`NODE:KIND[=VALUE]`), on a manual clock; `Err` with the usage error
/// of a fault that does not parse or fit.
pub(crate) fn simulation(
    network: &load::Network,
    fault_texts: &[String],
) -> Result<(InlineBus<Simulation>, ManualClock), String> {
    let simulated = Network::from_bus(&network.bus, &network.configured);
    let faults = crate::sim::fault::parse_all(fault_texts, &simulated)?;
    if !simulated.warnings.is_empty() {
        let mut err = std::io::stderr().lock();
        for warning in &simulated.warnings {
            let _ = writeln!(err, "{}", eds2rust::text::terminal_line(warning));
        }
    }
    let time = ManualClock::new();
    let simulation = simulated
        .simulation(&faults, time.now())
        .map_err(|e| e.to_string())?;
    Ok((InlineBus::manual(simulation, time.clone()), time))
}
