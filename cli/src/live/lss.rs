//! `lss scan` (fastscan) and `lss set-node-id` (CiA 305).

use std::io::Write;
use std::ops::ControlFlow;
use std::time::Duration;

use clap::{ArgGroup, Args};
use eds2rust_runtime::blocking::{Error, LssRequestError, Master};
use eds2rust_runtime::lss::{Identity, KnownIdentity, LssState};
use eds2rust_runtime::master::MasterEvent;
use eds2rust_runtime::nmt::{NmtCommand, NmtEvent, NmtTarget};
use eds2rust_runtime::od::NodeId;

use super::bus::{self, LiveBus, Opener};
use super::values::parse_int;
use super::{BusArgs, LiveError, node_arg, parse_duration};

/// How long `--activate` waits for the boot-up message.
const BOOT_WAIT: Duration = Duration::from_secs(2);

#[derive(Args, Debug)]
pub struct ScanArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// Time a slave has to answer each LSS request. Fastscan waits it out
    /// on every one of its up to 133 steps per slave.
    #[arg(long, value_name = "TIME", value_parser = parse_duration, default_value = "100ms")]
    pub lss_timeout: Duration,
    /// Give the slaves found node ids FIRST, FIRST+1, ... (pending until
    /// NMT reset communication).
    #[arg(long, value_name = "FIRST", value_parser = node_arg)]
    pub assign: Option<u8>,
    /// With --assign: make each slave store its node id.
    #[arg(long, requires = "assign")]
    pub store: bool,
}

#[derive(Args, Debug)]
#[command(group(ArgGroup::new("select").required(true).args(["identity", "fastscan", "global"])))]
pub struct SetNodeIdArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// Time a slave has to answer each LSS request.
    #[arg(long, value_name = "TIME", value_parser = parse_duration, default_value = "100ms")]
    pub lss_timeout: Duration,
    /// The slave's LSS address VENDOR:PRODUCT:REVISION:SERIAL (0x1018
    /// subs 1 to 4; decimal or 0x hex), selected by switch state selective.
    #[arg(long, value_name = "V:P:R:S", value_parser = parse_identity)]
    pub identity: Option<Identity>,
    /// The first slave without a node id that fastscan finds.
    #[arg(long)]
    pub fastscan: bool,
    /// Every LSS slave on the bus (switch state global): for a bus with
    /// only one.
    #[arg(long)]
    pub global: bool,
    /// Make the slave store the node id (it survives a power cycle).
    #[arg(long)]
    pub store: bool,
    /// Then send NMT reset communication to all nodes and wait for the
    /// boot-up message under the new node id.
    #[arg(long)]
    pub activate: bool,
    /// The new node id (1 to 127).
    #[arg(value_name = "NODE", value_parser = node_arg)]
    pub node: u8,
}

/// `V:P:R:S`, each decimal or 0x hex.
pub fn parse_identity(text: &str) -> Result<Identity, String> {
    let parts: Vec<Option<u32>> = text
        .split(':')
        .map(|p| parse_int(p).and_then(|v| u32::try_from(v).ok()))
        .collect();
    match parts.as_slice() {
        [Some(v), Some(p), Some(r), Some(s)] => Ok(Identity::new(*v, *p, *r, *s)),
        _ => Err(format!(
            "`{text}` is not an LSS address VENDOR:PRODUCT:REVISION:SERIAL (e.g. 0x2D3:0x1234:1:42)"
        )),
    }
}

fn lss_failed(what: &str, e: Error) -> LiveError {
    LiveError::Failed(format!("LSS {what}: {e}"))
}

fn row(identity: &Identity) -> String {
    format!(
        "0x{:08X}  0x{:08X}    0x{:08X}  0x{:08X}",
        identity.vendor_id, identity.product_code, identity.revision, identity.serial
    )
}

