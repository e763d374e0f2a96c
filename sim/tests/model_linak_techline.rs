//! The LINAK TECHLINE model against the runtime's master in virtual time.
//! Expected frames are written by hand from the manual (CANopen
//! Montageanleitung): the start-up trace of p. 28 (node 32, master node 1),
//! the command values of p. 30-31, the feedback layout and status bits of
//! p. 32-33, the error codes of p. 47-49, the EMCY codes of p. 52, the
//! stop reasons of p. 46; SDO, NMT and EMCY framing from CiA 301.

use std::time::Duration;

use eds2rust_drivers::linak_techline::errors::LinakErrors;
use eds2rust_runtime::master::Master;
use eds2rust_runtime::nmt::{NmtCommand, NmtState, NmtTarget};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::SdoError;
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_runtime::{CanId, Frame, Instant};
use eds2rust_sim::SimEvent;
use eds2rust_sim::bench::Bench;
use eds2rust_sim::models::linak_techline::{
    Direction, LinakTechline, LinakTechlineEvent, MANUAL_TRACE, NODE, Refusal, StopReason,
    default_config, simulator_with,
};

type B = Bench<LinakTechline>;

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).expect("frame")
}

/// Master node 1 with the manual's heartbeat (0x701, every 100 ms, state
/// Operational = 0x05) and the actuator at power-on.
fn bench_with(model: LinakTechline) -> B {
    let mut master = Master::new(NodeId::new(1).expect("node 1"), Some(ms(100)));
    master.heartbeat.set_state(NmtState::Operational);
    let device = simulator_with(model, default_config(), Instant::ZERO);
    Bench::new(master, device, Instant::ZERO)
}

/// Time scale 10: a full stroke of 50.3 mm takes about 1 s.
fn fast() -> LinakTechline {
    LinakTechline::new().with_time_scale(10.0)
}

/// A booted actuator after the manual's start-up ([`start_up`]).
fn started(model: LinakTechline) -> B {
    let mut b = bench_with(model);
    b.run_for(ms(150));
    start_up(&mut b, ms(50));
    b
}

/// The manual's start-up up to the Stop command: 0x1016 sub 1 = 0x000100C8,
/// NMT start, Stop (p. 28), with `pause` after NMT start and after Stop.
fn start_up(b: &mut B, pause: Duration) {
    b.download(NODE, 0x1016, 1, &[0xC8, 0x00, 0x01, 0x00])
        .expect("0x1016");
    nmt(b, NmtCommand::Start);
    b.run_for(pause);
    command(b, 0xFB03);
    b.run_for(pause);
}

fn nmt(b: &mut B, cmd: NmtCommand) {
    b.master
        .nmt
        .send(cmd, NmtTarget::Node(NODE))
        .expect("nmt queue");
    b.run_for(ms(1));
}

/// RPDO1 of node 32 (0x220) from the master.
fn rpdo(b: &mut B, data: [u8; 8]) {
    b.inject(&frame(0x220, &data));
}

/// RPDO1 with the position command `position` (0xFB00 clear error, 0xFB01
/// run out, 0xFB02 run in, 0xFB03 stop, ...) and every other field at its
/// default 0xFB.
fn command(b: &mut B, position: u16) {
    let [lo, hi] = position.to_le_bytes();
    rpdo(b, [lo, hi, 0xFB, 0xFB, 0xFB, 0xFB, 0x00, 0x00]);
}

/// Jams the spindle (`true`) or frees it.
fn jam(b: &mut B, jammed: bool) {
    let now = b.now();
    b.device.with_model(now, |m, _| m.set_jammed(jammed));
}

/// The trace from `from` on, without the master's heartbeats.
fn lines_since(b: &B, from: usize) -> Vec<String> {
    b.trace_lines()
        .into_iter()
        .skip(from)
        .filter(|l| !l.starts_with("701#"))
        .collect()
}

/// The TPDO1 frames from `from` on.
fn tpdos_since(b: &B, from: usize) -> Vec<String> {
    lines_since(b, from)
        .into_iter()
        .filter(|l| l.starts_with("1A0#"))
        .collect()
}

/// `frame` was on the bus since trace line `mark`.
fn assert_sent_since(b: &B, mark: usize, frame: &str) {
    let lines = lines_since(b, mark);
    assert!(lines.iter().any(|l| l == frame), "{frame} not in {lines:?}");
}

