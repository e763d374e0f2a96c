//! The seed machine on one bus (eds/machine/bus.yml): the Zimmer ACS axis
//! (node 40), the LINAK TECHLINE actuator (node 32) and the Interroll
//! EC5000 BI conveyor (node 5), each simulated by its seed model on ONE
//! virtual bus, booted by the master from the generated network's plan
//! (`eds2rust_machine::network::PLAN`, CiA 302-2: reset, identity
//! check, configuration download, heartbeats, start), then run together
//! through the PDOs the bus file configures, one step per SYNC (10 ms):
//!
//! - the axis is enabled and moved in cyclic synchronous position mode: a
//!   controlword and a target position in its RPDO1 at each SYNC, its
//!   statusword and position from its TPDO1;
//! - the actuator runs out to its end stop and back in (RPDO1 commands,
//!   TPDO1 feedback), as in the manual's start-up sequence;
//! - the conveyor is enabled in profile velocity mode, conveys and halts
//!   (RPDO1 controlword, TPDO4 statusword and velocity).
//!
//! ```text
//! cargo run -p eds2rust-sim --example machine [-- --trace] [--time-scale F]
//! ```
//!
//! The master process image is the generated `Inputs` (taken from the
//! master's PDO receiver each SYNC) and `Outputs` (set on the master's
//! RPDO transmitters each SYNC). With `--iface NAME --simulate` the three
//! simulators run on a (v)can interface.

#[path = "common/mod.rs"]
mod common;
#[path = "machine/sequences.rs"]
mod sequences;

use std::io::Write;
use std::process::ExitCode;
use std::time::Duration;

use eds2rust_machine::network::{self, Inputs, Outputs, PLAN};
use eds2rust_machine::{actuator, axis, conveyor};
use eds2rust_runtime::blocking;
use eds2rust_runtime::boot::{Configuration, NetworkEvent, NetworkReport};
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_sim::DeviceConfig;
use eds2rust_sim::harness::{Args, Harness, MasterPort};
use eds2rust_sim::models::{interroll_ec5000bi, linak_techline, zimmer_acs};
use sequences::{ActuatorStroke, AxisMove, ConveyorRun, log};

use common::{Res, node};

/// The axis's move in the cycle, µm.
pub const AXIS_DISTANCE_UM: i32 = 40_000;
/// Its speed at time scale 1, mm/s.
const AXIS_VELOCITY_MM_S: f64 = 50.0;
/// The conveyor's target velocity (0x60FF), mm/s.
pub const CONVEYOR_MM_S: i32 = 500;
/// How long it conveys at time scale 1.
const CONVEYING: Duration = Duration::from_secs(1);
/// The longest the boot may take.
const BOOT_DEADLINE: Duration = Duration::from_secs(10);
/// The line the run ends with when every device did its part.
pub const SUCCESS: &str = "The machine ran: three devices booted from the network's plan and worked at once through their PDOs.";

/// What the run ended with.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// The boot's report.
    pub report: NetworkReport,
    /// The axis's final position (µm).
    pub axis_um: i32,
    /// The actuator's positions at the outer and inner end stops (mm).
    pub actuator_mm: (f64, f64),
    /// The conveyor's velocity reached (mm/s).
    pub conveyor_mm_s: i32,
    /// SYNC cycles run.
    pub cycles: u32,
    /// Every frame on the bus in candump's compact form.
    pub trace: Vec<String>,
}

fn main() -> ExitCode {
    common::main("machine", run)
}

/// The three simulators on the harness's bus, at the node ids of the bus
/// file, with the mechanics `scale` times faster.
fn start_devices(args: &Args) -> Res<Harness> {
    let scale = args.time_scale;
    let at = |id: u8, config: DeviceConfig| -> Res<DeviceConfig> {
        Ok(DeviceConfig {
            node: Some(node(id)?),
            ..config
        })
    };
    let axis_config = at(axis::NODE_ID, zimmer_acs::default_config())?;
    let actuator_config = at(actuator::NODE_ID, linak_techline::default_config())?;
    let conveyor_config = at(
        conveyor::NODE_ID,
        interroll_ec5000bi::default_config(interroll_ec5000bi::DEFAULT_SERIAL),
    )?;
    let mut harness = Harness::start(args, |now| {
        zimmer_acs::simulator_with(
            zimmer_acs::ZimmerAcs::new().with_time_scale(scale),
            axis_config,
            now,
        )
    })?;
    harness.add_device(|now| {
        linak_techline::simulator_with(
            linak_techline::LinakTechline::new().with_time_scale(scale),
            actuator_config,
            now,
        )
    })?;
    harness.add_device(|now| {
        interroll_ec5000bi::simulator_with(
            interroll_ec5000bi::Ec5000Bi::new().with_time_scale(scale),
            conveyor_config,
            now,
        )
    })?;
    Ok(harness)
}

