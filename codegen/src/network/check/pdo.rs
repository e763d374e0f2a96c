//! PDOs: `net::pdo-mapping`, `net::pdo-direction`, `net::pdo-too-long`
//! (the mappings the bus file writes), `net::sdo-pdo-conflict` (SDO-list
//! writes to PDO parameters), `net::pdo-unproduced` and
//! `net::pdo-unconsumed` (PDOs awaited and never sent, sent and never
//! read).
//!
//! What "no one produces / consumes" means here: dcfgen's master.dcf
//! (remote PDO mappings, `-r`) receives every valid, mapped slave TPDO
//! and sends every valid, mapped slave RPDO, so no configured PDO lacks
//! its partner by construction. What is left: a PDO that is configured
//! but never goes out (synchronous without a SYNC producer, RTR-only,
//! which the master never requests), and a section that enables a PDO the
//! configured network does not have (an empty mapping: a slave TPDO that
//! sends empty frames no one reads, a slave RPDO no one sends; or a COB-ID
//! that stays invalid).

use std::collections::BTreeMap;

use super::context::{Net, Report, device_int};
use crate::ir::pdo::{MappedObject, MappingProblem, check_entry, mappable_bits};
use crate::ir::{DataType, Device, PdoDirection};
use crate::network::config::{Node, Pdo};
use crate::network::model::{MappingItem, PdoSection, SdoItem, SlaveSection, Spot};

pub(super) fn check(net: &Net, report: &mut Report<'_>) {
    for (i, slave) in net.bus.slaves.iter().enumerate() {
        mappings(slave, report);
        let Some(node) = net.node_of(i) else { continue };
        for item in &slave.sdo {
            sdo_write(slave, node, item, report);
        }
        never_sent(net, slave, node, report);
    }
}

fn label(direction: PdoDirection, n: u16) -> String {
    match direction {
        PdoDirection::Rpdo => format!("RPDO {n}"),
        PdoDirection::Tpdo => format!("TPDO {n}"),
    }
}

fn sections(slave: &SlaveSection) -> [(PdoDirection, &BTreeMap<u16, PdoSection>); 2] {
    [
        (PdoDirection::Rpdo, &slave.rpdo),
        (PdoDirection::Tpdo, &slave.tpdo),
    ]
}

/// What a mapping item maps, with the bit length dcfgen maps it with (the
/// type's shortest: 1 for BOOLEAN); `None` when the object does not exist
/// or has no fixed length (the configuration reports that,
/// `net::unknown-object`).
fn resolve(device: &Device, item: &MappingItem) -> Option<MappedObject> {
    let probe = MappedObject {
        index: item.index,
        subindex: item.sub_index,
        bits: 0,
    };
    let data_type = if probe.is_dummy() {
        DataType::from_code(item.index)
    } else {
        device
            .objects
            .get(&item.index)?
            .entries
            .get(&item.sub_index)?
            .data_type
    };
    Some(MappedObject {
        bits: mappable_bits(data_type)?[0],
        ..probe
    })
}

/// `net::pdo-mapping`, `net::pdo-direction`, `net::pdo-too-long` for the
/// mappings written in the bus file (the device file's own mappings are
/// the device reader's to check).
fn mappings(slave: &SlaveSection, report: &mut Report<'_>) {
    let device = &slave.device;
    for (direction, sections) in sections(slave) {
        for (&n, section) in sections {
            let Some(items) = &section.mapping else {
                continue;
            };
            let pdo = label(direction, n);
            let mut total = 0u32;
            for item in items {
                let Some(mapped) = resolve(device, item) else {
                    continue;
                };
                total += u32::from(mapped.bits);
                for problem in check_entry(device, mapped.raw()) {
                    let mut notes = Vec::new();
                    if let MappingProblem::NotMappable { .. } = problem {
                        notes.push("the device refuses the mapping at boot (SDO abort)".into());
                    }
                    notes.extend(problem.fix(direction.mapping_index(n), 0));
                    report.error(
                        "net::pdo-mapping",
                        &item.spot,
                        format!("{pdo} of `{}` {problem}", slave.name),
                        notes,
                    );
                }
                let entry = device
                    .objects
                    .get(&item.index)
                    .and_then(|o| o.entries.get(&item.sub_index));
                let Some(entry) = entry else { continue };
                if !direction.allows(entry.access) {
                    let (verb, way, other) = match direction {
                        PdoDirection::Rpdo => ("writes", "writable", "a TPDO"),
                        PdoDirection::Tpdo => ("reads", "readable", "an RPDO"),
                    };
                    report.error(
                        "net::pdo-direction",
                        &item.spot,
                        format!(
                            "{pdo} of `{}` {verb} 0x{:04X} sub {} (`{}`), which is `{}`, not {way}",
                            slave.name,
                            item.index,
                            item.sub_index,
                            entry.name,
                            entry.access.as_str()
                        ),
                        vec![format!("map it in {other}, or map another object")],
                    );
                }
            }
            if total > 64 {
                let spot = items.first().map_or(&section.spot, |i| &i.spot);
                report.error(
                    "net::pdo-too-long",
                    spot,
                    format!(
                        "{pdo} of `{}`: {}",
                        slave.name,
                        MappingProblem::TooLong { total }
                    ),
                    vec!["split the objects over two PDOs".into()],
                );
            }
        }
    }
}

