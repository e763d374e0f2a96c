//! The wiring rules: the bus file's own sections, nodes added or removed,
//! and, for a node in both networks, its id, identity, PDOs, error control,
//! `sdo:` writes and boot settings.

use std::collections::BTreeMap;
use std::fmt::Display;

use super::{MASTER, NetChange, NetKind, OPTIONS, Wiring};
use crate::diff::pdo::listed;
use crate::diff::{Severity, Val, hex};
use crate::network::config::{Node, Pdo};
use crate::network::model::{At, Bus, SlaveSection};
use crate::text::code_span;

/// A node in both networks: (bus, configured node, slave section) each side.
pub(super) struct Pair<'a> {
    pub old: (&'a Bus, &'a Node, &'a SlaveSection),
    pub new: (&'a Bus, &'a Node, &'a SlaveSection),
}

/// Pushes the changes of one section (a node, `master`, `options`).
struct Out<'a> {
    out: &'a mut Vec<NetChange>,
    node: &'a str,
}

impl Out<'_> {
    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        kind: Wiring,
        severity: Severity,
        (index, subindex): (u16, Option<u8>),
        place: &str,
        old: Option<Val>,
        new: Option<Val>,
        message: String,
    ) {
        self.out.push(NetChange {
            node: self.node.to_string(),
            kind: NetKind::Wiring(kind),
            severity,
            index,
            subindex,
            place: place.to_string(),
            rust_path: None,
            old,
            new,
            message,
        });
    }

    /// A value where 0 means off ([`graded`]), pushed when it changed.
    #[allow(clippy::too_many_arguments)]
    fn timed(
        &mut self,
        kind: Wiring,
        at: (u16, Option<u8>),
        place: &str,
        what: &str,
        unit: &str,
        old: u64,
        new: u64,
    ) {
        if old == new {
            return;
        }
        let message = match (old, new) {
            (0, n) => format!("{what} switched on: {n} {unit}"),
            (o, 0) => format!("{what} switched off: was {o} {unit}"),
            (o, n) => format!("{what} {o} → {n} {unit}"),
        };
        let (ov, nv) = (Val::Int(old.into()), Val::Int(new.into()));
        self.push(
            kind,
            graded(old, new),
            at,
            place,
            Some(ov),
            Some(nv),
            message,
        );
    }

    /// A boot setting compared as written: absent shows as `default`.
    fn setting<T: PartialEq + Display>(&mut self, key: &str, old: Option<&T>, new: Option<&T>) {
        if old == new {
            return;
        }
        let val = |v: Option<&T>| v.map(|v| Val::Text(v.to_string()));
        let show = |v: Option<&T>| v.map_or("default".to_string(), |v| v.to_string());
        let message = format!("{} {} → {}", code_span(key), show(old), show(new));
        self.push(
            Wiring::SettingChanged,
            Severity::Compatible,
            (0, None),
            key,
            val(old),
            val(new),
            message,
        );
    }
}

/// A time or period where 0 means off: switched on is additive, switched
/// off breaking, changed compatible (call only when `old != new`).
fn graded(old: u64, new: u64) -> Severity {
    match (old, new) {
        (0, _) => Severity::Additive,
        (_, 0) => Severity::Breaking,
        _ => Severity::Compatible,
    }
}

fn at_value<T>(at: &Option<At<T>>) -> Option<&T> {
    at.as_ref().map(|a| &a.value)
}

/// `0x1A8` as text, for COB-IDs and identity numbers.
fn hex_val(v: u32) -> Val {
    Val::Text(hex(v.into()))
}

