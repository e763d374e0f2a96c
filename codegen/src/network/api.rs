//! `eds2rust api` on a bus file: the network's wiring and every node's
//! device API as one lockable listing (docs/network.md, Reviewing a network
//! change). Lines are TAB-separated like the device listing
//! (docs/api-listing.md), each prefixed by its section:
//!
//! - `master → network → node_id=… → baudrate=… → sync_period=… → …`;
//! - per node, in the bus's order: `NODE → node → id=… → device_type=… → …`,
//!   then its configured PDOs `NODE → rpdo 1 → cob_id=… → … → mapping`,
//!   then the listing of its device as this network configures it
//!   ([`super::configured::configured_device`]: the `pdo::` lines are the
//!   network's PDOs), each line prefixed by `NODE`.

use std::fmt::Write;
use std::path::Path;

use super::config::{Configured, Node, Pdo};
use super::model::{Bus, MasterSection};
use crate::diag::Diagnostics;
use crate::r#gen::rust::od_plan::{DeviceNames, device_names};
use crate::r#gen::rust::{self, ApiListing};

/// The listing of a configured network; its errors are those of
/// generating each node's device (with `options.strict`, warnings too).
pub fn api_listing(
    bus: &Bus,
    configured: &Configured,
    options: &rust::Options,
) -> Result<ApiListing, Diagnostics> {
    let mut text = master_line(&bus.master);
    let mut warnings = Diagnostics::new();
    let mut errors = Diagnostics::new();
    for node in &configured.nodes {
        let Some(slave) = bus.slaves.get(node.slave) else {
            continue;
        };
        let prefix = node_column(&node.name);
        let names = device_names(&slave.device);
        text.push_str(&node_line(&prefix, node));
        for (direction, pdos) in [("rpdo", &node.rpdos), ("tpdo", &node.tpdos)] {
            for pdo in pdos {
                text.push_str(&pdo_line(&prefix, direction, pdo, &names));
            }
        }
        // The node's device with this network's PDOs, as the generated
        // network makes its module (`pdo::` lines are the network's PDOs).
        let device = super::configured::configured_device(&slave.device, node);
        match rust::api_listing(&device, options) {
            Ok(listing) => {
                warnings.extend(listing.warnings);
                for line in listing.text.lines() {
                    let _ = writeln!(text, "{prefix}\t{line}");
                }
            }
            Err(e) => errors.extend(e),
        }
    }
    if errors.has_errors() {
        errors.extend(warnings);
        errors.sort();
        return Err(errors);
    }
    Ok(ApiListing {
        text: crate::text::code(&text).into_owned(),
        warnings,
    })
}

/// Reads a bus file ([`super::read_file`]), configures it
/// ([`super::configure`]) and lists it; `read`'s levels and
/// `strict` apply to every diagnostic.
pub fn api_listing_file(
    path: &Path,
    read: &crate::read::Options,
) -> Result<ApiListing, Diagnostics> {
    let loaded = super::read_file(path, read);
    let mut diagnostics = loaded.diagnostics;
    let Some(bus) = loaded.bus.filter(|_| !diagnostics.has_errors()) else {
        return Err(diagnostics);
    };
    let (configured, more) = super::configure(&bus);
    diagnostics.extend(more);
    diagnostics.apply_levels(&read.levels, read.strict);
    if diagnostics.has_errors() {
        diagnostics.sort();
        return Err(diagnostics);
    }
    let (text, mut more) = match api_listing(&bus, &configured, &rust::Options::default()) {
        Ok(listing) => (Some(listing.text), listing.warnings),
        Err(errors) => (None, errors),
    };
    more.apply_levels(&read.levels, read.strict);
    diagnostics.extend(more);
    diagnostics.sort();
    match text {
        Some(text) if !diagnostics.has_errors() => Ok(ApiListing {
            text,
            warnings: diagnostics,
        }),
        _ => Err(diagnostics),
    }
}

/// The node's name as the first column: as written when it is one plain
/// word, else quoted and escaped as a Rust string literal (no TAB or line
/// break can reach a column).
fn node_column(name: &str) -> String {
    let plain = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '.'));
    if plain {
        name.to_string()
    } else {
        format!("{name:?}")
    }
}

