//! Node ids and COB-IDs: `net::node-id`, `net::node-id-collision`,
//! `net::cob-id-collision`, `net::cob-id-restricted`.

use std::collections::BTreeMap;

use super::context::{Net, Report};
use crate::network::config::Pdo;
use crate::network::model::{PdoSection, Spot};

/// The ranges of 11-bit CAN-IDs that CiA 301 restricts (no PDO, SYNC,
/// TIME or EMCY may use them), each with what it is kept for.
pub(super) const RESTRICTED: &[(u32, u32, &str)] = &[
    (0x000, 0x000, "NMT"),
    (0x001, 0x07F, "reserved"),
    (0x101, 0x180, "reserved"),
    (0x581, 0x5FF, "SDO responses"),
    (0x601, 0x67F, "SDO requests"),
    (0x6E0, 0x6FF, "reserved"),
    (0x701, 0x77F, "NMT error control"),
    (0x780, 0x7FF, "reserved, LSS"),
];

/// A COB-ID as the CAN identifier it sends: the 29-bit identifier when
/// bit 29 (frame) is set or the value does not fit 11 bits, else the
/// 11-bit one; flags (bits 31, 30) dropped.
pub(super) fn can_id(raw: u32) -> (u32, bool) {
    let id = raw & 0x1FFF_FFFF;
    if raw & 0x2000_0000 != 0 || id > 0x7FF {
        (id, true)
    } else {
        (id, false)
    }
}

/// One sender of one COB-ID.
struct Producer {
    id: (u32, bool),
    /// Who sends it, for the message (`node drive's TPDO 1`).
    who: String,
    spot: Spot,
    /// A PDO (its COB-ID is configurable) rather than a service fixed by
    /// the node id.
    pdo: bool,
    /// A PDO the bus file configures (not the device file's default).
    written: bool,
    /// For a PDO the master sends for a slave's RPDO: that slave's name
    /// and the RPDO number.
    mirrors: Option<(String, u16)>,
    /// TIME (the master's COB-ID is kept free for it; a slave producing
    /// TIME on it is no collision).
    time: bool,
}

pub(super) fn check(net: &Net, report: &mut Report<'_>) {
    node_ids(net, report);
    let producers = producers(net);
    collisions(&producers, report);
    restricted(&producers, report);
}

/// `net::node-id`, `net::node-id-collision`.
fn node_ids(net: &Net, report: &mut Report<'_>) {
    let master = &net.bus.master;
    let master_written = master.spots.contains_key("node_id");
    if net.master_id().is_none() {
        let spot = net.master_spot("node_id");
        if master_written && master.node_id != 255 {
            report.error(
                "net::node-id",
                &spot,
                format!("the master's node id {} is outside 1..=127", master.node_id),
                vec!["write a node id 1..=127 that no slave has".into()],
            );
        } else {
            report.warning(
                "net::node-id",
                &spot,
                "the master has no node id (255, unconfigured): its EMCY, heartbeat and \
                 the slaves' heartbeat consumer entries for it cannot be set up"
                    .into(),
                vec!["write `node_id:` (1..=127, one no slave has) in `master:`".into()],
            );
        }
    }
    for slave in &net.bus.slaves {
        let Some(id) = &slave.node_id else { continue };
        if id.value == 0 || (128..255).contains(&id.value) {
            report.error(
                "net::node-id",
                &id.spot,
                format!("node id {} is outside 1..=127", id.value),
                vec!["write a node id 1..=127 that no other node has".into()],
            );
        }
    }
    let mut seen: BTreeMap<u8, (String, Spot)> = BTreeMap::new();
    if let Some(m) = net.master_id() {
        seen.insert(m, ("the master".into(), net.master_spot("node_id")));
    }
    for (node, slave) in net.nodes() {
        if !crate::ir::NODE_IDS.contains(&node.node_id) {
            continue;
        }
        let spot = Net::node_id_spot(slave);
        match seen.get(&node.node_id) {
            Some((other, _)) => report.error(
                "net::node-id-collision",
                &spot,
                format!(
                    "node id {} of slave `{}` is also the node id of {other}",
                    node.node_id, node.name
                ),
                vec![format!(
                    "every node needs its own id: its EMCY, SDO and heartbeat COB-IDs \
                     follow from it; free ids: {}",
                    free_ids(&seen)
                )],
            ),
            None => {
                seen.insert(node.node_id, (format!("slave `{}`", node.name), spot));
            }
        }
    }
}

