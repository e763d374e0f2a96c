//! [`configure`]: each slave's bus
//! section applied to its device file as dcfgen applies it (identity,
//! TIME, heartbeat, guarding, error behaviour, PDOs, the `sdo` list), then
//! the master's part (heartbeat consumer entries on the slaves, the
//! master's own concise DCF).

use crate::diag::{Diagnostics, Severity};

use super::config::{ConciseEntry, Configured, Node};
use super::model::{AUTO_COB_ID_FIRST, At, Bus, MasterSection, SlaveSection, Spot};
use super::pdo_config::{INVALID, SlaveState};
use super::view::{DeviceView, pack};

/// Applies the bus file to every device as dcfgen does; what dcfgen warns
/// about or refuses becomes a diagnostic naming the bus file, line and key.
pub fn configure(bus: &Bus) -> (Configured, Diagnostics) {
    let mut diagnostics = Diagnostics::new();
    let mut next_auto = AUTO_COB_ID_FIRST;
    let mut nodes = Vec::new();
    for (position, slave) in bus.slaves.iter().enumerate() {
        let node_id = slave.node_id.as_ref().map(|n| n.value).or(slave
            .device
            .commissioning
            .as_ref()
            .and_then(|c| c.node_id));
        let Some(node_id) = node_id.filter(|&n| n != 255) else {
            let message = format!(
                "{}: no node id (no `node_id` key, no NodeID in the device file's [DeviceComissioning]); the slave is left out, as dcfgen leaves it out",
                slave.name
            );
            diagnostics.push(slave.spot.diagnostic(
                &bus.file,
                Severity::Warning,
                "net::no-node-id",
                message,
            ));
            continue;
        };
        let mut state = SlaveState {
            view: DeviceView {
                device: &slave.device,
                node_id,
            },
            name: &slave.name,
            bus_file: &bus.file,
            concise: Vec::new(),
            not_writable: Vec::new(),
            diagnostics: &mut diagnostics,
        };
        let node = configure_slave(&mut state, bus, slave, position, &mut next_auto);
        nodes.push(node);
    }
    let master_concise = configure_master(bus, &bus.master, &mut nodes, &mut diagnostics);
    (
        Configured {
            nodes,
            master_concise,
        },
        diagnostics,
    )
}

