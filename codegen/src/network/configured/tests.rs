use super::*;
use crate::network::config::{Node, Pdo};

/// The LINAK table: RPDO1 (command, 7 entries), TPDO1 (feedback) and TPDO2
/// (parallel feedback) by default.
fn linak() -> Device {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../eds/linak_techline.yaml");
    let loaded = crate::input::read_device(std::path::Path::new(path), &Default::default());
    loaded.device.expect("the LINAK table reads")
}

fn node(rpdos: Vec<Pdo>, tpdos: Vec<Pdo>) -> Node {
    Node {
        name: "actuator".into(),
        slave: 0,
        node_id: 32,
        rpdos,
        tpdos,
        disabled_rpdos: Vec::new(),
        disabled_tpdos: Vec::new(),
        concise: Vec::new(),
        heartbeat_producer: 100,
        guard_time: 0,
        life_time_factor: 0,
        heartbeat_consumer: false,
        emcy_cob_id: 0xA0,
        time_cob_id: 0x100,
        device_type: 0,
        vendor_id: 0x4AA,
        product_code: 0,
        revision_number: 0,
        serial_number: 0,
        dcf_path: String::new(),
        configuration_file: String::new(),
    }
}

fn pdo(number: u16, cob_id: u32, mapping: &[u32]) -> Pdo {
    let mapping = mapping.iter().map(|&r| MappedObject::from_raw(r)).collect();
    Pdo::new(number, cob_id, 1, mapping)
}

fn configured_value(device: &Device, index: u16, sub: u8) -> Option<i128> {
    let literal = device.objects[&index].entries[&sub]
        .parameter_value
        .as_ref()?;
    match literal.value {
        Value::Integer(v) => Some(v),
        _ => None,
    }
}

#[test]
fn the_network_mapping_and_cob_id_become_configured_values() {
    let device = linak();
    let default_rpdo1 = mapped(&device.objects[&0x1600]);
    let rpdo1: Vec<u32> = default_rpdo1.iter().map(|m| m.raw()).collect();
    // TPDO1 remapped to its first two entries; TPDO2 not used; RPDO1 kept.
    let node = node(
        vec![pdo(1, 0x220, &rpdo1)],
        vec![pdo(1, 0x1A0, &[0x2001_0110, 0x2001_0208])],
    );
    let out = configured_device(&device, &node);
    assert_eq!(configured_value(&out, 0x1A00, 0), Some(2));
    assert_eq!(configured_value(&out, 0x1A00, 1), Some(0x2001_0110));
    assert_eq!(configured_value(&out, 0x1A00, 2), Some(0x2001_0208));
    assert_eq!(configured_value(&out, 0x1800, 1), Some(0x1A0));
    assert_eq!(configured_value(&out, 0x1800, 2), Some(1));
    assert_eq!(configured_value(&out, 0x1A01, 0), Some(0), "TPDO2 unused");
    assert_eq!(configured_value(&out, 0x1600, 0), Some(rpdo1.len() as i128));
    // The label stays where the mapping is the default's, only there.
    let labels: Vec<_> = out
        .pdo_labels
        .iter()
        .map(|l| (l.direction, l.number))
        .collect();
    assert_eq!(labels, [(PdoDirection::Rpdo, 1)]);
    // The device's own entries are untouched.
    assert_eq!(device.objects[&0x1A00].entries[&1].parameter_value, None);
}

#[test]
fn an_extended_cob_id_has_the_frame_bit() {
    let device = linak();
    let node = node(Vec::new(), vec![pdo(1, 0x1234_5678, &[0x2001_0110])]);
    let out = configured_device(&device, &node);
    assert_eq!(configured_value(&out, 0x1800, 1), Some(0x3234_5678));
}
