//! The Interroll RollerDrive EC5000 BI model on a bench in virtual time,
//! checked against the manual (chapter numbers of the "Schnittstellen-
//! beschreibung RollerDrive EC5000 BI" V1.2) and CiA 301/305/402. Expected
//! frames and values are written out by hand.

use std::time::Duration;

use eds2rust_runtime::lss::LssState;
use eds2rust_runtime::master::{Master, MasterEvent};
use eds2rust_runtime::nmt::{NmtCommand, NmtTarget};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::SdoError;
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_runtime::{CanId, Frame, Instant};
use eds2rust_sim::bench::Bench;
use eds2rust_sim::models::interroll_ec5000bi::{
    DEFAULT_SERIAL, Ec5000Bi, default_config, identity, simulator_with,
};

fn node(n: u8) -> NodeId {
    NodeId::new(n).expect("node id")
}

const N127: u8 = 127;

fn bench(scale: f64) -> Bench<Ec5000Bi> {
    let model = Ec5000Bi::new().with_time_scale(scale);
    let device = simulator_with(model, default_config(DEFAULT_SERIAL), Instant::ZERO);
    // Master heartbeat 0: only its boot-up message.
    let master = Master::new(node(1), None);
    let mut b = Bench::new(master, device, Instant::ZERO);
    b.run_for(Duration::from_millis(1));
    b
}

fn up(b: &mut Bench<Ec5000Bi>, n: u8, index: u16, sub: u8) -> Vec<u8> {
    b.upload(node(n), index, sub)
        .unwrap_or_else(|e| panic!("upload {index:#06X}/{sub}: {e:?}"))
}

fn down(b: &mut Bench<Ec5000Bi>, n: u8, index: u16, sub: u8, data: &[u8]) {
    b.download(node(n), index, sub, data)
        .unwrap_or_else(|e| panic!("download {index:#06X}/{sub}: {e:?}"));
}

fn statusword(b: &mut Bench<Ec5000Bi>, n: u8) -> u16 {
    let d = up(b, n, 0x6041, 0);
    u16::from_le_bytes([d[0], d[1]])
}

fn controlword(b: &mut Bench<Ec5000Bi>, n: u8, cw: u16) {
    down(b, n, 0x6040, 0, &cw.to_le_bytes());
}

fn i32_at(b: &mut Bench<Ec5000Bi>, n: u8, index: u16) -> i32 {
    let d = up(b, n, index, 0);
    i32::from_le_bytes([d[0], d[1], d[2], d[3]])
}

fn abort_of(r: Result<(), SdoError>) -> AbortCode {
    match r {
        Err(SdoError::RemoteAbort(code)) => code,
        other => panic!("expected an abort, got {other:?}"),
    }
}

/// Switch on disabled 0x40 + voltage enabled (bit 4) + remote (bit 9).
const SW_SWITCH_ON_DISABLED: u16 = 0x0250;
/// Ready to switch on 0x21 + bits 4, 9.
const SW_READY: u16 = 0x0231;
/// Switched on 0x23 + bits 4, 9.
const SW_SWITCHED_ON: u16 = 0x0233;
/// Operation enabled 0x27 + bits 4, 9.
const SW_ENABLED: u16 = 0x0237;
/// Fault 0x08 + bits 4, 9.
const SW_FAULT: u16 = 0x0218;
/// Quick stop active 0x07 + bits 4, 9 (bit 5 "quick stop" is 0).
const SW_QUICK_STOP: u16 = 0x0217;

fn enable(b: &mut Bench<Ec5000Bi>, n: u8) {
    controlword(b, n, 0x0006);
    assert_eq!(statusword(b, n), SW_READY);
    controlword(b, n, 0x0007);
    assert_eq!(statusword(b, n), SW_SWITCHED_ON);
    controlword(b, n, 0x000F);
    assert_eq!(statusword(b, n), SW_ENABLED);
}

fn lines(b: &Bench<Ec5000Bi>) -> Vec<String> {
    b.trace_lines()
}