/// The last TPDO1 on the bus.
fn last_tpdo(b: &B) -> Option<String> {
    tpdos_since(b, 0).pop()
}

fn read(b: &mut B, index: u16, sub: u8) -> Vec<u8> {
    b.upload(NODE, index, sub)
        .unwrap_or_else(|e| panic!("read {index:#06X}/{sub}: {e:?}"))
}

fn model_events(b: &mut B) -> Vec<LinakTechlineEvent> {
    b.device_events
        .drain(..)
        .filter_map(|e| match e {
            SimEvent::Model(m) => Some(m),
            _ => None,
        })
        .collect()
}

fn abort(code: AbortCode) -> Result<(), SdoError> {
    Err(SdoError::RemoteAbort(code))
}

#[test]
fn start_up_follows_the_manuals_trace() {
    let mut b = bench_with(LinakTechline::new());
    b.run_for(ms(150));
    // Master heartbeat 0x701 [05] every 100 ms, boot-up 0x720 [00].
    assert_eq!(b.trace_lines(), ["701#00", "720#00", "701#05"]);
    assert_eq!(b.trace[2].0, Instant::from_millis(100));
    let mark = b.trace.len();
    start_up(&mut b, ms(20));
    // Exactly the manual's frames, in its order: SDO write and answer, NMT
    // start, TPDO1 "stop required" (error 1), Stop, end stop in, no error.
    // No TPDO2 (the trace shows none).
    assert_eq!(lines_since(&b, mark), MANUAL_TRACE[2..8]);
    // Standing still, TPDO1 repeats on its event timer (0x1800 sub 5, 250 ms).
    let mark = b.trace.len();
    b.run_for(ms(1000));
    assert_eq!(tpdos_since(&b, mark), vec!["1A0#00000081000000C0"; 4]);
}

#[test]
fn runs_out_to_the_end_stop_and_back() {
    let mut b = started(fast());
    let mark = b.trace.len();
    command(&mut b, 0xFB01);
    b.run_for(ms(1500));
    let out = tpdos_since(&b, mark);
    // Running out: current 0x06 (1.5 A), status 0x88, speed 0x0032 (5.0
    // mm/s) at full speed; then the end stop at 50.3 mm as in the trace.
    assert!(out.iter().any(|l| &l[8..16] == "06880032"), "{out:?}");
    assert_eq!(out.last().map(String::as_str), Some("1A0#F7010082000000C0"));
    assert_eq!(b.device.behaviour().position_mm(), 50.3);
    let mark = b.trace.len();
    command(&mut b, 0xFB02);
    b.run_for(ms(1500));
    let back = tpdos_since(&b, mark);
    assert!(back.iter().any(|l| &l[8..16] == "06900032"), "{back:?}");
    assert_eq!(
        back.last().map(String::as_str),
        Some("1A0#00000081000000C0")
    );
    // Counters (p. 42): one start and one end stop each way.
    assert_eq!(read(&mut b, 0x4000, 0x21), [1, 0, 0, 0]);
    assert_eq!(read(&mut b, 0x4000, 0x22), [1, 0, 0, 0]);
    assert_eq!(read(&mut b, 0x4000, 0x23), [1, 0, 0, 0]);
    assert_eq!(read(&mut b, 0x4000, 0x24), [1, 0, 0, 0]);
    let events = model_events(&mut b);
    assert!(events.contains(&LinakTechlineEvent::MotionStopped {
        position_mm: 50.3,
        reason: StopReason::EndStop(Direction::Out),
    }));
}

#[test]
fn moving_feedback_comes_once_per_event_timer() {
    // Real time: 50.3 mm at 5 mm/s take about 10 s.
    let mut b = started(LinakTechline::new());
    let mark = b.trace.len();
    command(&mut b, 0xFB01);
    b.run_for(ms(2000));
    let times: Vec<u64> = b.trace[mark..]
        .iter()
        .filter(|(_, f)| f.to_string().starts_with("1A0#"))
        .map(|(t, _)| t.as_micros() / 1000)
        .collect();
    // The start (status change), then about every 250 ms (the first
    // interval may be one step shorter).
    assert!((8..=10).contains(&times.len()), "{times:?}");
    for pair in times.windows(2).skip(1) {
        let gap = pair[1] - pair[0];
        assert!((230..=250).contains(&gap), "{times:?}");
    }
}

