//! `net boot --run`: the network kept running after its boot. The master
//! runs on (heartbeat, SYNC, the PDOs, supervision); what happens to the
//! slaves (lost, booted again, started, a boot error, an EMCY) is one line
//! each, with the time since the master started.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use eds2rust_runtime::blocking;
use eds2rust_runtime::boot::{BootEvent, NetworkEvent, NetworkPlan};
use eds2rust_runtime::emcy::EmcyEvent;
use eds2rust_runtime::master::MasterEvent;
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::transport::Bus;

use super::report::{Happening, Outcome};

/// How often the loop looks at Ctrl-C; the lines' times are this exact.
const POLL: Duration = Duration::from_millis(10);

/// What `event` says about a slave, if it is worth a line.
fn describe(event: &MasterEvent) -> Option<(NodeId, &'static str, String)> {
    Some(match event {
        MasterEvent::Network(NetworkEvent::Lost { node, status }) => {
            (*node, "lost", format!("lost: {status}"))
        }
        MasterEvent::Network(NetworkEvent::Rebooting(node)) => {
            (*node, "rebooting", "booting again".into())
        }
        MasterEvent::Network(NetworkEvent::Step {
            node,
            step: BootEvent::Booted,
        }) => (*node, "booted", "booted".into()),
        MasterEvent::Network(NetworkEvent::Started(node)) => (*node, "started", "started".into()),
        MasterEvent::Network(NetworkEvent::Failed(error)) => {
            (error.node, "failed", error.to_string())
        }
        MasterEvent::Emcy(EmcyEvent::Emergency { node, emcy }) => {
            (*node, "emcy", format!("EMCY {emcy}"))
        }
        _ => return None,
    })
}

/// Runs `m` for `duration` (until `stop` without one), a line on stdout
/// per happening when `lines`; then `outcome` holds every slave's state at
/// the end. The happenings, in order.
pub(crate) fn supervise<B: Bus>(
    m: &mut blocking::Master<B>,
    plan: &NetworkPlan,
    outcome: &mut Outcome,
    duration: Option<Duration>,
    stop: &AtomicBool,
    lines: bool,
) -> Result<Vec<Happening>, String> {
    let from = m.now();
    let end = duration.map(|d| from + d);
    let mut happenings = Vec::new();
    // The boot's own events are in the report already.
    m.drain_events().for_each(drop);
    let mut out = std::io::stdout();
    loop {
        let now = m.now();
        if stop.load(Ordering::Relaxed) || end.is_some_and(|e| now >= e) {
            break;
        }
        let chunk = end.map_or(POLL, |e| POLL.min(e - now));
        m.run_for(chunk).map_err(|e| e.to_string())?;
        let at = (m.now() - outcome.started).as_secs_f64();
        let events: Vec<MasterEvent> = m.drain_events().collect();
        for (node, kind, text) in events.iter().filter_map(describe) {
            let name = plan
                .slave(node)
                .map_or(String::new(), |s| s.name.to_string());
            let happening = Happening {
                seconds: at,
                node: node.get(),
                name,
                kind,
                text,
            };
            if lines {
                let _ = writeln!(out, "{}", happening.line());
            }
            happenings.push(happening);
        }
        let _ = out.flush();
    }
    if let Some(network) = m.core().network() {
        outcome.slaves = network.slaves().cloned().collect();
    }
    outcome.ran = Some(m.now() - from);
    outcome.ended = m.now();
    Ok(happenings)
}