fn has(b: &Bench<Ec5000Bi>, line: &str) -> bool {
    lines(b).iter().any(|l| l == line)
}

/// A drive at node 127 in real time, enabled in profile velocity mode with
/// target velocity `mm_s` (0x60FF).
fn conveying(mm_s: i32) -> Bench<Ec5000Bi> {
    let mut b = bench(1.0);
    enable(&mut b, N127);
    down(&mut b, N127, 0x60FF, 0, &mm_s.to_le_bytes());
    b
}

/// When the frames with CAN id `id` (`1FF#`) were sent.
fn sent_at(b: &Bench<Ec5000Bi>, id: &str) -> Vec<Instant> {
    b.trace
        .iter()
        .filter(|(_, f)| f.to_string().starts_with(id))
        .map(|(t, _)| *t)
        .collect()
}

#[test]
fn delivered_at_node_127_with_its_identity() {
    let mut b = bench(1.0);
    // Chapter 3: node id 127 as delivered; it boots like any node.
    assert!(has(&b, "77F#00"), "{:?}", lines(&b));
    // 1000h 0x00420192, 1018h vendor 1019 = 0x3FB, product 1, revision 0x00010001.
    assert_eq!(up(&mut b, N127, 0x1000, 0), [0x92, 0x01, 0x42, 0x00]);
    assert_eq!(up(&mut b, N127, 0x1018, 1), [0xFB, 0x03, 0x00, 0x00]);
    assert_eq!(up(&mut b, N127, 0x1018, 2), [0x01, 0x00, 0x00, 0x00]);
    assert_eq!(up(&mut b, N127, 0x1018, 3), [0x01, 0x00, 0x01, 0x00]);
    assert_eq!(up(&mut b, N127, 0x1018, 4), [0x87, 0xD6, 0x12, 0x00]);
    // 4650h sub 2: NodeID actual.
    assert_eq!(up(&mut b, N127, 0x4650, 2), [0x7F]);
    // Profile velocity mode is the default (chapter 4), displayed in 6061h.
    assert_eq!(up(&mut b, N127, 0x6061, 0), [0x03]);
    assert_eq!(statusword(&mut b, N127), SW_SWITCH_ON_DISABLED);
    // The SDO exchange itself, byte for byte (CiA 301 expedited upload).
    assert!(has(&b, "67F#4041600000000000"));
    assert!(has(&b, "5FF#4B41600050020000"));
}

fn lss_wait(b: &mut Bench<Ec5000Bi>) {
    assert!(
        b.run_until(Duration::from_secs(1), |e| matches!(e, MasterEvent::Lss(_))),
        "no LSS answer"
    );
    b.master_events.clear();
}

/// LSS (chapter 3, CiA 305): select the drive, give it node id 5, maybe
/// store, back to waiting, NMT reset communication.
fn assign_node_5(b: &mut Bench<Ec5000Bi>, store: bool) {
    let now = b.now();
    b.master
        .lss
        .switch_selective(now, identity(DEFAULT_SERIAL))
        .expect("lss idle");
    lss_wait(b);
    let now = b.now();
    b.master
        .lss
        .configure_node_id(now, node(5))
        .expect("lss idle");
    lss_wait(b);
    if store {
        let now = b.now();
        b.master.lss.store_configuration(now).expect("lss idle");
        lss_wait(b);
    }
    let now = b.now();
    b.master
        .lss
        .switch_global(now, LssState::Waiting)
        .expect("lss idle");
    lss_wait(b);
    b.master
        .nmt
        .send(NmtCommand::ResetCommunication, NmtTarget::Node(node(N127)))
        .expect("nmt queue");
    b.run_for(Duration::from_millis(20));
}

