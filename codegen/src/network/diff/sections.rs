//! The bus file's own sections: `options:` and `master:` (node id, bit
//! rate, SYNC, the master's heartbeat, and its other settings).

use std::collections::BTreeMap;

use super::out::{Out, consumer_time, graded};
use super::{MASTER, NetChange, OPTIONS, Wiring};
use crate::diff::{Severity, Val, hex};
use crate::network::model::Bus;

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
