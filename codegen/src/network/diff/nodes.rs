//! A node's wiring: added or removed, its node id, device identity and
//! file, its configured PDOs and its error control.

use super::out::{Out, Side, at_value, consumer_time, graded, hex_val};
use super::{NetChange, Wiring};
use crate::diff::pdo::listed;
use crate::diff::{Severity, Val, hex};
use crate::network::config::{Node, Pdo};
use crate::network::model::{Bus, SlaveSection};
use crate::text::code_span;

/// `device type 0x20192, vendor 0xB9, product 0x1, revision 0x2, serial
/// 0x0` as the master checks it (0: not checked).
fn show_identity(node: &Node) -> String {
    format!(
        "device type {}, vendor {}, product {}, revision {}, serial {}",
        hex(node.device_type.into()),
        hex(node.vendor_id.into()),
        hex(node.product_code.into()),
        hex(node.revision_number.into()),
        hex(node.serial_number.into())
    )
}

fn pdo_counts(node: &Node) -> String {
    let n = |k: usize, what: &str| format!("{k} {what}{}", if k == 1 { "" } else { "s" });
    format!(
        "{}, {}",
        n(node.rpdos.len(), "RPDO"),
        n(node.tpdos.len(), "TPDO")
    )
}

fn added_or_removed(out: &mut Vec<NetChange>, slave: &SlaveSection, node: &Node, added: bool) {
    let (kind, severity, verb) = if added {
        (Wiring::NodeAdded, Severity::Additive, "added")
    } else {
        (Wiring::NodeRemoved, Severity::Breaking, "removed")
    };
    let message = format!(
        "node {verb}: id {}, device file {} ({}), {}",
        node.node_id,
        code_span(&slave.dcf.value),
        show_identity(node),
        pdo_counts(node)
    );
    let id = Some(Val::Int(node.node_id.into()));
    let (old, new) = if added { (None, id) } else { (id, None) };
    Out {
        out,
        node: &node.name,
    }
    .push(kind, severity, (0, None), "node", old, new, message);
}

pub(super) fn node_added(out: &mut Vec<NetChange>, bus: &Bus, node: &Node) {
    if let Some(slave) = bus.slaves.get(node.slave) {
        added_or_removed(out, slave, node, true);
    }
}

pub(super) fn node_removed(out: &mut Vec<NetChange>, bus: &Bus, node: &Node) {
    if let Some(slave) = bus.slaves.get(node.slave) {
        added_or_removed(out, slave, node, false);
    }
}

/// A node in both networks: its id, identity, PDOs and error control.
pub(super) fn node(o: &mut Out, old: Side, new: Side) {
    let ((_, on, os), (_, nn, ns)) = (old, new);
    if on.node_id != nn.node_id {
        o.push(
            Wiring::NodeIdChanged,
            Severity::Breaking,
            (0, None),
            "node",
            Some(Val::Int(on.node_id.into())),
            Some(Val::Int(nn.node_id.into())),
            format!("node id {} → {}", on.node_id, nn.node_id),
        );
    }
    identity_changes(o, (on, os), (nn, ns));
    let ids = (on.node_id, nn.node_id);
    pdos(o, ("RPDO", 0x1400), ids, &on.rpdos, &nn.rpdos);
    pdos(o, ("TPDO", 0x1800), ids, &on.tpdos, &nn.tpdos);
    error_control(o, old, new);
}

