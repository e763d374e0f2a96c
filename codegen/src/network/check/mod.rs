//! The whole-bus check (`eds2rust net check`): what no single device file
//! can show, found in the bus file and the network [`configure`]d from it.
//! Every diagnostic names the bus file, the line and the key it is about,
//! and says what to do where a fix is known. The rules, by topic:
//!
//! - `ids`: node ids out of range or colliding, COB-IDs of two producers
//!   colliding, PDO COB-IDs in the ranges CiA 301 restricts;
//! - `pdo`: mappings the bus file writes that do not fit the device, SDO
//!   writes that change PDOs behind the `rpdo`/`tpdo` sections, PDOs that
//!   are sent and never used or awaited and never sent;
//! - `heartbeat`: heartbeat consumer times that cannot hold, consumers
//!   of a heartbeat no one produces (heartbeat and node guarding both set
//!   is the configuration's `net::heartbeat-and-guarding`);
//! - `load`: the bus load estimate ([`BusLoad`]) and its limit.
//!
//! [`configure`]: super::configure

mod context;
mod heartbeat;
mod ids;
mod load;
mod pdo;
#[cfg(test)]
mod tests;

use crate::diag::Diagnostics;

use super::config::Configured;
use super::model::Bus;
use context::{Net, Report};

pub use context::{CheckLimits, DEFAULT_MAX_BUS_LOAD_PERCENT};
pub use load::{BusLoad, LoadItem, bus_load, frame_bits};

/// Checks the whole bus: every `net::` rule. The diagnostics point into
/// the bus file by line and key; to show the lines, render them together
/// with the reader's diagnostics (which hold the bus file's text) after
/// [`Diagnostics::span_lines`].
pub fn check(bus: &Bus, configured: &Configured, limits: &CheckLimits) -> Diagnostics {
    let mut report = Report::new(bus);
    let net = Net { bus, configured };
    ids::check(&net, &mut report);
    pdo::check(&net, &mut report);
    heartbeat::check(&net, &mut report);
    load::check(&net, limits, &mut report);
    report.diagnostics
}