/// What a PDO section sets of one sub-index of its PDO's objects.
enum Sets {
    /// Nothing: the sub-index keeps the device file's value.
    Nothing,
    /// This value, written at `spot`; `None`: a value that cannot be
    /// known here (dcfgen rewrites it anyway).
    Value(Spot, Option<i128>),
}

/// What `section` (PDO `n`, configured as `pdo` when valid) sets of
/// `index`/`sub` (a communication object when `mapping` is false).
fn section_sets(
    section: &PdoSection,
    direction: PdoDirection,
    mapping: bool,
    sub: u8,
    pdo: Option<&Pdo>,
    device: &Device,
) -> Sets {
    let value = |spot: &Spot, v: Option<i128>| Sets::Value(spot.clone(), v);
    if mapping {
        let Some(items) = &section.mapping else {
            return Sets::Nothing;
        };
        let spot = items.first().map_or(&section.spot, |i| &i.spot);
        return match sub {
            0 => value(spot, Some(items.len() as i128)),
            k => match items.get(usize::from(k) - 1) {
                Some(item) => value(
                    &item.spot,
                    resolve(device, item).map(|m| i128::from(m.raw())),
                ),
                None => value(spot, None),
            },
        };
    }
    let field = |f: &Option<crate::network::model::At<u16>>| {
        f.as_ref()
            .map_or(Sets::Nothing, |a| value(&a.spot, Some(i128::from(a.value))))
    };
    match sub {
        1 => {
            let spot = section
                .cob_id
                .as_ref()
                .map_or(&section.enabled.spot, |c| &c.spot);
            let spot = if spot.line == 0 { &section.spot } else { spot };
            value(
                spot,
                Some(pdo.map_or(0x8000_0000, |p| i128::from(p.cob_id))),
            )
        }
        2 => section
            .transmission
            .as_ref()
            .map_or(Sets::Nothing, |a| value(&a.spot, Some(i128::from(a.value)))),
        3 => field(&section.inhibit_time),
        5 => match direction {
            PdoDirection::Tpdo => field(&section.event_timer),
            PdoDirection::Rpdo => field(&section.event_deadline),
        },
        6 => section
            .sync_start
            .as_ref()
            .map_or(Sets::Nothing, |a| value(&a.spot, Some(i128::from(a.value)))),
        _ => Sets::Nothing,
    }
}

/// Do two values of sub-index `sub` of a communication object mean the
/// same? (For the COB-ID: the same identifier with the same validity.)
fn same(mapping: bool, sub: u8, written: i128, set: i128) -> bool {
    if mapping || sub != 1 {
        return written == set;
    }
    let invalid = |v: i128| v & 0x8000_0000 != 0;
    let id = |v: i128| v & 0x1FFF_FFFF;
    invalid(written) == invalid(set) && (invalid(set) || id(written) == id(set))
}

