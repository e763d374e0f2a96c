//! The Zimmer ACS model against the runtime's master in virtual time. The
//! expected frames are written by hand from the manual (DDOC02148): node 40
//! (11.2), default PDOs (11.2.1: TPDO1 = statusword + actual position,
//! RPDO1 = controlword + target), statusword patterns and controlword
//! commands (15.1), error IDs (15.4), objects (15.5), STO (16.1.3),
//! signatures (11.4.4, 11.5); and from CiA 301 (SDO, EMCY, NMT frames).

use std::time::Duration;

use eds2rust_drivers::zimmer_acs::errors::ZimmerErrors;
use eds2rust_runtime::cia402::State;
use eds2rust_runtime::master::Master;
use eds2rust_runtime::nmt::{NmtCommand, NmtTarget};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::SdoError;
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_runtime::{CanId, Frame, Instant};
use eds2rust_sim::SimEvent;
use eds2rust_sim::bench::Bench;
use eds2rust_sim::models::zimmer_acs::{
    self, NODE, ZimmerAcs, ZimmerAcsEvent, default_config, simulator_with,
};

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

fn bench_with(model: ZimmerAcs) -> Bench<ZimmerAcs> {
    let device = simulator_with(model, default_config(), Instant::ZERO);
    let master = Master::new(NodeId::new(1).expect("node 1"), None);
    let mut b = Bench::new(master, device, Instant::ZERO);
    b.run_for(ms(1));
    b
}

fn bench() -> Bench<ZimmerAcs> {
    bench_with(ZimmerAcs::new())
}

fn write(b: &mut Bench<ZimmerAcs>, index: u16, sub: u8, data: &[u8]) {
    b.download(NODE, index, sub, data)
        .unwrap_or_else(|e| panic!("write {index:#06X}/{sub}: {e:?}"));
}

fn read(b: &mut Bench<ZimmerAcs>, index: u16, sub: u8) -> Vec<u8> {
    b.upload(NODE, index, sub)
        .unwrap_or_else(|e| panic!("read {index:#06X}/{sub}: {e:?}"))
}

fn statusword(b: &mut Bench<ZimmerAcs>) -> u16 {
    let data = read(b, 0x6041, 0);
    u16::from_le_bytes([data[0], data[1]])
}

fn position(b: &mut Bench<ZimmerAcs>) -> i32 {
    let data = read(b, 0x6064, 0);
    i32::from_le_bytes(data.try_into().expect("4 bytes"))
}

fn controlword(b: &mut Bench<ZimmerAcs>, cw: u16) {
    write(b, 0x6040, 0, &cw.to_le_bytes());
}

fn start_node(b: &mut Bench<ZimmerAcs>) {
    b.master
        .nmt
        .send(NmtCommand::Start, NmtTarget::Node(NODE))
        .expect("queue");
    b.run_for(ms(1));
}

/// 15.1.1 "typical values": Shutdown 6, Switch on 7, Enable operation 15.
fn enable(b: &mut Bench<ZimmerAcs>) {
    for cw in [0x06, 0x07, 0x0F] {
        controlword(b, cw);
    }
    b.run_for(ms(20));
}

fn lines_from(b: &Bench<ZimmerAcs>, start: usize) -> Vec<String> {
    b.trace[start..]
        .iter()
        .map(|(_, f)| f.to_string())
        .collect()
}

fn model_events(b: &mut Bench<ZimmerAcs>) -> Vec<ZimmerAcsEvent> {
    b.device_events
        .drain(..)
        .filter_map(|e| match e {
            SimEvent::Model(e) => Some(e),
            _ => None,
        })
        .collect()
}

/// The state machine's transitions (CiA 402 numbers) since the last call.
fn transitions(b: &mut Bench<ZimmerAcs>) -> Vec<u8> {
    model_events(b)
        .into_iter()
        .filter_map(|e| match e {
            ZimmerAcsEvent::StateChanged { transition, .. } => Some(transition),
            _ => None,
        })
        .collect()
}

