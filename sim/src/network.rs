//! A whole network simulated from its bus file (feature `files`): every
//! slave the bus file lists becomes a simulated device built from its
//! device file ([`crate::file`]), at the node id the bus file gives it,
//! with the generic CiA 402 drive ([`crate::cia402`]) for a device that
//! has a controlword and a statusword. All of them run as one sans-IO
//! [`Service`](eds2rust_runtime::Service), [`Simulation`], on the virtual
//! bus, on a SocketCAN interface, or behind a master's own bus in one
//! thread ([`InlineBus`], in virtual time for tests).
//!
//! [`Fault`]s make it go wrong as real machines do, per node: missing,
//! a wrong identity, a late boot, a power loss, an SDO abort during
//! configuration, a heartbeat that stops, a configuration already
//! current.
//!
//! ```no_run
//! # use eds2rust_runtime::{Instant, od::NodeId};
//! # use eds2rust_sim::network::{Fault, Network, NodeFault};
//! let network = Network::load("bus.yml")?;
//! let plan = network.plan().clone(); // what a master boots it by
//! let axis = NodeId::new(40).unwrap();
//! let sim = network.simulation(&[NodeFault::new(axis, Fault::Missing)], Instant::ZERO)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod fault;
mod inline;
mod node;
mod simulation;

use std::fmt;
use std::path::{Path, PathBuf};

use eds2rust::input::Options;
use eds2rust::network::config::Configured;
use eds2rust::network::model::Bus;
use eds2rust_runtime::Instant;
use eds2rust_runtime::boot::{NetworkPlan, SlaveConfig};
use eds2rust_runtime::od::NodeId;

pub use fault::{DEFAULT_ABORT, Fault, IdentityField, NodeFault};
pub use inline::{InlineBus, TICK};
pub use simulation::{Event, Simulation};

use crate::file::{self, LoadError, LoadedTable};
use node::{SimNode, with_values};

/// One slave of the network, as simulated.
#[derive(Debug, Clone)]
pub struct Slave {
    /// Its name in the bus file.
    pub name: String,
    /// The node id the bus file gives it.
    pub node: NodeId,
    /// Its device file's table.
    pub table: LoadedTable,
    /// Whether it runs the generic CiA 402 drive (its table has 0x6040
    /// and 0x6041).
    pub drive: bool,
}

/// A network read from its bus file, ready to be simulated.
#[derive(Debug, Clone)]
pub struct Network {
    /// The bus file.
    pub file: PathBuf,
    /// The slaves, in node id order.
    pub slaves: Vec<Slave>,
    /// What a CiA 302-2 master boots this network by
    /// (`eds2rust::network::boot_plan`).
    pub plan: NetworkPlan,
    /// The readers' warnings, one line each (`file:line: warning: ...`).
    pub warnings: Vec<String>,
    /// How much faster than real time the CiA 402 drives' mechanics move
    /// (1.0 by default).
    pub time_scale: f64,
}

/// A fault that does not fit the network.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FaultError {
    /// The fault.
    pub fault: NodeFault,
    /// Why it does not fit, and what to do.
    pub reason: String,
}

impl fmt::Display for FaultError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "fault `{}`: {}", self.fault, self.reason)
    }
}

impl std::error::Error for FaultError {}

impl Network {
    /// Reads the bus file at `path` and its device files (leniently, as
    /// `eds2rust check` without `--strict`), configures it as dcfgen does
    /// and builds every slave's table. Errors name file, line and key.
    pub fn load(path: impl AsRef<Path>) -> Result<Network, LoadError> {
        let path = path.as_ref();
        let loaded = eds2rust::network::read_file(path, &Options::lenient());
        let (bus, mut warnings) = file::accept(path, loaded.bus, &loaded.diagnostics)?;
        let (configured, diagnostics) = eds2rust::network::configure(&bus);
        let (configured, configure_warnings) = file::accept(path, Some(configured), &diagnostics)?;
        let mut network = Network::from_bus(&bus, &configured);
        warnings.extend(configure_warnings);
        warnings.append(&mut network.warnings);
        network.warnings = warnings;
        Ok(network)
    }

    /// The network of a bus file already read and configured
    /// (`eds2rust::network::read_file`, `configure`): its plan
    /// (`boot_plan`) and each configured slave's device table (with the
    /// conversion's warnings).
    pub fn from_bus(bus: &Bus, configured: &Configured) -> Network {
        let plan = eds2rust::network::boot_plan(bus, configured);
        let mut slaves = Vec::new();
        let mut warnings = Vec::new();
        for node in &configured.nodes {
            let (Some(id), Some(section)) = (NodeId::new(node.node_id), bus.slaves.get(node.slave))
            else {
                continue;
            };
            let mut table = file::from_device(&section.device_file, &section.device, Vec::new());
            warnings.append(&mut table.warnings);
            let drive = table.cia402_lacks().is_empty();
            slaves.push(Slave {
                name: node.name.clone(),
                node: id,
                table,
                drive,
            });
        }
        slaves.sort_by_key(|s| s.node);
        Network {
            file: bus.file.clone(),
            slaves,
            plan,
            warnings,
            time_scale: 1.0,
        }
    }

