//! `net boot --simulate`: the network's own simulation
//! (`eds2rust_sim::network`: every slave from its device file, at its node
//! id, with the generic CiA 402 drive where the device is a drive) behind
//! the master's bus in this process (`InlineBus`), in virtual time: a
//! manual clock the simulation moves, so the boot takes as long as the
//! CPU needs and the times shown are the simulated ones.

use std::io::Write;
use std::time::Duration;

use eds2rust_runtime::boot::NetworkPlan;
use eds2rust_runtime::transport::ManualClock;
use eds2rust_sim::network::{InlineBus, Network, NodeFault};

use super::Outcome;
use crate::net::load;

/// Boots `plan` against the simulation of `network` with `faults`.
pub(crate) fn boot(
    network: &load::Network,
    plan: &NetworkPlan,
    faults: &[NodeFault],
    timeout: Duration,
) -> Result<Outcome, String> {
    let simulated = Network::from_bus(&network.bus, &network.configured);
    if !simulated.warnings.is_empty() {
        let mut err = std::io::stderr().lock();
        for warning in &simulated.warnings {
            let _ = writeln!(err, "{}", eds2rust::text::terminal_line(warning));
        }
    }
    let time = ManualClock::new();
    let simulation = simulated
        .simulation(faults, time.now())
        .map_err(|e| e.to_string())?;
    let bus = InlineBus::manual(simulation, time.clone());
    let mut outcome = super::boot(bus, time.clock(), plan, timeout)?;
    outcome.simulated = true;
    Ok(outcome)
}
