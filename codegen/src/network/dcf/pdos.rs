//! The master's PDOs in master.dcf: one RPDO per slave TPDO and one TPDO
//! per slave RPDO, numbered in slave order; the 0x2000/0x2200 objects they
//! map (each object of a slave once, in the PDO that maps it first); the
//! remote PDO mappings (0x5800–0x5FFF).

use crate::ir::{DataType, Device, ObjectKind};
use crate::network::config::{Configured, Node, Pdo};
use crate::network::model::Bus;

use super::Difference;
use super::ini::{HIGHEST, HIGHEST_PDO, Ini, array, hex, record, sub, values, var};

/// The RPDOs (master receives) or TPDOs (master sends) of the master.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Side {
    Rx,
    Tx,
}

impl Side {
    pub(super) fn comm_base(self) -> u32 {
        match self {
            Side::Rx => 0x1400,
            Side::Tx => 0x1800,
        }
    }
    /// Where the master's objects mapped by this side's PDOs live.
    fn object_base(self) -> u32 {
        match self {
            Side::Rx => 0x2000,
            Side::Tx => 0x2200,
        }
    }
    fn name(self) -> &'static str {
        match self {
            Side::Rx => "RPDO",
            Side::Tx => "TPDO",
        }
    }
}

/// One master PDO: the slave PDO it mirrors.
struct Mirror<'a> {
    node: &'a Node,
    pdo: &'a Pdo,
    /// False for a PDO the bus file disables (see [`Node::disabled_tpdos`]).
    enabled: bool,
}

/// The master PDOs of one side with where each mapped slave object lands
/// in the master: `values[k][j]` is the mapping entry `j` of PDO `k`, and
/// `objects[k]` the slave objects that PDO `k` maps first (each object of
/// a slave gets one master sub-object, in the PDO that maps it first).
pub(super) struct MasterPdos<'a> {
    pub(super) side: Side,
    mirrors: Vec<Mirror<'a>>,
    values: Vec<Vec<u32>>,
    objects: Vec<Vec<MappedInfo>>,
}

/// What the master declares of a mapped slave object.
struct MappedInfo {
    name: String,
    data_type: u16,
}

impl<'a> MasterPdos<'a> {
    pub(super) fn new(bus: &'a Bus, configured: &'a Configured, side: Side) -> Self {
        let mut pdos = MasterPdos {
            side,
            mirrors: Vec::new(),
            values: Vec::new(),
            objects: Vec::new(),
        };
        for node in &configured.nodes {
            let Some(slave) = bus.slaves.get(node.slave) else {
                continue;
            };
            // A slave's TPDOs are the master's RPDOs and the other way round.
            let (running, disabled) = match side {
                Side::Rx => (&node.tpdos, &node.disabled_tpdos),
                Side::Tx => (&node.rpdos, &node.disabled_rpdos),
            };
            let mut list: Vec<(&Pdo, bool)> = running.iter().map(|p| (p, true)).collect();
            list.extend(disabled.iter().map(|p| (p, false)));
            list.sort_by_key(|(p, _)| p.number);
            let mut seen: Vec<((u16, u8), u32)> = Vec::new();
            for (pdo, enabled) in list {
                let k = pdos.mirrors.len() as u32;
                let (mut values, mut objects) = (Vec::new(), Vec::new());
                for mapped in &pdo.mapping {
                    let key = (mapped.index, mapped.subindex);
                    let value = match seen.iter().find(|(k, _)| *k == key) {
                        Some((_, value)) => *value,
                        None => {
                            let info = mapped_info(&slave.device, mapped.index, mapped.subindex);
                            objects.push(MappedInfo {
                                name: format!("{}: {}", slave.name, info.name),
                                data_type: info.data_type,
                            });
                            let value = (side.object_base() + k) << 16
                                | (objects.len() as u32 & 0xFF) << 8
                                | u32::from(mapped.bits);
                            seen.push((key, value));
                            value
                        }
                    };
                    values.push(value);
                }
                pdos.values.push(values);
                pdos.objects.push(objects);
                pdos.mirrors.push(Mirror { node, pdo, enabled });
            }
        }
        pdos
    }

    pub(super) fn len(&self) -> u32 {
        self.mirrors.len() as u32
    }

    /// The indices of the master objects this side maps, ascending.
    pub(super) fn object_indices(&self) -> impl Iterator<Item = u32> + '_ {
        let base = self.side.object_base();
        (0..self.len())
            .filter(move |&k| !self.objects[k as usize].is_empty())
            .map(move |k| base + k)
    }
}

/// The name and data type code of a slave's mapped object (a dummy entry:
/// the type it stands for).
fn mapped_info(device: &Device, index: u16, sub_index: u8) -> MappedInfo {
    if index < 0x1000 {
        return MappedInfo {
            name: DataType::from_code(index).name().to_string(),
            data_type: index,
        };
    }
    match device
        .objects
        .get(&index)
        .and_then(|o| o.entries.get(&sub_index).map(|e| (o, e)))
    {
        Some((object, entry)) => {
            let name = if matches!(object.kind, ObjectKind::Var | ObjectKind::Domain) {
                object
                    .denotation
                    .clone()
                    .unwrap_or_else(|| object.name.clone())
            } else {
                entry
                    .denotation
                    .clone()
                    .unwrap_or_else(|| entry.name.clone())
            };
            MappedInfo {
                name,
                data_type: entry.data_type.code(),
            }
        }
        None => MappedInfo {
            name: format!("0x{index:04X}/{sub_index}"),
            data_type: 0,
        },
    }
}