    /// The plan a master boots the network by.
    pub fn plan(&self) -> &NetworkPlan {
        &self.plan
    }

    /// The slave `node`.
    pub fn slave(&self, node: NodeId) -> Option<&Slave> {
        self.slaves.iter().find(|s| s.node == node)
    }

    /// The node id of the slave named `name` in the bus file.
    pub fn node_named(&self, name: &str) -> Option<NodeId> {
        self.slaves.iter().find(|s| s.name == name).map(|s| s.node)
    }

    /// Whether `faults` fit the network: each names a slave of it, and a
    /// [`Fault::ConfigurationCurrent`] a slave whose configuration carries
    /// a date and time (0x1020). The error says what to do.
    pub fn check(&self, faults: &[NodeFault]) -> Result<(), FaultError> {
        for fault in faults {
            let Some(slave) = self.slave(fault.node) else {
                let known: Vec<String> = self
                    .slaves
                    .iter()
                    .map(|s| format!("{} ({})", s.node, s.name))
                    .collect();
                return Err(FaultError {
                    fault: *fault,
                    reason: format!(
                        "{} has no slave with node id {}; its slaves: {}",
                        self.file.display(),
                        fault.node,
                        known.join(", ")
                    ),
                });
            };
            let dated = self
                .plan
                .slave(fault.node)
                .is_some_and(|s| s.plan.configuration_date_time.is_some());
            if fault.fault == Fault::ConfigurationCurrent && !dated {
                return Err(FaultError {
                    fault: *fault,
                    reason: format!(
                        "the configuration of `{}` in {} carries no date and time; add \
                         `sdo:` writes of 0x1020 sub 1 (date) and sub 2 (time) to its section",
                        slave.name,
                        self.file.display()
                    ),
                });
            }
        }
        Ok(())
    }

    /// The simulation of every slave, started at `now`, with `faults`
    /// (several per node are applied together); an error when they do not
    /// fit the network ([`Network::check`]). Each slave holds the identity
    /// and software version the network checks (0x1000, 0x1018 sub 1–4,
    /// 0x1F56 sub 1 where the plan expects a value), so that without faults
    /// every check passes.
    pub fn simulation(&self, faults: &[NodeFault], now: Instant) -> Result<Simulation, FaultError> {
        self.check(faults)?;
        let mut nodes = Vec::new();
        for slave in &self.slaves {
            let mine: Vec<Fault> = faults
                .iter()
                .filter(|f| f.node == slave.node)
                .map(|f| f.fault)
                .collect();
            // The device the network expects: the identity and software
            // version it checks (the device file's [DeviceInfo], the bus
            // file's revision, serial number and software version),
            // whatever the file's defaults say.
            let mut values = expected_values(self.plan.slave(slave.node));
            let mut stored = Vec::new();
            for fault in &mine {
                match *fault {
                    Fault::Identity(field, value) => values.push((field.object(), value)),
                    Fault::ConfigurationDate { date, time } => {
                        values.push(((0x1020, 1), date));
                        values.push(((0x1020, 2), time));
                    }
                    Fault::ConfigurationCurrent => {
                        // Checked: the configuration carries a date and time.
                        if let Some(config) = self.plan.slave(slave.node) {
                            stored = config
                                .plan
                                .configuration
                                .iter()
                                .map(|w| (w.index, w.sub_index, w.data.to_vec()))
                                .collect();
                        }
                    }
                    _ => {}
                }
            }
            let objects = with_values(slave.table.objects, &values);
            let mut node = SimNode::new(
                slave.name.clone(),
                slave.node,
                objects,
                slave.drive,
                &mine,
                now,
            );
            node.set_stored(stored);
            node.set_time_scale(self.time_scale);
            nodes.push(node);
        }
        Ok(Simulation::new(nodes, now))
    }
}

/// The identity values and software version `slave`'s plan checks (the
/// non-zero ones), as (object, value).
fn expected_values(slave: Option<&SlaveConfig>) -> Vec<((u16, u8), u32)> {
    let Some(plan) = slave.map(|s| &s.plan) else {
        return Vec::new();
    };
    let expected = [
        plan.device_type,
        plan.vendor_id,
        plan.product_code,
        plan.revision_number,
        plan.serial_number,
    ];
    let objects = IdentityField::ALL.iter().map(|field| field.object());
    objects
        .chain([(0x1F56, 1)])
        .zip(expected.into_iter().chain([plan.software_version]))
        .filter(|(_, value)| *value != 0)
        .collect()
}

#[cfg(test)]
mod tests;
