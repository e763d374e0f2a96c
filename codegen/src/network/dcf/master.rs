//! master.dcf: the master's object dictionary as dcfgen writes it for a
//! bus: its own communication objects, the CiA 302 per-slave arrays
//! (0x1F81 assignment, 0x1F84–0x1F86 expected identity, 0x1F22 concise
//! DCFs, 0x1F58 program data, 0x1016 heartbeat consumers, 0x1028 EMCY
//! consumers), one master RPDO per slave TPDO and one master TPDO per
//! slave RPDO (numbered in slave order), the 0x2000/0x2200 objects they
//! map, and with `remote_pdo` the remote PDO mappings (0x5800–0x5FFF).

use crate::ir::{DataType, Device, ObjectKind};
use crate::network::config::{Configured, Node, Pdo};
use crate::network::model::{Bus, SlaveSection};

use super::ini::{Ini, hex};
use super::{Difference, consumer_heartbeat_time};

/// Sub 0's name in a record (the PDO parameters write it lower-case).
const HIGHEST: &str = "Highest sub-index supported";
const HIGHEST_PDO: &str = "highest sub-index supported";

/// The RPDOs (master receives) or TPDOs (master sends) of the master.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Side {
    Rx,
    Tx,
}

impl Side {
    fn comm_base(self) -> u32 {
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
struct MasterPdos<'a> {
    side: Side,
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
    fn new(bus: &'a Bus, configured: &'a Configured, side: Side) -> Self {
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

    fn len(&self) -> u32 {
        self.mirrors.len() as u32
    }

    /// The indices of the master objects this side maps, ascending.
    fn object_indices(&self) -> impl Iterator<Item = u32> + '_ {
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

/// The whole master.dcf text, and where it deliberately differs from
/// dcfgen's for this bus.
pub(super) fn master_dcf(
    bus: &Bus,
    configured: &Configured,
    remote_pdo: bool,
) -> (String, Vec<Difference>) {
    let master = &bus.master;
    let rx = MasterPdos::new(bus, configured, Side::Rx);
    let tx = MasterPdos::new(bus, configured, Side::Tx);
    let mut differences = Vec::new();
    let uploads: Vec<(u8, &str)> = slaves(bus, configured)
        .filter(|(node, _)| !node.configuration_file.is_empty())
        .map(|(node, slave)| {
            if let Some(file) = &slave.configuration_file {
                differences.push(Difference::ConfigurationFile {
                    node: node.name.clone(),
                    node_id: node.node_id,
                    file: file.value.clone(),
                });
            }
            (node.node_id, node.configuration_file.as_str())
        })
        .collect();
    let software: Vec<(u8, &str)> = slaves(bus, configured)
        .filter_map(|(node, slave)| {
            let file = slave.software_file.as_ref()?.value.as_str();
            (!file.is_empty()).then_some((node.node_id, file))
        })
        .collect();
    let mut ini = Ini::default();

    ini.section("DeviceComissioning")
        .key("NodeID", master.node_id)
        .key("NodeName", "")
        .key("NodeRefd", "")
        .key("Baudrate", master.baudrate)
        .key("NetNumber", 1)
        .key("NetworkName", "")
        .key("NetRefd", "")
        .key("CANopenManager", 1)
        .key("LSS_SerialNumber", hex(master.serial_number, 8));
    ini.section("DeviceInfo")
        .key("VendorName", "")
        .key("VendorNumber", hex(master.vendor_id, 8))
        .key("ProductName", "")
        .key("ProductNumber", hex(master.product_code, 8))
        .key("RevisionNumber", hex(master.revision_number, 8))
        .key("OrderCode", "");
    for rate in [10, 20, 50, 125, 250, 500, 800, 1000] {
        ini.key(format!("BaudRate_{rate}"), 1);
    }
    ini.key("SimpleBootUpMaster", 1)
        .key("SimpleBootUpSlave", 0)
        .key("Granularity", 1)
        .key("DynamicChannelsSupported", 0)
        .key("GroupMessaging", 0)
        .key("NrOfRxPDO", rx.len())
        .key("NrOfTxPDO", tx.len())
        .key("LSS_Supported", 1);
    ini.section("DummyUsage");
    for code in (0x01..=0x07)
        .chain([0x10])
        .chain(0x12..=0x16)
        .chain(0x18..=0x1B)
    {
        ini.key(format!("Dummy{code:04X}"), 1);
    }

    let mut optional: Vec<u32> = vec![
        0x1003, 0x1005, 0x1006, 0x1007, 0x1012, 0x1013, 0x1014, 0x1015,
    ];
    if master.heartbeat_consumer {
        optional.push(0x1016);
    }
    optional.extend([0x1017, 0x1019, 0x1028, 0x1029, 0x102A]);
    for side in [&rx, &tx] {
        optional.extend((0..side.len()).map(|k| side.side.comm_base() + k));
        optional.extend((0..side.len()).map(|k| side.side.comm_base() + 0x200 + k));
    }
    if !uploads.is_empty() {
        optional.push(0x1F22);
    }
    optional.extend([0x1F25, 0x1F55]);
    if !software.is_empty() {
        optional.push(0x1F58);
    }
    optional.extend([
        0x1F80, 0x1F81, 0x1F82, 0x1F84, 0x1F85, 0x1F86, 0x1F87, 0x1F88, 0x1F89, 0x1F8A,
    ]);
    let mut manufacturer: Vec<u32> = rx.object_indices().chain(tx.object_indices()).collect();
    if remote_pdo {
        for base in [0x5800, 0x5A00] {
            manufacturer.extend((0..rx.len()).map(|k| base + k));
        }
        for base in [0x5C00, 0x5E00] {
            manufacturer.extend((0..tx.len()).map(|k| base + k));
        }
    }
    for (name, list) in [
        ("MandatoryObjects", &vec![0x1000, 0x1001, 0x1018]),
        ("OptionalObjects", &optional),
        ("ManufacturerObjects", &manufacturer),
    ] {
        ini.section(name).key("SupportedObjects", list.len());
        for (n, index) in list.iter().enumerate() {
            ini.key((n + 1).to_string(), hex(*index, 4));
        }
    }

    var(
        &mut ini,
        0x1000,
        "Device type",
        0x0007,
        "ro",
        Some(hex(0u32, 8)),
    );
    var(&mut ini, 0x1001, "Error register", 0x0005, "ro", None);
    array(
        &mut ini,
        0x1003,
        "Pre-defined error field",
        0x0007,
        "ro",
        254,
    );
    var(
        &mut ini,
        0x1005,
        "COB-ID SYNC message",
        0x0007,
        "rw",
        Some(hex(0x4000_0080u32, 8)),
    );
    var(
        &mut ini,
        0x1006,
        "Communication cycle period",
        0x0007,
        "rw",
        Some(master.sync_period.to_string()),
    );
    var(
        &mut ini,
        0x1007,
        "Synchronous window length",
        0x0007,
        "rw",
        Some(master.sync_window.to_string()),
    );
    var(
        &mut ini,
        0x1012,
        "COB-ID time stamp object",
        0x0007,
        "rw",
        Some(hex(master.time_cob_id, 8)),
    );
    var(
        &mut ini,
        0x1013,
        "High resolution time stamp",
        0x0007,
        "rw",
        None,
    )
    .key("PDOMapping", 1);
    var(
        &mut ini,
        0x1014,
        "COB-ID EMCY",
        0x0007,
        "rw",
        Some("$NODEID+0x80".to_string()),
    );
    var(
        &mut ini,
        0x1015,
        "Inhibit time EMCY",
        0x0006,
        "rw",
        Some(master.emcy_inhibit_time.to_string()),
    );
    if master.heartbeat_consumer {
        let entries: Vec<(String, String)> = slaves(bus, configured)
            .filter(|(node, _)| node.heartbeat_producer != 0)
            .enumerate()
            .map(|(n, (node, slave))| {
                let time = consumer_heartbeat_time(bus, node, slave, n + 1, &mut differences);
                (
                    (n + 1).to_string(),
                    hex(u32::from(node.node_id) << 16 | u32::from(time), 8),
                )
            })
            .collect();
        array(
            &mut ini,
            0x1016,
            "Consumer heartbeat time",
            0x0007,
            "rw",
            127,
        );
        values(&mut ini, 0x1016, entries);
    }
    var(
        &mut ini,
        0x1017,
        "Producer heartbeat time",
        0x0006,
        "rw",
        Some(master.heartbeat_producer.to_string()),
    );
    record(&mut ini, 0x1018, "Identity Object", 4, HIGHEST);
    sub(
        &mut ini,
        0x1018,
        1,
        "Vendor-ID",
        0x0007,
        "ro",
        Some(hex(master.vendor_id, 8)),
    );
    sub(
        &mut ini,
        0x1018,
        2,
        "Product code",
        0x0007,
        "ro",
        Some(hex(master.product_code, 8)),
    );
    sub(
        &mut ini,
        0x1018,
        3,
        "Revision number",
        0x0007,
        "ro",
        Some(hex(master.revision_number, 8)),
    );
    sub(&mut ini, 0x1018, 4, "Serial number", 0x0007, "ro", None);
    var(
        &mut ini,
        0x1019,
        "Synchronous counter overflow value",
        0x0005,
        "rw",
        Some(master.sync_overflow.to_string()),
    );
    ini.section("1028")
        .key("ParameterName", "Emergency consumer object")
        .key("ObjectType", "0x08")
        .key("DataType", hex(0x0007u32, 4))
        .key("AccessType", "rw")
        .key("DefaultValue", hex(0x8000_0000u32, 8))
        .key("CompactSubObj", 127);
    let emcy = configured
        .nodes
        .iter()
        .filter(|node| node.emcy_cob_id & 0x8000_0000 == 0)
        .map(|node| (node.node_id.to_string(), hex(node.emcy_cob_id, 8)))
        .collect();
    values(&mut ini, 0x1028, emcy);
    array(&mut ini, 0x1029, "Error behavior object", 0x0005, "rw", 254);
    let behavior = master
        .error_behavior
        .iter()
        .map(|(sub, value)| (sub.to_string(), hex(*value, 2)))
        .collect();
    values(&mut ini, 0x1029, behavior);
    var(
        &mut ini,
        0x102A,
        "NMT inhibit time",
        0x0006,
        "rw",
        Some(master.nmt_inhibit_time.to_string()),
    );

    for (k, mirror) in rx.mirrors.iter().enumerate() {
        let index = 0x1400 + k as u32;
        let cob_id = master_cob_id(mirror, index, &mut differences);
        record(
            &mut ini,
            index,
            "RPDO communication parameter",
            5,
            HIGHEST_PDO,
        );
        sub(
            &mut ini,
            index,
            1,
            "COB-ID used by RPDO",
            0x0007,
            "rw",
            Some(hex(cob_id, 8)),
        );
        sub(
            &mut ini,
            index,
            2,
            "transmission type",
            0x0005,
            "rw",
            Some(hex(mirror.pdo.transmission, 2)),
        );
        sub(&mut ini, index, 3, "inhibit time", 0x0006, "rw", None);
        sub(
            &mut ini,
            index,
            4,
            "compatibility entry",
            0x0005,
            "rw",
            None,
        );
        sub(
            &mut ini,
            index,
            5,
            "event-timer",
            0x0006,
            "rw",
            Some(mirror.pdo.master_event_timer.to_string()),
        );
    }
    mappings(&mut ini, &rx);
    for (k, mirror) in tx.mirrors.iter().enumerate() {
        let index = 0x1800 + k as u32;
        let pdo = mirror.pdo;
        let cob_id = master_cob_id(mirror, index, &mut differences);
        record(
            &mut ini,
            index,
            "TPDO communication parameter",
            6,
            HIGHEST_PDO,
        );
        sub(
            &mut ini,
            index,
            1,
            "COB-ID used by TPDO",
            0x0007,
            "rw",
            Some(hex(cob_id, 8)),
        );
        sub(
            &mut ini,
            index,
            2,
            "transmission type",
            0x0005,
            "rw",
            Some(hex(pdo.transmission, 2)),
        );
        sub(
            &mut ini,
            index,
            3,
            "inhibit time",
            0x0006,
            "rw",
            Some(pdo.inhibit_time.to_string()),
        );
        sub(&mut ini, index, 4, "reserved", 0x0005, "rw", None);
        sub(
            &mut ini,
            index,
            5,
            "event timer",
            0x0006,
            "rw",
            Some(pdo.master_event_timer.to_string()),
        );
        sub(
            &mut ini,
            index,
            6,
            "SYNC start value",
            0x0005,
            "rw",
            Some(pdo.master_sync_start.to_string()),
        );
    }
    mappings(&mut ini, &tx);

    if !uploads.is_empty() {
        files_array(&mut ini, 0x1F22, "Concise DCF", "Node-ID", &uploads);
    }
    array(&mut ini, 0x1F25, "Configuration request", 0x0005, "wo", 127);
    array(
        &mut ini,
        0x1F55,
        "Expected software identification",
        0x0007,
        "rw",
        127,
    );
    if !software.is_empty() {
        files_array(
            &mut ini,
            0x1F58,
            "Program data",
            "Program data of node-ID",
            &software,
        );
    }
    var(
        &mut ini,
        0x1F80,
        "NMT startup",
        0x0007,
        "rw",
        Some(hex(nmt_startup(bus), 8)),
    );
    array(&mut ini, 0x1F81, "NMT slave assignment", 0x0007, "rw", 127);
    let assignment = slaves(bus, configured)
        .map(|(node, slave)| {
            (
                node.node_id.to_string(),
                hex(slave_assignment(bus, node, slave), 8),
            )
        })
        .collect();
    values(&mut ini, 0x1F81, assignment);
    array(&mut ini, 0x1F82, "Request NMT", 0x0005, "rw", 127);
    let has_product_sub = |slave: &SlaveSection| {
        slave
            .device
            .objects
            .get(&0x1018)
            .is_some_and(|o| o.entries.contains_key(&2))
    };
    let identities: [(u32, &str, fn(&Node) -> u32); 3] = [
        (0x1F84, "Device type identification", |n| n.device_type),
        (0x1F85, "Vendor identification", |n| n.vendor_id),
        (0x1F86, "Product code", |n| n.product_code),
    ];
    for (index, name, value_of) in identities {
        array(&mut ini, index, name, 0x0007, "rw", 127);
        let mut entries = Vec::new();
        for (node, slave) in slaves(bus, configured) {
            let value = value_of(node);
            if value == 0 {
                continue;
            }
            if index == 0x1F86 && !has_product_sub(slave) {
                differences.push(Difference::UnlistedProductCode {
                    node: node.name.clone(),
                });
                continue;
            }
            entries.push((node.node_id.to_string(), hex(value, 8)));
        }
        values(&mut ini, index, entries);
    }
    array(&mut ini, 0x1F87, "Revision_number", 0x0007, "rw", 127);
    array(&mut ini, 0x1F88, "Serial number", 0x0007, "rw", 127);
    var(
        &mut ini,
        0x1F89,
        "Boot time",
        0x0007,
        "rw",
        Some(master.boot_time.to_string()),
    );
    array(&mut ini, 0x1F8A, "Restore configuration", 0x0005, "rw", 127);
    let restore = slaves(bus, configured)
        .filter_map(|(node, slave)| {
            let value = slave.restore_configuration.as_ref()?.value;
            (value != 0).then(|| (node.node_id.to_string(), hex(value, 2)))
        })
        .collect();
    values(&mut ini, 0x1F8A, restore);

    for pdos in [&rx, &tx] {
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
            record(&mut ini, index, &title, objects.len() as u32, HIGHEST);
            for (i, object) in objects.iter().enumerate() {
                sub(
                    &mut ini,
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
        remote(&mut ini, &rx, 0x5800, 0x5A00, "TPDO");
        remote(&mut ini, &tx, 0x5C00, 0x5E00, "RPDO");
    }
    (ini.render(), differences)
}

/// The configured nodes with their bus file sections.
fn slaves<'a>(
    bus: &'a Bus,
    configured: &'a Configured,
) -> impl Iterator<Item = (&'a Node, &'a SlaveSection)> {
    configured
        .nodes
        .iter()
        .filter_map(|node| Some((node, bus.slaves.get(node.slave)?)))
}

/// 0x1F80: the master's NMT start-up flags.
fn nmt_startup(bus: &Bus) -> u32 {
    let m = &bus.master;
    let flag = |on: bool, bit: u32| if on { bit } else { 0 };
    0x01 | flag(m.start_all_nodes, 0x02)
        | flag(!m.start, 0x04)
        | flag(!m.start_nodes, 0x08)
        | flag(m.reset_all_nodes, 0x10)
        | flag(m.stop_all_nodes, 0x40)
}

/// 0x1F81: how the master boots one slave.
fn slave_assignment(bus: &Bus, node: &Node, slave: &SlaveSection) -> u32 {
    let on = |value: &Option<crate::network::model::At<bool>>, default: bool| {
        value.as_ref().map_or(default, |at| at.value)
    };
    let flag = |on: bool, bit: u32| if on { bit } else { 0 };
    let software_version = slave.software_version.as_ref().map_or(0, |at| at.value);
    let software_file = slave
        .software_file
        .as_ref()
        .is_some_and(|at| !at.value.is_empty());
    let restore = slave
        .restore_configuration
        .as_ref()
        .map_or(0, |at| at.value);
    let retry = slave
        .retry_factor
        .as_ref()
        .map_or(bus.options.retry_factor, |at| at.value);
    0x01 | flag(on(&slave.boot, true), 0x04)
        | flag(on(&slave.mandatory, false), 0x08)
        | flag(!on(&slave.reset_communication, true), 0x10)
        | flag(software_version != 0, 0x20)
        | flag(software_file, 0x40)
        | flag(restore != 0, 0x80)
        | (retry & 0xFF) << 8
        | u32::from(node.guard_time) << 16
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

/// A 0x1F22/0x1F58-like array of DOMAIN files per node id 1–127.
fn files_array(ini: &mut Ini, index: u32, name: &str, sub_name: &str, files: &[(u8, &str)]) {
    ini.section(format!("{index:04X}"))
        .key("SubNumber", 128)
        .key("ParameterName", name)
        .key("ObjectType", "0x08");
    sub(
        ini,
        index,
        0,
        HIGHEST,
        0x0005,
        "const",
        Some("127".to_string()),
    );
    for node_id in 1..=127u8 {
        sub(
            ini,
            index,
            u32::from(node_id),
            &format!("{sub_name} {node_id}"),
            0x000F,
            "ro",
            None,
        );
        for (_, file) in files.iter().filter(|(n, _)| *n == node_id) {
            ini.key("UploadFile", file);
        }
    }
}

fn var<'a>(
    ini: &'a mut Ini,
    index: u32,
    name: &str,
    data_type: u32,
    access: &str,
    default: Option<String>,
) -> &'a mut Ini {
    ini.section(format!("{index:04X}"));
    entry_keys(ini, name, data_type, access, default)
}

fn entry_keys<'a>(
    ini: &'a mut Ini,
    name: &str,
    data_type: u32,
    access: &str,
    default: Option<String>,
) -> &'a mut Ini {
    ini.key("ParameterName", name)
        .key("DataType", hex(data_type, 4))
        .key("AccessType", access);
    if let Some(default) = default {
        ini.key("DefaultValue", default);
    }
    ini
}

/// A RECORD's head and its sub 0 (`highest` its value).
fn record(ini: &mut Ini, index: u32, name: &str, highest: u32, sub0: &str) {
    ini.section(format!("{index:04X}"))
        .key("SubNumber", highest + 1)
        .key("ParameterName", name)
        .key("ObjectType", "0x09");
    sub(
        ini,
        index,
        0,
        sub0,
        0x0005,
        "const",
        Some(highest.to_string()),
    );
}

fn sub<'a>(
    ini: &'a mut Ini,
    index: u32,
    sub: u32,
    name: &str,
    data_type: u32,
    access: &str,
    default: Option<String>,
) -> &'a mut Ini {
    ini.section(format!("{index:04X}sub{sub:X}"));
    entry_keys(ini, name, data_type, access, default)
}

/// A compact ARRAY of `len` entries.
fn array(ini: &mut Ini, index: u32, name: &str, data_type: u32, access: &str, len: usize) {
    ini.section(format!("{index:04X}"))
        .key("ParameterName", name)
        .key("ObjectType", "0x08")
        .key("DataType", hex(data_type, 4))
        .key("AccessType", access)
        .key("CompactSubObj", len);
}

/// The `[xxxxValue]` section of a compact array.
fn values(ini: &mut Ini, index: u32, entries: Vec<(String, String)>) {
    ini.section(format!("{index:04X}Value"))
        .key("NrOfEntries", entries.len());
    for (key, value) in entries {
        ini.key(key, value);
    }
}