/// The first few node ids not in `used`, for the note.
fn free_ids(used: &BTreeMap<u8, (String, Spot)>) -> String {
    let free: Vec<String> = crate::ir::NODE_IDS
        .filter(|id| !used.contains_key(id))
        .take(5)
        .map(|id| id.to_string())
        .collect();
    format!("{}, ...", free.join(", "))
}

/// Every sender of a COB-ID on the bus, masters's services first, then
/// each node's services and PDOs in the bus's order. Services of a node
/// whose id is taken already are left out (`net::node-id-collision`
/// reports that).
fn producers(net: &Net) -> Vec<Producer> {
    let mut out = Vec::new();
    let service = |id: u32, who: String, spot: &Spot| Producer {
        id: (id, false),
        who,
        spot: spot.clone(),
        pdo: false,
        written: false,
        mirrors: None,
        time: false,
    };
    let master = &net.bus.master;
    out.push(service(0x000, "NMT (the master)".into(), &master.spot));
    if master.sync_period > 0 {
        out.push(service(
            0x080,
            "SYNC (the master)".into(),
            &net.master_spot("sync_period"),
        ));
    }
    // TIME's COB-ID is kept free whether the master sends or receives it.
    out.push(Producer {
        id: can_id(master.time_cob_id),
        time: true,
        ..service(0, "TIME".into(), &net.master_spot("time_cob_id"))
    });
    out.push(service(
        0x7E4,
        "LSS (the slaves' responses)".into(),
        &master.spot,
    ));
    out.push(service(
        0x7E5,
        "LSS (the master's requests)".into(),
        &master.spot,
    ));
    let mut ids = Vec::new();
    if let Some(m) = net.master_id() {
        ids.push(m);
        let spot = net.master_spot("node_id");
        node_services(&mut out, m, "the master", 0x80 + u32::from(m), &spot);
    }
    for (node, slave) in net.nodes() {
        // A node whose id is out of range or taken: its COB-IDs follow
        // from the id, and `net::node-id*` reports that already.
        if !crate::ir::NODE_IDS.contains(&node.node_id) || ids.contains(&node.node_id) {
            continue;
        }
        ids.push(node.node_id);
        let spot = Net::node_id_spot(slave);
        let who = format!("slave `{}`", node.name);
        node_services(&mut out, node.node_id, &who, node.emcy_cob_id, &spot);
        if node.time_cob_id & 0x4000_0000 != 0 {
            out.push(Producer {
                id: can_id(node.time_cob_id),
                time: true,
                ..service(0, format!("TIME ({who})"), &spot)
            });
        }
        for pdo in &node.tpdos {
            out.push(pdo_producer(
                pdo,
                format!("TPDO {} of slave `{}`", pdo.number, node.name),
                cob_id_spot(slave.tpdo.get(&pdo.number), pdo, &slave.spot),
                None,
            ));
        }
        for pdo in &node.rpdos {
            out.push(pdo_producer(
                pdo,
                format!(
                    "the master (its TPDO for RPDO {} of slave `{}`)",
                    pdo.number, node.name
                ),
                cob_id_spot(slave.rpdo.get(&pdo.number), pdo, &slave.spot),
                Some((node.name.clone(), pdo.number)),
            ));
        }
    }
    out
}

/// EMCY (unless invalid), the two SDO server channels and NMT error control
/// of node `id`.
fn node_services(out: &mut Vec<Producer>, id: u8, who: &str, emcy: u32, spot: &Spot) {
    let id32 = u32::from(id);
    let mut push = |cob: (u32, bool), what: &str| {
        out.push(Producer {
            id: cob,
            who: format!("{what} of {who} (node {id})"),
            spot: spot.clone(),
            pdo: false,
            written: false,
            mirrors: None,
            time: false,
        });
    };
    if emcy & 0x8000_0000 == 0 {
        // A device file without a value for 0x1014 uses the pre-defined
        // COB-ID (0x000 is NMT's, never an EMCY's).
        let cob = if emcy & 0x1FFF_FFFF == 0 {
            0x80 + id32
        } else {
            emcy
        };
        push(can_id(cob), "EMCY");
    }
    push((0x580 + id32, false), "the SDO response");
    push((0x600 + id32, false), "the SDO request");
    push((0x700 + id32, false), "heartbeat/boot-up");
}

