//! The plan a CiA 302-2 master boots the network by
//! ([`eds2rust_runtime::boot::NetworkPlan`]), from the bus file as
//! configured: what master.dcf says (0x1F80 start-up flags, 0x1F81 slave
//! assignment, 0x1F84–0x1F88 expected identity, 0x1F89 boot time, 0x1016
//! consumer times), each slave's concise DCF as its configuration, and
//! the PDOs the master sends and receives. The generated network embeds
//! the same value ([`crate::gen`]); `eds2rust net boot` reads it at run
//! time.

use std::borrow::Cow;
use std::num::NonZeroU8;
use std::time::Duration;

use eds2rust_runtime::boot::{
    ConfigWrite, MasterPlan, NetworkPlan, PdoLink, SlaveConfig, SlavePlan, Supervision,
};
use eds2rust_runtime::nmt::NmtCommand;
use eds2rust_runtime::od::NodeId;

use super::config::{Configured, Node, Pdo, consumer_time};
use super::model::Bus;

/// The boot plan of `bus` as `configured` (see the module documentation).
/// Slaves whose node id is no valid one (checked by `net check`) are left
/// out.
pub fn boot_plan(bus: &Bus, configured: &Configured) -> NetworkPlan {
    let m = &bus.master;
    let ms = |v: u64| (v != 0).then(|| Duration::from_millis(v));
    let master = MasterPlan {
        node: NodeId::new(m.node_id).unwrap_or(NodeId::new(1).expect("1 is a node id")),
        heartbeat: ms(u64::from(m.heartbeat_producer)),
        sync_period: (m.sync_period != 0)
            .then(|| Duration::from_micros(u64::from(m.sync_period))),
        sync_overflow: m.sync_overflow,
    };
    let mut slaves = Vec::new();
    let mut receive = Vec::new();
    let mut transmit = Vec::new();
    for node in &configured.nodes {
        let Some(id) = NodeId::new(node.node_id) else {
            continue;
        };
        slaves.push(slave_config(bus, node, id));
        receive.extend(node.tpdos.iter().map(|p| link(id, p, p.master_event_timer)));
        transmit.extend(node.rpdos.iter().map(|p| link(id, p, p.event_timer)));
    }
    slaves.sort_by_key(|s| s.plan.node);
    NetworkPlan {
        master,
        slaves: Cow::Owned(slaves),
        boot_time: ms(u64::from(m.boot_time)),
        response_time: NetworkPlan::DEFAULT_RESPONSE_TIME,
        start_nodes: m.start_nodes,
        start_all_nodes: m.start_all_nodes,
        start_master: m.start,
        reset_all_nodes: m.reset_all_nodes,
        stop_all_nodes: m.stop_all_nodes,
        receive: Cow::Owned(receive),
        transmit: Cow::Owned(transmit),
    }
}

fn slave_config(bus: &Bus, node: &Node, id: NodeId) -> SlaveConfig {
    let section = bus.slaves.get(node.slave);
    let flag = |get: fn(&super::model::SlaveSection) -> Option<bool>, default: bool| {
        section.and_then(get).unwrap_or(default)
    };
    let reset = flag(|s| s.reset_communication.as_ref().map(|a| a.value), true)
        .then_some(NmtCommand::ResetCommunication);
    let software_version = section
        .and_then(|s| s.software_version.as_ref())
        .map_or(0, |a| a.value);
    let supervision = supervision(bus, node);
    let date = concise_u32(node, 0x1020, 1);
    let time = concise_u32(node, 0x1020, 2);
    let configuration = node
        .concise
        .iter()
        .map(|e| ConfigWrite {
            index: e.index,
            sub_index: e.sub_index,
            data: Cow::Owned(e.data.clone()),
        })
        .collect();
    SlaveConfig {
        name: Cow::Owned(node.name.clone()),
        plan: SlavePlan {
            node: id,
            device_type: node.device_type,
            vendor_id: node.vendor_id,
            product_code: node.product_code,
            revision_number: node.revision_number,
            serial_number: node.serial_number,
            software_version,
            configuration_date_time: date.zip(time),
            configuration: Cow::Owned(configuration),
            reset,
            heartbeat: matches!(supervision, Supervision::Heartbeat(_)),
            start: false,
        },
        boot: flag(|s| s.boot.as_ref().map(|a| a.value), true),
        mandatory: flag(|s| s.mandatory.as_ref().map(|a| a.value), false),
        supervision,
    }
}

/// Heartbeat when the master consumes the slave's (the bus file's
/// `heartbeat_consumer` on the master, a producer time on the slave),
/// else guarding when the slave has a guard time and life time factor.
fn supervision(bus: &Bus, node: &Node) -> Supervision {
    let consumer = consumer_time(bus, node);
    if bus.master.heartbeat_consumer && node.heartbeat_producer != 0 && consumer != 0 {
        return Supervision::Heartbeat(Duration::from_millis(consumer));
    }
    match NonZeroU8::new(node.life_time_factor) {
        Some(life_time_factor) if node.guard_time != 0 => Supervision::Guarding {
            guard_time: Duration::from_millis(u64::from(node.guard_time)),
            life_time_factor,
        },
        _ => Supervision::None,
    }
}

/// A U32 the slave's configuration writes to (index, sub).
fn concise_u32(node: &Node, index: u16, sub: u8) -> Option<u32> {
    let entry = node
        .concise
        .iter()
        .rev()
        .find(|e| e.index == index && e.sub_index == sub)?;
    let bytes: [u8; 4] = entry.data.get(..4)?.try_into().ok()?;
    Some(u32::from_le_bytes(bytes))
}

/// A slave's PDO as the master sees it, with `event_timer` (ms).
fn link(node: NodeId, pdo: &Pdo, event_timer: u16) -> PdoLink {
    let bits: u32 = pdo.mapping.iter().map(|m| u32::from(m.bits)).sum();
    PdoLink {
        node,
        number: pdo.number,
        cob_id: pdo.cob_id,
        transmission: pdo.transmission,
        len: u8::try_from(bits.div_ceil(8)).unwrap_or(u8::MAX),
        event_timer,
        inhibit_time: pdo.inhibit_time,
    }
}
