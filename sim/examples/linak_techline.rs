//! LINAK TECHLINE actuator: the start-up sequence of the manual (CANopen
//! Montageanleitung p. 28), then run out to the end stop and back in.
//!
//! ```text
//! cargo run -p eds2rust-sim --example linak_techline -- [--trace] [--time-scale F]
//! cargo run -p eds2rust-sim --example linak_techline -- --iface can0 [--simulate]
//! ```
//!
//! The master is node 1 with a heartbeat every 100 ms (0x701 [05]); the
//! actuator is node 32 at 250 kbit/s. A full stroke of the simulated
//! actuator (50.3 mm at about 5 mm/s) takes about 10 s each way, so the
//! whole run takes about 21 s at `--time-scale 1`; `--time-scale 10` makes
//! it about 3 s. On a real actuator (`--iface` without `--simulate`) the
//! time scale has no effect and each stroke may take up to a minute.
//!
//! The master first resets the actuator (NMT reset node), so that its
//! boot-up message follows the master's heartbeat as in the manual's trace
//! and the sequence works whether or not the actuator was already on.

use std::error::Error;
use std::fmt;
use std::io::Write;
use std::ops::ControlFlow;
use std::process::ExitCode;
use std::time::Duration;

use eds2rust_drivers::linak_techline::od::consumer_heartbeat_time::{
    ConsumerHeartbeatTime, ConsumerHeartbeatTimeValue,
};
use eds2rust_drivers::linak_techline::od::{command, feedback};
use eds2rust_drivers::linak_techline::pdo::{Rpdo1Command, Tpdo1Feedback};
use eds2rust_runtime::blocking;
use eds2rust_runtime::emcy::EmcyEvent;
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::nmt::{NmtCommand, NmtEvent, NmtState};
use eds2rust_runtime::od::Scaled as _;
use eds2rust_sim::harness::{Args, Harness};
use eds2rust_sim::models::linak_techline::{LinakTechline, NODE, default_config, simulator_with};

#[allow(clippy::duplicate_mod, reason = "the demo includes the three examples")]
#[path = "common/mod.rs"]
mod common;

use common::Master;

/// The master's node id in the manual's trace (0x701).
const MASTER_NODE: u8 = 1;
/// The master's heartbeat period (p. 28: every 100 ms).
const MASTER_HEARTBEAT: Duration = Duration::from_millis(100);
/// The consumer time the master writes into 0x1016 sub 1 (p. 28: 200 ms).
const CONSUMER_TIME_MS: u16 = 200;
/// Longest wait for a protocol answer (boot-up, a TPDO).
const ANSWER_TIMEOUT: Duration = Duration::from_secs(2);

/// What the run ended with.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Position at the outer end stop, mm.
    pub out_end_mm: f64,
    /// Final position, mm.
    pub final_position_mm: f64,
    /// Final status flags (0x2001 sub 3).
    pub status: u8,
    /// Final error code (0x2001 sub 4).
    pub error_code: u8,
    /// Every frame on the bus in candump's compact form.
    pub trace: Vec<String>,
}

/// A step of the scenario that did not happen.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScenarioError(pub String);

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl Error for ScenarioError {}

type Result<T> = common::Res<T>;

fn main() -> ExitCode {
    common::main("linak_techline", run)
}

/// Runs the scenario (see the file's documentation) and prints its
/// progress to `out`.
pub fn run(args: &Args, out: &mut dyn Write) -> Result<Summary> {
    let scale = args.time_scale;
    let harness = Harness::start(args, |now| {
        simulator_with(
            LinakTechline::new().with_time_scale(scale),
            default_config(),
            now,
        )
    })?;
    let me = common::node(MASTER_NODE)?;
    let mut core = master::Master::new(me, Some(MASTER_HEARTBEAT));
    core.heartbeat.set_state(NmtState::Operational);
    // A stroke takes about 10 s at 5 mm/s; a real actuator may be longer
    // and slower, and does not follow the time scale.
    let stroke_time = if args.simulates() {
        Duration::from_secs_f64(30.0 / scale) + ANSWER_TIMEOUT
    } else {
        Duration::from_secs(60)
    };

    let ((outside, inside), trace) = common::run_master(harness, core, |m| {
        m.start()?;
        m.run_for(MASTER_HEARTBEAT + MASTER_HEARTBEAT / 2)?;
        writeln!(
            out,
            "master node {MASTER_NODE}: heartbeat 0x701 every 100 ms"
        )?;
        // Only the boot-up after the reset counts.
        m.drain_events();
        m.nmt(NmtCommand::ResetNode, NODE)?;
        wait_boot_up(m)?;
        writeln!(
            out,
            "node {NODE}: booted (0x{:03X} [00])",
            0x700 + u16::from(NODE.get())
        )?;

        let consume = ConsumerHeartbeatTimeValue::from_raw(0)
            .with_node_id(MASTER_NODE)
            .with_heartbeat_time(CONSUMER_TIME_MS);
        m.write::<ConsumerHeartbeatTime<1>>(NODE, consume)?;
        writeln!(
            out,
            "node {NODE}: consumes the heartbeat of node {MASTER_NODE}, {CONSUMER_TIME_MS} ms (0x1016 sub 1)"
        )?;
        m.nmt(NmtCommand::Start, NODE)?;
        let first = next_feedback(m, ANSWER_TIMEOUT, "after NMT start")?;
        report(out, "operational", &first)?;

        send(m, command::PositionValue::STOP)?;
        let ready = wait_feedback(m, out, ANSWER_TIMEOUT, "error code 0 after Stop", |f| {
            f.error_code.to_raw() == 0
        })?;
        report(out, "stop", &ready)?;

        send(m, command::PositionValue::RUN_OUT)?;
        writeln!(out, "run out")?;
        let outside = wait_feedback(m, out, stroke_time, "end stop out", |f| {
            f.status_flags.end_stop_out()
        })?;
        report(out, "end stop out", &outside)?;

        send(m, command::PositionValue::RUN_IN)?;
        writeln!(out, "run in")?;
        let inside = wait_feedback(m, out, stroke_time, "end stop in", |f| {
            f.status_flags.end_stop_in() && !f.status_flags.running_in()
        })?;
        report(out, "end stop in", &inside)?;
        Ok((outside, inside))
    })?;
    Ok(Summary {
        out_end_mm: position_mm(&outside),
        final_position_mm: position_mm(&inside),
        status: inside.status_flags.to_raw(),
        error_code: inside.error_code.to_raw(),
        trace,
    })
}