/// The `options:` and `master:` sections.
pub(super) fn bus(out: &mut Vec<NetChange>, old: &Bus, new: &Bus) {
    let mut o = Out { out, node: OPTIONS };
    let (oo, no) = (&old.options, &new.options);
    o.setting("dcf_path", Some(&oo.dcf_path), Some(&no.dcf_path));
    o.setting(
        "heartbeat_multiplier",
        Some(&oo.heartbeat_multiplier),
        Some(&no.heartbeat_multiplier),
    );
    o.setting(
        "retry_factor",
        Some(&oo.retry_factor),
        Some(&no.retry_factor),
    );

    let mut o = Out { out, node: MASTER };
    let (om, nm) = (&old.master, &new.master);
    if om.node_id != nm.node_id {
        o.push(
            Wiring::NodeIdChanged,
            Severity::Breaking,
            (0, None),
            "node",
            Some(Val::Int(om.node_id.into())),
            Some(Val::Int(nm.node_id.into())),
            format!("master node id {} → {}", om.node_id, nm.node_id),
        );
    }
    if om.baudrate != nm.baudrate {
        o.push(
            Wiring::BaudrateChanged,
            Severity::Breaking,
            (0, None),
            "baudrate",
            Some(Val::Int(om.baudrate.into())),
            Some(Val::Int(nm.baudrate.into())),
            format!(
                "bit rate {} → {} kbit/s: every node must follow",
                om.baudrate, nm.baudrate
            ),
        );
    }
    let sync = (0x1006, Some(0));
    o.timed(
        Wiring::SyncPeriodChanged,
        sync,
        "SYNC",
        "SYNC period",
        "µs",
        om.sync_period.into(),
        nm.sync_period.into(),
    );
    if om.sync_window != nm.sync_window {
        o.push(
            Wiring::SyncWindowChanged,
            Severity::Compatible,
            (0x1007, Some(0)),
            "SYNC",
            Some(Val::Int(om.sync_window.into())),
            Some(Val::Int(nm.sync_window.into())),
            format!("SYNC window {} → {} µs", om.sync_window, nm.sync_window),
        );
    }
    if om.sync_overflow != nm.sync_overflow {
        o.push(
            Wiring::SyncOverflowChanged,
            Severity::Compatible,
            (0x1019, Some(0)),
            "SYNC",
            Some(Val::Int(om.sync_overflow.into())),
            Some(Val::Int(nm.sync_overflow.into())),
            format!(
                "SYNC counter overflow {} → {}",
                om.sync_overflow, nm.sync_overflow
            ),
        );
    }
    o.timed(
        Wiring::HeartbeatProducerChanged,
        (0x1017, Some(0)),
        "heartbeat",
        "master heartbeat producer time",
        "ms",
        om.heartbeat_producer.into(),
        nm.heartbeat_producer.into(),
    );
    if om.heartbeat_consumer != nm.heartbeat_consumer {
        o.push(
            Wiring::HeartbeatConsumerChanged,
            graded(om.heartbeat_consumer.into(), nm.heartbeat_consumer.into()),
            (0x1016, None),
            "heartbeat",
            Some(Val::Bool(om.heartbeat_consumer)),
            Some(Val::Bool(nm.heartbeat_consumer)),
            format!(
                "the master consumes the slaves' heartbeats: {} → {}",
                om.heartbeat_consumer, nm.heartbeat_consumer
            ),
        );
    }
    let waited = |m: &crate::network::model::MasterSection| {
        consumer_time(m.heartbeat_producer, m.heartbeat_multiplier)
    };
    if om.heartbeat_multiplier != nm.heartbeat_multiplier
        && om.heartbeat_producer == nm.heartbeat_producer
    {
        o.push(
            Wiring::HeartbeatConsumerChanged,
            Severity::Compatible,
            (0, None),
            "heartbeat",
            Some(Val::Real(om.heartbeat_multiplier)),
            Some(Val::Real(nm.heartbeat_multiplier)),
            format!(
                "heartbeat multiplier {} → {}: slaves consuming the master's heartbeat wait {} → {} ms",
                om.heartbeat_multiplier,
                nm.heartbeat_multiplier,
                waited(om),
                waited(nm)
            ),
        );
    }
    o.setting(
        "vendor_id",
        Some(&hex(om.vendor_id.into())),
        Some(&hex(nm.vendor_id.into())),
    );
    o.setting(
        "product_code",
        Some(&hex(om.product_code.into())),
        Some(&hex(nm.product_code.into())),
    );
    o.setting(
        "revision_number",
        Some(&hex(om.revision_number.into())),
        Some(&hex(nm.revision_number.into())),
    );
    o.setting(
        "serial_number",
        Some(&hex(om.serial_number.into())),
        Some(&hex(nm.serial_number.into())),
    );
    o.setting(
        "time_cob_id",
        Some(&hex(om.time_cob_id.into())),
        Some(&hex(nm.time_cob_id.into())),
    );
    o.setting(
        "emcy_inhibit_time",
        Some(&om.emcy_inhibit_time),
        Some(&nm.emcy_inhibit_time),
    );
    let behavior = |m: &BTreeMap<u8, u8>| {
        m.iter()
            .map(|(s, v)| format!("{s}: {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    o.setting(
        "error_behavior",
        Some(&behavior(&om.error_behavior)),
        Some(&behavior(&nm.error_behavior)),
    );
    o.setting(
        "nmt_inhibit_time",
        Some(&om.nmt_inhibit_time),
        Some(&nm.nmt_inhibit_time),
    );
    o.setting("start", Some(&om.start), Some(&nm.start));
    o.setting("start_nodes", Some(&om.start_nodes), Some(&nm.start_nodes));
    o.setting(
        "start_all_nodes",
        Some(&om.start_all_nodes),
        Some(&nm.start_all_nodes),
    );
    o.setting(
        "reset_all_nodes",
        Some(&om.reset_all_nodes),
        Some(&nm.reset_all_nodes),
    );
    o.setting(
        "stop_all_nodes",
        Some(&om.stop_all_nodes),
        Some(&nm.stop_all_nodes),
    );
    o.setting("boot_time", Some(&om.boot_time), Some(&nm.boot_time));
}

/// How long a consumer waits for a heartbeat produced every `producer` ms
/// (dcfgen: the producer time times the multiplier, truncated to 16 bits).
fn consumer_time(producer: u16, multiplier: f64) -> u64 {
    ((f64::from(producer) * multiplier) as u64) & 0xFFFF
}

/// `vendor 0xB9, product 0x1, revision 0x2` of a slave (the bus file's
/// `revision_number` wins over the device file's, as in dcfgen).
fn identity(slave: &SlaveSection) -> (Option<u32>, Option<u32>, Option<u32>) {
    let id = &slave.device.identity;
    let revision = at_value(&slave.revision_number)
        .copied()
        .or(id.revision_number);
    (id.vendor_number, id.product_number, revision)
}

fn show_identity((vendor, product, revision): (Option<u32>, Option<u32>, Option<u32>)) -> String {
    let n = |v: Option<u32>| v.map_or("unknown".to_string(), |v| hex(v.into()));
    format!(
        "vendor {}, product {}, revision {}",
        n(vendor),
        n(product),
        n(revision)
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
        show_identity(identity(slave)),
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

/// A node in both networks.
pub(super) fn node(out: &mut Vec<NetChange>, pair: Pair) {
    let ((ob, on, os), (nb, nn, ns)) = (pair.old, pair.new);
    let mut o = Out {
        out,
        node: &nn.name,
    };
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
    identity_changes(&mut o, os, ns);
    pdos(&mut o, "RPDO", 0x1400, &on.rpdos, &nn.rpdos);
    pdos(&mut o, "TPDO", 0x1800, &on.tpdos, &nn.tpdos);
    error_control(&mut o, (ob, on, os), (nb, nn, ns));
    sdo_writes(&mut o, os, ns);
    settings(&mut o, (ob, on, os), (nb, nn, ns));
}

fn identity_changes(o: &mut Out, os: &SlaveSection, ns: &SlaveSection) {
    let (oi, ni) = (identity(os), identity(ns));
    let files = (&os.dcf.value, &ns.dcf.value);
    let same_device = (oi.0, oi.1) == (ni.0, ni.1);
    if oi != ni {
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
        o.push(
            Wiring::NodeIdentityChanged,
            severity,
            (0x1018, None),
            "node",
            Some(Val::Text(show_identity(oi))),
            Some(Val::Text(show_identity(ni))),
            format!(
                "identity {} → {}{file}",
                show_identity(oi),
                show_identity(ni)
            ),
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
                "device file {} → {} (same vendor and product)",
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

/// One direction's PDOs, by number.
fn pdos(o: &mut Out, prefix: &str, comm_base: u16, old: &[Pdo], new: &[Pdo]) {
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
            let message = format!(
                "{name} COB-ID {} → {}",
                hex(p.cob_id.into()),
                hex(n.cob_id.into())
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

type Side<'a> = (&'a Bus, &'a Node, &'a SlaveSection);

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

/// `0x2000 sub 1` and, where the device names it, the object's name.
fn sdo_place(slave: &SlaveSection, (index, sub): (u16, u8)) -> (String, String) {
    let place = format!("0x{index:04X} sub {sub}");
    let name = slave
        .device
        .objects
        .get(&index)
        .map(|obj| {
            obj.entries
                .get(&sub)
                .map_or(obj.name.as_str(), |e| e.name.as_str())
        })
        .map_or(String::new(), |n| format!(" ({})", code_span(n)));
    (place, name)
}

/// The `sdo:` writes, by (index, sub-index): added, removed, changed
/// values, and the order of the writes kept by both.
fn sdo_writes(o: &mut Out, os: &SlaveSection, ns: &SlaveSection) {
    let group = |s: &SlaveSection| {
        let mut writes: BTreeMap<(u16, u8), Vec<i128>> = BTreeMap::new();
        let mut order: Vec<(u16, u8)> = Vec::new();
        for item in &s.sdo {
            let key = (item.index, item.sub_index);
            writes.entry(key).or_default().push(item.value);
            if !order.contains(&key) {
                order.push(key);
            }
        }
        (writes, order)
    };
    let ((ow, oo), (nw, no)) = (group(os), group(ns));
    let val = |v: &[i128]| match v {
        [one] => Val::Int(*one),
        many => Val::List(many.iter().map(|v| hex(*v)).collect()),
    };
    let show = |v: &[i128]| {
        v.iter()
            .map(|v| hex(*v))
            .collect::<Vec<_>>()
            .join(", then ")
    };
    let mut keys: Vec<(u16, u8)> = ow.keys().chain(nw.keys()).copied().collect();
    keys.sort_unstable();
    keys.dedup();
    for key in keys {
        let at = (key.0, Some(key.1));
        let (place, name) = sdo_place(ns, key);
        match (ow.get(&key), nw.get(&key)) {
            (None, Some(n)) => o.push(
                Wiring::SdoWriteAdded,
                Severity::Compatible,
                at,
                &place,
                None,
                Some(val(n)),
                format!("boot writes {} to {place}{name}", show(n)),
            ),
            (Some(p), None) => {
                let (_, name) = sdo_place(os, key);
                o.push(
                    Wiring::SdoWriteRemoved,
                    Severity::Compatible,
                    at,
                    &place,
                    Some(val(p)),
                    None,
                    format!("boot no longer writes {} to {place}{name}", show(p)),
                );
            }
            (Some(p), Some(n)) if p != n => o.push(
                Wiring::SdoWriteChanged,
                Severity::Compatible,
                at,
                &place,
                Some(val(p)),
                Some(val(n)),
                format!("boot writes {place}{name}: {} → {}", show(p), show(n)),
            ),
            _ => {}
        }
    }
    let common = |order: &[(u16, u8)], other: &BTreeMap<(u16, u8), Vec<i128>>| -> Vec<String> {
        order
            .iter()
            .filter(|k| other.contains_key(k))
            .map(|&(i, s)| format!("0x{i:04X} sub {s}"))
            .collect()
    };
    let (oc, nc) = (common(&oo, &nw), common(&no, &ow));
    if oc != nc {
        let message = format!(
            "boot writes reordered: {} → {}",
            oc.join(", "),
            nc.join(", ")
        );
        o.push(
            Wiring::SdoWritesReordered,
            Severity::Compatible,
            (0, None),
            "sdo",
            Some(Val::List(oc)),
            Some(Val::List(nc)),
            message,
        );
    }
}

/// The slave's other keys, as written (absent: `default`: a change of
/// `options:` is reported there once), and the TIME COB-ID.
fn settings(o: &mut Out, (_, on, os): Side, (_, nn, ns): Side) {
    o.setting("dcf_path", at_value(&os.dcf_path), at_value(&ns.dcf_path));
    o.setting(
        "retry_factor",
        at_value(&os.retry_factor),
        at_value(&ns.retry_factor),
    );
    o.setting(
        "time_cob_id",
        Some(&hex(on.time_cob_id.into())),
        Some(&hex(nn.time_cob_id.into())),
    );
    let serial = |s: &SlaveSection| at_value(&s.serial_number).map(|v| hex((*v).into()));
    o.setting("serial_number", serial(os).as_ref(), serial(ns).as_ref());
    let mut subs: Vec<u8> = os
        .error_behavior
        .keys()
        .chain(ns.error_behavior.keys())
        .copied()
        .collect();
    subs.sort_unstable();
    subs.dedup();
    for sub in subs {
        let get = |s: &SlaveSection| s.error_behavior.get(&sub).map(|a| a.value);
        o.setting(
            &format!("error_behavior.{sub}"),
            get(os).as_ref(),
            get(ns).as_ref(),
        );
    }
    o.setting("boot", at_value(&os.boot), at_value(&ns.boot));
    o.setting(
        "mandatory",
        at_value(&os.mandatory),
        at_value(&ns.mandatory),
    );
    o.setting(
        "reset_communication",
        at_value(&os.reset_communication),
        at_value(&ns.reset_communication),
    );
    o.setting(
        "software_file",
        at_value(&os.software_file),
        at_value(&ns.software_file),
    );
    o.setting(
        "software_version",
        at_value(&os.software_version),
        at_value(&ns.software_version),
    );
    o.setting(
        "configuration_file",
        at_value(&os.configuration_file),
        at_value(&ns.configuration_file),
    );
    o.setting(
        "restore_configuration",
        at_value(&os.restore_configuration),
        at_value(&ns.restore_configuration),
    );
}