/// A new set-point: the target `target_um` (0x607A), then controlword
/// `cw` with bit 4 (and bit 5 or 6 as `cw` says).
fn set_point(b: &mut Bench<ZimmerAcs>, target_um: i32, cw: u16) {
    write(b, 0x607A, 0, &target_um.to_le_bytes());
    controlword(b, cw);
}

/// An axis at time scale `scale`, enabled, 200 ms into a move to
/// `target_um`.
fn moving(scale: f64, target_um: i32) -> Bench<ZimmerAcs> {
    let mut b = bench_with(ZimmerAcs::new().with_time_scale(scale));
    enable(&mut b);
    set_point(&mut b, target_um, 0x1F);
    b.run_for(ms(200));
    b
}

/// The STO inputs (true = 24 V).
fn set_sto(b: &mut Bench<ZimmerAcs>, sto1: bool, sto2: bool) {
    let now = b.now();
    b.device
        .with_model(now, |m, ctx| m.set_sto(ctx, sto1, sto2));
}

fn frames_with_id(b: &Bench<ZimmerAcs>, start: usize, id: &str) -> Vec<String> {
    lines_from(b, start)
        .into_iter()
        .filter(|l| l.starts_with(id))
        .collect()
}

fn abort(code: AbortCode) -> Result<(), SdoError> {
    Err(SdoError::RemoteAbort(code))
}

#[test]
fn boots_at_node_40_and_enables_with_6_7_15_over_sdo() {
    let mut b = bench();
    // The master's boot-up, then node 40's; 0x1017 has no default in the
    // manual: no heartbeat.
    assert_eq!(lines_from(&b, 0), ["701#00", "728#00"]);
    let start = b.trace.len();
    start_node(&mut b);
    // The default TPDOs go out on entering Operational (11.2.1):
    // Switch on disabled = 0x0040, position 0, velocity 0, following
    // error 0 and torque 0.
    assert_eq!(
        lines_from(&b, start),
        [
            "000#0128",
            "1A8#400000000000",
            "2A8#00000000",
            "3A8#000000000000"
        ]
    );
    let start = b.trace.len();
    enable(&mut b);
    assert_eq!(
        lines_from(&b, start),
        [
            "628#2B40600006000000", // Shutdown
            "5A8#6040600000000000",
            "1A8#210000000000",     // Ready to switch on
            "628#2B40600007000000", // Switch on
            "5A8#6040600000000000",
            "1A8#330000000000",     // Switched on, voltage enabled (bit 4)
            "628#2B4060000F000000", // Enable operation
            "5A8#6040600000000000",
            "1A8#374000000000", // Operation enabled, bit 14 (angle found)
            "1A8#374400000000", // + target reached after the window time
        ]
    );
    assert_eq!(b.device.behaviour().state(), Some(State::OperationEnabled));
    assert!(b.device.behaviour().clamp_released());
    // Mode of operation: 1 (profile position) by default (15.5).
    assert_eq!(read(&mut b, 0x6061, 0), [1]);
    assert_eq!(transitions(&mut b), [0, 1, 2, 3, 4]);
}

