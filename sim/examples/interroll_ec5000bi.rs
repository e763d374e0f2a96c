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

use std::error::Error;
use std::io::Write;
use std::ops::ControlFlow;
use std::time::Duration;

use eds2rust_drivers::interroll_ec5000bi::{DEFAULT_NODE_ID, od};
use eds2rust_runtime::blocking;
use eds2rust_runtime::cia402::State;
use eds2rust_runtime::lss::{Identity, LssState};
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::nmt::{NmtCommand, NmtEvent};
use eds2rust_runtime::od::{self as rod, Entry, NodeId};
use eds2rust_sim::harness::{Args, Harness, MasterPort};
use eds2rust_sim::models::interroll_ec5000bi::{
    DEFAULT_SERIAL, Ec5000Bi, default_config, simulator_with,
};

type Res<T> = Result<T, Box<dyn Error>>;
type M = blocking::Master<MasterPort>;

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

fn main() {
    let args = match Args::from_env() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    if let Err(e) = run(&args, &mut std::io::stdout()) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn node(n: u8) -> Res<NodeId> {
    NodeId::new(n).ok_or_else(|| format!("{n} is not a node id").into())
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
    let mut harness = Harness::start(args, |now| {
        let model = Ec5000Bi::new().with_time_scale(scale);
        simulator_with(model, default_config(DEFAULT_SERIAL), now)
    })?;
    let core = master::Master::new(node(1)?, None);
    let mut m = blocking::Master::with_clock(harness.take_port()?, core, harness.clock());
    m.start()?;
    let result = scenario(&mut m, args, out);
    drop(m);
    let trace = harness.stop()?;
    let mut summary = result?;
    summary.trace = trace;
    Ok(summary)
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

/// Decoding the recorded trace with the seed table (the tests).
#[cfg(test)]
#[path = "decoded/mod.rs"]
#[allow(
    clippy::duplicate_mod,
    reason = "each example is a crate of its own; the demo includes all three"
)]
mod decoded;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lss_then_velocity_mode_on_the_virtual_bus() {
        let args = Args {
            time_scale: 20.0,
            ..Args::default()
        };
        let mut out = Vec::new();
        let s = run(&args, &mut out).expect("scenario");
        let text = String::from_utf8_lossy(&out);
        println!("{text}");
        assert_eq!(s.node, 5);
        // Operation enabled, halted (zero motion hold), at rest.
        assert_eq!(s.statusword, 0x0237);
        assert_eq!(s.state, Some(State::OperationEnabled));
        assert_eq!(s.velocity_mm_s, 0);
        assert!(s.position_mm > 0);
        // Chapter 3 / CiA 305, byte for byte.
        let expected = [
            "7E5#40FB030000000000",
            "7E5#4101000000000000",
            "7E5#4201000100000000",
            "7E5#4387D61200000000",
            "7E4#4400000000000000",
            "7E5#1105000000000000",
            "7E4#1100000000000000",
            "7E5#1700000000000000",
            "7E4#1700000000000000",
            "7E5#0400000000000000",
            "000#827F",
            "705#00",
        ];
        let start = s
            .trace
            .iter()
            .position(|l| l == expected[0])
            .expect("switch selective in the trace");
        assert_eq!(&s.trace[start..start + expected.len()], expected);
        // Before: the drive booted at 127 and answered there (0x1018 sub 4).
        let boot = s
            .trace
            .iter()
            .position(|l| l == "77F#00")
            .expect("boot-up 127");
        assert!(boot < start);
        assert!(s.trace.iter().any(|l| l == "5FF#4318100487D61200"));
        for line in [
            "000#0105",             // NMT start node 5
            "605#2F60600003000000", // 0x6060 = 3
            "605#2B40600006000000", // shutdown
            "605#2B40600007000000", // switch on
            "605#2B4060000F000000", // enable operation
        ] {
            assert!(s.trace.iter().any(|l| l == line), "{line} missing");
        }
        // 0x60FF = 500 (INTEGER32, expedited 4 bytes) and the halt word.
        assert!(s.trace.iter().any(|l| l == "605#23FF6000F4010000"));
        assert!(s.trace.iter().any(|l| l == "605#2B4060000F010000"));
        assert!(text.contains("velocity reached"));
        assert!(text.contains("Operation enabled"));
    }

    // The trace decoded with the seed table (eds/interroll_ec5000bi.yaml)
    // against what the example printed.

    use eds2rust_decode::Decoder;

    use super::decoded::{self, *};
    use serde_json::Value as Json;

    /// A decoder that knows the drive by `eds/interroll_ec5000bi.yaml` at
    /// both its node ids: 127 (delivery) and 5 (after LSS).
    fn seed_decoder() -> Decoder {
        let device = decoded::seed("interroll_ec5000bi");
        let mut decoder = Decoder::new();
        decoder.add_node(DEFAULT_NODE_ID, device.clone());
        decoder.add_node(NEW_NODE, device);
        decoder
    }

    /// The next SDO transfer of `node`'s entry `index` sub `sub` from
    /// `from` on.
    fn transfer(
        records: &[Json],
        from: usize,
        (node, index, sub): (u8, u16, u8),
        direction: &str,
    ) -> usize {
        let what = format!("an SDO {direction} of {index:#06X} sub {sub} of node {node}");
        find(records, from, &what, |r| {
            r["event"] == "sdo-transfer"
                && r["node"] == node
                && r["index"] == index
                && r["subindex"] == sub
                && r["direction"] == direction
        })
    }

    /// A printed number, decimal or `0x` hex.
    fn number(text: &str) -> u64 {
        let text = text.trim();
        match text.strip_prefix("0x") {
            Some(hex) => u64::from_str_radix(hex, 16),
            None => text.parse(),
        }
        .unwrap_or_else(|_| panic!("{text} is no number"))
    }

    /// A printed `N unit`.
    fn quantity(text: &str) -> (f64, String) {
        let (n, unit) = text.trim().split_once(' ').expect("N unit");
        (n.parse().expect("a number"), unit.to_string())
    }

    #[test]
    fn the_trace_decodes_to_the_printed_values() {
        // Slow enough that the velocity is printed during the ramp.
        let args = Args {
            time_scale: 2.0,
            ..Args::default()
        };
        let mut out = Vec::new();
        let summary = run(&args, &mut out)
            .unwrap_or_else(|e| panic!("{e}\n{}", String::from_utf8_lossy(&out)));
        let text = String::from_utf8(out).expect("utf-8");
        println!("{text}");
        let records = decode(&mut seed_decoder(), &summary.trace);
        assert_every_frame_decodes(&records);
        let (old, new) = (DEFAULT_NODE_ID, NEW_NODE);
        let text_of = |i: usize| records[i]["text"].as_str().expect("text");
        // The master does one thing at a time: every printed line is
        // matched by records after those of the line before (`at`).
        let mut at = 0;
        let mut identity = Vec::new();
        let mut end = None;
        for line in text.lines() {
            assert!(end.is_none(), "a line after the last: {line}\n{text}");
            let sdo_line = line.trim_start();
            if let Some(rest) = line.strip_prefix(&format!("node {old} (delivery state): ")) {
                // `vendor 0x3FB, product 1, revision 0x00010001, serial number 1234567`
                for (sub, part) in (1u8..).zip(rest.split(", ")) {
                    let (_, value) = part.rsplit_once(' ').expect("name value");
                    at = transfer(&records, at, (old, 0x1018, sub), "upload");
                    assert_eq!(records[at]["value"], number(value), "{line}: {part}");
                    identity.push(number(value));
                }
            } else if let Some(serial) =
                line.strip_prefix("LSS: selecting the drive with serial number ")
            {
                // Switch state selective: vendor, product, revision, serial.
                assert_eq!(identity.last(), Some(&number(serial)), "{line}");
                let parts = ["VendorId", "ProductCode", "Revision", "Serial"];
                for (part, value) in parts.iter().zip(&identity) {
                    let request = format!("LSS request: SwitchStateSelective({part}, {value})");
                    at = find(&records, at, &request, |r| r["text"] == request.as_str());
                }
                at = find(&records, at, line, |r| {
                    r["text"] == "LSS response: SwitchStateSelective"
                });
            } else if let Some(id) = line
                .strip_prefix("LSS: node id ")
                .and_then(|l| l.strip_suffix(" configured"))
            {
                let request = format!("LSS request: ConfigureNodeId({id})");
                at = find(&records, at, &request, |r| r["text"] == request.as_str());
                at = find(&records, at, line, |r| {
                    r["text"] == "LSS response: ConfigureNodeId { error: 0, spec: 0 }"
                });
            } else if line.starts_with("LSS: configuration stored") {
                at = find(&records, at, line, |r| {
                    r["text"] == "LSS request: StoreConfiguration"
                });
                at = find(&records, at, line, |r| {
                    r["text"] == "LSS response: StoreConfiguration { error: 0, spec: 0 }"
                });
            } else if line == format!("NMT: node {new} booted (reset communication)") {
                at = find(&records, at, "NMT reset communication", |r| {
                    r["protocol"] == "nmt"
                        && r["command"] == "reset communication"
                        && r["target"] == old
                });
                at = find(&records, at, line, |r| {
                    r["protocol"] == "heartbeat" && r["node"] == new && r["state"] == "boot-up"
                });
            } else if let Some(rest) = line.strip_prefix(&format!("node {new}: ")) {
                // `EC5000, serial number 1234567`
                let (name, serial) = rest.split_once(", serial number ").expect("name, serial");
                at = transfer(&records, at, (new, 0x1008, 0), "upload");
                assert_eq!(records[at]["value"], name, "{line}");
                at = transfer(&records, at, (new, 0x1018, 4), "upload");
                assert_eq!(records[at]["value"], number(serial), "{line}");
            } else if let Some(rest) = line.strip_prefix("CiA 402: ") {
                // `profile velocity mode (0x6060 = 3)`
                let (mode, rest) = rest.split_once(" mode (0x").expect("mode (0x....");
                let (index, value) = rest.trim_end_matches(')').split_once(" = ").expect("=");
                let index = u16::from_str_radix(index, 16).expect("hex");
                at = transfer(&records, at, (new, index, 0), "download");
                assert_eq!(records[at]["value"], number(value), "{line}");
                assert!(
                    text_of(at).ends_with(&format!("\"{mode}\"")),
                    "{line}: {}",
                    text_of(at)
                );
            } else if let Some(rest) = sdo_line.strip_prefix("statusword 0x") {
                // `0250 (Switch on disabled)`
                let (sw, state) = rest.split_once(" (").expect("sw (state)");
                at = transfer(&records, at, (new, 0x6041, 0), "upload");
                assert_eq!(records[at]["value"], number(&format!("0x{sw}")), "{line}");
                let state = state.trim_end_matches(')');
                assert!(names_state(text_of(at), state), "{line}: {}", text_of(at));
            } else if let Some(rest) = sdo_line.strip_prefix("controlword ") {
                // `0x0006 -> statusword 0x0231 (Ready to switch on)`: the
                // write, then the first read that shows the state.
                let (cw, rest) = rest.split_once(" -> statusword ").expect("cw -> sw");
                let (sw, state) = rest.split_once(" (").expect("sw (state)");
                let state = state.trim_end_matches(')');
                at = transfer(&records, at, (new, 0x6040, 0), "download");
                assert_eq!(records[at]["value"], number(cw), "{line}");
                at = find(&records, at, line, |r| {
                    r["event"] == "sdo-transfer"
                        && r["node"] == new
                        && r["index"] == 0x6041
                        && r["direction"] == "upload"
                        && r["value"] == number(sw)
                });
                assert!(names_state(text_of(at), state), "{line}: {}", text_of(at));
            } else if let Some(rest) = line.strip_prefix("target velocity ") {
                // `500 mm/s (0.5 m/s)`
                let (mm_s, m_s) = rest.split_once(" (").expect("mm/s (m/s)");
                at = transfer(&records, at, (new, 0x60FF, 0), "download");
                let (value, unit) = physical(&records[at]);
                assert_eq!((value, unit.clone()), quantity(mm_s), "{line}");
                assert_eq!(unit, "mm/s");
                assert_eq!(format!("{} m/s", value / 1000.0), m_s.trim_end_matches(')'));
            } else if let Some(rest) = sdo_line
                .strip_prefix("velocity reached: ")
                .or_else(|| sdo_line.strip_prefix("velocity "))
            {
                // Polled every 25 ms, printed at most every 100 ms.
                at = find(&records, at, line, |r| {
                    r["event"] == "sdo-transfer"
                        && r["node"] == new
                        && r["index"] == 0x606C
                        && r["direction"] == "upload"
                        && physical(r) == quantity(rest)
                });
            } else if line.starts_with("monitoring") {
                // A heading.
            } else if let Some(rest) = sdo_line.strip_prefix("motor temperature ") {
                // `25 °C (maximum so far 25 °C)`
                let (now, max) = rest.split_once(" (maximum so far ").expect("(maximum)");
                at = transfer(&records, at, (new, 0x2200, 6), "upload");
                assert_eq!(physical(&records[at]), quantity(now), "{line}");
                at = transfer(&records, at, (new, 0x2200, 5), "upload");
                let max = max.trim_end_matches(')');
                assert_eq!(physical(&records[at]), quantity(max), "{line}");
            } else if let Some(rest) = sdo_line.strip_prefix("DC link voltage ") {
                // `23.97 V, torque 85 ‰ of rated`: mV on the bus.
                let (volts, torque) = rest.split_once(", torque ").expect("V, torque");
                at = transfer(&records, at, (new, 0x6079, 0), "upload");
                let (mv, unit) = physical(&records[at]);
                assert_eq!(unit, "mV", "{line}");
                assert_eq!(format!("{:.2} V", mv / 1000.0), volts, "{line}");
                at = transfer(&records, at, (new, 0x6077, 0), "upload");
                let torque = torque.strip_suffix(" of rated").expect("of rated");
                assert_eq!(physical(&records[at]), quantity(torque), "{line}");
            } else if let Some(rest) = sdo_line.strip_prefix("power average ") {
                // `0 W, start/stops 1, rotations 2, working hours 0 h`
                let parts: Vec<&str> = rest.split(", ").collect();
                let [power, starts, turns, hours] = parts[..] else {
                    panic!("{line}")
                };
                at = transfer(&records, at, (new, 0x2200, 8), "upload");
                assert_eq!(physical(&records[at]), quantity(power), "{line}");
                for (sub, part) in [(1, starts), (9, turns)] {
                    let (_, n) = part.rsplit_once(' ').expect("name N");
                    at = transfer(&records, at, (new, 0x2200, sub), "upload");
                    assert_eq!(records[at]["value"], number(n), "{line}");
                }
                at = transfer(&records, at, (new, 0x2200, 2), "upload");
                let hours = hours.strip_prefix("working hours ").expect("working hours");
                assert_eq!(physical(&records[at]), quantity(hours), "{line}");
            } else if let Some(rest) = sdo_line.strip_prefix("status lights: ") {
                // `temperature green, power green, error quantity green,
                // lifetime green`: the named values of the lights.
                let entries = [(0x2211, 1), (0x2211, 2), (0x2211, 3), (0x2210, 0)];
                let parts: Vec<&str> = rest.split(", ").collect();
                assert_eq!(parts.len(), entries.len(), "{line}");
                for ((index, sub), part) in entries.into_iter().zip(parts) {
                    let (_, colour) = part.rsplit_once(' ').expect("light colour");
                    at = transfer(&records, at, (new, index, sub), "upload");
                    let named = format!("\"{colour}\"");
                    assert!(text_of(at).ends_with(&named), "{line}: {}", text_of(at));
                }
            } else if let Some(bit) = line
                .strip_prefix("halt (controlword bit ")
                .and_then(|l| l.strip_suffix(')'))
            {
                let bit = number(bit);
                at = transfer(&records, at, (new, 0x6040, 0), "download");
                let cw = records[at]["value"].as_u64().expect("a controlword");
                assert!(cw & 1 << bit != 0, "{line}: {}", text_of(at));
                assert!(text_of(at).contains("\"halt\""), "{line}: {}", text_of(at));
            } else if let Some(rest) = sdo_line.strip_prefix("standstill at ") {
                // `764 mm, statusword 0x0237 (Operation enabled, zero motion
                // hold)`: 0x606C read until 0, then 0x6064 and 0x6041.
                let (position, rest) = rest.split_once(", statusword ").expect("position, sw");
                let (sw, state) = rest.split_once(" (").expect("sw (state)");
                let (state, _) = state.split_once(", ").expect("state, hold");
                let rest = records.get(at..).unwrap_or_default();
                let stopped = at
                    + rest
                        .iter()
                        .position(|r| {
                            r["event"] == "sdo-transfer"
                                && r["node"] == new
                                && r["index"] == 0x606C
                                && r["value"] == 0
                        })
                        .expect("a velocity of 0 after the halt");
                assert_eq!(physical(&records[stopped]), (0.0, "mm/s".into()));
                at = transfer(&records, stopped, (new, 0x6064, 0), "upload");
                let (mm, unit) = physical(&records[at]);
                assert_eq!((mm, unit), quantity(position), "{line}");
                assert_eq!(f64::from(summary.position_mm), mm);
                at = transfer(&records, at, (new, 0x6041, 0), "upload");
                assert_eq!(records[at]["value"], number(sw), "{line}");
                assert!(names_state(text_of(at), state), "{line}: {}", text_of(at));
                assert_eq!(records[at]["value"], summary.statusword);
                assert_eq!(summary.state.map(State::name), Some(state));
                // The last velocity read is the standstill's.
                let last = records.iter().rposition(|r| {
                    r["event"] == "sdo-transfer" && r["node"] == new && r["index"] == 0x606C
                });
                assert_eq!(last, Some(stopped));
                assert_eq!(records[stopped]["value"], summary.velocity_mm_s);
                end = Some(at);
            } else {
                panic!("a line this test does not know: {line}\n{text}");
            }
        }
        assert!(end.is_some(), "no final line:\n{text}");
        assert_eq!(summary.node, new);
    }
}