fn configure_slave(
    state: &mut SlaveState<'_>,
    bus: &Bus,
    slave: &SlaveSection,
    position: usize,
    next_auto: &mut u32,
) -> Node {
    let view = &state.view;
    let device = view.device;
    let identity = &device.identity;
    let from_1018 = |sub| view.u32_or_zero(0x1018, sub);
    let mut node = Node {
        name: slave.name.clone(),
        slave: position,
        node_id: view.node_id,
        rpdos: Vec::new(),
        tpdos: Vec::new(),
        disabled_rpdos: Vec::new(),
        disabled_tpdos: Vec::new(),
        concise: Vec::new(),
        heartbeat_producer: view
            .integer(0x1017, 0)
            .and_then(|v| u16::try_from(v).ok())
            .unwrap_or(0),
        guard_time: view
            .integer(0x100C, 0)
            .and_then(|v| u16::try_from(v).ok())
            .unwrap_or(0),
        life_time_factor: view
            .integer(0x100D, 0)
            .and_then(|v| u8::try_from(v).ok())
            .unwrap_or(0),
        heartbeat_consumer: slave.heartbeat_consumer.as_ref().is_some_and(|c| c.value),
        emcy_cob_id: if view.has_object(0x1014) {
            view.u32_or_zero(0x1014, 0)
        } else {
            INVALID
        },
        time_cob_id: if view.has_object(0x1012) {
            view.u32_or_zero(0x1012, 0)
        } else {
            0x100
        },
        device_type: view.u32_or_zero(0x1000, 0),
        vendor_id: identity.vendor_number.unwrap_or_else(|| from_1018(1)),
        product_code: identity.product_number.unwrap_or_else(|| from_1018(2)),
        revision_number: identity.revision_number.unwrap_or_else(|| from_1018(3)),
        serial_number: device
            .commissioning
            .as_ref()
            .and_then(|c| c.lss_serial_number)
            .unwrap_or_else(|| from_1018(4)),
        // dcfgen expands environment variables in dcf_path.
        dcf_path: expand_vars(
            slave
                .dcf_path
                .as_ref()
                .map_or(&bus.options.dcf_path, |p| &p.value),
            |name| std::env::var(name).ok(),
        ),
        configuration_file: String::new(),
    };
    identity_override(
        state,
        &slave.revision_number,
        &mut node.revision_number,
        "revision number",
    );
    identity_override(
        state,
        &slave.serial_number,
        &mut node.serial_number,
        "serial number",
    );

    set_comm(
        state,
        &slave.time_cob_id,
        &mut node.time_cob_id,
        0x1012,
        "time_cob_id",
    );
    set_comm(
        state,
        &slave.heartbeat_producer,
        &mut node.heartbeat_producer,
        0x1017,
        "heartbeat_producer",
    );
    set_comm(
        state,
        &slave.guard_time,
        &mut node.guard_time,
        0x100C,
        "guard_time",
    );
    set_comm(
        state,
        &slave.life_time_factor,
        &mut node.life_time_factor,
        0x100D,
        "life_time_factor",
    );
    if node.guard_time != 0 && node.life_time_factor != 0 && node.heartbeat_producer != 0 {
        let spot = slave
            .heartbeat_producer
            .as_ref()
            .map_or(&slave.spot, |h| &h.spot);
        let message = "heartbeat and node guarding are both set; a node runs one of them, so the master uses the heartbeat and ignores the guard time".to_string();
        state.report(
            spot,
            Severity::Warning,
            "net::heartbeat-and-guarding",
            message,
        );
        node.guard_time = 0;
        node.life_time_factor = 0;
    }
    for (&sub, value) in &slave.error_behavior {
        match state.view.integer(0x1029, sub) {
            Some(current) if sub != 0 => {
                if current != i128::from(value.value) {
                    state.write(0x1029, sub, i128::from(value.value), &value.spot);
                }
            }
            _ => {
                let message = format!(
                    "sub-object 0x1029/{sub} (error behaviour) does not exist in the device file; the setting is ignored"
                );
                state.report(
                    &value.spot,
                    Severity::Warning,
                    "net::missing-object",
                    message,
                );
            }
        }
    }
    (node.rpdos, node.disabled_rpdos) = configure_pdos(state, &slave.rpdo, 0x1400, next_auto);
    (node.tpdos, node.disabled_tpdos) = configure_pdos(state, &slave.tpdo, 0x1800, next_auto);

    if let Some(v) = &slave.software_version
        && state.view.entry(0x1F56, 1).is_none()
    {
        let message = "`software_version` is given, but the device has no 0x1F56/1 (program software identification) to check it against".to_string();
        state.report(&v.spot, Severity::Warning, "net::missing-object", message);
    }
    if let Some(r) = &slave.restore_configuration
        && state.view.entry(0x1011, r.value).is_none()
    {
        let message = format!(
            "`restore_configuration: {}` needs sub-object 0x1011/{}, which the device file lacks",
            r.value, r.value
        );
        state.report(&r.spot, Severity::Warning, "net::missing-object", message);
    }
    for item in &slave.sdo {
        state.write(item.index, item.sub_index, item.value, &item.spot);
    }
    if let Some(file) = &slave.configuration_file {
        node.configuration_file = file.value.clone();
    } else if !state.concise.is_empty() {
        node.configuration_file = join(&node.dcf_path, &format!("{}.bin", slave.name));
    }
    node.concise = std::mem::take(&mut state.concise);
    node
}

/// The bus file's identity number wins over the device file's; a
/// different non-zero one is worth a word.
fn identity_override(
    state: &mut SlaveState<'_>,
    given: &Option<At<u32>>,
    number: &mut u32,
    what: &str,
) {
    if let Some(given) = given {
        if *number != 0 && *number != given.value {
            let message = format!(
                "the {what} 0x{:08X} differs from the device file's 0x{:08X}; the master will expect 0x{:08X}",
                given.value, *number, given.value
            );
            state.report(
                &given.spot,
                Severity::Warning,
                "net::identity-differs",
                message,
            );
        }
        *number = given.value;
    }
}

