//! What a bus file configures, as dcfgen computes it: each node's PDOs
//! after the bus file's `rpdo`/`tpdo` sections are applied to its device
//! file, the concise DCF (the SDO writes at boot, 0x1F22 format) per node,
//! the effective heartbeat and guarding times. One implementation, used by
//! `net dcf`, `net check`, the generated network and the network diff.

use crate::ir::pdo::MappedObject;

use super::model::Spot;

/// The configured network.
#[derive(Debug, Clone)]
pub struct Configured {
    /// The nodes dcfgen keeps (a slave without a node id is dropped with a
    /// warning), in the bus's slave order.
    pub nodes: Vec<Node>,
    /// The master's own concise DCF (master.bin): 0x1018/4, 0x1F55,
    /// 0x1F87, 0x1F88 writes; empty when dcfgen writes no master.bin.
    pub master_concise: Vec<ConciseEntry>,
}

/// One configured slave.
#[derive(Debug, Clone)]
pub struct Node {
    /// The slave's name (its YAML key).
    pub name: String,
    /// Position of its section in [`Bus::slaves`](super::model::Bus::slaves).
    pub slave: usize,
    pub node_id: u8,
    /// The PDOs the node receives (its RPDOs), valid and mapped ones only,
    /// by number.
    pub rpdos: Vec<Pdo>,
    /// The PDOs the node transmits (its TPDOs), valid and mapped ones only,
    /// by number.
    pub tpdos: Vec<Pdo>,
    /// The PDOs the bus file disables (`enabled: false`) whose device-file
    /// COB-ID was valid and whose mapping is not empty, by number: dcfgen
    /// keeps them valid in master.dcf; `net dcf` mirrors them there under
    /// their numbers, not valid. Not part of the running network.
    pub disabled_rpdos: Vec<Pdo>,
    pub disabled_tpdos: Vec<Pdo>,
    /// The node's concise DCF (`NAME.bin`) in dcfgen's order; empty when
    /// dcfgen writes no file for it.
    pub concise: Vec<ConciseEntry>,
    /// Effective heartbeat producer time (ms) after the bus file.
    pub heartbeat_producer: u16,
    /// Effective guard time (ms) and life time factor (0 when heartbeat wins).
    pub guard_time: u16,
    pub life_time_factor: u8,
    /// Whether the node consumes the master's heartbeat.
    pub heartbeat_consumer: bool,
    /// The COB-IDs of the node's EMCY (0x1014, bit 31 kept) and TIME (0x1012).
    pub emcy_cob_id: u32,
    pub time_cob_id: u32,
    /// Identity as the master checks it (0x1000, 0x1018 sub 1–4, from the
    /// device file's `[DeviceInfo]`/0x1018/`[DeviceComissioning]` and the
    /// bus file's `revision_number`/`serial_number`); 0 means not checked.
    pub device_type: u32,
    pub vendor_id: u32,
    pub product_code: u32,
    pub revision_number: u32,
    pub serial_number: u32,
    /// Where the master finds this node's files at run time (`dcf_path`).
    pub dcf_path: String,
    /// The node's concise DCF as the master names it in 0x1F22
    /// (`<dcf_path>/<name>.bin`, or the bus file's `configuration_file`);
    /// empty when there is none.
    pub configuration_file: String,
}

/// One PDO as configured.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pdo {
    /// 1-based PDO number on the node.
    pub number: u16,
    /// The COB-ID entry's value as configured (sub 1 of the communication
    /// parameter): bit 30 (no RTR) and bit 29 (29-bit identifier) kept, bit
    /// 31 clear (only valid PDOs are listed). [`Pdo::can_id`] gives the
    /// identifier.
    pub cob_id: u32,
    pub transmission: u8,
    pub inhibit_time: u16,
    pub event_timer: u16,
    pub sync_start: u8,
    /// Sub 5 of the master's mirror of this PDO in master.dcf: for a
    /// slave's RPDO (a master TPDO) the bus file's `event_timer`, for a
    /// slave's TPDO (a master RPDO) its `event_deadline`; 0 when absent.
    pub master_event_timer: u16,
    /// Sub 6 of the master TPDO that mirrors a slave's RPDO: the bus file's
    /// `sync_start` (0 when absent).
    pub master_sync_start: u8,
    pub mapping: Vec<MappedObject>,
    /// Where the bus file configures it (`None`: the device file's default).
    pub spot: Option<Spot>,
}

/// A PDO of transmission type 1 mapping `(index, sub-index, bits)`, for tests.
#[cfg(test)]
pub(crate) fn test_pdo(number: u16, cob_id: u32, mapping: &[(u16, u8, u8)]) -> Pdo {
    let mapping = mapping
        .iter()
        .map(|&(index, subindex, bits)| MappedObject {
            index,
            subindex,
            bits,
        })
        .collect();
    Pdo::new(number, cob_id, 1, mapping)
}

impl Pdo {
    /// A PDO with this number, COB-ID entry value, transmission type and
    /// mapping; no inhibit time, timers or SYNC start value, not from the
    /// bus file.
    pub fn new(number: u16, cob_id: u32, transmission: u8, mapping: Vec<MappedObject>) -> Pdo {
        Pdo {
            number,
            cob_id,
            transmission,
            inhibit_time: 0,
            event_timer: 0,
            sync_start: 0,
            master_event_timer: 0,
            master_sync_start: 0,
            mapping,
            spot: None,
        }
    }

    /// The CAN identifier the PDO is sent on, and whether it is a 29-bit one.
    pub fn can_id(&self) -> (u32, bool) {
        can_id(self.cob_id)
    }
}

/// The CAN identifier of a COB-ID entry's value (CiA 301: bits 0–28 the
/// identifier, bit 29 set for a 29-bit one; bits 30 and 31 are flags), and
/// whether it is a 29-bit one. An identifier above 0x7FF without bit 29 is
/// taken as a 29-bit one too.
pub fn can_id(raw: u32) -> (u32, bool) {
    let id = raw & 0x1FFF_FFFF;
    if raw & 0x2000_0000 != 0 || id > 0x7FF {
        (id, true)
    } else {
        (id, false)
    }
}

/// A heartbeat consumer time as dcfgen computes it from a producer time
/// (ms) and a multiplier: the product truncated towards zero (Python's
/// `int()`), 0 when negative or not a number. Where it goes into a 16-bit
/// entry, dcfgen keeps the low 16 bits.
pub fn heartbeat_product(time: u16, multiplier: f64) -> u64 {
    let product = f64::from(time) * multiplier;
    if product.is_nan() || product <= 0.0 {
        0
    } else {
        product as u64
    }
}

/// The consumer time (ms) a master uses for a slave's heartbeat: the
/// slave's producer time times its `heartbeat_multiplier` (or the bus
/// options'), as dcfgen computes it; not clamped to 16 bits.
pub fn consumer_time(bus: &super::model::Bus, node: &Node) -> u64 {
    let slave = bus.slaves.get(node.slave);
    let multiplier = slave
        .and_then(|s| s.heartbeat_multiplier.as_ref())
        .map_or(bus.options.heartbeat_multiplier, |at| at.value);
    heartbeat_product(node.heartbeat_producer, multiplier)
}

/// One entry of a concise DCF.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConciseEntry {
    pub index: u16,
    pub sub_index: u8,
    /// The value, little-endian, as long as its data type.
    pub data: Vec<u8>,
    /// The bus file's key that causes it, where there is one.
    pub spot: Option<Spot>,
}