#[test]
fn runs_to_a_position_and_stops_on_an_invalid_value() {
    let mut b = started(fast());
    // 20.0 mm = 200 = 0x00C8: standing there, no end stop, status 0x80.
    rpdo(&mut b, [0xC8, 0x00, 0xFB, 0xFB, 0xFB, 0xFB, 0x00, 0x00]);
    b.run_for(ms(1000));
    assert_eq!(last_tpdo(&b).as_deref(), Some("1A0#C8000080000000C0"));
    // Run out, then 0xFB06 (invalid): the actuator ramps down and stays.
    command(&mut b, 0xFB01);
    b.run_for(ms(200));
    command(&mut b, 0xFB06);
    b.run_for(ms(500));
    let stopped = b.device.behaviour().position_mm();
    assert!(stopped > 20.0 && stopped < 50.0, "{stopped}");
    assert_eq!(b.device.behaviour().running(), None);
    // A speed of 0xFC is invalid: run out does not move.
    let here = b.device.behaviour().position_mm();
    rpdo(&mut b, [0x01, 0xFB, 0xFB, 0xFC, 0xFB, 0xFB, 0x00, 0x00]);
    b.run_for(ms(300));
    assert_eq!(b.device.behaviour().position_mm(), here);
}

#[test]
fn no_command_without_the_masters_heartbeat() {
    let mut b = bench_with(fast());
    b.run_for(ms(150));
    // 0x1016 sub 1 at its default 0xC8 names no producer: status bit 5
    // "heartbeat required" (0xA1 with end stop in and bit 7); commands are
    // refused.
    assert_eq!(read(&mut b, 0x2001, 3), [0xA1]);
    assert_eq!(read(&mut b, 0x2001, 4), [0x01]);
    assert_eq!(
        b.download(NODE, 0x2000, 1, &[0x03, 0xFB]),
        abort(AbortCode::CannotTransferDeviceState)
    );
    b.download(NODE, 0x1016, 1, &[0xC8, 0x00, 0x01, 0x00])
        .expect("0x1016");
    assert_eq!(read(&mut b, 0x2001, 3), [0x81]);
    // Stop by SDO (p. 29 writes the command by SDO too) ends the lock.
    b.download(NODE, 0x2000, 1, &[0x03, 0xFB]).expect("stop");
    b.run_for(ms(20));
    assert_eq!(read(&mut b, 0x2001, 4), [0x00]);
    // Motion only in Operational.
    assert_eq!(
        b.download(NODE, 0x2000, 1, &[0x01, 0xFB]),
        abort(AbortCode::CannotTransferDeviceState)
    );
}

#[test]
fn power_up_lock_refuses_runs_until_stop() {
    let mut b = bench_with(fast());
    b.run_for(ms(150));
    b.download(NODE, 0x1016, 1, &[0xC8, 0x00, 0x01, 0x00])
        .expect("0x1016");
    nmt(&mut b, NmtCommand::Start);
    model_events(&mut b);
    command(&mut b, 0xFB01);
    b.run_for(ms(300));
    assert_eq!(b.device.behaviour().position_mm(), 0.0);
    assert!(
        model_events(&mut b).contains(&LinakTechlineEvent::CommandRefused {
            command: 0xFB01,
            reason: Refusal::Error(LinakErrors::PowerUpLock),
        })
    );
    // Clear error (0xFB00) releases it as well as Stop does.
    command(&mut b, 0xFB00);
    b.run_for(ms(20));
    assert_eq!(last_tpdo(&b).as_deref(), Some("1A0#00000081000000C0"));
    // Leaving and entering Operational arms the lock again (p. 27).
    nmt(&mut b, NmtCommand::EnterPreOperational);
    let mark = b.trace.len();
    nmt(&mut b, NmtCommand::Start);
    assert_eq!(tpdos_since(&b, mark), ["1A0#00000081010000C0"]);
}

