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
use std::time::{Duration, Instant as WallClock};

use eds2rust_drivers::zimmer_acs::od;
use eds2rust_drivers::zimmer_acs::pdo::Tpdo1StatusAndPosition;
use eds2rust_runtime::CanId;
use eds2rust_runtime::blocking;
use eds2rust_runtime::cia402::{
    Drive, DriveConfig, Event, ModeOfOperation, Move, State, Statusword,
};
use eds2rust_runtime::emcy::EmcyEvent;
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::nmt::NmtCommand;
use eds2rust_runtime::od::{Entry, NodeId};
use eds2rust_runtime::pdo::PdoEvent;
use eds2rust_sim::harness::{Args, Harness, MasterPort};
use eds2rust_sim::models::zimmer_acs::{self, NODE, ZimmerAcs};

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

fn main() {
    let args = match Args::from_env() {
        Ok(args) => args,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut out = std::io::stdout();
    if let Err(e) = run(&args, &mut out) {
        eprintln!("zimmer_acs: {e}");
        std::process::exit(1);
    }
}

/// Runs the scenario (see the file's documentation) on the bus `args`
/// chooses, printing progress to `out`.
pub fn run(args: &Args, out: &mut dyn std::io::Write) -> Result<Summary, Box<dyn Error>> {
    let scale = args.time_scale;
    let mut harness = Harness::start(args, |now| {
        let model = ZimmerAcs::new().with_time_scale(scale);
        zimmer_acs::simulator_with(model, zimmer_acs::default_config(), now)
    })?;
    let me = NodeId::new(MASTER_NODE).ok_or_else(|| fail("bad master node id".into()))?;
    let core = master::Master::new(me, None);
    let mut session = Session {
        master: blocking::Master::with_clock(harness.take_port()?, core, harness.clock()),
        drive: Drive::new(DriveConfig::default()),
        tpdo1: Tpdo1StatusAndPosition::can_id(NODE),
        last_statusword: WallClock::now(),
        last_print: None,
        position_um: None,
        states: Vec::new(),
        out,
    };
    let result = session.scenario();
    let trace = harness.stop()?;
    let position_um = result?;
    Ok(Summary {
        state: session.drive.state(),
        position_um,
        states: session.states,
        trace,
    })
}

/// The master, the CiA 402 helper and what was seen.
struct Session<'a> {
    master: blocking::Master<MasterPort>,
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

    /// `expected` appears in `trace` in this order (other frames between).
    fn assert_in_order(trace: &[String], expected: &[&str]) {
        let mut rest = trace.iter();
        for frame in expected {
            assert!(
                rest.any(|line| line == frame),
                "{frame} missing (in order) from the trace:\n{}",
                trace.join("\n")
            );
        }
    }

    #[test]
    fn enables_and_moves_to_the_target_on_the_virtual_bus() {
        let args = Args {
            time_scale: 20.0,
            ..Args::default()
        };
        let mut out = Vec::new();
        let summary = run(&args, &mut out).expect("the scenario runs");
        let text = String::from_utf8(out).expect("utf-8");
        assert_eq!(summary.state, Some(State::OperationEnabled), "{text}");
        assert_eq!(summary.position_um, TARGET_UM);
        assert_eq!(
            summary.states,
            [
                State::SwitchOnDisabled,
                State::ReadyToSwitchOn,
                State::SwitchedOn,
                State::OperationEnabled
            ]
        );
        assert!(
            text.contains("state: Switched on -> Operation enabled (statusword 0x4037)"),
            "{text}"
        );
        assert!(
            text.contains("target reached (bit 10) at 40.000 mm"),
            "{text}"
        );
        // The master's frames and the device's frames each in their order
        // (between the two, only cause and effect is ordered on the bus).
        let from = |ids: &[&str]| -> Vec<String> {
            summary
                .trace
                .iter()
                .filter(|l| ids.iter().any(|id| l.starts_with(id)))
                .cloned()
                .collect()
        };
        assert_in_order(
            &from(&["000#", "628#"]),
            &[
                "628#4041600000000000", // SDO read 0x6041
                "000#0128",             // NMT start node 40
                "628#2B40600006000000", // controlword Shutdown
                "628#2B40600007000000", // Switch on
                "628#2B4060000F000000", // Enable operation
                "628#2F60600001000000", // modes of operation: 1
                "628#2381600032000000", // profile velocity 50 mm/s
                "628#23836000F4010000", // profile acceleration 500 mm/s²
                "628#23846000F4010000", // profile deceleration 500 mm/s²
                "628#237A6000409C0000", // target 40 000 µm
                "628#2B4060001F000000", // new set-point (bit 4)
                "628#2B4060000F000000", // bit 4 back to 0 after the acknowledge
            ],
        );
        assert_in_order(
            &from(&["728#", "5A8#4B41", "1A8#"]),
            &[
                "728#00",               // boot-up of node 40
                "5A8#4B41600040000000", // statusword 0x0040
                "1A8#400000000000",     // TPDO1: Switch on disabled, 0 µm
                "1A8#210000000000",     // Ready to switch on
                "1A8#330000000000",     // Switched on, voltage enabled
                "1A8#374000000000",     // Operation enabled, angle found
                "1A8#375000000000",     // set-point acknowledge
                "1A8#374000000000",     // acknowledge cleared with bit 4
                "1A8#3744409C0000",     // target reached at 40 000 µm
            ],
        );
    }

    // The trace decoded with the seed table (eds/zimmer_acs.yaml) against
    // what the example printed.

    use eds2rust_decode::Decoder;

    use super::decoded::{self, *};
    use serde_json::Value as Json;

    /// A decoder that knows node 40 by `eds/zimmer_acs.yaml`.
    fn seed_decoder() -> Decoder {
        let device = decoded::seed("zimmer_acs");
        let mut decoder = Decoder::new();
        decoder.add_node(NODE.get(), device);
        decoder
    }

    /// `record` is an SDO transfer of node 40's entry `index` sub `sub`.
    fn is_transfer(record: &Json, index: u16, sub: u8, direction: &str) -> bool {
        record["event"] == "sdo-transfer"
            && record["node"] == NODE.get()
            && record["index"] == index
            && record["subindex"] == sub
            && record["direction"] == direction
    }

    /// A `0x...` number of the printed text.
    fn hex(text: &str) -> u16 {
        let digits = text.trim().trim_start_matches("0x");
        u16::from_str_radix(digits, 16).unwrap_or_else(|_| panic!("{text} is no hex number"))
    }

    /// A statusword and position the example handed to its state machine:
    /// from a TPDO1, or from its SDO reads of 0x6041 and then 0x6064.
    struct Seen {
        at: usize,
        statusword: u16,
        /// The decoded statusword (with its CiA 402 state).
        text: String,
        /// The position's physical value and unit.
        position: f64,
        unit: String,
    }

    fn seen(records: &[Json]) -> Vec<Seen> {
        let mut out = Vec::new();
        let mut read = None;
        for (at, r) in records.iter().enumerate() {
            if r["pdo"] == "tpdo1" && r["node"] == NODE.get() {
                let sw = field(r, "Statusword");
                let p = field(r, "Position actual value");
                out.push(Seen {
                    at,
                    statusword: sw["raw"].as_u64().expect("a statusword") as u16,
                    text: sw["text"].as_str().expect("text").to_string(),
                    position: p["value"].as_f64().expect("a position"),
                    unit: p["unit"].as_str().unwrap_or_default().to_string(),
                });
            } else if is_transfer(r, 0x6041, 0, "upload") {
                read = Some(r);
            } else if is_transfer(r, 0x6064, 0, "upload")
                && let Some(sw) = read.take()
            {
                let (position, unit) = physical(r);
                out.push(Seen {
                    at,
                    statusword: sw["value"].as_u64().expect("a statusword") as u16,
                    text: sw["text"].as_str().expect("text").to_string(),
                    position,
                    unit,
                });
            }
        }
        out
    }

    /// A position in µm as the example prints it (mm, three decimals).
    fn as_mm(value: f64, unit: &str) -> String {
        assert_eq!(unit, "µm", "positions are µm on the bus");
        format!("{:.3}", value / 1000.0)
    }

    #[test]
    fn the_trace_decodes_to_the_printed_values() {
        // Slow enough that positions are printed while the carriage moves
        // (every 100 ms of the half-second move).
        let args = Args {
            time_scale: 2.0,
            ..Args::default()
        };
        let mut out = Vec::new();
        let summary = run(&args, &mut out).expect("the scenario runs");
        let text = String::from_utf8(out).expect("utf-8");
        println!("{text}");
        let records = decode(&mut seed_decoder(), &summary.trace);
        assert_every_frame_decodes(&records);
        let seen = seen(&records);
        let seen_from = |from: usize, what: &str, accept: &dyn Fn(&Seen) -> bool| -> &Seen {
            seen.iter()
                .find(|s| s.at >= from && accept(s))
                .unwrap_or_else(|| {
                    panic!(
                        "no statusword from {from} on {what}:\n{}",
                        texts(&records, from)
                    )
                })
        };
        // Everything printed so far was seen by record `at`; the last
        // statusword and position lines matched these records.
        let mut at = 0;
        let mut last_state = None;
        let mut last_position = None;
        let mut target_at = None;
        let mut end = None;
        let (mut states, mut positions) = (0, 0);
        for line in text.lines() {
            assert!(end.is_none(), "a line after the last: {line}\n{text}");
            if let Some(rest) = line.strip_prefix("state: ") {
                // `state: A -> B (statusword 0x....)`
                let (_, rest) = rest.split_once(" -> ").expect("A -> B");
                let (state, sw) = rest.split_once(" (statusword ").expect("statusword");
                let sw = hex(sw.trim_end_matches(')'));
                let after = last_state.map_or(at, |l: usize| at.max(l + 1));
                let s = seen_from(after, line, &|s| s.statusword == sw);
                assert!(names_state(&s.text, state), "{line}: {}", s.text);
                (at, last_state) = (s.at, Some(s.at));
                states += 1;
            } else if let Some(rest) = line.strip_prefix("position ") {
                // `position    0.000 mm (statusword 0x....)`
                let (mm, sw) = rest.split_once(" mm (statusword ").expect("position");
                let (mm, sw) = (mm.trim(), hex(sw.trim_end_matches(')')));
                let after = last_position.map_or(at, |l: usize| at.max(l + 1));
                let s = seen_from(after, line, &|s| {
                    s.statusword == sw && as_mm(s.position, &s.unit) == mm
                });
                (at, last_position) = (s.at, Some(s.at));
                positions += 1;
            } else if line == format!("node {NODE}: NMT start") {
                at = find(&records, at, line, |r| {
                    r["protocol"] == "nmt" && r["command"] == "start" && r["target"] == NODE.get()
                });
            } else if let Some(rest) = line.strip_prefix("enable: ") {
                // Announced: the writes follow, each with the state change it
                // causes, so `at` stays.
                let list = rest.split(" (").next().unwrap_or(rest);
                let mut from = at;
                for step in list.split(", ") {
                    let (name, cw) = step.rsplit_once(' ').expect("NAME 0x..");
                    let i = find(&records, from, step, |r| {
                        is_transfer(r, 0x6040, 0, "download") && r["value"] == hex(cw)
                    });
                    let decoded = records[i]["text"].as_str().expect("text");
                    assert!(names_state(decoded, name), "{step}: {decoded}");
                    from = i + 1;
                }
            } else if let Some(rest) = line.strip_prefix("profile position: ") {
                // `50 mm/s, 500 mm/s², target 40.000 mm`: mode 1, then the
                // profile (written before the line), then the target
                // (written by the move after it).
                let parts: Vec<&str> = rest.split(", ").collect();
                let [velocity, ramp, target] = parts[..] else {
                    panic!("{line}")
                };
                let mode = find(&records, at, "modes of operation 1", |r| {
                    is_transfer(r, 0x6060, 0, "download") && r["value"] == 1
                });
                let decoded = records[mode]["text"].as_str().expect("text");
                assert!(decoded.ends_with("\"profile position\""), "{decoded}");
                let mut from = mode + 1;
                for (index, printed) in [(0x6081, velocity), (0x6083, ramp), (0x6084, ramp)] {
                    let (number, unit) = printed.split_once(' ').expect("N unit");
                    let number: f64 = number.parse().expect("a number");
                    let i = find(&records, from, printed, |r| {
                        is_transfer(r, index, 0, "download")
                    });
                    assert_eq!(physical(&records[i]), (number, unit.to_string()), "{line}");
                    from = i + 1;
                }
                at = from - 1;
                let mm = target
                    .strip_prefix("target ")
                    .and_then(|t| t.strip_suffix(" mm"));
                let i = find(&records, from, target, |r| {
                    is_transfer(r, 0x607A, 0, "download")
                });
                let (value, unit) = physical(&records[i]);
                assert_eq!(Some(as_mm(value, &unit).as_str()), mm, "{line}");
                target_at = Some(i);
            } else if let Some(rest) = line.strip_prefix("set-point acknowledged (bit ") {
                let bit: u32 = rest.trim_end_matches(')').parse().expect("a bit");
                let after = at.max(target_at.expect("the target was written") + 1);
                let s = seen_from(after, line, &|s| s.statusword & 1 << bit != 0);
                assert!(s.text.contains("\"setpoint ack\""), "{line}: {}", s.text);
                at = s.at;
            } else if let Some(rest) = line.strip_prefix("target reached (bit ") {
                // `10) at 40.000 mm, state Operation enabled`: the statusword
                // with bit 10, then the position read by SDO at the end.
                let (bit, rest) = rest.split_once(") at ").expect("bit");
                let (mm, state) = rest.split_once(" mm, state ").expect("position, state");
                let bit: u32 = bit.parse().expect("a bit");
                let s = seen_from(at, line, &|s| s.statusword & 1 << bit != 0);
                assert!(s.text.contains("\"target reached\""), "{line}: {}", s.text);
                assert!(names_state(&s.text, state), "{line}: {}", s.text);
                let last = records
                    .iter()
                    .rposition(|r| is_transfer(r, 0x6064, 0, "upload"))
                    .expect("the position read at the end");
                assert!(last > s.at, "{line}:\n{}", texts(&records, s.at));
                let (value, unit) = physical(&records[last]);
                assert_eq!(as_mm(value, &unit), mm, "{line}");
                assert_eq!(f64::from(summary.position_um), value);
                assert_eq!(summary.state.map(State::name), Some(state));
                end = Some(last);
            } else {
                panic!("a line this test does not know: {line}\n{text}");
            }
        }
        assert!(end.is_some(), "no final line:\n{text}");
        assert_eq!(states, summary.states.len(), "{text}");
        assert!(positions >= 1, "{text}");
    }
}