#[test]
fn lss_assigns_node_5_and_store_survives_power_cycle() {
    let mut b = bench(1.0);
    assign_node_5(&mut b, true);
    let expected = [
        "7E5#40FB030000000000", // switch selective: vendor id 0x3FB
        "7E5#4101000000000000", // product code 1
        "7E5#4201000100000000", // revision 0x00010001
        "7E5#4387D61200000000", // serial
        "7E4#4400000000000000", // selected
        "7E5#1105000000000000", // configure node id 5
        "7E4#1100000000000000", // ... success
        "7E5#1700000000000000", // store configuration
        "7E4#1700000000000000", // ... success
        "7E5#0400000000000000", // switch global: waiting
        "000#827F",             // NMT reset communication, node 127
        "705#00",               // boot-up of node 5
    ];
    let all = lines(&b);
    let start = all
        .iter()
        .position(|l| l == expected[0])
        .expect("LSS start");
    assert_eq!(&all[start..start + expected.len()], expected);
    assert_eq!(up(&mut b, 5, 0x4650, 2), [0x05]);
    assert_eq!(up(&mut b, 5, 0x1200, 1), [0x05, 0x06, 0x00, 0x00]);
    // Power off and on: the stored node id stays.
    b.trace.clear();
    let now = b.now();
    b.device.power_cycle(now);
    b.run_for(Duration::from_millis(5));
    assert_eq!(lines(&b), ["705#00"]);
    assert_eq!(statusword(&mut b, 5), SW_SWITCH_ON_DISABLED);
}

#[test]
fn without_store_the_drive_is_back_at_127_after_power_cycle() {
    let mut b = bench(1.0);
    assign_node_5(&mut b, false);
    assert!(has(&b, "705#00"));
    assert!(!has(&b, "7E5#1700000000000000"));
    b.trace.clear();
    let now = b.now();
    b.device.power_cycle(now);
    b.run_for(Duration::from_millis(5));
    assert_eq!(lines(&b), ["77F#00"]);
    assert_eq!(up(&mut b, N127, 0x4650, 2), [0x7F]);
}

#[test]
fn enable_sequence_follows_chapter_2() {
    let mut b = bench(1.0);
    enable(&mut b, N127);
    // Expedited download of 0x000F to 6040h and its confirmation.
    assert!(has(&b, "67F#2B4060000F000000"));
    assert!(has(&b, "5FF#6040600000000000"));
    // Transition 5 (disable operation), 6 (shutdown), 7 (disable voltage).
    controlword(&mut b, N127, 0x0007);
    assert_eq!(statusword(&mut b, N127), SW_SWITCHED_ON);
    controlword(&mut b, N127, 0x0006);
    assert_eq!(statusword(&mut b, N127), SW_READY);
    controlword(&mut b, N127, 0x0000);
    assert_eq!(statusword(&mut b, N127), SW_SWITCH_ON_DISABLED);
}

#[test]
fn velocity_mode_ramps_runs_and_halts() {
    let mut b = bench(1.0);
    down(&mut b, N127, 0x6083, 0, &1000u32.to_le_bytes());
    down(&mut b, N127, 0x6084, 0, &2000u32.to_le_bytes());
    enable(&mut b, N127);
    down(&mut b, N127, 0x60FF, 0, &500i32.to_le_bytes());
    // 1000 mm/s²: 250 mm/s after 250 ms (one step of 10 ms either way).
    b.run_for(Duration::from_millis(250));
    let v = i32_at(&mut b, N127, 0x606C);
    assert!((235..=265).contains(&v), "v = {v}");
    b.run_for(Duration::from_millis(500));
    assert_eq!(up(&mut b, N127, 0x606C, 0), [0xF4, 0x01, 0x00, 0x00]);
    // Bits 10 and 12 are reserved in velocity mode (chapter 4.2).
    assert_eq!(statusword(&mut b, N127), SW_ENABLED);
    let torque = i16::from_le_bytes(up(&mut b, N127, 0x6077, 0).try_into().expect("2 bytes"));
    assert!(torque > 0, "torque {torque}");
    b.run_for(Duration::from_millis(1000));
    // One start counted (2200h sub 1); the roller has turned (sub 9: one
    // turn is 157 mm, 6092h).
    assert_eq!(up(&mut b, N127, 0x2200, 1), [1, 0, 0, 0]);
    let pos = i32_at(&mut b, N127, 0x6064);
    assert!(pos > 500, "position {pos}");
    // Halt (bit 8): 500 mm/s at 2000 mm/s² is at rest after 250 ms.
    controlword(&mut b, N127, 0x010F);
    b.run_for(Duration::from_millis(300));
    assert_eq!(i32_at(&mut b, N127, 0x606C), 0);
    assert_eq!(statusword(&mut b, N127), SW_ENABLED);
    let held = i32_at(&mut b, N127, 0x6064);
    b.run_for(Duration::from_millis(500));
    assert_eq!(i32_at(&mut b, N127, 0x6064), held, "zero motion hold");
    // Halt released: it runs again.
    controlword(&mut b, N127, 0x000F);
    b.run_for(Duration::from_millis(100));
    assert!(i32_at(&mut b, N127, 0x606C) > 0);
}