/// Boots the network and runs the three sequences (see the file's
/// documentation), printing a log to `out`.
pub fn run(args: &Args, out: &mut dyn Write) -> Res<Summary> {
    let mut harness = start_devices(args)?;
    let core = master::Master::for_network(&PLAN)?;
    let mut m = blocking::Master::with_clock(harness.take_port()?, core, harness.clock());
    m.start()?;
    writeln!(
        out,
        "master node {}: {} kbit/s, SYNC every {} ms, heartbeat {} ms; booting {} slaves",
        network::MASTER_NODE_ID,
        network::BIT_RATE_KBIT,
        network::SYNC_PERIOD_US / 1000,
        network::MASTER_HEARTBEAT_MS,
        PLAN.slaves.len()
    )?;
    let report = m.boot_network(PLAN, m.now() + BOOT_DEADLINE)?;
    for event in m.drain_events() {
        if let MasterEvent::Network(NetworkEvent::Failed(e)) = event {
            writeln!(out, "boot: {e}")?;
        }
    }
    print_report(out, &report)?;
    if !report.booted || report.slaves.iter().any(|s| s.error.is_some()) {
        return Err("the network did not boot".into());
    }
    // bus.yml maps the conveyor's target velocity into no enabled RPDO
    // (RPDO3 is off): it is set once, by SDO, before the cycle.
    m.write::<conveyor::od::TargetVelocity>(
        node(conveyor::NODE_ID)?,
        conveyor::od::TargetVelocityValue(CONVEYOR_MM_S),
    )?;
    writeln!(
        out,
        "conveyor: target velocity {CONVEYOR_MM_S} mm/s (0x60FF by SDO)"
    )?;
    let (summary_cycles, axis, actuator, conveyor) = cycle(&mut m, args, out)?;
    let trace = harness.stop()?;
    writeln!(out, "{SUCCESS}")?;
    Ok(Summary {
        report,
        axis_um: axis.reached_um.unwrap_or_default(),
        actuator_mm: (
            actuator.out_end_mm.unwrap_or(f64::NAN),
            actuator.in_end_mm.unwrap_or(f64::NAN),
        ),
        conveyor_mm_s: conveyor.reached_mm_s.unwrap_or_default(),
        cycles: summary_cycles,
        trace,
    })
}

/// One row per slave: node, name, identity, configuration, state, time.
fn print_report(out: &mut dyn Write, report: &NetworkReport) -> Res<()> {
    for s in &report.slaves {
        let configuration = match s.configuration {
            Some(Configuration::Written(n)) => format!("{n} entries written"),
            Some(Configuration::Current) => "current".into(),
            Some(Configuration::NotManaged) => "not managed".into(),
            None => "-".into(),
        };
        let took = s.boot_started.zip(s.boot_ended).map_or_else(
            || "-".into(),
            |(a, b)| format!("{} ms", (b - a).as_millis()),
        );
        writeln!(
            out,
            "  node {:>3} {:<9} identity {:<7} configuration {:<18} {:?} in {took}",
            s.node.get(),
            s.name,
            if s.identity_checked { "checked" } else { "-" },
            configuration,
            s.state,
        )?;
    }
    Ok(())
}