/// Where a PDO's COB-ID is written: its `cob_id:`, else its section,
/// else the slave (a device file's default PDO).
fn cob_id_spot(section: Option<&PdoSection>, pdo: &Pdo, slave: &Spot) -> Spot {
    section
        .and_then(|s| s.cob_id.as_ref().map(|c| &c.spot))
        .or(pdo.spot.as_ref())
        .unwrap_or(slave)
        .clone()
}

fn pdo_producer(pdo: &Pdo, who: String, spot: Spot, mirrors: Option<(String, u16)>) -> Producer {
    Producer {
        id: can_id(pdo.cob_id),
        who,
        spot,
        pdo: true,
        written: pdo.spot.is_some(),
        mirrors,
        time: false,
    }
}

fn show(id: (u32, bool)) -> String {
    match id {
        (id, false) => format!("0x{id:03X}"),
        (id, true) => format!("0x{id:08X} (29-bit)"),
    }
}

/// `net::cob-id-collision`: each producer that shares its COB-ID with an
/// earlier one, reported at the PDO of the pair (its COB-ID is what can
/// be changed).
fn collisions(producers: &[Producer], report: &mut Report<'_>) {
    for (j, later) in producers.iter().enumerate() {
        let Some(first) = producers[..j]
            .iter()
            .find(|p| p.id == later.id && !(p.time && later.time))
        else {
            continue;
        };
        // Where the fix is: a PDO the bus file configures, else a PDO,
        // else the later node.
        let rank = |p: &Producer| u8::from(p.pdo) + u8::from(p.written);
        let spot = if rank(later) >= rank(first) {
            &later.spot
        } else {
            &first.spot
        };
        let mut notes = Vec::new();
        let sender = [first, later]
            .into_iter()
            .find(|p| p.pdo && p.mirrors.is_none())
            .map(|p| p.who.clone());
        match (&first.mirrors, &later.mirrors, sender) {
            (None, Some((slave, n)), Some(sender)) | (Some((slave, n)), None, Some(sender)) => {
                notes.push(format!(
                    "RPDO {n} of slave `{slave}` listens to {sender} directly; dcfgen's \
                     master.dcf turns every slave RPDO into a master TPDO, so the master \
                     sends on this COB-ID too"
                ));
                notes.push(
                    "give the RPDO a COB-ID of its own and let the application copy the \
                     data, or leave this RPDO out of the bus file and configure it over SDO \
                     at run time"
                        .into(),
                );
            }
            _ if first.pdo || later.pdo => notes.push(
                "give the PDO a COB-ID no other node sends (`cob_id:` in its section; \
                 `auto` picks a free one for PDOs past the fourth)"
                    .into(),
            ),
            _ => notes.push("give one of the nodes another node id".into()),
        }
        report.error(
            "net::cob-id-collision",
            spot,
            format!(
                "COB-ID {} is sent by {} and by {}",
                show(later.id),
                first.who,
                later.who
            ),
            notes,
        );
    }
}

/// `net::cob-id-restricted`: a PDO on an 11-bit CAN-ID that CiA 301
/// restricts.
fn restricted(producers: &[Producer], report: &mut Report<'_>) {
    for p in producers.iter().filter(|p| p.pdo && !p.id.1) {
        let id = p.id.0;
        let Some(&(low, high, what)) = RESTRICTED.iter().find(|(l, h, _)| (*l..=*h).contains(&id))
        else {
            continue;
        };
        let range = if low == high {
            format!("0x{low:03X}")
        } else {
            format!("0x{low:03X}–0x{high:03X}")
        };
        report.warning(
            "net::cob-id-restricted",
            &p.spot,
            format!(
                "{} uses COB-ID 0x{id:03X}, which CiA 301 restricts ({range}: {what})",
                p.who
            ),
            vec![
                "devices may refuse it; give the PDO a COB-ID in 0x181–0x57F or \
                 0x680–0x6DF"
                    .into(),
            ],
        );
    }
}