#[test]
fn target_below_the_minimum_velocity_holds() {
    let mut b = conveying(10);
    b.run_for(Duration::from_millis(300));
    assert_eq!(i32_at(&mut b, N127, 0x606C), 0);
    // Above the maximum profile velocity (607Fh 2000): limited, bit 11.
    down(&mut b, N127, 0x60FF, 0, &2500i32.to_le_bytes());
    b.run_for(Duration::from_millis(100));
    assert_eq!(statusword(&mut b, N127) & 0x0800, 0x0800);
}

#[test]
fn mode_change_follows_the_matrix_of_chapter_4_1() {
    let mut b = conveying(300);
    b.run_for(Duration::from_millis(200));
    // Running (52): no change to position mode.
    let r = b.download(node(N127), 0x6060, 0, &[1]);
    assert_eq!(abort_of(r), AbortCode::CannotTransferDeviceState);
    assert!(has(&b, "5FF#8060600022000008"));
    // Mode 2 is not one of 1, 3, 6.
    let r = b.download(node(N127), 0x6060, 0, &[2]);
    assert_eq!(abort_of(r), AbortCode::InvalidValue);
    assert!(has(&b, "5FF#8060600030000906"));
    // Halted at rest (51, zero motion hold): to position mode (30).
    controlword(&mut b, N127, 0x010F);
    b.run_for(Duration::from_millis(500));
    down(&mut b, N127, 0x6060, 0, &[1]);
    assert_eq!(up(&mut b, N127, 0x6061, 0), [0x01]);
}

#[test]
fn profile_position_handshake_and_homing_37() {
    let mut b = bench(5.0);
    down(&mut b, N127, 0x6060, 0, &[1]);
    enable(&mut b, N127);
    down(&mut b, N127, 0x6081, 0, &500u32.to_le_bytes());
    down(&mut b, N127, 0x607A, 0, &1000i32.to_le_bytes());
    // New set-point (bit 4): acknowledged with bit 12.
    controlword(&mut b, N127, 0x001F);
    assert_eq!(statusword(&mut b, N127), SW_ENABLED | 0x1000);
    controlword(&mut b, N127, 0x000F);
    assert_eq!(statusword(&mut b, N127) & 0x1000, 0);
    // 1000 mm at 500 mm/s: about 2.5 s of drive time, 0.5 s here.
    b.run_for(Duration::from_millis(1500));
    assert_eq!(up(&mut b, N127, 0x6064, 0), [0xE8, 0x03, 0x00, 0x00]);
    // Target reached (bit 10).
    assert_eq!(statusword(&mut b, N127), SW_ENABLED | 0x0400);
    // Relative (bit 6) -200 mm.
    down(&mut b, N127, 0x607A, 0, &(-200i32).to_le_bytes());
    controlword(&mut b, N127, 0x005F);
    controlword(&mut b, N127, 0x004F);
    b.run_for(Duration::from_millis(1000));
    assert_eq!(i32_at(&mut b, N127, 0x6064), 800);
    // Homing: halt, mode 6 (chapter 4.3), bit 4: position 0 without motion.
    controlword(&mut b, N127, 0x014F);
    down(&mut b, N127, 0x6060, 0, &[6]);
    controlword(&mut b, N127, 0x011F);
    assert_eq!(i32_at(&mut b, N127, 0x6064), 0);
    // Homing attained (bit 12) and target reached (bit 10).
    assert_eq!(statusword(&mut b, N127), SW_ENABLED | 0x1400);
}