#[test]
fn profile_position_move_with_the_set_point_handshake() {
    let mut b = bench();
    start_node(&mut b);
    enable(&mut b);
    write(&mut b, 0x6081, 0, &50u32.to_le_bytes()); // 50 mm/s
    write(&mut b, 0x6083, 0, &500u32.to_le_bytes()); // 500 mm/s²
    write(&mut b, 0x6084, 0, &1000u32.to_le_bytes()); // 1000 mm/s²
    write(&mut b, 0x607A, 0, &40_000i32.to_le_bytes()); // 40 mm in µm
    let start = b.trace.len();
    controlword(&mut b, 0x1F); // new set-point (bit 4)
    // Set-point acknowledge (bit 12) at once, target reached cleared.
    assert_eq!(
        lines_from(&b, start),
        [
            "628#2B4060001F000000",
            "5A8#6040600000000000",
            "1A8#375000000000"
        ]
    );
    controlword(&mut b, 0x0F);
    assert_eq!(statusword(&mut b), 0x4037);
    // Trapezoid: 0.1 s ramp (2.5 mm), 0.725 s at 50 mm/s, 0.05 s braking.
    b.run_for(ms(500));
    let p = position(&mut b);
    assert!((21_000..24_000).contains(&p), "position {p}");
    assert_eq!(read(&mut b, 0x606C, 0), 50i32.to_le_bytes());
    b.run_for(ms(500));
    assert_eq!(position(&mut b), 40_000);
    assert_eq!(statusword(&mut b), 0x4437);
    // The last TPDO1: target reached at 40 000 µm = 0x00009C40.
    let tpdo = frames_with_id(&b, start, "1A8#");
    assert_eq!(tpdo.last().map(String::as_str), Some("1A8#3744409C0000"));
    let events = model_events(&mut b);
    assert!(events.contains(&ZimmerAcsEvent::MotionStarted {
        from_um: 0,
        to_um: 40_000
    }));
    assert!(events.contains(&ZimmerAcsEvent::TargetReached {
        position_um: 40_000
    }));
}

#[test]
fn relative_targets_and_targets_beyond_the_stroke() {
    let mut b = bench_with(ZimmerAcs::new().with_time_scale(10.0));
    enable(&mut b);
    set_point(&mut b, 30_000, 0x1F);
    controlword(&mut b, 0x0F);
    b.run_for(ms(200));
    assert_eq!(position(&mut b), 30_000);
    // Relative (bit 6): +25 mm from the last target.
    set_point(&mut b, 25_000, 0x5F);
    controlword(&mut b, 0x4F);
    b.run_for(ms(200));
    assert_eq!(position(&mut b), 55_000);
    assert_eq!(statusword(&mut b) & 0x0800, 0);
    // 150 mm on an ACS40 (100 mm stroke): clamped to 0x3007/2, bit 11.
    assert_eq!(read(&mut b, 0x3007, 2), 100_000i32.to_le_bytes());
    set_point(&mut b, 150_000, 0x1F);
    controlword(&mut b, 0x0F);
    b.run_for(ms(200));
    assert_eq!(position(&mut b), 100_000);
    assert_eq!(statusword(&mut b), 0x4C37);
    assert!(
        model_events(&mut b).contains(&ZimmerAcsEvent::TargetLimited {
            requested_um: 150_000,
            limited_um: 100_000
        })
    );
}

#[test]
fn a_profile_velocity_of_0_is_error_0x7391_with_emcy() {
    let mut b = bench();
    enable(&mut b);
    write(&mut b, 0x6081, 0, &0u32.to_le_bytes());
    write(&mut b, 0x607A, 0, &10_000i32.to_le_bytes());
    let start = b.trace.len();
    controlword(&mut b, 0x1F);
    b.run_for(ms(20));
    // EMCY 0x80 + 40: error ID 0x7391, error register 0 (no 0x1001).
    assert_eq!(frames_with_id(&b, start, "0A8#"), ["0A8#9173000000000000"]);
    // Fault, bit 14 still set.
    assert_eq!(statusword(&mut b), 0x4008);
    assert_eq!(read(&mut b, 0x603F, 0), [0x91, 0x73]);
    assert_eq!(read(&mut b, 0x1003, 0), [1]);
    assert_eq!(read(&mut b, 0x1003, 1), 0x7391u32.to_le_bytes());
    assert_eq!(position(&mut b), 0);
}