/// The COB-ID of a mirrored PDO in the master: the slave's, not valid when
/// the bus file disables the slave's PDO.
fn master_cob_id(mirror: &Mirror, index: u32, differences: &mut Vec<Difference>) -> u32 {
    if mirror.enabled {
        return mirror.pdo.cob_id;
    }
    differences.push(Difference::DisabledPdoInvalid {
        index: index as u16,
        node: mirror.node.name.clone(),
        number: mirror.pdo.number,
    });
    mirror.pdo.cob_id | 0x8000_0000
}

/// The communication and mapping parameters of every master PDO.
pub(super) fn write_parameters(
    ini: &mut Ini,
    rx: &MasterPdos,
    tx: &MasterPdos,
    differences: &mut Vec<Difference>,
) {
    for pdos in [rx, tx] {
        for (k, mirror) in pdos.mirrors.iter().enumerate() {
            let index = pdos.side.comm_base() + k as u32;
            let pdo = mirror.pdo;
            let cob_id = hex(master_cob_id(mirror, index, differences), 8);
            let transmission = hex(pdo.transmission, 2);
            let timer = pdo.master_event_timer.to_string();
            // (sub-index, name, data type, default)
            let subs: Vec<(u32, &str, u32, Option<String>)> = match pdos.side {
                Side::Rx => vec![
                    (1, "COB-ID used by RPDO", 0x0007, Some(cob_id)),
                    (2, "transmission type", 0x0005, Some(transmission)),
                    (3, "inhibit time", 0x0006, None),
                    (4, "compatibility entry", 0x0005, None),
                    (5, "event-timer", 0x0006, Some(timer)),
                ],
                Side::Tx => vec![
                    (1, "COB-ID used by TPDO", 0x0007, Some(cob_id)),
                    (2, "transmission type", 0x0005, Some(transmission)),
                    (
                        3,
                        "inhibit time",
                        0x0006,
                        Some(pdo.inhibit_time.to_string()),
                    ),
                    (4, "reserved", 0x0005, None),
                    (5, "event timer", 0x0006, Some(timer)),
                    (
                        6,
                        "SYNC start value",
                        0x0005,
                        Some(pdo.master_sync_start.to_string()),
                    ),
                ],
            };
            let title = format!("{} communication parameter", pdos.side.name());
            record(ini, index, &title, subs.len() as u32, HIGHEST_PDO);
            for (s, name, data_type, default) in subs {
                sub(ini, index, s, name, data_type, "rw", default);
            }
        }
        mappings(ini, pdos);
    }
}

/// The objects the master's PDOs map (0x2000+ for RPDOs, 0x2200+ for
/// TPDOs) and, with `remote_pdo`, the remote PDO mappings.
pub(super) fn write_mapped_objects(
    ini: &mut Ini,
    rx: &MasterPdos,
    tx: &MasterPdos,
    remote_pdo: bool,
) {
    for pdos in [rx, tx] {
        let access = if pdos.side == Side::Rx { "rww" } else { "rwr" };
        for (k, objects) in pdos.objects.iter().enumerate() {
            if objects.is_empty() {
                continue;
            }
            let index = pdos.side.object_base() + k as u32;
            let title = format!(
                "Mapped application objects for {} {}",
                pdos.side.name(),
                k + 1
            );
            record(ini, index, &title, objects.len() as u32, HIGHEST);
            for (i, object) in objects.iter().enumerate() {
                sub(
                    ini,
                    index,
                    i as u32 + 1,
                    &object.name,
                    u32::from(object.data_type),
                    access,
                    None,
                )
                .key("PDOMapping", 1);
            }
        }
    }
    if remote_pdo {
        remote(ini, rx, 0x5800, 0x5A00, "TPDO");
        remote(ini, tx, 0x5C00, 0x5E00, "RPDO");
    }
}

/// The 0x16xx/0x1Axx mapping arrays of one side.
fn mappings(ini: &mut Ini, pdos: &MasterPdos) {
    let title = format!("{} mapping parameter", pdos.side.name());
    for (k, values_k) in pdos.values.iter().enumerate() {
        let index = pdos.side.comm_base() + 0x200 + k as u32;
        ini.section(format!("{index:04X}"))
            .key("ParameterName", &title)
            .key("ObjectType", "0x09")
            .key("DataType", hex(0x0007u32, 4))
            .key("AccessType", "rw")
            .key("CompactSubObj", values_k.len());
        let entries = values_k
            .iter()
            .enumerate()
            .map(|(j, v)| ((j + 1).to_string(), hex(*v, 8)))
            .collect();
        values(ini, index, entries);
    }
}

/// The remote PDO objects of one side: which slave PDO each master PDO is
/// and what it maps in the slave.
fn remote(ini: &mut Ini, pdos: &MasterPdos, number_base: u32, mapping_base: u32, slave_side: &str) {
    for (k, mirror) in pdos.mirrors.iter().enumerate() {
        let value = u32::from(mirror.pdo.number) << 8 | u32::from(mirror.node.node_id);
        let title = format!("Remote {slave_side} number and node-ID");
        var(
            ini,
            number_base + k as u32,
            &title,
            0x0007,
            "rw",
            Some(hex(value, 8)),
        );
    }
    for (k, mirror) in pdos.mirrors.iter().enumerate() {
        let index = mapping_base + k as u32;
        let title = format!("Remote {slave_side} mapping parameter");
        array(ini, index, &title, 0x0007, "rw", mirror.pdo.mapping.len());
        let entries = mirror
            .pdo
            .mapping
            .iter()
            .enumerate()
            .map(|(i, mapped)| ((i + 1).to_string(), hex(mapped.raw(), 8)))
            .collect();
        values(ini, index, entries);
    }
}
