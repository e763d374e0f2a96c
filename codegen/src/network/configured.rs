//! A node's device as the network configures it, in the IR: the PDO mapping
//! and communication entries hold the network's values as configured values
//! (`parameter_value`, as a DCF holds them), the PDOs the network leaves
//! unused map nothing, and a default PDO keeps its label only where the
//! network keeps its mapping. The generator makes the node's PDO structs
//! from this device with the code that makes a device's default PDOs, so a
//! network's PDO and a device's default PDO of one layout are one codec.

use crate::ir::pdo::{MappedObject, is_mapping_object, raw_mapping};
use crate::ir::{Device, Entry, Literal, Object, PdoDirection, Value};

use super::config::{Node, Pdo};

/// `device` (the node's device file, `$NODEID` unresolved) with `node`'s
/// configured PDOs written in.
pub fn configured_device(device: &Device, node: &Node) -> Device {
    let mut out = device.clone();
    let mut kept_labels = Vec::new();
    let mappings: Vec<u16> = out
        .objects
        .keys()
        .copied()
        .filter(|&i| is_mapping_object(i))
        .collect();
    for index in mappings {
        let (direction, number) = if index >= 0x1A00 {
            (PdoDirection::Tpdo, index - 0x1A00 + 1)
        } else {
            (PdoDirection::Rpdo, index - 0x1600 + 1)
        };
        let pdos = match direction {
            PdoDirection::Rpdo => &node.rpdos,
            PdoDirection::Tpdo => &node.tpdos,
        };
        let pdo = pdos.iter().find(|p| p.number == number);
        let Some(object) = out.objects.get_mut(&index) else {
            continue;
        };
        match pdo {
            Some(pdo) => {
                if mapped(object) == pdo.mapping {
                    kept_labels.push((direction, number));
                }
                write_mapping(object, &pdo.mapping);
            }
            None => set(object, 0, 0, "0".into()),
        }
        if let Some(pdo) = pdo
            && let Some(comm) = out.objects.get_mut(&direction.communication_index(number))
        {
            write_communication(comm, direction, pdo);
        }
    }
    out.pdo_labels
        .retain(|l| kept_labels.contains(&(l.direction, l.number)));
    out
}

/// The objects a mapping object maps now (configured value, else default).
fn mapped(object: &Object) -> Vec<MappedObject> {
    let count = object
        .entries
        .get(&0)
        .and_then(|e| raw_mapping(e))
        .unwrap_or(0);
    object
        .entries
        .values()
        .filter(|e| e.subindex >= 1 && u32::from(e.subindex) <= count)
        .filter_map(|e| raw_mapping(e))
        .filter(|&raw| raw != 0)
        .map(MappedObject::from_raw)
        .collect()
}

fn write_mapping(object: &mut Object, mapping: &[MappedObject]) {
    set(object, 0, mapping.len() as i128, mapping.len().to_string());
    for (i, item) in mapping.iter().enumerate() {
        let Ok(sub) = u8::try_from(i + 1) else { break };
        if !object.entries.contains_key(&sub) {
            // A mapping sub the device file does not list (its table gave
            // fewer): shaped like the one before it.
            if let Some(before) = object.entries.get(&(sub - 1)).cloned() {
                let mut entry = before;
                entry.subindex = sub;
                entry.name = format!("Mapped object {sub}");
                object.entries.insert(sub, entry);
            }
        }
        let raw = item.raw();
        set(object, sub, raw.into(), format!("0x{raw:08X}"));
    }
}

fn write_communication(comm: &mut Object, direction: PdoDirection, pdo: &Pdo) {
    // The COB-ID entry: the identifier, bit 29 for a 29-bit one.
    let frame = if pdo.cob_id > 0x7FF { 1 << 29 } else { 0 };
    let cob_id = pdo.cob_id | frame;
    set(comm, 1, cob_id.into(), format!("0x{cob_id:X}"));
    set(
        comm,
        2,
        pdo.transmission.into(),
        pdo.transmission.to_string(),
    );
    if direction == PdoDirection::Tpdo {
        set(
            comm,
            3,
            pdo.inhibit_time.into(),
            pdo.inhibit_time.to_string(),
        );
        set(comm, 6, pdo.sync_start.into(), pdo.sync_start.to_string());
    }
    set(comm, 5, pdo.event_timer.into(), pdo.event_timer.to_string());
}

/// Sets the configured value of an entry the object has.
fn set(object: &mut Object, sub: u8, value: i128, text: String) {
    if let Some(entry) = object.entries.get_mut(&sub) {
        configure(entry, value, text);
    }
}

fn configure(entry: &mut Entry, value: i128, text: String) {
    entry.parameter_value = Some(Literal {
        value: Value::Integer(value),
        plus_node_id: false,
        text,
    });
}

#[cfg(test)]
mod tests;