/// The SYNC cycle: at each SYNC the inputs are taken, each sequence steps
/// and the outputs are set, until all three are done.
fn cycle(
    m: &mut blocking::Master<MasterPort>,
    args: &Args,
    out: &mut dyn Write,
) -> Res<(u32, AxisMove, ActuatorStroke, ConveyorRun)> {
    let scale = if args.simulates() {
        args.time_scale
    } else {
        1.0
    };
    let period = Duration::from_micros(u64::from(network::SYNC_PERIOD_US));
    let mut axis = AxisMove::new(AXIS_DISTANCE_UM, AXIS_VELOCITY_MM_S * 1000.0 * scale);
    let mut actuator = ActuatorStroke::default();
    let mut conveyor = ConveyorRun::new(CONVEYOR_MM_S, CONVEYING.div_f64(scale));
    // Every output starts from a valid command: drives disabled, the
    // actuator stopped at default current, speed and ramps.
    let mut outputs = Outputs {
        axis_rpdo1: axis::pdo::Rpdo1ControlAndTargetPosition {
            controlword: axis::od::ControlwordValue(0),
            target_position: axis::od::TargetPositionValue(0),
        },
        actuator_rpdo1: actuator::pdo::Rpdo1Command {
            position: actuator::od::command::PositionValue::STOP,
            current_limit: actuator::od::command::CurrentLimitValue::DEFAULT,
            speed: actuator::od::command::SpeedValue::DEFAULT,
            soft_start: actuator::od::command::SoftStartValue::DEFAULT,
            soft_stop: actuator::od::command::SoftStopValue::DEFAULT,
            reserved_6: 0,
            reserved_7: 0,
        },
        conveyor_rpdo1: conveyor::pdo::Rpdo1VelocityCommand {
            controlword: conveyor::od::ControlwordValue(0),
            modes_of_operation: conveyor::od::ModesOfOperationValue::PROFILE_VELOCITY,
            profile_velocity: conveyor::od::ProfileVelocityValue(0),
        },
    };
    let mut inputs = Inputs::new();
    // The actuator's stroke takes about 10 s each way at time scale 1.
    let limit = Duration::from_secs_f64(60.0 / scale) + Duration::from_secs(5);
    let start = m.now();
    m.core_mut().set_sync_events(true);
    let mut cycles = 0u32;
    while !(axis.done() && actuator.done() && conveyor.done()) {
        let at = m.now() - start;
        if at > limit {
            return Err(format!(
                "the sequences did not end within {limit:?} (axis {}, actuator {}, conveyor {})",
                state(axis.done()),
                state(actuator.done()),
                state(conveyor.done())
            )
            .into());
        }
        match m.wait_event(m.now() + period * 10)? {
            Some(MasterEvent::Sync(_)) => {}
            Some(MasterEvent::Network(event)) => {
                writeln!(out, "network: {event:?}")?;
                if matches!(event, NetworkEvent::Lost { .. } | NetworkEvent::Failed(_)) {
                    return Err(format!("a slave was lost during the cycle: {event:?}").into());
                }
                continue;
            }
            Some(MasterEvent::Emcy(e)) => {
                log(out, at, "emcy", &format!("{e:?}"))?;
                continue;
            }
            // Nothing yet (a thread that ran late): the time limit above
            // ends a bus that went quiet.
            Some(_) | None => continue,
        }
        cycles += 1;
        let now = m.now();
        inputs.take_latest(&m.core().pdo_rx)?;
        axis.step(now, at, period, &inputs, &mut outputs, out)?;
        actuator.step(at, &inputs, &mut outputs, out)?;
        conveyor.step(now, at, &inputs, &mut outputs, out)?;
        outputs.set_pdos(m.core_mut(), now)?;
        m.flush()?;
    }
    m.core_mut().set_sync_events(false);
    writeln!(
        out,
        "{cycles} SYNC cycles: axis at {:.3} mm, actuator out at {:.1} mm and back, conveyor ran at {} mm/s",
        f64::from(axis.reached_um.unwrap_or_default()) / 1000.0,
        actuator.out_end_mm.unwrap_or(f64::NAN),
        conveyor.reached_mm_s.unwrap_or_default()
    )?;
    Ok((cycles, axis, actuator, conveyor))
}

fn state(done: bool) -> &'static str {
    if done { "done" } else { "not done" }
}

#[cfg(test)]
mod machine_tests {
    use super::*;

    // downstream/machine checks that the generated plan is `boot_plan` of
    // the bus file.

    /// The README's command, on the virtual bus with fast mechanics.
    #[test]
    fn the_machine_boots_and_runs_on_one_bus() {
        let (summary, text) = common::run_at(20.0, run);
        assert!(text.ends_with(&format!("{SUCCESS}\n")), "{text}");
        assert!(summary.report.booted, "{text}");
        assert_eq!(summary.report.slaves.len(), 3, "{text}");
        assert!((summary.axis_um - AXIS_DISTANCE_UM).abs() <= 10, "{text}");
        assert!((summary.conveyor_mm_s - CONVEYOR_MM_S).abs() <= 5, "{text}");
        // The axis moved by RPDO: no SDO download initiate to 0x6040
        // (controlword) or 0x607A (target position).
        for frame in &summary.trace {
            let Some(data) = frame.strip_prefix("628#") else {
                continue;
            };
            let byte = |i: usize| {
                data.get(2 * i..2 * i + 2)
                    .and_then(|b| u8::from_str_radix(b, 16).ok())
            };
            let (Some(cs), Some(lo), Some(hi)) = (byte(0), byte(1), byte(2)) else {
                continue;
            };
            let index = u16::from_le_bytes([lo, hi]);
            assert!(
                cs >> 5 != 1 || !matches!(index, 0x6040 | 0x607A),
                "an SDO write of the axis's motion objects: {frame}\n{text}"
            );
        }
        assert!(
            summary.trace.iter().any(|f| f.starts_with("228#")),
            "the axis's RPDO1 on the bus\n{text}"
        );
    }
}