#[test]
fn heartbeat_loss_stops_sets_error_5_and_sends_emcy_0x8130() {
    let mut b = started(LinakTechline::new());
    command(&mut b, 0xFB01);
    b.run_for(ms(500));
    assert_eq!(b.device.behaviour().running(), Some(Direction::Out));
    let now = b.now();
    b.master.heartbeat.set_period(now, None);
    let mark = b.trace.len();
    b.run_for(ms(400));
    let lines = lines_since(&b, mark);
    // EMCY of node 32 (0x80 + 0x20): code 0x8130, error register 0x11
    // (generic + communication), then TPDO1 with bit 5 and error 5.
    let emcy = lines
        .iter()
        .position(|l| l == "0A0#3081110000000000")
        .expect("EMCY");
    let tpdo = lines.get(emcy + 1).expect("TPDO after the EMCY");
    assert_eq!(&tpdo[8..14], "00A005", "{tpdo}"); // current 0, status 0xA0, error 5
    assert_eq!(b.device.behaviour().running(), None);
    assert_eq!(read(&mut b, 0x1001, 0), [0x11]);
    // Without the heartbeat no command is taken.
    assert_eq!(
        b.download(NODE, 0x2000, 1, &[0x00, 0xFB]),
        abort(AbortCode::CannotTransferDeviceState)
    );
    // Heartbeat back: bit 5 clears, error 5 stays until Clear error.
    let now = b.now();
    b.master.heartbeat.set_period(now, Some(ms(100)));
    b.run_for(ms(150));
    assert_eq!(read(&mut b, 0x2001, 3), [0x80]);
    assert_eq!(read(&mut b, 0x2001, 4), [0x05]);
    command(&mut b, 0xFB01);
    b.run_for(ms(100));
    assert_eq!(b.device.behaviour().running(), None);
    let mark = b.trace.len();
    command(&mut b, 0xFB00);
    b.run_for(ms(20));
    assert_sent_since(&b, mark, "0A0#0000000000000000");
    assert_eq!(read(&mut b, 0x2001, 4), [0x00]);
    assert_eq!(read(&mut b, 0x1001, 0), [0x00]);
    // Stop reason 2048 "communication interrupted" (p. 46), one
    // communication error counted.
    assert_eq!(read(&mut b, 0x4000, 0x26), [0x00, 0x08]);
    assert_eq!(read(&mut b, 0x4000, 0x20), [1, 0]);
}

#[test]
fn jammed_spindle_is_error_12_with_emcy_0xff05() {
    let mut b = started(fast());
    jam(&mut b, true);
    let mark = b.trace.len();
    command(&mut b, 0xFB01);
    b.run_for(ms(200));
    // Code 0xFF05 "position does not change", register 0x81 (generic +
    // manufacturer); feedback error 12 (0x0C), not running, end stop in.
    assert_sent_since(&b, mark, "0A0#05FF810000000000");
    assert_eq!(
        tpdos_since(&b, mark).last().map(String::as_str),
        Some("1A0#000000810C0000C0")
    );
    assert_eq!(read(&mut b, 0x4000, 0x26), [0x00, 0x02]); // reason 512
    // Run out is refused while the error is there.
    command(&mut b, 0xFB01);
    b.run_for(ms(100));
    assert!(
        model_events(&mut b).contains(&LinakTechlineEvent::CommandRefused {
            command: 0xFB01,
            reason: Refusal::Error(LinakErrors::PositionNotChanging),
        })
    );
    // Freed and cleared (p. 29): EMCY error reset, error 0, moves again.
    jam(&mut b, false);
    let mark = b.trace.len();
    command(&mut b, 0xFB00);
    b.run_for(ms(20));
    assert_sent_since(&b, mark, "0A0#0000000000000000");
    command(&mut b, 0xFB01);
    b.run_for(ms(1500));
    assert_eq!(b.device.behaviour().position_mm(), 50.3);
}

