//! Interroll RollerDrive EC5000 BI: LSS assigns node id 5 to the drive at
//! its delivery node id 127 and stores it, then profile velocity mode runs
//! and halts.
//!
//! ```text
//! cargo run -p eds2rust-sim --example interroll_ec5000bi -- [--trace] [--time-scale F]
//! cargo run -p eds2rust-sim --example interroll_ec5000bi -- --iface can0
//! ```
//!
//! Without `--iface` the drive is simulated on a virtual bus. On a real
//! bus the drive must still be at node id 127: its LSS address (0x1018)
//! is read there by SDO, then LSS switch state selective picks exactly
//! that drive (chapter 3), so other drives may be connected.

use std::io::Write;
use std::ops::ControlFlow;
use std::process::ExitCode;
use std::time::Duration;

use eds2rust_drivers::interroll_ec5000bi::{DEFAULT_NODE_ID, od};
use eds2rust_runtime::cia402::State;
use eds2rust_runtime::lss::{Identity, LssState};
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::nmt::{NmtCommand, NmtEvent};
use eds2rust_runtime::od::{self as rod, Entry, NodeId};
use eds2rust_sim::harness::{Args, Harness};
use eds2rust_sim::models::interroll_ec5000bi::{
    DEFAULT_SERIAL, Ec5000Bi, default_config, simulator_with,
};

#[allow(clippy::duplicate_mod, reason = "the demo includes the three examples")]
#[path = "common/mod.rs"]
mod common;

use common::{Res, node};

type M = common::Master;

/// The node id LSS gives the drive.
const NEW_NODE: u8 = 5;
/// The demo's target velocity, mm/s (0x60FF, chapter 4.2).
const TARGET_MM_S: i32 = 500;
/// Profile acceleration and deceleration, mm/s² (0x6083, 0x6084).
const RAMP_MM_S2: u32 = 1000;
/// How close 0x606C must come to the target to count as reached, mm/s.
const TOLERANCE_MM_S: i32 = 5;
/// Longest wait for any state or velocity.
const WAIT: Duration = Duration::from_secs(5);

/// What the run ended with.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Summary {
    /// The drive's node id at the end.
    pub node: u8,
    /// The last statusword read.
    pub statusword: u16,
    /// Its CiA 402 state.
    pub state: Option<State>,
    /// The last velocity actual value, mm/s.
    pub velocity_mm_s: i32,
    /// The position actual value at standstill, mm.
    pub position_mm: i32,
    /// Every frame on the bus in candump's compact form.
    pub trace: Vec<String>,
}

fn main() -> ExitCode {
    common::main("interroll_ec5000bi", run)
}

/// Reads entry `E` of `n`, naming it in the error.
fn read<E>(m: &mut M, n: NodeId) -> Res<E::Value>
where
    E: Entry,
    E::Access: rod::Read,
    E::Value: rod::Scalar,
{
    m.read::<E>(n).map_err(|e| {
        format!(
            "node {}: reading {} ({:#06X} sub {}): {e}",
            n.get(),
            E::NAME,
            E::INDEX,
            E::SUBINDEX
        )
        .into()
    })
}

/// Writes entry `E` of `n`, naming it in the error.
fn write<E>(m: &mut M, n: NodeId, value: E::Value) -> Res<()>
where
    E: Entry,
    E::Access: rod::Write,
    E::Value: rod::Scalar + std::fmt::Debug,
{
    m.write::<E>(n, value).map_err(|e| {
        format!(
            "node {}: writing {value:?} to {} ({:#06X} sub {}): {e}",
            n.get(),
            E::NAME,
            E::INDEX,
            E::SUBINDEX
        )
        .into()
    })
}

/// Polls `probe` every 25 ms until it yields a value or `WAIT` passes.
fn wait_for<T>(m: &mut M, what: &str, mut probe: impl FnMut(&mut M) -> Res<Option<T>>) -> Res<T> {
    let start = std::time::Instant::now();
    loop {
        if let Some(v) = probe(m)? {
            return Ok(v);
        }
        if start.elapsed() > WAIT {
            return Err(format!("timed out after {WAIT:?} waiting for {what}").into());
        }
        m.run_for(Duration::from_millis(25))?;
    }
}

fn state_name(sw: u16) -> &'static str {
    State::from_statusword(sw).map_or("unknown state", State::name)
}