#[test]
fn undervoltage_is_a_fault_with_emcy_and_error_field() {
    let mut b = bench(1.0);
    enable(&mut b, N127);
    let now = b.now();
    b.device
        .with_model(now, |m, _| m.set_supply_voltage_mv(16_000));
    b.run_for(Duration::from_millis(20));
    // EMCY 0x3220, error register: generic (bit 0) + voltage (bit 2).
    assert!(has(&b, "0FF#2032050000000000"), "{:?}", lines(&b));
    assert_eq!(statusword(&mut b, N127), SW_FAULT);
    assert_eq!(up(&mut b, N127, 0x1001, 0), [0x05]);
    // Chapter 5.1: the newest entry at sub 1, code in bytes 0-1.
    assert_eq!(up(&mut b, N127, 0x1003, 0), [0x01]);
    assert_eq!(up(&mut b, N127, 0x1003, 1), [0x20, 0x32, 0x00, 0x00]);
    // Chapter 5.2: no acknowledgement while the error is present.
    controlword(&mut b, N127, 0x0080);
    assert_eq!(statusword(&mut b, N127), SW_FAULT);
    b.device
        .with_model(b.now(), |m, _| m.set_supply_voltage_mv(24_000));
    b.run_for(Duration::from_millis(20));
    controlword(&mut b, N127, 0x0000);
    controlword(&mut b, N127, 0x0080);
    assert_eq!(statusword(&mut b, N127), SW_SWITCH_ON_DISABLED);
    assert!(has(&b, "0FF#0000000000000000"));
    assert_eq!(up(&mut b, N127, 0x1001, 0), [0x00]);
    // The history stays (no entry when an error disappears).
    assert_eq!(up(&mut b, N127, 0x1003, 0), [0x01]);
}

/// 1016h sub 1: watch node 1 with 200 ms.
fn watch_master(b: &mut Bench<Ec5000Bi>) {
    down(b, N127, 0x1016, 1, &[0xC8, 0x00, 0x01, 0x00]);
    b.inject(&Frame::new(CanId::Standard(0x701), &[0x05]).expect("frame"));
}

#[test]
fn lost_heartbeat_with_option_1_is_a_fault() {
    let mut b = bench(1.0);
    down(&mut b, N127, 0x6007, 0, &[0x01, 0x00]);
    enable(&mut b, N127);
    watch_master(&mut b);
    b.run_for(Duration::from_millis(300));
    // EMCY 0x8130, register generic + communication (bit 4).
    assert!(has(&b, "0FF#3081110000000000"), "{:?}", lines(&b));
    assert_eq!(statusword(&mut b, N127), SW_FAULT);
    // The heartbeat is back: the fault can be acknowledged.
    b.inject(&Frame::new(CanId::Standard(0x701), &[0x05]).expect("frame"));
    controlword(&mut b, N127, 0x0080);
    assert_eq!(statusword(&mut b, N127), SW_SWITCH_ON_DISABLED);
}

#[test]
fn lost_heartbeat_with_option_3_quick_stops() {
    let mut b = bench(1.0);
    down(&mut b, N127, 0x6007, 0, &[0x03, 0x00]);
    enable(&mut b, N127);
    down(&mut b, N127, 0x60FF, 0, &400i32.to_le_bytes());
    watch_master(&mut b);
    b.run_for(Duration::from_millis(500));
    assert_eq!(statusword(&mut b, N127), SW_QUICK_STOP);
    assert_eq!(i32_at(&mut b, N127, 0x606C), 0);
    // 2200h sub 7: one quick stop counted.
    assert_eq!(up(&mut b, N127, 0x2200, 7), [0x01, 0x00]);
    // No EMCY: option 3 is not a fault.
    assert!(!lines(&b).iter().any(|l| l.starts_with("0FF#")));
    // Transition 16: enable operation again.
    controlword(&mut b, N127, 0x000F);
    assert_eq!(statusword(&mut b, N127), SW_ENABLED);
}