/// A communication setting (`key`, object `index` sub 0): written when it
/// differs from the device's value; a device without the object gets a
/// warning and no write.
fn set_comm<T>(
    state: &mut SlaveState<'_>,
    given: &Option<At<T>>,
    current: &mut T,
    index: u16,
    key: &str,
) where
    T: Copy + PartialEq + Into<i128>,
{
    let Some(given) = given else { return };
    if given.value != *current {
        if state.view.has_object(index) {
            state.write(index, 0, given.value.into(), &given.spot);
        } else {
            let message = format!(
                "`{key}` needs object 0x{index:04X}, which the device file lacks; the setting is not written"
            );
            state.report(
                &given.spot,
                Severity::Warning,
                "net::missing-object",
                message,
            );
        }
    }
    *current = given.value;
}

fn configure_pdos(
    state: &mut SlaveState<'_>,
    sections: &std::collections::BTreeMap<u16, super::model::PdoSection>,
    first_comm: u16,
    next_auto: &mut u32,
) -> (Vec<super::config::Pdo>, Vec<super::config::Pdo>) {
    let kind = if first_comm == 0x1800 { "TPDO" } else { "RPDO" };
    let mut pdos: Vec<_> = (0..512u16)
        .filter(|i| state.view.has_object(first_comm + i))
        .map(|i| state.device_pdo(first_comm + i, i + 1))
        .collect();
    // dcfgen applies the sections in the order the file writes them.
    let mut disabled = Vec::new();
    let mut ordered: Vec<_> = sections.iter().collect();
    ordered.sort_by_key(|(number, section)| (section.spot.line, **number));
    for (&number, section) in ordered {
        match pdos.iter_mut().find(|p| p.number == number) {
            Some(pdo) => {
                if state.apply(pdo, first_comm + number - 1, section, next_auto) {
                    disabled.push(number);
                }
            }
            None => {
                let message = format!(
                    "the device file has no {kind} {number} (no object 0x{:04X}); its PDOs are {}",
                    first_comm + number - 1,
                    list_numbers(&pdos)
                );
                state.report(&section.spot, Severity::Error, "net::no-such-pdo", message);
            }
        }
    }
    // dcfgen keeps a disabled PDO whose COB-ID was valid in master.dcf.
    let (disabled, mut pdos): (Vec<_>, Vec<_>) = pdos
        .into_iter()
        .filter(|p| !p.mapping.is_empty())
        .partition(|p| disabled.contains(&p.number));
    pdos.retain(|p| p.cob_id & INVALID == 0);
    (pdos, disabled)
}

