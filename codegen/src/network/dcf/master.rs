//! master.dcf: the master's object dictionary as dcfgen writes it for a
//! bus: its own communication objects, the CiA 302 per-slave arrays
//! (0x1F81 assignment, 0x1F84–0x1F86 expected identity, 0x1F22 concise
//! DCFs, 0x1F58 program data, 0x1016 heartbeat consumers, 0x1028 EMCY
//! consumers), one master RPDO per slave TPDO and one master TPDO per
//! slave RPDO (numbered in slave order), the 0x2000/0x2200 objects they
//! map, and with `remote_pdo` the remote PDO mappings (0x5800–0x5FFF).

use crate::network::config::{Configured, Node};
use crate::network::configure::join;
use crate::network::model::{Bus, SlaveSection};

use super::ini::{HIGHEST, Ini, array, files_array, hex, record, sub, values, var};
use super::pdos::{self, MasterPdos, Side};
use super::{Difference, consumer_heartbeat_time};

/// How a per-slave identity array takes its value from a node.
type ValueOf = fn(&Node) -> u32;

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
            // dcfgen names its own file whatever the key says.
            let dcfgen_file = (!node.concise.is_empty())
                .then(|| join(&node.dcf_path, &format!("{}.bin", node.name)));
            if let Some(file) = &slave.configuration_file
                && dcfgen_file.as_deref() != Some(file.value.as_str())
            {
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
            .map(|(n, (node, _))| {
                let time = consumer_heartbeat_time(bus, node, n + 1, &mut differences);
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

    pdos::write_parameters(&mut ini, &rx, &tx, &mut differences);

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
    let identities: [(u32, &str, ValueOf); 3] = [
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

    pdos::write_mapped_objects(&mut ini, &rx, &tx, remote_pdo);
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