#[test]
fn a_blocked_axis_is_a_following_error_and_fault_reset_clears_it() {
    let mut b = bench();
    enable(&mut b);
    let now = b.now();
    b.device.with_model(now, |m, _| m.set_blocked(true));
    write(&mut b, 0x607A, 0, &50_000i32.to_le_bytes());
    let start = b.trace.len();
    controlword(&mut b, 0x1F);
    controlword(&mut b, 0x0F);
    // 100 mm/s, 1000 mm/s²: 1 mm (0x6065) after 45 ms, then 100 ms (0x6066).
    b.run_for(ms(300));
    assert_eq!(frames_with_id(&b, start, "0A8#"), ["0A8#8773000000000000"]);
    // Fault with bit 13 (following error) and bit 14.
    assert_eq!(statusword(&mut b), 0x6008);
    assert_eq!(position(&mut b), 0);
    assert!(
        model_events(&mut b).contains(&ZimmerAcsEvent::Fault(ZimmerErrors::PositionFollowingError))
    );
    // Fault reset (rising edge of bit 7, 15.1.1): transition 15, EMCY
    // 0x0000, and the device clears bit 7 again.
    let start = b.trace.len();
    controlword(&mut b, 0x80);
    assert_eq!(frames_with_id(&b, start, "0A8#"), ["0A8#0000000000000000"]);
    assert_eq!(statusword(&mut b), 0x4040);
    assert_eq!(read(&mut b, 0x6040, 0), [0, 0]);
    // 0x603F keeps the last error (15.5 "last detected error").
    assert_eq!(read(&mut b, 0x603F, 0), [0x87, 0x73]);
}

#[test]
fn sto_dropping_in_operation_enabled_is_0x3283_and_blocks_switching_on() {
    let mut b = bench();
    // Both inputs high: STO1, STO2, supply OK, report (15.5 0x251A).
    assert_eq!(read(&mut b, 0x251A, 0), [0x17, 0x00]);
    enable(&mut b);
    let start = b.trace.len();
    set_sto(&mut b, false, false);
    b.run_for(ms(1));
    assert_eq!(frames_with_id(&b, start, "0A8#"), ["0A8#8332000000000000"]);
    // Fault, no voltage (bit 4 = 0, status LED blue/red, 11.3).
    assert_eq!(statusword(&mut b), 0x4008);
    assert_eq!(read(&mut b, 0x251A, 0), [0x04, 0x00]);
    assert!(!b.device.behaviour().clamp_released());
    controlword(&mut b, 0x80);
    controlword(&mut b, 0x06);
    assert_eq!(statusword(&mut b), 0x4021);
    // Switch on while STO is active: 0x3280.
    let start = b.trace.len();
    controlword(&mut b, 0x07);
    assert_eq!(frames_with_id(&b, start, "0A8#"), ["0A8#8032000000000000"]);
    assert_eq!(statusword(&mut b), 0x4008);
    // Inputs back: reset and enable work again.
    set_sto(&mut b, true, true);
    controlword(&mut b, 0x80);
    enable(&mut b);
    assert_eq!(statusword(&mut b), 0x4437);
}

#[test]
fn differing_sto_inputs_latch_0x3282_until_power_on() {
    let mut b = bench();
    set_sto(&mut b, true, false);
    b.run_for(ms(10));
    // STO1, supply OK, abnormal fault; no report (16.1.3 irregular STO).
    assert_eq!(read(&mut b, 0x251A, 0), [0x0D, 0x00]);
    assert_eq!(statusword(&mut b), 0x0040);
    let start = b.trace.len();
    b.run_for(ms(1500));
    assert_eq!(frames_with_id(&b, start, "0A8#"), ["0A8#8232000000000000"]);
    assert_eq!(statusword(&mut b), 0x0008);
    // Latched: inputs back high, fault reset refused.
    set_sto(&mut b, true, true);
    controlword(&mut b, 0x80);
    assert_eq!(statusword(&mut b), 0x0008);
    // Report = NOR(STO1, STO2) = 0, abnormal fault stays.
    assert_eq!(read(&mut b, 0x251A, 0), [0x0F, 0x00]);
    let now = b.now();
    b.device.power_cycle(now);
    b.run_for(ms(1));
    assert_eq!(statusword(&mut b), 0x0040);
    assert_eq!(read(&mut b, 0x251A, 0), [0x17, 0x00]);
}

