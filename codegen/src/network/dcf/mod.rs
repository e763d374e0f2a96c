//! The files dcfgen writes for a bus: `master.dcf`, one concise DCF
//! (`NAME.bin`) per slave with SDO writes at boot, and `master.bin` when
//! the master has writes of its own. Equal to dcfgen's (dcf-tools 2.4.2,
//! `-r` for remote PDO mappings) entry by entry, except for the
//! [`Difference`]s, where dcfgen is wrong and we are not.

pub mod concise;
mod ini;
mod master;
mod pdos;

use std::fmt;

use super::config::{Configured, Node};
use super::model::Bus;

/// One file to write, by its name in the output directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputFile {
    pub name: String,
    pub bytes: Vec<u8>,
}

/// What `net dcf` writes for a bus.
#[derive(Debug, Clone)]
pub struct Written {
    /// In dcfgen's order: the slaves' `.bin` files, `master.dcf`,
    /// `master.bin`.
    pub files: Vec<OutputFile>,
    /// Where these files deliberately differ from dcfgen's.
    pub differences: Vec<Difference>,
}

/// A place where our master.dcf deliberately differs from dcfgen's.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Difference {
    /// The bus file disables a slave's PDO (`enabled: false`) and the
    /// slave's concise DCF makes it invalid, but the device file's COB-ID
    /// was valid: dcfgen keeps the master's mirror of it valid (the master
    /// would wait for, or send, a PDO that the slave no longer uses); we
    /// write it with bit 31 set, under the same number.
    DisabledPdoInvalid {
        index: u16,
        node: String,
        number: u16,
    },
    /// The master's heartbeat consumer time for a slave (its producer time
    /// times the multiplier) exceeds 65535 ms: dcfgen keeps the low 16 bits
    /// (a shorter time, so false heartbeat errors); we write 65535.
    HeartbeatClamped {
        node: String,
        entry: usize,
        time: u64,
    },
    /// The slave gives `configuration_file`: dcfgen stores it as
    /// `dcf_path` (unused by then) and ignores it; we write it as the
    /// slave's 0x1F22 upload file, as the key says.
    ConfigurationFile {
        node: String,
        node_id: u8,
        file: String,
    },
    /// A slave's device file names a product code (`[DeviceInfo]`) but has
    /// no 0x1018/2: dcfgen leaves its 0x1F86 entry out and still counts it
    /// in `NrOfEntries`; we count only the entries written.
    UnlistedProductCode { node: String },
}

impl fmt::Display for Difference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Difference::DisabledPdoInvalid {
                index,
                node,
                number,
            } => write!(
                f,
                "0x{index:04X}/1 mirrors {node}'s disabled PDO {number}: written not valid (dcfgen: valid)"
            ),
            Difference::HeartbeatClamped { node, entry, time } => write!(
                f,
                "0x1016/{entry}: consumer time of {node} {time} ms written as 65535 (dcfgen: {} ms)",
                time & 0xFFFF
            ),
            Difference::ConfigurationFile { node, file, .. } => write!(
                f,
                "0x1F22: {node}'s configuration_file {file} is its upload file (dcfgen ignores the key)"
            ),
            Difference::UnlistedProductCode { node } => write!(
                f,
                "0x1F86: {node} has no 0x1018/2, not counted (dcfgen counts it without an entry)"
            ),
        }
    }
}

/// Every file dcfgen writes for `bus`, with `remote_pdo` as its `-r`.
pub fn files(bus: &Bus, configured: &Configured, remote_pdo: bool) -> Written {
    let mut files: Vec<OutputFile> = configured
        .nodes
        .iter()
        .filter(|node| !node.concise.is_empty())
        .map(|node| OutputFile {
            name: format!("{}.bin", node.name),
            bytes: concise::encode(&node.concise),
        })
        .collect();
    let (text, differences) = master::master_dcf(bus, configured, remote_pdo);
    files.push(OutputFile {
        name: "master.dcf".to_string(),
        bytes: text.into_bytes(),
    });
    if !configured.master_concise.is_empty() {
        files.push(OutputFile {
            name: "master.bin".to_string(),
            bytes: concise::encode(&configured.master_concise),
        });
    }
    Written { files, differences }
}

/// The master's heartbeat consumer time for a slave: its producer time
/// times its multiplier (the slave's, else the options'), truncated as
/// dcfgen does, at most 65535 ms.
fn consumer_heartbeat_time(
    bus: &Bus,
    node: &Node,
    entry: usize,
    differences: &mut Vec<Difference>,
) -> u16 {
    let time = super::config::consumer_time(bus, node);
    u16::try_from(time).unwrap_or_else(|_| {
        differences.push(Difference::HeartbeatClamped {
            node: node.name.clone(),
            entry,
            time,
        });
        u16::MAX
    })
}

pub use super::config::heartbeat_product;

#[cfg(test)]
mod tests;