/// Writes the controlword and waits until the statusword shows `want`.
fn command(m: &mut M, n: NodeId, out: &mut dyn Write, cw: u16, want: State) -> Res<u16> {
    write::<od::Controlword>(m, n, od::ControlwordValue(cw))?;
    let what = format!("node {} to reach {} (0x6041)", n.get(), want.name());
    let sw = wait_for(m, &what, |m| {
        let sw = read::<od::Statusword>(m, n)?.0;
        Ok((State::from_statusword(sw) == Some(want)).then_some(sw))
    })?;
    writeln!(
        out,
        "  controlword 0x{cw:04X} -> statusword 0x{sw:04X} ({})",
        state_name(sw)
    )?;
    Ok(sw)
}

/// LSS (chapter 3): switch state selective, configure node id 5, store,
/// back to waiting, NMT reset communication; waits for the boot-up.
fn assign_node_id(m: &mut M, address: Identity, out: &mut dyn Write) -> Res<NodeId> {
    let new = node(NEW_NODE)?;
    let serial = address.serial;
    writeln!(out, "LSS: selecting the drive with serial number {serial}")?;
    m.lss_switch_selective(address)
        .map_err(|e| format!("LSS switch state selective (serial {serial}): {e}"))?;
    m.lss_configure_node_id(new)
        .map_err(|e| format!("LSS configure node id {NEW_NODE}: {e}"))?;
    writeln!(out, "LSS: node id {NEW_NODE} configured")?;
    m.lss_store()
        .map_err(|e| format!("LSS store configuration: {e}"))?;
    writeln!(out, "LSS: configuration stored (survives a power cycle)")?;
    m.lss_switch_global(LssState::Waiting)
        .map_err(|e| format!("LSS switch state global (waiting): {e}"))?;
    m.nmt(NmtCommand::ResetCommunication, node(DEFAULT_NODE_ID)?)?;
    let deadline = std::time::Instant::now() + WAIT;
    m.run_until(deadline, |e| match e {
        MasterEvent::Nmt(NmtEvent::BootUp(n)) if *n == new => ControlFlow::Break(()),
        _ => ControlFlow::Continue(()),
    })
    .map_err(|e| format!("waiting for the boot-up of node {NEW_NODE}: {e}"))?;
    writeln!(out, "NMT: node {NEW_NODE} booted (reset communication)")?;
    Ok(new)
}

/// The monitoring values of chapter 6.
fn print_monitoring(m: &mut M, n: NodeId, out: &mut dyn Write, simulated: bool) -> Res<()> {
    use od::health_traffic_light as light;
    use od::monitoring_values as mon;
    let colour = |v: u8| match v {
        0 => "green",
        1 => "yellow",
        2 => "red",
        _ => "?",
    };
    let note = if simulated {
        " (simulated by the model)"
    } else {
        ""
    };
    writeln!(out, "monitoring{note}:")?;
    let t = read::<mon::ActualTemperature>(m, n)?.0;
    let t_max = read::<mon::AbsoluteMaximumTemperature>(m, n)?.0;
    writeln!(
        out,
        "  motor temperature {t} °C (maximum so far {t_max} °C)"
    )?;
    let u = read::<od::DcLinkCircuitVoltage>(m, n)?.0;
    let torque = read::<od::TorqueActualValue>(m, n)?.0;
    writeln!(
        out,
        "  DC link voltage {:.2} V, torque {torque} ‰ of rated",
        f64::from(u) / 1000.0
    )?;
    let p = read::<mon::PowerAverageMech>(m, n)?.0;
    let starts = read::<mon::StartStops>(m, n)?;
    let turns = read::<mon::NumberOfRotations>(m, n)?;
    let hours = read::<mon::WorkingHours>(m, n)?.0;
    writeln!(
        out,
        "  power average {p} W, start/stops {starts}, rotations {turns}, working hours {hours} h"
    )?;
    let lt = read::<light::Temperature>(m, n)?.0;
    let lp = read::<light::Power>(m, n)?.0;
    let le = read::<light::ErrorQuantity>(m, n)?.0;
    let ll = read::<od::LifetimeTrafficLight>(m, n)?.0;
    writeln!(
        out,
        "  status lights: temperature {}, power {}, error quantity {}, lifetime {}",
        colour(lt),
        colour(lp),
        colour(le),
        colour(ll)
    )?;
    Ok(())
}

/// The scenario: LSS, then velocity mode (see the file's documentation).
pub fn run(args: &Args, out: &mut dyn Write) -> Res<Summary> {
    let scale = args.time_scale;
    let harness = Harness::start(args, |now| {
        let model = Ec5000Bi::new().with_time_scale(scale);
        simulator_with(model, default_config(DEFAULT_SERIAL), now)
    })?;
    let core = master::Master::new(node(1)?, None);
    let (summary, trace) = common::run_master(harness, core, |m| {
        m.start()?;
        scenario(m, args, out)
    })?;
    Ok(Summary { trace, ..summary })
}

