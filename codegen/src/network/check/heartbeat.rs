//! Error control: `net::heartbeat-timing` (a consumer time that cannot
//! hold for its producer), `net::heartbeat-no-producer` (a consumer of a
//! heartbeat no node sends). Heartbeat and node guarding both set
//! (`net::heartbeat-and-guarding`) is reported by the configuration,
//! which drops the guarding as dcfgen does.
//!
//! dcfgen sets every consumer time to the producer time times the
//! multiplier, truncated and cut to 16 bits (`int(p * m) & 0xFFFF`): the
//! master consumes each slave's heartbeat so (0x1016 in master.dcf), and a
//! slave with `heartbeat_consumer: true` the master's. A consumer time not
//! above its producer time signals a lost heartbeat although none was.

use super::context::{Net, Report, device_int};
use crate::network::config::Node;
use crate::network::model::{SlaveSection, Spot};

pub(super) fn check(net: &Net, report: &mut Report<'_>) {
    master_consumes(net, report);
    slaves_consume_master(net, report);
    for (node, slave) in net.nodes() {
        device_consumers(net, node, slave, report);
    }
}

/// dcfgen's consumer time for producer time `producer` and `multiplier`,
/// and the untruncated product.
fn consumer_time(producer: u16, multiplier: f64) -> (u16, f64) {
    let product = f64::from(producer) * multiplier;
    let whole = crate::network::config::heartbeat_product(producer, multiplier);
    ((whole & 0xFFFF) as u16, product)
}

fn timing_problem(producer: u16, multiplier: f64) -> Option<String> {
    let (time, product) = consumer_time(producer, multiplier);
    if time > producer {
        return None;
    }
    let cut = if product >= 65536.0 {
        format!(", {product} cut to 16 bits")
    } else {
        String::new()
    };
    Some(format!(
        "a consumer time of {time} ms ({producer} ms × {multiplier}{cut}) for a heartbeat \
         sent every {producer} ms: the consumer reports a lost heartbeat while none is lost"
    ))
}

fn timing_fix(producer: u16) -> String {
    if u32::from(producer) * 3 <= 0xFFFF {
        "use a `heartbeat_multiplier` above 1 (dcfgen's default is 3)".into()
    } else {
        "shorten `heartbeat_producer`: the consumer time (producer time × multiplier) \
         must fit 16 bits (65535 ms), so with dcfgen's multiplier 3 at most 21845 ms"
            .into()
    }
}

fn first_spot(candidates: &[Option<&Spot>], fallback: &Spot) -> Spot {
    candidates
        .iter()
        .flatten()
        .find(|s| s.line > 0)
        .map_or_else(|| fallback.clone(), |s| (*s).clone())
}

/// The master's consumer entries for the slaves' heartbeats.
fn master_consumes(net: &Net, report: &mut Report<'_>) {
    if !net.bus.master.heartbeat_consumer {
        return;
    }
    for (node, slave) in net.nodes() {
        let producer = node.heartbeat_producer;
        if producer == 0 {
            continue;
        }
        let multiplier = slave
            .heartbeat_multiplier
            .as_ref()
            .map_or(net.bus.options.heartbeat_multiplier, |m| m.value);
        let spot = first_spot(
            &[
                slave.heartbeat_multiplier.as_ref().map(|m| &m.spot),
                slave.heartbeat_producer.as_ref().map(|p| &p.spot),
            ],
            &slave.spot,
        );
        let (wrapped, product) = consumer_time(producer, multiplier);
        if product >= 65536.0 {
            // `net dcf` writes the longest time 0x1016 holds (a deliberate
            // difference); dcfgen's master.dcf would have the cut one.
            report.warning(
                "net::heartbeat-timing",
                &spot,
                format!(
                    "the master's consumer time for `{}`'s heartbeat, {producer} ms × {multiplier} = {product} ms, does not fit the 16 bits of 0x1016: `eds2rust net dcf` writes 65535 ms, dcfgen 2.4.2 writes {wrapped} ms, shorter than the heartbeat period",
                    node.name
                ),
                vec![timing_fix(producer)],
            );
            continue;
        }
        let Some(problem) = timing_problem(producer, multiplier) else {
            continue;
        };
        report.error(
            "net::heartbeat-timing",
            &spot,
            format!(
                "the master consumes `{}`'s heartbeat with {problem}",
                node.name
            ),
            vec![timing_fix(producer)],
        );
    }
}