fn list_numbers(pdos: &[super::config::Pdo]) -> String {
    if pdos.is_empty() {
        return "none".to_string();
    }
    pdos.iter()
        .map(|p| p.number.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The master's part: heartbeat consumer entries (0x1016) on the slaves,
/// and the master's own concise DCF.
fn configure_master(
    bus: &Bus,
    master: &MasterSection,
    nodes: &mut [Node],
    diagnostics: &mut Diagnostics,
) -> Vec<ConciseEntry> {
    let heartbeat = i128::from(super::config::heartbeat_product(
        master.heartbeat_producer,
        master.heartbeat_multiplier,
    ));
    for node in nodes.iter_mut() {
        let slave = &bus.slaves[node.slave];
        let mut state = SlaveState {
            view: DeviceView {
                device: &slave.device,
                node_id: node.node_id,
            },
            name: &slave.name,
            bus_file: &bus.file,
            concise: std::mem::take(&mut node.concise),
            not_writable: Vec::new(),
            diagnostics,
        };
        let consumers: Vec<(u8, i128)> = state
            .view
            .subs(0x1016)
            .into_iter()
            .map(|s| (s, state.view.integer(0x1016, s).unwrap_or(0)))
            .collect();
        let node_of = |v: i128| ((v >> 16) & 0xFF) as u8;
        if node.heartbeat_consumer && heartbeat > 0 {
            let spot = slave
                .heartbeat_consumer
                .as_ref()
                .map_or(&slave.spot, |c| &c.spot)
                .clone();
            let sub = consumers
                .iter()
                .find(|(_, v)| node_of(*v) == master.node_id)
                .or_else(|| {
                    consumers
                        .iter()
                        .find(|(_, v)| v & 0xFFFF == 0 || node_of(*v) == 0 || node_of(*v) > 127)
                })
                .map(|(s, _)| *s);
            match sub {
                Some(sub) => {
                    let value = (i128::from(master.node_id) << 16) | (heartbeat & 0xFFFF);
                    state.write_first(0x1016, sub, value, &spot);
                }
                None => {
                    let message = if consumers.is_empty() {
                        "`heartbeat_consumer` is set, but the device file has no 0x1016 (consumer heartbeat time) entries".to_string()
                    } else {
                        "`heartbeat_consumer` is set, but every entry of 0x1016 already watches another node".to_string()
                    };
                    state.report(&spot, Severity::Warning, "net::missing-object", message);
                }
            }
        } else {
            for (sub, value) in consumers {
                if value & 0xFFFF != 0 && node_of(value) == master.node_id {
                    let spot = slave.spot.clone();
                    state.write_first(0x1016, sub, i128::from(master.node_id) << 16, &spot);
                }
            }
        }
        node.concise = std::mem::take(&mut state.concise);
    }
    let mut concise = Vec::new();
    let mut push = |index: u16, sub: u8, value: u32, spot: Spot| {
        let data = pack(crate::ir::DataType::Unsigned32, i128::from(value)).unwrap_or_default();
        concise.push(ConciseEntry {
            index,
            sub_index: sub,
            data,
            spot: Some(spot),
        });
    };
    if master.serial_number != 0 {
        let spot = master
            .spots
            .get("serial_number")
            .cloned()
            .unwrap_or_default();
        push(0x1018, 4, master.serial_number, spot);
    }
    for node in nodes.iter() {
        let slave = &bus.slaves[node.slave];
        let view = DeviceView {
            device: &slave.device,
            node_id: node.node_id,
        };
        if let Some(v) = &slave.software_version
            && v.value != 0
        {
            push(0x1F55, node.node_id, v.value, v.spot.clone());
        }
        let spot_of =
            |given: &Option<At<u32>>| given.as_ref().map_or(&slave.spot, |g| &g.spot).clone();
        if node.revision_number != 0 && view.entry(0x1018, 3).is_some() {
            push(
                0x1F87,
                node.node_id,
                node.revision_number,
                spot_of(&slave.revision_number),
            );
        }
        if node.serial_number != 0 && view.entry(0x1018, 4).is_some() {
            push(
                0x1F88,
                node.node_id,
                node.serial_number,
                spot_of(&slave.serial_number),
            );
        }
    }
    concise
}

/// `dir` and `file` joined with `/` as dcfgen joins them (`os.path.join`).
pub(crate) fn join(dir: &str, file: &str) -> String {
    if dir.is_empty() || dir.ends_with('/') {
        format!("{dir}{file}")
    } else {
        format!("{dir}/{file}")
    }
}

/// `$NAME` and `${NAME}` replaced by the variable's value where it is set
/// (`NAME` of letters, digits and `_`); the rest kept as written.
pub(crate) fn expand_vars(text: &str, var: impl Fn(&str) -> Option<String>) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(at) = rest.find('$') {
        out.push_str(&rest[..at]);
        let after = &rest[at + 1..];
        let (name, len) = if let Some(inner) = after.strip_prefix('{') {
            match inner.find('}') {
                Some(end) => (&inner[..end], end + 2),
                None => ("", 0),
            }
        } else {
            let end = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            (&after[..end], end)
        };
        match (len, var(name)) {
            (1.., Some(value)) if !name.is_empty() => out.push_str(&value),
            _ => out.push_str(&rest[at..at + 1 + len]),
        }
        rest = &rest[at + 1 + len..];
    }
    out.push_str(rest);
    out
}
