//! Checks across objects, run after lowering: PDO mapping entries must name
//! existing, mappable objects of the right size.

use super::ini::Document;
use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::{DataType, Device, Entry, Value, ValueKind};

/// Runs every cross-object check of a device read from `doc`.
pub fn check_device(doc: &Document, device: &Device, diags: &mut Diagnostics) {
    for (&index, object) in &device.objects {
        let is_mapping = (0x1600..=0x17FF).contains(&index) || (0x1A00..=0x1BFF).contains(&index);
        if !is_mapping {
            continue;
        }
        for entry in object.entries.values().filter(|e| e.subindex >= 1) {
            check_mapping_entry(doc, device, index, entry, diags);
        }
    }
}

fn check_mapping_entry(
    doc: &Document,
    device: &Device,
    index: u16,
    entry: &Entry,
    diags: &mut Diagnostics,
) {
    let Some(literal) = entry.parameter_value.as_ref().or(entry.default.as_ref()) else {
        return;
    };
    let (Value::Integer(raw), false) = (&literal.value, literal.plus_node_id) else {
        return;
    };
    let Ok(raw) = u32::try_from(*raw) else { return };
    if raw == 0 {
        return;
    }
    let (target, sub, bits) = ((raw >> 16) as u16, (raw >> 8) as u8, raw as u8);
    let mut warn = |message: String| {
        let key = if entry.parameter_value.is_some() {
            "ParameterValue"
        } else {
            "DefaultValue"
        };
        // Point at the value when the entry's section has it, else at the section.
        let section = doc.section_at_line(entry.origin.line);
        let prop = section.and_then(|s| s.get(key));
        diags.push(Diagnostic {
            severity: Severity::Warning,
            code: "eds::pdo-mapping",
            file: doc.file.clone(),
            location: Location {
                line: Some(prop.map_or(entry.origin.line, |p| p.line)),
                span: prop
                    .map(|p| p.value_span.clone())
                    .or_else(|| section.map(|s| s.header_span.clone())),
                section: section.map(|s| s.name.to_string()),
                key: prop.map(|p| p.key.to_string()),
            },
            message,
            notes: Vec::new(),
        });
    };
    if (1..=0x7).contains(&target) {
        // A dummy entry: a basic data type used as a gap.
        let data_type = DataType::from_code(target);
        if !device.dummy_usage.is_empty() && !device.dummy_usage.contains(&data_type) {
            warn(format!(
                "mapping of 0x{index:04X} sub {}: dummy {} is not enabled in [DummyUsage]",
                entry.subindex,
                data_type.name()
            ));
        }
        return;
    }
    let Some(object) = device.objects.get(&target) else {
        warn(format!(
            "maps object 0x{target:04X} sub {sub}, which does not exist"
        ));
        return;
    };
    let Some(mapped) = object.entries.get(&sub) else {
        warn(format!(
            "maps object 0x{target:04X} sub {sub}; 0x{target:04X} has no sub-index {sub}"
        ));
        return;
    };
    if !mapped.pdo_mappable {
        warn(format!(
            "maps 0x{target:04X} sub {sub} (`{}`), which is not PDO-mappable",
            mapped.name
        ));
    }
    let expected = match mapped.data_type.value_kind() {
        Some(ValueKind::Integer { bits: 1, .. }) => Some(&[1u32, 8][..]),
        Some(ValueKind::Integer { bits, .. }) | Some(ValueKind::Real { bits }) => {
            Some(match bits {
                8 => &[8][..],
                16 => &[16],
                24 => &[24],
                32 => &[32],
                40 => &[40],
                48 => &[48],
                56 => &[56],
                _ => &[64],
            })
        }
        _ => None,
    };
    if let Some(expected) = expected
        && !expected.contains(&u32::from(bits))
    {
        warn(format!(
            "maps 0x{target:04X} sub {sub} with {bits} bits, but its type {} has {} bits",
            mapped.data_type.name(),
            expected[expected.len() - 1]
        ));
    }
}