/// The slaves' consumer entries for the master's heartbeat.
fn slaves_consume_master(net: &Net, report: &mut Report<'_>) {
    let master = &net.bus.master;
    let producer = master.heartbeat_producer;
    let mut timing_reported = false;
    for (node, slave) in net.nodes() {
        if !node.heartbeat_consumer {
            continue;
        }
        let spot = first_spot(
            &[slave.heartbeat_consumer.as_ref().map(|c| &c.spot)],
            &slave.spot,
        );
        if producer == 0 {
            report.warning(
                "net::heartbeat-no-producer",
                &spot,
                format!(
                    "`{}` is to consume the master's heartbeat, but the master sends none \
                     (its `heartbeat_producer` is 0): dcfgen writes no consumer entry",
                    node.name
                ),
                vec!["set `heartbeat_producer` (ms) in `master:`".into()],
            );
        } else if !timing_reported
            && let Some(problem) = timing_problem(producer, master.heartbeat_multiplier)
        {
            timing_reported = true;
            let spot = first_spot(
                &[
                    master.spots.get("heartbeat_multiplier"),
                    master.spots.get("heartbeat_producer"),
                ],
                &master.spot,
            );
            report.error(
                "net::heartbeat-timing",
                &spot,
                format!(
                    "the slaves that consume the master's heartbeat (`{}` first) get {problem}",
                    node.name
                ),
                vec![timing_fix(producer)],
            );
        }
    }
}

/// The consumer entries (0x1016) a slave's device file sets by itself,
/// unless the configuration rewrites them.
fn device_consumers(net: &Net, node: &Node, slave: &SlaveSection, report: &mut Report<'_>) {
    let Some(object) = slave.device.objects.get(&0x1016) else {
        return;
    };
    for (&sub, entry) in object.entries.iter().filter(|(s, _)| **s >= 1) {
        let rewritten = node
            .concise
            .iter()
            .any(|c| c.index == 0x1016 && c.sub_index == sub);
        if rewritten {
            continue;
        }
        let Some(value) = device_int(&slave.device, 0x1016, sub, node.node_id) else {
            continue;
        };
        let time = (value & 0xFFFF) as u16;
        let id = ((value >> 16) & 0xFF) as u8;
        if time == 0 || !crate::ir::NODE_IDS.contains(&id) {
            continue;
        }
        let origin = format!(
            "0x1016 sub {sub} of `{}` ({}:{}) consumes node {id}'s heartbeat with {time} ms",
            slave.name, entry.origin.file, entry.origin.line
        );
        let spot = &slave.dcf.spot;
        let producer = if net.master_id() == Some(id) {
            Some(("the master".to_string(), net.bus.master.heartbeat_producer))
        } else {
            net.nodes()
                .find(|(n, _)| n.node_id == id)
                .map(|(n, _)| (format!("`{}`", n.name), n.heartbeat_producer))
        };
        match producer {
            None => report.warning(
                "net::heartbeat-no-producer",
                spot,
                format!("{origin}, but no node {id} is on this bus"),
                vec![format!(
                    "clear the entry with an `sdo:` write of 0 to 0x1016 sub {sub}, or \
                     give the producer node id {id}"
                )],
            ),
            Some((who, 0)) => report.warning(
                "net::heartbeat-no-producer",
                spot,
                format!("{origin}, but {who} sends no heartbeat"),
                vec![format!(
                    "set {who}'s `heartbeat_producer`, or clear the entry with an `sdo:` \
                     write of 0 to 0x1016 sub {sub}"
                )],
            ),
            Some((who, producer)) if time <= producer => report.error(
                "net::heartbeat-timing",
                spot,
                format!(
                    "{origin}, not longer than {who}'s producer time of {producer} ms: it \
                     reports a lost heartbeat while none is lost"
                ),
                vec![format!(
                    "write a longer time with an `sdo:` write to 0x1016 sub {sub}: \
                     `value: 0x{:08X}` ({} ms)",
                    (u32::from(id) << 16) | (u32::from(producer) * 3).min(0xFFFF),
                    (u32::from(producer) * 3).min(0xFFFF)
                )],
            ),
            Some(_) => {}
        }
    }
}

#[cfg(test)]
pub(super) fn consumer_time_for_tests(producer: u16, multiplier: f64) -> u16 {
    consumer_time(producer, multiplier).0
}
