//! `nmt start|stop|preop|reset|reset-comm` and `scan`.

use std::collections::BTreeMap;
use std::io::Write;
use std::ops::ControlFlow;
use std::time::Duration;

use eds2rust_runtime::blocking::{Error, Master};
use eds2rust_runtime::master::MasterEvent;
use eds2rust_runtime::nmt::{NmtCommand, NmtEvent, NmtState, NmtTarget};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::SdoError;
use eds2rust_runtime::sdo::client::ClientEvent;

use super::bus::{self, LiveBus, Opener};
use super::{LiveError, NmtArgs, NmtVerb, ScanArgs};

/// How long `--confirm` waits for the node.
const CONFIRM_WAIT: Duration = Duration::from_secs(2);

/// Nodes probed at once by `scan`: a real interface's transmit queue
/// (txqueuelen 10 by default) takes a few frames at a time.
const PROBE_BATCH: usize = 16;

/// Slack over the probe timeout for the answers of one batch.
const PROBE_SLACK: Duration = Duration::from_millis(50);

pub fn state_name(state: NmtState) -> &'static str {
    match state {
        NmtState::BootUp => "boot-up",
        NmtState::Stopped => "stopped",
        NmtState::Operational => "operational",
        NmtState::PreOperational => "pre-operational",
    }
}

fn io_failed(e: Error) -> LiveError {
    LiveError::Failed(e.to_string())
}

pub fn command(open: impl Opener, a: &NmtArgs, out: &mut dyn Write) -> Result<(), LiveError> {
    let (cmd, name) = match a.verb {
        NmtVerb::Start => (NmtCommand::Start, "start"),
        NmtVerb::Stop => (NmtCommand::Stop, "stop"),
        NmtVerb::Preop => (NmtCommand::EnterPreOperational, "enter pre-operational"),
        NmtVerb::Reset => (NmtCommand::ResetNode, "reset node"),
        NmtVerb::ResetComm => (NmtCommand::ResetCommunication, "reset communication"),
    };
    let target = match (a.node, a.all) {
        (Some(n), false) => NmtTarget::Node(bus::node_id(n)?),
        (None, true) => NmtTarget::All,
        _ => {
            return Err(LiveError::Usage(
                "name the node with --node, or every node with --all".to_string(),
            ));
        }
    };
    let mut m = bus::master(open()?);
    m.nmt(cmd, target).map_err(io_failed)?;
    let target = match target {
        NmtTarget::Node(node) => {
            writeln!(out, "sent NMT {name} to node {}", node.get())?;
            Some(node)
        }
        NmtTarget::All => {
            writeln!(out, "sent NMT {name} to all nodes")?;
            None
        }
    };
    let Some(node) = target.filter(|_| a.confirm) else {
        return Ok(());
    };
    let reset = matches!(cmd, NmtCommand::ResetNode | NmtCommand::ResetCommunication);
    let wanted = cmd.target_state();
    let deadline = m.now() + CONFIRM_WAIT;
    let seen = m.run_until(deadline, |event| match event {
        MasterEvent::Nmt(NmtEvent::BootUp(n)) if *n == node && reset => {
            ControlFlow::Break(NmtState::BootUp)
        }
        MasterEvent::Nmt(NmtEvent::StateChanged { node: n, to, .. })
            if *n == node && !reset && *to == wanted =>
        {
            ControlFlow::Break(*to)
        }
        _ => ControlFlow::Continue(()),
    });
    match seen {
        Ok(NmtState::BootUp) => writeln!(out, "node {}: boot-up seen", node.get())?,
        Ok(state) => writeln!(
            out,
            "node {}: {} (heartbeat)",
            node.get(),
            state_name(state)
        )?,
        Err(Error::DeadlinePassed) if reset => {
            return Err(LiveError::Failed(format!(
                "node {} sent no boot-up message within {} s",
                node.get(),
                CONFIRM_WAIT.as_secs()
            )));
        }
        Err(Error::DeadlinePassed) => {
            return Err(LiveError::Failed(format!(
                "node {} sent no heartbeat in state {} within {} s (is its heartbeat, 0x1017, on?)",
                node.get(),
                state_name(wanted),
                CONFIRM_WAIT.as_secs()
            )));
        }
        Err(e) => return Err(io_failed(e)),
    }
    Ok(())
}

/// What `scan` learnt about one node.
#[derive(Debug, Default)]
struct Seen {
    boot_up: bool,
    heartbeat: bool,
    /// Answered the probe (with a value or an abort).
    answered: bool,
    device_type: Option<u32>,
    identity: [Option<u32>; 4],
}

fn u32_of(data: &[u8]) -> Option<u32> {
    let b: [u8; 4] = data.get(..4)?.try_into().ok()?;
    Some(u32::from_le_bytes(b))
}

