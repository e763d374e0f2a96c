//! Zimmer ACS40/ACS60 compact axis: the manual's enable sequence, then a
//! profile-position move, printing every state transition and the position
//! while the carriage moves.
//!
//! The master (node 1) starts node 40 (11.2), so that the default TPDO1
//! (statusword + actual position, 11.2.1) comes, and drives the CiA 402
//! state machine with the runtime's `cia402::Drive`: controlword 0x06,
//! 0x07, 0x0F (15.1.1, as the manual's example 11.2.2), mode of operation
//! 1 (profile position), profile velocity/acceleration/deceleration, the
//! target, and the set-point handshake (bit 4, acknowledge bit 12, target
//! reached bit 10). Writes go by SDO; statuswords come from TPDO1, or from
//! SDO reads when no TPDO1 arrives (a device whose TPDO1 is not sent on
//! change). Positions are µm on the bus (15.5), printed in mm.
//!
//! `cargo run -p eds2rust-sim --example zimmer_acs -- [--trace]
//! [--time-scale F] [--iface can0 [--simulate]]`. The move takes about a
//! second at time scale 1.

use std::error::Error;
use std::fmt;
use std::process::ExitCode;
use std::time::{Duration, Instant as WallClock};

use eds2rust_drivers::zimmer_acs::od;
use eds2rust_drivers::zimmer_acs::pdo::Tpdo1StatusAndPosition;
use eds2rust_runtime::CanId;
use eds2rust_runtime::cia402::{
    Drive, DriveConfig, Event, ModeOfOperation, Move, State, Statusword,
};
use eds2rust_runtime::emcy::EmcyEvent;
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::nmt::NmtCommand;
use eds2rust_runtime::od::Entry;
use eds2rust_runtime::pdo::PdoEvent;
use eds2rust_sim::harness::{Args, Harness};
use eds2rust_sim::models::zimmer_acs::{self, NODE, ZimmerAcs};

#[allow(clippy::duplicate_mod, reason = "the demo includes the three examples")]
#[path = "common/mod.rs"]
mod common;

use common::Master;

/// The master's node id.
const MASTER_NODE: u8 = 1;
/// The target: 40 mm (µm on the bus).
pub const TARGET_UM: i32 = 40_000;
/// Profile velocity [mm/s].
pub const VELOCITY_MM_S: u32 = 50;
/// Profile acceleration and deceleration [mm/s²].
pub const RAMP_MM_S2: u32 = 500;
/// Without a TPDO1 for this long, the statusword is read by SDO.
const TPDO_SILENCE: Duration = Duration::from_millis(200);
/// Positions are printed at most this often while moving.
const PRINT_EVERY: Duration = Duration::from_millis(100);

/// What the run ended with.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// The last state seen.
    pub state: Option<State>,
    /// The actual position read at the end (µm).
    pub position_um: i32,
    /// Every state the statusword showed, in order.
    pub states: Vec<State>,
    /// Every frame on the bus in candump's compact form.
    pub trace: Vec<String>,
}

/// A failure of the scenario, saying what was awaited or written where.
#[derive(Debug)]
struct Failure(String);

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl Error for Failure {}

fn fail(message: String) -> Box<dyn Error> {
    Box::new(Failure(message))
}

fn main() -> ExitCode {
    common::main("zimmer_acs", run)
}

/// Runs the scenario (see the file's documentation) on the bus `args`
/// chooses, printing progress to `out`.
pub fn run(args: &Args, out: &mut dyn std::io::Write) -> Result<Summary, Box<dyn Error>> {
    let scale = args.time_scale;
    let harness = Harness::start(args, |now| {
        let model = ZimmerAcs::new().with_time_scale(scale);
        zimmer_acs::simulator_with(model, zimmer_acs::default_config(), now)
    })?;
    let me = common::node(MASTER_NODE)?;
    let core = master::Master::new(me, None);
    let ((position_um, state, states), trace) = common::run_master(harness, core, |master| {
        let mut session = Session {
            master,
            drive: Drive::new(DriveConfig::default()),
            tpdo1: Tpdo1StatusAndPosition::can_id(NODE),
            last_statusword: WallClock::now(),
            last_print: None,
            position_um: None,
            states: Vec::new(),
            out,
        };
        let position_um = session.scenario()?;
        Ok((position_um, session.drive.state(), session.states))
    })?;
    Ok(Summary {
        state,
        position_um,
        states,
        trace,
    })
}