#[test]
fn high_temperature_is_a_warning_then_an_error() {
    let mut b = bench(1.0);
    // 4231h: threshold 95 °C, hysteresis 2 K.
    b.device
        .with_model(b.now(), |m, _| m.set_motor_temperature(96.0));
    b.run_for(Duration::from_millis(20));
    // Warning 0xFFA8, register generic + temperature; statusword bit 7.
    assert!(has(&b, "0FF#A8FF090000000000"), "{:?}", lines(&b));
    assert_eq!(statusword(&mut b, N127), SW_SWITCH_ON_DISABLED | 0x0080);
    b.device
        .with_model(b.now(), |m, _| m.set_motor_temperature(90.0));
    b.run_for(Duration::from_millis(20));
    assert!(has(&b, "0FF#0000000000000000"));
    assert_eq!(statusword(&mut b, N127), SW_SWITCH_ON_DISABLED);
    // Far above the threshold: error 0x4310 and Fault.
    b.device
        .with_model(b.now(), |m, _| m.set_motor_temperature(110.0));
    b.run_for(Duration::from_millis(1100));
    assert!(has(&b, "0FF#1043090000000000"), "{:?}", lines(&b));
    assert_eq!(statusword(&mut b, N127) & 0x004F, 0x0008);
    // The temperature status light (2211h sub 1) is red, the actual
    // temperature (2200h sub 6) is 110 °C.
    assert_eq!(up(&mut b, N127, 0x2211, 1), [0x02]);
    assert_eq!(up(&mut b, N127, 0x2200, 6), [110, 0]);
}

#[test]
fn tpdos_follow_chapter_8() {
    let mut b = bench(1.0);
    b.trace.clear();
    b.master
        .nmt
        .send(NmtCommand::Start, NmtTarget::Node(node(N127)))
        .expect("nmt queue");
    b.run_for(Duration::from_millis(5));
    // TPDO1: statusword, mode display, error register, 25 °C, torque 0.
    assert!(has(&b, "1FF#5002030019000000"), "{:?}", lines(&b));
    // TPDO2: statusword, position 0; TPDO3: statusword, velocity 0.
    assert!(has(&b, "2FF#500200000000"));
    assert!(has(&b, "3FF#500200000000"));
    // Event timer 2000 ms: sent again without a change.
    b.run_for(Duration::from_millis(2100));
    let tpdo1 = sent_at(&b, "1FF#");
    assert_eq!(tpdo1.len(), 2);
    assert_eq!(
        tpdo1[1].saturating_duration_since(tpdo1[0]),
        Duration::from_millis(2000)
    );
    // Inhibit time 100 ms between changes of the statusword.
    b.trace.clear();
    controlword(&mut b, N127, 0x0006);
    controlword(&mut b, N127, 0x0007);
    controlword(&mut b, N127, 0x000F);
    b.run_for(Duration::from_millis(300));
    let times = sent_at(&b, "1FF#");
    assert!(times.len() >= 2);
    for w in times.windows(2) {
        assert!(w[1].saturating_duration_since(w[0]) >= Duration::from_millis(100));
    }
    assert!(has(&b, "1FF#3702030019000000"), "{:?}", lines(&b));
}

#[test]
fn polarity_takes_only_the_listed_values() {
    let mut b = bench(1.0);
    let r = b.download(node(N127), 0x607E, 0, &[0x01]);
    assert_eq!(abort_of(r), AbortCode::InvalidValue);
    down(&mut b, N127, 0x607E, 0, &[0x40]);
    enable(&mut b, N127);
    // Velocity polarity: +300 runs the roller backwards, 606Ch reads +300.
    down(&mut b, N127, 0x60FF, 0, &300i32.to_le_bytes());
    b.run_for(Duration::from_millis(600));
    assert_eq!(i32_at(&mut b, N127, 0x606C), 300);
    let raw = b.device.behaviour().velocity_mm_s();
    assert!(raw < 0.0, "raw velocity {raw}");
}