#[test]
fn the_clamping_element_follows_the_state_machine_unless_overridden() {
    let mut b = bench();
    assert!(!b.device.behaviour().clamp_released());
    // 11.6: values 0, 1, 2 only.
    assert_eq!(
        b.download(NODE, 0x2129, 0, &[3, 0]),
        abort(AbortCode::InvalidValue)
    );
    // Overridden and locked: the carriage cannot move, a move ends in a
    // following error.
    write(&mut b, 0x2129, 0, &[2, 0]);
    enable(&mut b);
    assert!(!b.device.behaviour().clamp_released());
    set_point(&mut b, 20_000, 0x1F);
    b.run_for(ms(300));
    // Fault, following error, angle found; the acknowledge went with
    // Operation enabled.
    assert_eq!(statusword(&mut b), 0x6008);
    assert_eq!(position(&mut b), 0);
    // Back to the state machine: released in Operation enabled only.
    write(&mut b, 0x2129, 0, &[0, 0]);
    controlword(&mut b, 0x80);
    model_events(&mut b);
    enable(&mut b);
    assert!(b.device.behaviour().clamp_released());
    controlword(&mut b, 0x07);
    assert!(!b.device.behaviour().clamp_released());
    let clamp: Vec<ZimmerAcsEvent> = model_events(&mut b)
        .into_iter()
        .filter(|e| matches!(e, ZimmerAcsEvent::Clamp { .. }))
        .collect();
    assert_eq!(
        clamp,
        [
            ZimmerAcsEvent::Clamp { released: true },
            ZimmerAcsEvent::Clamp { released: false }
        ]
    );
}

#[test]
fn store_and_restore_take_only_their_signatures() {
    let mut b = bench();
    assert_eq!(read(&mut b, 0x6081, 0), 100u32.to_le_bytes());
    write(&mut b, 0x6081, 0, &80u32.to_le_bytes());
    // Wrong signatures are refused with 0x08000020 (CiA 301).
    assert_eq!(
        b.download(NODE, 0x1010, 1, b"evas"),
        abort(AbortCode::CannotTransfer)
    );
    assert_eq!(
        b.download(NODE, 0x1011, 1, b"save"),
        abort(AbortCode::CannotTransfer)
    );
    // 11.4.4: 0x65766173 "save", on the bus 73 61 76 65.
    let start = b.trace.len();
    write(&mut b, 0x1010, 1, &0x6576_6173u32.to_le_bytes());
    assert_eq!(lines_from(&b, start)[0], "628#2310100173617665");
    write(&mut b, 0x6081, 0, &60u32.to_le_bytes());
    let now = b.now();
    b.device.power_cycle(now);
    b.run_for(ms(1));
    assert_eq!(read(&mut b, 0x6081, 0), 80u32.to_le_bytes());
    // 11.5: 0x64616F6C "load"; the defaults come at the next power-on.
    let start = b.trace.len();
    write(&mut b, 0x1011, 1, &0x6461_6F6Cu32.to_le_bytes());
    assert_eq!(lines_from(&b, start)[0], "628#231110016C6F6164");
    assert_eq!(read(&mut b, 0x6081, 0), 80u32.to_le_bytes());
    let now = b.now();
    b.device.power_cycle(now);
    b.run_for(ms(1));
    assert_eq!(read(&mut b, 0x6081, 0), 100u32.to_le_bytes());
}

#[test]
fn the_position_survives_a_power_cycle_and_the_controlword_does_not() {
    let mut b = moving(10.0, 12_345);
    write(&mut b, 0x1010, 1, b"save");
    let now = b.now();
    b.device.power_cycle(now);
    b.run_for(ms(1));
    assert_eq!(position(&mut b), 12_345);
    assert_eq!(read(&mut b, 0x6040, 0), [0, 0]);
    assert_eq!(statusword(&mut b), 0x0040);
}