/// `net::sdo-pdo-conflict`: one `sdo:` write to a PDO parameter object.
fn sdo_write(slave: &SlaveSection, node: &Node, item: &SdoItem, report: &mut Report<'_>) {
    let (direction, mapping, first) = match item.index {
        0x1400..=0x15FF => (PdoDirection::Rpdo, false, 0x1400),
        0x1600..=0x17FF => (PdoDirection::Rpdo, true, 0x1600),
        0x1800..=0x19FF => (PdoDirection::Tpdo, false, 0x1800),
        0x1A00..=0x1BFF => (PdoDirection::Tpdo, true, 0x1A00),
        _ => return,
    };
    let n = item.index - first + 1;
    let pdo_name = label(direction, n);
    let (sections, pdos, key) = match direction {
        PdoDirection::Rpdo => (&slave.rpdo, &node.rpdos, "rpdo"),
        PdoDirection::Tpdo => (&slave.tpdo, &node.tpdos, "tpdo"),
    };
    let pdo = pdos.iter().find(|p| p.number == n);
    let show = |v: i128| {
        if (mapping && item.sub_index > 0) || item.sub_index == 1 {
            format!("0x{v:08X}")
        } else {
            v.to_string()
        }
    };
    let what = format!(
        "this SDO write sets 0x{:04X} sub {} ({pdo_name}'s {}) to {}",
        item.index,
        item.sub_index,
        if mapping {
            "mapping"
        } else {
            "communication parameter"
        },
        show(item.value)
    );
    let sets = sections.get(&n).map_or(Sets::Nothing, |s| {
        section_sets(s, direction, mapping, item.sub_index, pdo, &slave.device)
    });
    match sets {
        Sets::Value(spot, Some(set)) if same(mapping, item.sub_index, item.value, set) => {
            report.warning(
                "net::sdo-pdo-conflict",
                &item.spot,
                format!(
                    "{what}, which `{}` (line {}) sets already",
                    spot.key, spot.line
                ),
                vec!["drop the SDO write".into()],
            );
        }
        Sets::Value(spot, set) => {
            let set = set.map_or_else(String::new, |v| format!(" to {}", show(v)));
            report.error(
                "net::sdo-pdo-conflict",
                &item.spot,
                format!(
                    "{what}, but `{}` (line {}) sets it{set}",
                    spot.key, spot.line
                ),
                vec![
                    "the SDO list is written last, so the device gets the SDO value while \
                     master.dcf and the generated network follow the section; drop the SDO \
                     write and change the section"
                        .into(),
                ],
            );
        }
        Sets::Nothing => {
            let Some(default) = device_int(&slave.device, item.index, item.sub_index, node.node_id)
            else {
                return;
            };
            if same(mapping, item.sub_index, item.value, default) {
                return;
            }
            let severity_error = mapping || item.sub_index == 1;
            let message = format!(
                "{what}, behind the `{key}` section: master.dcf and the generated network \
                 follow the bus file's sections and the device file ({} here), not \
                 the SDO list",
                show(default)
            );
            let notes = vec![format!(
                "write it in the section instead: `{key}: {{ {n}: {{ ... }} }}`"
            )];
            if severity_error {
                report.error("net::sdo-pdo-conflict", &item.spot, message, notes);
            } else {
                report.warning("net::sdo-pdo-conflict", &item.spot, message, notes);
            }
        }
    }
}

/// `net::pdo-unproduced`, `net::pdo-unconsumed`.
fn never_sent(net: &Net, slave: &SlaveSection, node: &Node, report: &mut Report<'_>) {
    let no_sync = net.bus.master.sync_period == 0;
    for (direction, sections) in sections(slave) {
        let pdos = match direction {
            PdoDirection::Rpdo => &node.rpdos,
            PdoDirection::Tpdo => &node.tpdos,
        };
        for pdo in pdos {
            let section = sections.get(&pdo.number);
            let spot = section
                .and_then(|s| s.transmission.as_ref().map(|t| &t.spot))
                .or(pdo.spot.as_ref())
                .unwrap_or(&slave.spot);
            let name = format!("{} of `{}`", label(direction, pdo.number), slave.name);
            let t = pdo.transmission;
            if t <= 240 && no_sync {
                let sender = match direction {
                    PdoDirection::Tpdo => "the slave sends it",
                    PdoDirection::Rpdo => "the master sends its TPDO for it",
                };
                report.warning(
                    "net::pdo-unproduced",
                    spot,
                    format!(
                        "{name} is synchronous (transmission {t}), but no SYNC is sent \
                         (the master's `sync_period` is 0): {sender} on SYNC only, so it never goes out"
                    ),
                    vec![
                        "set the master's `sync_period` (µs), or make the PDO \
                         event-driven (`transmission: 255` with an `event_timer`)"
                            .into(),
                    ],
                );
            } else if direction == PdoDirection::Tpdo && (t == 252 || t == 253) {
                report.warning(
                    "net::pdo-unproduced",
                    spot,
                    format!(
                        "{name} is sent on remote request only (transmission {t}), and the \
                         master never requests it: its RPDO for it never arrives"
                    ),
                    vec!["make it synchronous (1..=240) or event-driven (254, 255)".into()],
                );
            }
        }
        for (&n, section) in sections {
            if !section.enabled.value || pdos.iter().any(|p| p.number == n) {
                continue;
            }
            let empty = section.mapping.as_ref().is_some_and(Vec::is_empty);
            let name = format!("{} of `{}`", label(direction, n), slave.name);
            let (code, message) = match (direction, empty) {
                (PdoDirection::Tpdo, true) => (
                    "net::pdo-unconsumed",
                    format!(
                        "{name} is enabled with an empty mapping: the slave sends empty \
                         frames that no one reads (dcfgen gives the master no RPDO for it)"
                    ),
                ),
                (PdoDirection::Rpdo, true) => (
                    "net::pdo-unproduced",
                    format!(
                        "{name} is enabled with an empty mapping: no one sends it (dcfgen \
                         gives the master no TPDO for it)"
                    ),
                ),
                (_, false) => (
                    "net::pdo-unproduced",
                    format!(
                        "{name} is enabled here but is not a valid PDO once configured: its \
                         device file's mapping is empty, or its COB-ID there has bit 31 set \
                         and the section gives no `cob_id:` (dcfgen then skips the section)"
                    ),
                ),
            };
            report.warning(
                code,
                &section.spot,
                message,
                vec!["write `enabled: false`, or give it a `mapping:` and a `cob_id:`".into()],
            );
        }
    }
}