pub fn scan(open: impl Opener, a: &ScanArgs, out: &mut dyn Write) -> Result<(), LiveError> {
    let mut m = bus::master(open()?);
    m.core_mut().lss.set_timeout(a.lss_timeout);
    m.lss_switch_global(LssState::Waiting)
        .map_err(|e| lss_failed("switch state global", e))?;
    let mut found: Vec<(Identity, Option<u8>)> = Vec::new();
    while found.len() < 127 {
        let Some(identity) = m
            .lss_fastscan(KnownIdentity::NONE)
            .map_err(|e| lss_failed("fastscan", e))?
        else {
            break;
        };
        let mut assigned = None;
        if let Some(first) = a.assign {
            let n = usize::from(first) + found.len();
            let node = u8::try_from(n).ok().and_then(NodeId::new).ok_or_else(|| {
                LiveError::Failed(format!("--assign {first}: node id {n} is past 127"))
            })?;
            m.lss_configure_node_id(node)
                .map_err(|e| lss_failed("configure node id", e))?;
            if a.store {
                m.lss_store()
                    .map_err(|e| lss_failed("store configuration", e))?;
            }
            // A slave with a pending node id takes no part in the next scan.
            m.lss_switch_global(LssState::Waiting)
                .map_err(|e| lss_failed("switch state global", e))?;
            assigned = Some(node.get());
        }
        found.push((identity, assigned));
    }
    // Slaves found and left in the configuration state go back to waiting.
    m.lss_switch_global(LssState::Waiting)
        .map_err(|e| lss_failed("switch state global", e))?;
    if found.is_empty() {
        return Err(LiveError::Failed(
            "fastscan found no LSS slave without a node id".into(),
        ));
    }
    let assign = a.assign.is_some();
    writeln!(
        out,
        "vendor id   product code  revision    serial{}",
        if assign { "      node id" } else { "" }
    )?;
    for (identity, node) in &found {
        match node {
            Some(n) => writeln!(out, "{}  {n}", row(identity))?,
            None => writeln!(out, "{}", row(identity))?,
        }
    }
    writeln!(
        out,
        "{} LSS slave{} without a node id{}",
        found.len(),
        if found.len() == 1 { "" } else { "s" },
        if assign {
            "; the node ids take effect at NMT reset communication"
        } else {
            ""
        }
    )?;
    Ok(())
}

pub fn set_node_id(
    open: impl Opener,
    a: &SetNodeIdArgs,
    out: &mut dyn Write,
) -> Result<(), LiveError> {
    let node = bus::node_id(a.node)?;
    let mut m = bus::master(open()?);
    m.core_mut().lss.set_timeout(a.lss_timeout);
    if let Some(identity) = a.identity {
        m.lss_switch_selective(identity).map_err(|e| match e {
            Error::Lss(LssRequestError::NoResponse) => LiveError::Failed(format!(
                "no LSS slave with the address {} answered",
                row(&identity)
                    .split_whitespace()
                    .collect::<Vec<_>>()
                    .join(":")
            )),
            e => lss_failed("switch state selective", e),
        })?;
        writeln!(out, "selected the slave {}", identity)?;
    } else if a.fastscan {
        m.lss_switch_global(LssState::Waiting)
            .map_err(|e| lss_failed("switch state global", e))?;
        match m
            .lss_fastscan(KnownIdentity::NONE)
            .map_err(|e| lss_failed("fastscan", e))?
        {
            Some(identity) => writeln!(out, "fastscan found {identity}")?,
            None => {
                return Err(LiveError::Failed(
                    "fastscan found no LSS slave without a node id".into(),
                ));
            }
        }
    } else {
        m.lss_switch_global(LssState::Configuration)
            .map_err(|e| lss_failed("switch state global", e))?;
        writeln!(out, "switched every LSS slave to the configuration state")?;
    }
    let configured = m
        .lss_configure_node_id(node)
        .map_err(|e| lss_failed("configure node id", e));
    if let Err(e) = configured {
        let _ = m.lss_switch_global(LssState::Waiting);
        return Err(e);
    }
    writeln!(out, "node id {} configured", node.get())?;
    if a.store {
        if let Err(e) = m.lss_store() {
            let _ = m.lss_switch_global(LssState::Waiting);
            return Err(lss_failed("store configuration", e));
        }
        writeln!(out, "stored")?;
    }
    m.lss_switch_global(LssState::Waiting)
        .map_err(|e| lss_failed("switch state global", e))?;
    if !a.activate {
        writeln!(
            out,
            "the node id takes effect at the next NMT reset communication (eds2rust nmt reset-comm --all)"
        )?;
        return Ok(());
    }
    activate(&mut m, node, out)
}

/// NMT reset communication to all nodes; waits for `node`'s boot-up.
fn activate(m: &mut Master<LiveBus>, node: NodeId, out: &mut dyn Write) -> Result<(), LiveError> {
    m.nmt(NmtCommand::ResetCommunication, NmtTarget::All)
        .map_err(|e| LiveError::Failed(e.to_string()))?;
    writeln!(out, "sent NMT reset communication to all nodes")?;
    let deadline = m.now() + BOOT_WAIT;
    match m.run_until(deadline, |event| match event {
        MasterEvent::Nmt(NmtEvent::BootUp(n)) if *n == node => ControlFlow::Break(()),
        _ => ControlFlow::Continue(()),
    }) {
        Ok(()) => {
            writeln!(out, "node {}: boot-up seen", node.get())?;
            Ok(())
        }
        Err(Error::DeadlinePassed) => Err(LiveError::Failed(format!(
            "no boot-up message from node {} within {} s",
            node.get(),
            BOOT_WAIT.as_secs()
        ))),
        Err(e) => Err(LiveError::Failed(e.to_string())),
    }
}
