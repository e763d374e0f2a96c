//! Checks across objects, run after lowering: PDO mapping entries must name
//! existing, mappable objects of the right size; in a DCF, `$NODEID`
//! formulas must fit their type for the node id it configures.

use super::ini::Document;
use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::pdo::{self, MappingProblem};
use crate::ir::{Device, Entry, node_value_problems};

/// Runs every cross-object check of a device read from `doc`.
pub fn check_device(doc: &Document, device: &Device, diags: &mut Diagnostics) {
    if let Some(node_id) = device.commissioning.as_ref().and_then(|c| c.node_id) {
        check_node_values(doc, device, node_id, diags);
    }
    for (&index, object) in &device.objects {
        if !pdo::is_mapping_object(index) {
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
    let Some(raw) = pdo::raw_mapping(entry) else {
        return;
    };
    for problem in pdo::check_entry(device, raw) {
        report_mapping_problem(doc, index, entry, problem, diags);
    }
}

fn report_mapping_problem(
    doc: &Document,
    index: u16,
    entry: &Entry,
    problem: MappingProblem,
    diags: &mut Diagnostics,
) {
    let fix = problem.fix(index, entry.subindex);
    let message = match problem {
        MappingProblem::DummyNotEnabled { .. } => {
            format!("mapping of 0x{index:04X} sub {}: {problem}", entry.subindex)
        }
        _ => problem.to_string(),
    };
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
        notes: fix.into_iter().collect(),
    });
}

/// A DCF names its node: every `$NODEID` formula is then one value, which
/// must fit its type.
fn check_node_values(doc: &Document, device: &Device, node_id: u8, diags: &mut Diagnostics) {
    for entry in device.objects.values().flat_map(|o| o.entries.values()) {
        for (key, why) in node_value_problems(entry, node_id) {
            let section = doc.section_at_line(entry.origin.line);
            let prop = section.and_then(|s| s.get(key));
            diags.push(Diagnostic {
                severity: Severity::Error,
                code: "eds::value-out-of-range",
                file: doc.file.clone(),
                location: Location {
                    line: Some(prop.map_or(entry.origin.line, |p| p.line)),
                    span: prop.map(|p| p.value_span.clone()),
                    section: section.map(|s| s.name.to_string()),
                    key: Some(prop.map_or(key, |p| p.key).to_string()),
                },
                message: format!("{why} ([DeviceComissioning] NodeID={node_id})"),
                notes: vec![
                    "the node cannot hold this value: change the formula or the node id".into(),
                ],
            });
        }
    }
}