/// Waits for the actuator's boot-up message.
fn wait_boot_up(m: &mut Master) -> Result<()> {
    let deadline = std::time::Instant::now() + ANSWER_TIMEOUT;
    m.run_until(deadline, |e| match e {
        MasterEvent::Nmt(NmtEvent::BootUp(n)) if *n == NODE => ControlFlow::Break(()),
        _ => ControlFlow::Continue(()),
    })
    .map_err(|e| {
        wait_error(
            e,
            &format!(
                "node {NODE}: no boot-up message within {ANSWER_TIMEOUT:?} after NMT reset node"
            ),
        )
    })
}

/// Sends RPDO1 with `position` and every other field at its default
/// (0xFB), as the manual's trace does.
fn send(m: &mut Master, position: command::PositionValue) -> Result<()> {
    let command = Rpdo1Command {
        position,
        current_limit: command::CurrentLimitValue::DEFAULT,
        speed: command::SpeedValue::DEFAULT,
        soft_start: command::SoftStartValue::DEFAULT,
        soft_stop: command::SoftStopValue::DEFAULT,
        reserved_6: 0,
        reserved_7: 0,
    };
    m.send_pdo(NODE, &command)
        .map_err(|e| ScenarioError(format!("node {NODE}: RPDO1 {command:?}: {e}")))?;
    Ok(())
}

/// The next TPDO1 of the actuator; an EMCY from it meanwhile is an error.
fn next_feedback(m: &mut Master, timeout: Duration, what: &str) -> Result<Tpdo1Feedback> {
    let feedback = m
        .next_pdo::<Tpdo1Feedback>(NODE, timeout)
        .map_err(|e| ScenarioError(format!("node {NODE}: TPDO1 {what}: {e}")))?;
    for event in m.drain_events() {
        if let MasterEvent::Emcy(EmcyEvent::Emergency { node, emcy }) = event
            && node == NODE
            && emcy.code != 0
        {
            return Err(ScenarioError(format!(
                "node {NODE}: EMCY 0x{:04X} while waiting for {what}",
                emcy.code
            ))
            .into());
        }
    }
    Ok(feedback)
}

/// TPDO1s until `done` holds, printing those on the way.
fn wait_feedback(
    m: &mut Master,
    out: &mut dyn Write,
    timeout: Duration,
    what: &str,
    done: impl Fn(&Tpdo1Feedback) -> bool,
) -> Result<Tpdo1Feedback> {
    let end = std::time::Instant::now() + timeout;
    loop {
        let left = end.saturating_duration_since(std::time::Instant::now());
        let f = next_feedback(m, left, what)?;
        if done(&f) {
            return Ok(f);
        }
        let s = f.status_flags;
        if s.running_out() || s.running_in() {
            report(
                out,
                if s.running_out() {
                    "running out"
                } else {
                    "running in"
                },
                &f,
            )?;
        }
    }
}

fn wait_error(e: blocking::Error, what: &str) -> Box<dyn Error> {
    match e {
        blocking::Error::DeadlinePassed => Box::new(ScenarioError(what.to_string())),
        e => Box::new(e),
    }
}

fn position_mm(f: &Tpdo1Feedback) -> f64 {
    f.position.number().map_or(f64::NAN, |n| n.value())
}

/// One line: position in mm, current, speed, flags, error.
fn report(out: &mut dyn Write, label: &str, f: &Tpdo1Feedback) -> Result<()> {
    let current = match f.current.kind() {
        feedback::CurrentKind::Number(n) => format!("{:.2} A", n.value()),
        other => other.name().to_string(),
    };
    let speed = f
        .speed
        .number()
        .map_or_else(|| "?".into(), |n| format!("{:.1} mm/s", n.value()));
    let s = f.status_flags;
    let flags: Vec<&str> = [
        (s.end_stop_in(), "end stop in"),
        (s.end_stop_out(), "end stop out"),
        (s.overcurrent(), "overcurrent"),
        (s.running_out(), "running out"),
        (s.running_in(), "running in"),
        (s.heartbeat_required(), "heartbeat required"),
        (s.outside_nominal_conditions(), "outside nominal conditions"),
    ]
    .into_iter()
    .filter_map(|(on, name)| on.then_some(name))
    .collect();
    let error = f.error_code.kind();
    writeln!(
        out,
        "  {label}: {:.1} mm, {current}, {speed}, [{}], error {} ({})",
        position_mm(f),
        flags.join(", "),
        f.error_code.to_raw(),
        error.name(),
    )?;
    Ok(())
}

/// The scenario on the virtual bus, and its trace decoded with the seed
/// table against what the example printed.
#[cfg(test)]
#[path = "linak_techline/tests.rs"]
mod tests;