/// The LSS address of the drive at node id 127, read by SDO (0x1018).
fn read_address(m: &mut M, out: &mut dyn Write) -> Res<Identity> {
    use od::identity as id;
    let n = node(DEFAULT_NODE_ID)?;
    let address = Identity::new(
        read::<id::VendorId>(m, n)?,
        read::<id::ProductCode>(m, n)?,
        read::<id::RevisionNumber>(m, n)?,
        read::<id::SerialNumber>(m, n)?,
    );
    writeln!(
        out,
        "node {DEFAULT_NODE_ID} (delivery state): vendor 0x{:X}, product {}, revision 0x{:08X}, serial number {}",
        address.vendor_id, address.product_code, address.revision, address.serial
    )?;
    Ok(address)
}

fn scenario(m: &mut M, args: &Args, out: &mut dyn Write) -> Res<Summary> {
    let address = read_address(m, out)?;
    let n = assign_node_id(m, address, out)?;
    let name = m
        .read_string::<od::ManufacturerDeviceName>(n)
        .map_err(|e| format!("node {NEW_NODE}: reading 0x1008: {e}"))?;
    let sn = read::<od::identity::SerialNumber>(m, n)?;
    writeln!(out, "node {NEW_NODE}: {name}, serial number {sn}")?;
    m.nmt(NmtCommand::Start, n)?;

    writeln!(out, "CiA 402: profile velocity mode (0x6060 = 3)")?;
    write::<od::ModesOfOperation>(m, n, od::ModesOfOperationValue::PROFILE_VELOCITY)?;
    write::<od::ProfileAcceleration>(m, n, od::ProfileAccelerationValue(RAMP_MM_S2))?;
    write::<od::ProfileDeceleration>(m, n, od::ProfileDecelerationValue(RAMP_MM_S2))?;
    let sw = read::<od::Statusword>(m, n)?.0;
    writeln!(out, "  statusword 0x{sw:04X} ({})", state_name(sw))?;
    command(m, n, out, 0x0006, State::ReadyToSwitchOn)?;
    command(m, n, out, 0x0007, State::SwitchedOn)?;
    command(m, n, out, 0x000F, State::OperationEnabled)?;

    writeln!(
        out,
        "target velocity {TARGET_MM_S} mm/s ({} m/s)",
        f64::from(TARGET_MM_S) / 1000.0
    )?;
    write::<od::TargetVelocity>(m, n, od::TargetVelocityValue(TARGET_MM_S))?;
    let what =
        format!("node {NEW_NODE}: velocity actual value (0x606C) to reach {TARGET_MM_S} mm/s");
    let mut last_print = std::time::Instant::now();
    let v = wait_for(m, &what, |m| {
        let v = read::<od::VelocityActualValue>(m, n)?.0;
        if (v - TARGET_MM_S).abs() <= TOLERANCE_MM_S {
            return Ok(Some(v));
        }
        if last_print.elapsed() >= Duration::from_millis(100) {
            last_print = std::time::Instant::now();
            writeln!(out, "  velocity {v} mm/s")?;
        }
        Ok(None)
    })?;
    writeln!(out, "  velocity reached: {v} mm/s")?;
    // One second of conveying, in the simulator's time.
    m.run_for(Duration::from_secs_f64(1.0 / args.time_scale))?;
    print_monitoring(m, n, out, args.simulates())?;

    writeln!(out, "halt (controlword bit 8)")?;
    write::<od::Controlword>(m, n, od::ControlwordValue(0x010F))?;
    let what = format!("node {NEW_NODE}: standstill (0x606C = 0)");
    let v = wait_for(m, &what, |m| {
        let v = read::<od::VelocityActualValue>(m, n)?.0;
        Ok((v == 0).then_some(v))
    })?;
    let position = read::<od::PositionActualValue>(m, n)?.0;
    let sw = read::<od::Statusword>(m, n)?.0;
    writeln!(
        out,
        "  standstill at {position} mm, statusword 0x{sw:04X} ({}, zero motion hold)",
        state_name(sw)
    )?;
    Ok(Summary {
        node: n.get(),
        statusword: sw,
        state: State::from_statusword(sw),
        velocity_mm_s: v,
        position_mm: position,
        trace: Vec::new(),
    })
}

/// The scenario on the virtual bus, and its trace decoded with the seed
/// table against what the example printed.
#[cfg(test)]
#[path = "interroll_ec5000bi/tests.rs"]
mod tests;