#[test]
fn obstacle_trips_the_current_limit() {
    let mut b = started(fast());
    let now = b.now();
    b.device
        .with_model(now, |m, _| m.set_obstacle_out(Some(20.0)));
    command(&mut b, 0xFB01);
    b.run_for(ms(1000));
    // Stopped at 20.0 mm (0x00C8), status 0x84 (overcurrent), error 0.
    assert_eq!(last_tpdo(&b).as_deref(), Some("1A0#C8000084000000C0"));
    assert_eq!(read(&mut b, 0x4000, 0x1C), [1]); // default limit, out
    assert_eq!(read(&mut b, 0x4000, 0x26), [0x08, 0x00]); // reason 8
    assert_eq!(read(&mut b, 0x4000, 0x10), [16]); // 4.0 A peak
    // Run in is allowed (no error code) and clears the flag.
    command(&mut b, 0xFB02);
    b.run_for(ms(1000));
    assert_eq!(last_tpdo(&b).as_deref(), Some("1A0#00000081000000C0"));
    // A user limit of 1.0 A (0x04) is below the running current: cut off at
    // once, counted as a user-limit overload (0x4000 sub 0x1E).
    rpdo(&mut b, [0x01, 0xFB, 0x04, 0xFB, 0xFB, 0xFB, 0x00, 0x00]);
    b.run_for(ms(100));
    assert_eq!(b.device.behaviour().position_mm(), 0.0);
    assert_eq!(read(&mut b, 0x4000, 0x1E), [1]);
    assert_eq!(read(&mut b, 0x2001, 3), [0x85]);
}

#[test]
fn undervoltage_is_error_4_and_clears_by_itself() {
    let mut b = started(fast());
    let mark = b.trace.len();
    let now = b.now();
    b.device
        .with_model(now, |m, ctx| m.set_undervoltage(ctx, true));
    b.run_for(ms(20));
    let lines = lines_since(&b, mark);
    // EMCY 0x3221, register 0x05 (generic + voltage); status 0xC1 (outside
    // nominal conditions), error 4.
    assert_eq!(lines[..2], ["0A0#2132050000000000", "1A0#000000C1040000C0"]);
    let now = b.now();
    b.device
        .with_model(now, |m, ctx| m.set_undervoltage(ctx, false));
    b.run_for(ms(20));
    let lines = lines_since(&b, mark);
    assert!(
        lines.ends_with(&[
            "0A0#0000000000000000".to_string(),
            "1A0#00000081000000C0".to_string()
        ]),
        "{lines:?}"
    );
}

#[test]
fn identity_and_lss_address() {
    let mut b = started(fast());
    assert_eq!(read(&mut b, 0x1018, 1), [0xAA, 0x04, 0x00, 0x00]);
    assert_eq!(read(&mut b, 0x1014, 0), [0xA0, 0x00, 0x00, 0x00]);
    assert_eq!(read(&mut b, 0x1800, 5), [0xFA, 0x00]);
    // TPDO2 (parallel feedback) is off: no parallel system.
    assert_eq!(read(&mut b, 0x1801, 1)[3] & 0x80, 0x80);
}

#[test]
fn recovery_run_moves_despite_error_12() {
    let mut b = started(fast());
    jam(&mut b, true);
    command(&mut b, 0xFB01);
    b.run_for(ms(200));
    assert_eq!(read(&mut b, 0x2001, 4), [0x0C]);
    jam(&mut b, false);
    // Recovery run out (0xFB04) is taken with error 12 present; the error
    // stays until Clear error.
    command(&mut b, 0xFB04);
    b.run_for(ms(1500));
    assert_eq!(b.device.behaviour().position_mm(), 50.3);
    assert_eq!(read(&mut b, 0x2001, 4), [0x0C]);
}

#[test]
fn speed_setting_scales_the_feedback_speed() {
    let mut b = started(LinakTechline::new());
    // Speed 0x64 = 100 × 0.5 % = 50 %: 2.5 mm/s = 0x0019 in 0.1 mm/s.
    rpdo(&mut b, [0x01, 0xFB, 0xFB, 0x64, 0xFB, 0xFB, 0x00, 0x00]);
    b.run_for(ms(1000));
    let last = last_tpdo(&b).unwrap_or_default();
    assert_eq!(&last[8..18], "0688001900", "{last}");
    // Changed during the run (p. 26): 100 % again, 5.0 mm/s.
    rpdo(&mut b, [0x01, 0xFB, 0xFB, 0xC8, 0xFB, 0xFB, 0x00, 0x00]);
    b.run_for(ms(600));
    let last = last_tpdo(&b).unwrap_or_default();
    assert_eq!(&last[8..18], "0688003200", "{last}");
}