fn hex(v: u32) -> String {
    format!("0x{v:X}")
}

fn master_line(m: &MasterSection) -> String {
    format!(
        "master\tnetwork\tnode_id={}\tbaudrate={}\tsync_period={}\tsync_window={}\tsync_overflow={}\theartbeat_producer={}\theartbeat_consumer={}\n",
        m.node_id,
        m.baudrate,
        m.sync_period,
        m.sync_window,
        m.sync_overflow,
        m.heartbeat_producer,
        m.heartbeat_consumer
    )
}

/// The node's id, the identity the master checks (0: not checked) and its
/// error control.
fn node_line(prefix: &str, node: &Node) -> String {
    format!(
        "{prefix}\tnode\tid={}\tdevice_type={}\tvendor={}\tproduct={}\trevision={}\tserial={}\theartbeat_producer={}\theartbeat_consumer={}\n",
        node.node_id,
        hex(node.device_type),
        hex(node.vendor_id),
        hex(node.product_code),
        hex(node.revision_number),
        hex(node.serial_number),
        node.heartbeat_producer,
        node.heartbeat_consumer
    )
}

/// `0x6041.0@0..16:od::Statusword, …` (`dummy 0x0005@16..24` for a gap).
fn mapping(pdo: &Pdo, names: &DeviceNames) -> String {
    let mut start = 0u32;
    let items: Vec<String> = pdo
        .mapping
        .iter()
        .map(|m| {
            let end = start + u32::from(m.bits);
            let item = if m.is_dummy() {
                format!("dummy 0x{:04X}@{start}..{end}", m.index)
            } else {
                let path = names
                    .entries
                    .get(&(m.index, m.subindex))
                    .map_or(String::new(), |p| format!(":{}", p.0));
                format!("0x{:04X}.{}@{start}..{end}{path}", m.index, m.subindex)
            };
            start = end;
            item
        })
        .collect();
    items.join(", ")
}

fn pdo_line(prefix: &str, direction: &str, pdo: &Pdo, names: &DeviceNames) -> String {
    format!(
        "{prefix}\t{direction} {}\tcob_id={}\ttransmission={}\tinhibit_time={}\tevent_timer={}\tsync_start={}\t{}\n",
        pdo.number,
        hex(pdo.cob_id),
        pdo.transmission,
        pdo.inhibit_time,
        pdo.event_timer,
        pdo.sync_start,
        mapping(pdo, names)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::pdo::MappedObject;

    #[test]
    fn node_names_that_are_not_one_word_are_quoted() {
        assert_eq!(node_column("axis_1"), "axis_1");
        assert_eq!(node_column("prbt-joint.2"), "prbt-joint.2");
        assert_eq!(node_column("a\tb"), "\"a\\tb\"");
        assert_eq!(node_column("two words"), "\"two words\"");
        assert_eq!(node_column(""), "\"\"");
    }

    #[test]
    fn a_mapping_lists_bit_ranges_gaps_and_unknown_entries() {
        let mapped = vec![
            MappedObject {
                index: 0x6041,
                subindex: 0,
                bits: 16,
            },
            MappedObject {
                index: 0x0005,
                subindex: 0,
                bits: 8,
            },
            MappedObject {
                index: 0x2000,
                subindex: 3,
                bits: 32,
            },
        ];
        let pdo = Pdo::new(1, 0x181, 1, mapped);
        assert_eq!(
            mapping(&pdo, &DeviceNames::default()),
            "0x6041.0@0..16, dummy 0x0005@16..24, 0x2000.3@24..56"
        );
        assert_eq!(
            pdo_line("axis", "tpdo", &pdo, &DeviceNames::default()),
            "axis\ttpdo 1\tcob_id=0x181\ttransmission=1\tinhibit_time=0\tevent_timer=0\tsync_start=0\t0x6041.0@0..16, dummy 0x0005@16..24, 0x2000.3@24..56\n"
        );
    }
}