#[test]
fn modes_and_option_codes_outside_the_manual_are_refused() {
    let mut b = bench();
    // 11.1.2: profile position (1) and cyclic synchronous position (8).
    assert_eq!(
        b.download(NODE, 0x6060, 0, &[3]),
        abort(AbortCode::InvalidValue)
    );
    assert_eq!(
        b.download(NODE, 0x6060, 0, &[6]),
        abort(AbortCode::InvalidValue)
    );
    write(&mut b, 0x6060, 0, &[8]);
    assert_eq!(read(&mut b, 0x6061, 0), [8]);
    write(&mut b, 0x6060, 0, &[1]);
    // 15.5 0x605A: 0, 1, 2, 5, 6.
    assert_eq!(
        b.download(NODE, 0x605A, 0, &[3, 0]),
        abort(AbortCode::InvalidValue)
    );
    write(&mut b, 0x605A, 0, &[6, 0]);
    // 15.5 0x605D: not while the power stage is enabled.
    write(&mut b, 0x605D, 0, &[2, 0]);
    enable(&mut b);
    assert_eq!(
        b.download(NODE, 0x605D, 0, &[1, 0]),
        abort(AbortCode::CannotTransferDeviceState)
    );
    // Read-only objects of 15.5.
    assert_eq!(
        b.download(NODE, 0x6041, 0, &[0, 0]),
        abort(AbortCode::WriteReadOnly)
    );
    assert_eq!(
        b.download(NODE, 0x3007, 2, &[0; 4]),
        abort(AbortCode::WriteReadOnly)
    );
}

#[test]
fn quick_stop_ramps_down_then_disables() {
    let mut b = moving(2.0, 90_000);
    let moving = position(&mut b);
    assert!(moving > 0 && moving < 90_000);
    model_events(&mut b);
    controlword(&mut b, 0x02); // Quick stop (15.1.1)
    assert_eq!(statusword(&mut b) & 0x006F, 0x0007);
    b.run_for(ms(100));
    // Option code 2: quick stop ramp (0x300A/2), then Switch on disabled.
    assert_eq!(statusword(&mut b), 0x4040);
    let stopped = position(&mut b);
    assert!(stopped >= moving && stopped < 90_000);
    assert_eq!(transitions(&mut b), [11, 12]);
}

#[test]
fn the_axis_runs_on_the_default_pdos_alone() {
    // 11.2.1: "the CiA 402 functions can be used over the PDOs alone".
    let mut b = bench_with(ZimmerAcs::new().with_time_scale(10.0));
    start_node(&mut b);
    let rpdo = |data: &[u8]| Frame::new(CanId::Standard(0x228), data).expect("frame");
    for cw in [0x06u8, 0x07, 0x0F] {
        b.inject(&rpdo(&[cw, 0, 0, 0, 0, 0]));
    }
    b.run_for(ms(20));
    // RPDO2: profile velocity 20 mm/s.
    b.inject(&Frame::new(CanId::Standard(0x328), &20u32.to_le_bytes()).expect("frame"));
    let start = b.trace.len();
    // Controlword 0x1F and target 10 mm (0x2710) in one RPDO1.
    b.inject(&rpdo(&[0x1F, 0x00, 0x10, 0x27, 0x00, 0x00]));
    b.inject(&rpdo(&[0x0F, 0x00, 0x10, 0x27, 0x00, 0x00]));
    b.run_for(ms(200));
    let tpdo = frames_with_id(&b, start, "1A8#");
    assert_eq!(tpdo.first().map(String::as_str), Some("1A8#375000000000"));
    assert_eq!(tpdo.last().map(String::as_str), Some("1A8#374410270000"));
    assert_eq!(
        model_events(&mut b)
            .into_iter()
            .filter(|e| matches!(e, ZimmerAcsEvent::SetPointAccepted { .. }))
            .collect::<Vec<_>>(),
        [ZimmerAcsEvent::SetPointAccepted {
            target_um: 10_000,
            relative: false,
            immediate: false
        }]
    );
    assert_eq!(
        zimmer_acs::BIT_RATE,
        eds2rust_runtime::lss::BitRate::Kbit500
    );
}