/// The identity the master checks: another device type, vendor or
/// product is another device (breaking); another revision or serial
/// number is the same device (compatible). A new device file with the same
/// identity is compatible too (its API changes are the device diff's).
fn identity_changes(
    o: &mut Out,
    (on, os): (&Node, &SlaveSection),
    (nn, ns): (&Node, &SlaveSection),
) {
    let device = |n: &Node| (n.device_type, n.vendor_id, n.product_code);
    let full = |n: &Node| (device(n), n.revision_number, n.serial_number);
    let files = (&os.dcf.value, &ns.dcf.value);
    let same_device = device(on) == device(nn);
    if full(on) != full(nn) {
        let severity = if same_device {
            Severity::Compatible
        } else {
            Severity::Breaking
        };
        let file = if files.0 == files.1 {
            String::new()
        } else {
            format!(
                " (device file {} → {})",
                code_span(files.0),
                code_span(files.1)
            )
        };
        let (oi, ni) = (show_identity(on), show_identity(nn));
        let message = format!("identity {oi} → {ni}{file}");
        o.push(
            Wiring::NodeIdentityChanged,
            severity,
            (0x1018, None),
            "node",
            Some(Val::Text(oi)),
            Some(Val::Text(ni)),
            message,
        );
    }
    if files.0 != files.1 && same_device {
        o.push(
            Wiring::NodeDeviceFileChanged,
            Severity::Compatible,
            (0, None),
            "node",
            Some(Val::Text(files.0.clone())),
            Some(Val::Text(files.1.clone())),
            format!(
                "device file {} → {} (same device type, vendor and product)",
                code_span(files.0),
                code_span(files.1)
            ),
        );
    }
}

fn mapping(pdo: &Pdo) -> Val {
    Val::List(listed(
        &pdo.mapping.iter().map(|m| m.raw()).collect::<Vec<_>>(),
    ))
}

/// One direction's PDOs, by number. `ids`: the node's old and new id (a
/// COB-ID that moves with it says so).
fn pdos(o: &mut Out, (prefix, comm_base): (&str, u16), ids: (u8, u8), old: &[Pdo], new: &[Pdo]) {
    let mut numbers: Vec<u16> = old.iter().chain(new).map(|p| p.number).collect();
    numbers.sort_unstable();
    numbers.dedup();
    for number in numbers {
        let name = format!("{prefix}{number}");
        let comm = comm_base.wrapping_add(number.wrapping_sub(1) & 0x1FF);
        let map = comm.wrapping_add(0x200);
        let find = |list: &[Pdo]| list.iter().find(|p| p.number == number).cloned();
        let (p, n) = match (find(old), find(new)) {
            (None, Some(n)) => {
                let message = format!(
                    "{name} enabled: COB-ID {}, transmission {}, mapping {}",
                    hex(n.cob_id.into()),
                    n.transmission,
                    mapping(&n)
                );
                o.push(
                    Wiring::PdoEnabled,
                    Severity::Additive,
                    (comm, None),
                    &name,
                    None,
                    Some(mapping(&n)),
                    message,
                );
                continue;
            }
            (Some(p), None) => {
                let message = format!(
                    "{name} disabled: was COB-ID {}, mapping {}",
                    hex(p.cob_id.into()),
                    mapping(&p)
                );
                o.push(
                    Wiring::PdoDisabled,
                    Severity::Breaking,
                    (comm, None),
                    &name,
                    Some(mapping(&p)),
                    None,
                    message,
                );
                continue;
            }
            (Some(p), Some(n)) => (p, n),
            (None, None) => continue,
        };
        if p.mapping != n.mapping {
            let (ov, nv) = (mapping(&p), mapping(&n));
            let message = format!("{name} remapped: {ov} → {nv}");
            o.push(
                Wiring::PdoRemapped,
                Severity::Breaking,
                (map, None),
                &name,
                Some(ov),
                Some(nv),
                message,
            );
        }
        if p.cob_id != n.cob_id {
            let with_id = ids.0 != ids.1
                && i64::from(n.cob_id) - i64::from(p.cob_id) == i64::from(ids.1) - i64::from(ids.0);
            let message = format!(
                "{name} COB-ID {} → {}{}",
                hex(p.cob_id.into()),
                hex(n.cob_id.into()),
                if with_id { " (with the node id)" } else { "" }
            );
            o.push(
                Wiring::PdoCobIdMoved,
                Severity::Breaking,
                (comm, Some(1)),
                &name,
                Some(hex_val(p.cob_id)),
                Some(hex_val(n.cob_id)),
                message,
            );
        }
        let fields: [(Wiring, u8, &str, &str, u16, u16); 4] = [
            (
                Wiring::PdoTransmissionChanged,
                2,
                "transmission type",
                "",
                p.transmission.into(),
                n.transmission.into(),
            ),
            (
                Wiring::PdoInhibitTimeChanged,
                3,
                "inhibit time",
                " × 100 µs",
                p.inhibit_time,
                n.inhibit_time,
            ),
            (
                Wiring::PdoEventTimerChanged,
                5,
                "event timer",
                " ms",
                p.event_timer,
                n.event_timer,
            ),
            (
                Wiring::PdoSyncStartChanged,
                6,
                "SYNC start value",
                "",
                p.sync_start.into(),
                n.sync_start.into(),
            ),
        ];
        for (kind, sub, what, unit, ov, nv) in fields {
            if ov != nv {
                o.push(
                    kind,
                    Severity::Compatible,
                    (comm, Some(sub)),
                    &name,
                    Some(Val::Int(ov.into())),
                    Some(Val::Int(nv.into())),
                    format!("{name} {what} {ov}{unit} → {nv}{unit}"),
                );
            }
        }
    }
}

