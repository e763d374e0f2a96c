//! `--fault NODE:KIND[=VALUE]` of `eds2rust sim --network`: the text of a
//! fault into the simulation's typed [`NodeFault`], against the network
//! (NODE is a node id or a slave's name in the bus file).

use std::time::Duration;

use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_sim::network::{DEFAULT_ABORT, Fault, IdentityField, Network, NodeFault};

use crate::live::{parse_duration, values};

/// The kinds, for the messages and --help.
pub const KINDS: &str = "missing, device-type=V, vendor-id=V, product-code=V, revision=V, \
     serial=V, late-boot=T, power-loss=AT[+OFF], sdo-abort=INDEX:SUB[:CODE], \
     heartbeat-stops=AT[+FOR], config-current (V a number, T a time: 500ms, 2s; a bare \
     number is ms)";

/// How long a power loss lasts when `power-loss=AT` gives no `+OFF`.
pub const DEFAULT_OFF: Duration = Duration::from_secs(1);

/// Parses `text` (`NODE:KIND[=VALUE]`) against `network`.
pub fn parse(text: &str, network: &Network) -> Result<NodeFault, String> {
    let bad = |why: String| format!("--fault `{text}`: {why}");
    let (node, spec) = text
        .split_once(':')
        .ok_or_else(|| bad(format!("not NODE:KIND[=VALUE]; the kinds: {KINDS}")))?;
    let node = node_of(node.trim(), network).map_err(&bad)?;
    let fault = fault(spec.trim()).map_err(&bad)?;
    Ok(NodeFault::new(node, fault))
}

/// Every `--fault` of `texts` parsed against `network`, and checked to
/// fit it ([`Network::check`]); `eds2rust sim --network` and `eds2rust
/// net boot --simulate` take them so.
pub fn parse_all(texts: &[String], network: &Network) -> Result<Vec<NodeFault>, String> {
    let faults = texts
        .iter()
        .map(|text| parse(text, network))
        .collect::<Result<Vec<_>, _>>()?;
    network.check(&faults).map_err(|e| e.to_string())?;
    Ok(faults)
}

/// A node id (1 to 127, decimal or 0x hex) or a slave's name.
fn node_of(text: &str, network: &Network) -> Result<NodeId, String> {
    if let Some(node) = network.node_named(text) {
        return Ok(node);
    }
    let slaves: Vec<String> = network
        .slaves
        .iter()
        .map(|s| format!("{} ({})", s.node, s.name))
        .collect();
    let known = || {
        format!(
            "the slaves of {}: {}",
            network.file.display(),
            slaves.join(", ")
        )
    };
    match values::parse_int(text)
        .and_then(|v| u8::try_from(v).ok())
        .and_then(NodeId::new)
    {
        Some(node) if network.slave(node).is_some() => Ok(node),
        Some(node) => Err(format!("no slave has node id {node}; {}", known())),
        None => Err(format!(
            "`{text}` is neither a node id nor a slave's name; {}",
            known()
        )),
    }
}

fn number(text: &str, what: &str) -> Result<u32, String> {
    values::parse_int(text)
        .and_then(|v| u32::try_from(v).ok())
        .ok_or_else(|| format!("`{text}` is not {what} (a 32-bit number, decimal or 0x hex)"))
}

/// `AT` or `AT+FOR`.
fn times(text: &str) -> Result<(Duration, Option<Duration>), String> {
    let (at, rest) = match text.split_once('+') {
        Some((at, rest)) => (at, Some(rest)),
        None => (text, None),
    };
    let at = parse_duration(at)?;
    let rest = rest.map(parse_duration).transpose()?;
    Ok((at, rest))
}

fn fault(spec: &str) -> Result<Fault, String> {
    let (kind, value) = match spec.split_once('=') {
        Some((k, v)) => (k.trim(), Some(v.trim())),
        None => (spec, None),
    };
    let need = || format!("`{kind}` needs a value (`{kind}=...`); the kinds: {KINDS}");
    let identity = |field: IdentityField| -> Result<Fault, String> {
        let v = value.ok_or_else(need)?;
        Ok(Fault::Identity(field, number(v, field.name())?))
    };
    let fault = match kind {
        "missing" => Fault::Missing,
        "config-current" => Fault::ConfigurationCurrent,
        "device-type" => identity(IdentityField::DeviceType)?,
        "vendor-id" => identity(IdentityField::VendorId)?,
        "product-code" => identity(IdentityField::ProductCode)?,
        "revision" | "revision-number" => identity(IdentityField::RevisionNumber)?,
        "serial" | "serial-number" => identity(IdentityField::SerialNumber)?,
        "late-boot" => Fault::LateBoot(parse_duration(value.ok_or_else(need)?)?),
        "power-loss" => {
            let (at, off) = times(value.ok_or_else(need)?)?;
            Fault::PowerLoss {
                at,
                off: off.unwrap_or(DEFAULT_OFF),
            }
        }
        "heartbeat-stops" => {
            let (at, resume) = times(value.ok_or_else(need)?)?;
            Fault::HeartbeatStops { at, resume }
        }
        "sdo-abort" => {
            let v = value.ok_or_else(need)?;
            let parts: Vec<&str> = v.split(':').collect();
            let (index, sub, code) = match parts.as_slice() {
                [i, s] => (i, s, None),
                [i, s, c] => (i, s, Some(c)),
                _ => {
                    return Err(format!(
                        "`{v}` is not INDEX:SUB[:CODE] (0x6060:0:0x06090030)"
                    ));
                }
            };
            let index = values::parse_int(index)
                .and_then(|v| u16::try_from(v).ok())
                .ok_or_else(|| format!("`{index}` is not an object index (0x6060)"))?;
            let sub = values::parse_int(sub)
                .and_then(|v| u8::try_from(v).ok())
                .ok_or_else(|| format!("`{sub}` is not a sub-index (0 to 255)"))?;
            let code = match code {
                Some(c) => AbortCode::from_code(number(c, "an abort code")?),
                None => DEFAULT_ABORT,
            };
            Fault::SdoAbort { index, sub, code }
        }
        other => return Err(format!("unknown kind `{other}`; the kinds: {KINDS}")),
    };
    if value.is_some() && matches!(fault, Fault::Missing | Fault::ConfigurationCurrent) {
        return Err(format!("`{kind}` takes no value"));
    }
    Ok(fault)
}