/// The master, the CiA 402 helper and what was seen.
struct Session<'a> {
    master: &'a mut Master,
    drive: Drive,
    tpdo1: CanId,
    last_statusword: WallClock,
    last_print: Option<WallClock>,
    position_um: Option<i32>,
    states: Vec<State>,
    out: &'a mut dyn std::io::Write,
}

fn mm(um: i32) -> f64 {
    f64::from(um) / 1000.0
}

impl Session<'_> {
    fn scenario(&mut self) -> Result<i32, Box<dyn Error>> {
        self.tpdo1 = self
            .master
            .core_mut()
            .pdo_rx
            .watch_pdo::<Tpdo1StatusAndPosition>(NODE)?;
        self.master.start()?;
        // The first statusword by SDO: the node is there (booted).
        self.read_status()?;
        // 15.3: PDOs only in Operational.
        self.master.nmt(NmtCommand::Start, NODE)?;
        writeln!(self.out, "node {NODE}: NMT start")?;

        writeln!(
            self.out,
            "enable: Shutdown 0x06, Switch on 0x07, Enable operation 0x0F (15.1.1)"
        )?;
        let now = self.master.now();
        self.drive.enable(now);
        self.wait_for("Operation enabled", Duration::from_secs(5), |e| {
            matches!(e, Event::Enabled)
        })?;

        self.drive.set_mode(ModeOfOperation::ProfilePosition)?;
        self.drive
            .set_profile(VELOCITY_MM_S, RAMP_MM_S2, RAMP_MM_S2);
        self.send_writes()?;
        writeln!(
            self.out,
            "profile position: {VELOCITY_MM_S} mm/s, {RAMP_MM_S2} mm/s², target {:.3} mm",
            mm(TARGET_UM)
        )?;
        let now = self.master.now();
        self.drive.move_to(now, TARGET_UM, Move::default())?;
        self.wait_for("set-point acknowledge", Duration::from_secs(2), |e| {
            matches!(e, Event::SetPointAcknowledged)
        })?;
        writeln!(self.out, "set-point acknowledged (bit 12)")?;
        self.wait_for("target reached", Duration::from_secs(60), |e| {
            matches!(e, Event::TargetReached)
        })?;
        let position = self.read_position()?;
        writeln!(
            self.out,
            "target reached (bit 10) at {:.3} mm, state {}",
            mm(position),
            self.drive.state().map_or("unknown", State::name)
        )?;
        Ok(position)
    }

    /// Performs the helper's writes by SDO, in order.
    fn send_writes(&mut self) -> Result<(), Box<dyn Error>> {
        while let Some(w) = self.drive.poll_write() {
            self.master
                .download(NODE, w.index, w.sub, &w.value.to_le_bytes())
                .map_err(|e| {
                    fail(format!(
                        "node {NODE}: writing {:#06X} sub {} = {:?}: {e}",
                        w.index, w.sub, w.value
                    ))
                })?;
        }
        Ok(())
    }

    /// Reads the statusword and position by SDO and hands them on.
    fn read_status(&mut self) -> Result<(), Box<dyn Error>> {
        let sw = self.master.read::<od::Statusword>(NODE).map_err(|e| {
            fail(format!(
                "node {NODE}: reading the statusword {:#06X}: {e}",
                od::Statusword::INDEX
            ))
        })?;
        let position = self.read_position()?;
        self.statusword(Statusword(sw.0), position)
    }

    fn read_position(&mut self) -> Result<i32, Box<dyn Error>> {
        let p = self
            .master
            .read::<od::PositionActualValue>(NODE)
            .map_err(|e| {
                fail(format!(
                    "node {NODE}: reading the actual position {:#06X}: {e}",
                    od::PositionActualValue::INDEX
                ))
            })?;
        Ok(p.0)
    }

    /// A statusword and position from TPDO1 or SDO: state changes and
    /// (at most every [`PRINT_EVERY`]) the position are printed.
    fn statusword(&mut self, sw: Statusword, position_um: i32) -> Result<(), Box<dyn Error>> {
        self.last_statusword = WallClock::now();
        let before = self.drive.state();
        let now = self.master.now();
        self.drive.update_statusword(now, sw);
        let after = self.drive.state();
        if before != after {
            writeln!(
                self.out,
                "state: {} -> {} (statusword {:#06X})",
                before.map_or("unknown", State::name),
                after.map_or("unknown", State::name),
                sw.0
            )?;
            self.states.extend(after);
        }
        let moved = self.position_um != Some(position_um);
        let due = self.last_print.is_none_or(|t| t.elapsed() >= PRINT_EVERY);
        if moved && due {
            writeln!(
                self.out,
                "position {:8.3} mm (statusword {:#06X})",
                mm(position_um),
                sw.0
            )?;
            self.last_print = Some(WallClock::now());
        }
        self.position_um = Some(position_um);
        Ok(())
    }

    /// Runs until the helper reports what `done` accepts; a timeout, a failed operation or a fault ends it with an
    /// error naming what was awaited.
    fn wait_for(
        &mut self,
        what: &str,
        limit: Duration,
        done: impl Fn(&Event) -> bool,
    ) -> Result<(), Box<dyn Error>> {
        let deadline = WallClock::now() + limit;
        loop {
            self.send_writes()?;
            while let Some(event) = self.drive.poll_event() {
                match event {
                    Event::Timeout { step, state } | Event::Failed { step, state } => {
                        return Err(fail(format!(
                            "node {NODE}: waiting for {what}: the drive helper gave up in step \
                             {step:?} in state {}",
                            state.map_or("unknown", State::name)
                        )));
                    }
                    Event::FaultDetected => {
                        return Err(fail(format!(
                            "node {NODE}: fault while waiting for {what} (error code in {:#06X})",
                            od::ErrorCode::INDEX
                        )));
                    }
                    _ => {}
                }
                if done(&event) {
                    return self.send_writes();
                }
            }
            if WallClock::now() >= deadline {
                return Err(fail(format!(
                    "node {NODE}: no {what} within {} ms",
                    limit.as_millis()
                )));
            }
            let now = self.master.now();
            if self.drive.poll_timeout().is_some_and(|at| at <= now) {
                self.drive.handle_timeout(now);
            }
            match self
                .master
                .wait_event(self.master.now() + Duration::from_millis(10))?
            {
                Some(MasterEvent::Pdo(PdoEvent::Received {
                    can_id, data, len, ..
                })) if can_id == self.tpdo1 => {
                    let tpdo = Tpdo1StatusAndPosition::decode(data.get(..len).unwrap_or(&[]))
                        .map_err(|e| {
                            fail(format!(
                                "node {NODE}: TPDO1 {can_id} has {} bytes, not {}",
                                e.actual, e.expected
                            ))
                        })?;
                    self.statusword(Statusword(tpdo.statusword.0), tpdo.position_actual_value.0)?;
                }
                Some(MasterEvent::Emcy(EmcyEvent::Emergency { node, emcy })) => {
                    writeln!(self.out, "EMCY from node {node}: error {:#06X}", emcy.code)?
                }
                _ => {}
            }
            if self.last_statusword.elapsed() >= TPDO_SILENCE {
                self.read_status()?;
            }
        }
    }
}

/// The scenario on the virtual bus, and its trace decoded with the seed
/// table against what the example printed.
#[cfg(test)]
#[path = "zimmer_acs/tests.rs"]
mod tests;