/// The slave's effective heartbeat multiplier (its own, else the options').
fn multiplier(bus: &Bus, slave: &SlaveSection) -> f64 {
    at_value(&slave.heartbeat_multiplier)
        .copied()
        .unwrap_or(bus.options.heartbeat_multiplier)
}

fn error_control(o: &mut Out, (ob, on, os): Side, (nb, nn, ns): Side) {
    o.timed(
        Wiring::HeartbeatProducerChanged,
        (0x1017, Some(0)),
        "heartbeat",
        "heartbeat producer time",
        "ms",
        on.heartbeat_producer.into(),
        nn.heartbeat_producer.into(),
    );
    if on.heartbeat_consumer != nn.heartbeat_consumer {
        o.push(
            Wiring::HeartbeatConsumerChanged,
            graded(on.heartbeat_consumer.into(), nn.heartbeat_consumer.into()),
            (0x1016, None),
            "heartbeat",
            Some(Val::Bool(on.heartbeat_consumer)),
            Some(Val::Bool(nn.heartbeat_consumer)),
            format!(
                "consumes the master's heartbeat: {} → {}",
                on.heartbeat_consumer, nn.heartbeat_consumer
            ),
        );
    }
    // The master's consumer time for this node moves with the producer
    // time (reported above) and with the multiplier (reported here).
    let (om, nm) = (multiplier(ob, os), multiplier(nb, ns));
    if om != nm && on.heartbeat_producer == nn.heartbeat_producer && on.heartbeat_producer != 0 {
        let (ot, nt) = (
            consumer_time(on.heartbeat_producer, om),
            consumer_time(nn.heartbeat_producer, nm),
        );
        o.push(
            Wiring::HeartbeatConsumerChanged,
            Severity::Compatible,
            (0, None),
            "heartbeat",
            Some(Val::Real(om)),
            Some(Val::Real(nm)),
            format!(
                "heartbeat multiplier {om} → {nm}: the master waits {ot} → {nt} ms for its heartbeat"
            ),
        );
    }
    let (og, ng) = (
        (on.guard_time, on.life_time_factor),
        (nn.guard_time, nn.life_time_factor),
    );
    if og != ng {
        let life = |(t, f): (u16, u8)| u64::from(t) * u64::from(f);
        o.push(
            Wiring::GuardingChanged,
            graded(life(og), life(ng)),
            (0x100C, None),
            "guarding",
            Some(Val::List(vec![og.0.to_string(), og.1.to_string()])),
            Some(Val::List(vec![ng.0.to_string(), ng.1.to_string()])),
            format!(
                "node guarding {} ms × {} → {} ms × {}",
                og.0, og.1, ng.0, ng.1
            ),
        );
    }
}