/// Takes in the NMT and heartbeat news of one event.
fn note(seen: &mut BTreeMap<u8, Seen>, event: &MasterEvent) {
    match event {
        MasterEvent::Nmt(NmtEvent::BootUp(n)) => seen.entry(n.get()).or_default().boot_up = true,
        MasterEvent::Nmt(NmtEvent::StateChanged { node, .. }) => {
            seen.entry(node.get()).or_default().heartbeat = true;
        }
        _ => {}
    }
}

fn run(
    m: &mut Master<LiveBus>,
    deadline: eds2rust_runtime::Instant,
    mut f: impl FnMut(&MasterEvent) -> ControlFlow<()>,
) -> Result<(), LiveError> {
    match m.run_until(deadline, |e| f(e)) {
        Ok(()) | Err(Error::DeadlinePassed) => Ok(()),
        Err(e) => Err(io_failed(e)),
    }
}

pub fn scan(open: impl Opener, a: &ScanArgs, out: &mut dyn Write) -> Result<(), LiveError> {
    let mut m = bus::master(open()?);
    let mut seen: BTreeMap<u8, Seen> = BTreeMap::new();
    let deadline = m.now() + a.listen;
    run(&mut m, deadline, |event| {
        note(&mut seen, event);
        ControlFlow::Continue(())
    })?;
    if !a.no_probe {
        let all: Vec<NodeId> = (1..=127).filter_map(NodeId::new).collect();
        for batch in all.chunks(PROBE_BATCH) {
            let now = m.now();
            for &node in batch {
                bus::sdo_client(&mut m, node, a.probe_timeout);
                if let Some(client) = m.core_mut().sdo(node) {
                    // A fresh client is idle: this cannot be refused.
                    let _ = client.upload(now, 0x1000, 0);
                }
            }
            m.flush().map_err(io_failed)?;
            let mut pending = batch.len();
            let deadline = m.now() + a.probe_timeout + PROBE_SLACK;
            run(&mut m, deadline, |event| {
                note(&mut seen, event);
                if let MasterEvent::Sdo(node, e) = event {
                    pending = pending.saturating_sub(1);
                    match e {
                        ClientEvent::Uploaded { data, .. } => {
                            let s = seen.entry(node.get()).or_default();
                            s.answered = true;
                            s.device_type = u32_of(data);
                        }
                        ClientEvent::Failed {
                            error: SdoError::RemoteAbort(_) | SdoError::BadResponse { .. },
                            ..
                        } => seen.entry(node.get()).or_default().answered = true,
                        _ => {}
                    }
                }
                if pending == 0 {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            })?;
            for &node in batch {
                m.core_mut().remove_sdo_client(node);
            }
        }
    }
    if seen.is_empty() {
        return Err(LiveError::Failed(format!(
            "no node answered (listened {} ms{})",
            a.listen.as_millis(),
            if a.no_probe {
                ""
            } else {
                ", probed nodes 1 to 127"
            }
        )));
    }
    let nodes: Vec<u8> = seen.keys().copied().collect();
    for n in nodes {
        let Some(node) = NodeId::new(n) else { continue };
        bus::sdo_client(&mut m, node, a.bus.timeout);
        let entry = seen.entry(n).or_default();
        if entry.device_type.is_none()
            && let Ok(data) = m.upload(node, 0x1000, 0)
        {
            entry.device_type = u32_of(&data);
        }
        for sub in 1..=4u8 {
            match m.upload(node, 0x1018, sub) {
                Ok(data) => entry.identity[usize::from(sub - 1)] = u32_of(&data),
                Err(eds2rust_runtime::blocking::Error::Sdo {
                    error: SdoError::Timeout,
                    ..
                }) => break,
                Err(_) => {}
            }
        }
    }
    let hex = |v: Option<u32>| v.map_or_else(|| "-".to_string(), |v| format!("0x{v:08X}"));
    let header = format!(
        "{:>4}  {:<15}  {:<11}  {:<10}  {:<12}  {:<10}  {}",
        "node", "state", "device type", "vendor id", "product code", "revision", "serial"
    );
    writeln!(out, "{header}")?;
    for (n, s) in &seen {
        let state = NodeId::new(*n)
            .and_then(|node| m.core().nmt.state(node))
            .map(state_name)
            .unwrap_or(if s.boot_up { "boot-up" } else { "-" });
        writeln!(
            out,
            "{n:>4}  {state:<15}  {:<11}  {:<10}  {:<12}  {:<10}  {}",
            hex(s.device_type),
            hex(s.identity[0]),
            hex(s.identity[1]),
            hex(s.identity[2]),
            hex(s.identity[3])
        )?;
    }
    let probed = seen.values().filter(|s| s.answered).count();
    writeln!(
        out,
        "{} node{} found ({} answered SDO, {} sent boot-up or heartbeat)",
        seen.len(),
        if seen.len() == 1 { "" } else { "s" },
        probed,
        seen.values().filter(|s| s.boot_up || s.heartbeat).count()
    )?;
    Ok(())
}
