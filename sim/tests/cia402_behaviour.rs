//! The generic CiA 402 behaviour (`eds2rust_sim::cia402`) on hand-written
//! tables, driven by the runtime's master-side `cia402::Drive` in virtual
//! time: writes by SDO download, the statusword by SDO upload every 5 ms.
//! Expected values and times are computed from CiA 402 and the profile
//! (a trapezoid: distance d at velocity v with acceleration a takes
//! d/v + v/a when it reaches v).

use std::time::Duration;

use eds2rust_runtime::Instant;
use eds2rust_runtime::cia402::{
    Drive, DriveConfig, Event, ModeOfOperation, Move, State, Statusword,
};
use eds2rust_runtime::master::Master;
use eds2rust_runtime::od::AccessRight::{Ro, Rw, Rww};
use eds2rust_runtime::od::DataType::{
    Integer8, Integer16, Integer32, Unsigned8, Unsigned16, Unsigned32,
};
use eds2rust_runtime::od::{DefaultValue, NodeId, Number, ObjectInfo as O};
use eds2rust_runtime::sdo::SdoError;
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_sim::bench::Bench;
use eds2rust_sim::cia402::{self, Cia402};
use eds2rust_sim::{DeviceConfig, SimEvent};

const fn int(v: i128) -> DefaultValue {
    DefaultValue::Number(Number::Int(v))
}

/// A drive with the usual CiA 402 objects; profile velocity and ramps at
/// 0 (the fallbacks apply until the test writes them); software limits
/// ±100000; following error window 1000 for 50 ms.
static FULL: &[O] = &[
    O::new(0x1000, 0, "Device type", Unsigned32, Ro, false).with_default(int(0x0002_0192)),
    O::new(0x1001, 0, "Error register", Unsigned8, Ro, true),
    O::new(0x1018, 0, "Identity", Unsigned8, Ro, false).with_default(int(1)),
    O::new(0x1018, 1, "Vendor-ID", Unsigned32, Ro, false).with_default(int(0x1234)),
    O::new(0x603F, 0, "Error code", Unsigned16, Ro, true),
    O::new(0x6040, 0, "Controlword", Unsigned16, Rww, true),
    O::new(0x6041, 0, "Statusword", Unsigned16, Ro, true),
    O::new(0x605A, 0, "Quick stop option code", Integer16, Rw, false).with_default(int(2)),
    O::new(0x605D, 0, "Halt option code", Integer16, Rw, false).with_default(int(1)),
    O::new(0x6060, 0, "Modes of operation", Integer8, Rw, true).with_default(int(1)),
    O::new(0x6061, 0, "Modes of operation display", Integer8, Ro, true),
    O::new(0x6062, 0, "Position demand value", Integer32, Ro, true),
    O::new(0x6064, 0, "Position actual value", Integer32, Ro, true),
    O::new(0x6065, 0, "Following error window", Unsigned32, Rw, false).with_default(int(1000)),
    O::new(0x6066, 0, "Following error time out", Unsigned16, Rw, false).with_default(int(50)),
    O::new(0x6067, 0, "Position window", Unsigned32, Rw, false).with_default(int(0)),
    O::new(0x606C, 0, "Velocity actual value", Integer32, Ro, true),
    O::new(0x607A, 0, "Target position", Integer32, Rww, true),
    O::new(0x607C, 0, "Home offset", Integer32, Rw, false),
    O::new(0x607D, 0, "Software position limit", Unsigned8, Ro, false).with_default(int(2)),
    O::new(0x607D, 1, "Min position limit", Integer32, Rw, false).with_default(int(-100_000)),
    O::new(0x607D, 2, "Max position limit", Integer32, Rw, false).with_default(int(100_000)),
    O::new(0x6081, 0, "Profile velocity", Unsigned32, Rw, true),
    O::new(0x6083, 0, "Profile acceleration", Unsigned32, Rw, true),
    O::new(0x6084, 0, "Profile deceleration", Unsigned32, Rw, true),
    O::new(0x6085, 0, "Quick stop deceleration", Unsigned32, Rw, false),
    O::new(0x6098, 0, "Homing method", Integer8, Rw, false),
    O::new(
        0x60F4,
        0,
        "Following error actual value",
        Integer32,
        Ro,
        true,
    ),
    O::new(0x60FF, 0, "Target velocity", Integer32, Rww, true),
];

/// Only what every drive has, and a mode object without a target.
static MINIMAL: &[O] = &[
    O::new(0x1000, 0, "Device type", Unsigned32, Ro, false).with_default(int(402)),
    O::new(0x6040, 0, "Controlword", Unsigned16, Rww, true),
    O::new(0x6041, 0, "Statusword", Unsigned16, Ro, true),
    O::new(0x6060, 0, "Modes of operation", Integer8, Rw, true),
];

/// [`MINIMAL`] with a target position and 0x6502 declaring profile
/// position, velocity and interpolated position (0x43).
static DECLARES_IP: &[O] = &[
    O::new(0x1000, 0, "Device type", Unsigned32, Ro, false).with_default(int(402)),
    O::new(0x6040, 0, "Controlword", Unsigned16, Rww, true),
    O::new(0x6041, 0, "Statusword", Unsigned16, Ro, true),
    O::new(0x6060, 0, "Modes of operation", Integer8, Rw, true),
    O::new(0x6061, 0, "Modes of operation display", Integer8, Ro, true),
    O::new(0x6064, 0, "Position actual value", Integer32, Ro, true),
    O::new(0x607A, 0, "Target position", Integer32, Rww, true),
    O::new(0x6502, 0, "Supported drive modes", Unsigned32, Ro, false).with_default(int(0x43)),
];

fn node() -> NodeId {
    NodeId::new(7).expect("node id")
}

/// The bench and the master-side helper.
struct Rig {
    bench: Bench<Cia402>,
    drive: Drive,
    events: Vec<(Instant, Event)>,
}

impl Rig {
    fn new(objects: &'static [O]) -> Rig {
        let device = cia402::simulator(
            objects,
            DeviceConfig::node(node()),
            Cia402::new(),
            Instant::ZERO,
        );
        let master = Master::new(NodeId::new(1).expect("master"), None);
        let mut rig = Rig {
            bench: Bench::new(master, device, Instant::ZERO),
            drive: Drive::new(DriveConfig::default()),
            events: Vec::new(),
        };
        rig.pump();
        rig
    }

    fn upload_int(&mut self, index: u16) -> i64 {
        let data = self.bench.upload(node(), index, 0).expect("upload");
        let mut raw = [0u8; 8];
        raw[..data.len()].copy_from_slice(&data);
        let v = i64::from_le_bytes(raw);
        let shift = 64 - 8 * data.len() as u32;
        (v << shift) >> shift
    }

    fn statusword(&mut self) -> Statusword {
        Statusword(self.upload_int(0x6041) as u16)
    }

    /// The helper's writes by SDO, then one statusword into the helper.
    fn pump(&mut self) {
        while let Some(w) = self.drive.poll_write() {
            self.bench
                .download(node(), w.index, w.sub, &w.value.to_le_bytes())
                .unwrap_or_else(|e| panic!("writing {:#06X}: {e}", w.index));
        }
        let sw = self.statusword();
        let now = self.bench.now();
        self.drive.update_statusword(now, sw);
        if self.drive.poll_timeout().is_some_and(|t| t <= now) {
            self.drive.handle_timeout(now);
        }
        while let Some(e) = self.drive.poll_event() {
            self.events.push((now, e));
        }
    }

    /// Runs until the helper reports what `done` accepts; returns when.
    fn wait(&mut self, limit: Duration, done: impl Fn(&Event) -> bool) -> Instant {
        let end = self.bench.now() + limit;
        let mut seen = self.events.len();
        loop {
            self.pump();
            if let Some((at, _)) = self.events[seen..].iter().find(|(_, e)| done(e)) {
                return *at;
            }
            if let Some((_, e)) = self.events[seen..]
                .iter()
                .find(|(_, e)| matches!(e, Event::Timeout { .. } | Event::Failed { .. }))
            {
                panic!("the helper gave up: {e:?}; events {:?}", self.events);
            }
            seen = self.events.len();
            assert!(
                self.bench.now() < end,
                "timed out; events {:?}",
                self.events
            );
            self.bench.run_for(Duration::from_millis(5));
        }
    }

    fn enable(&mut self) {
        let now = self.bench.now();
        self.drive.enable(now);
        self.wait(Duration::from_secs(2), |e| matches!(e, Event::Enabled));
    }

    fn pp(&mut self, velocity: u32, acceleration: u32) {
        self.drive
            .set_mode(ModeOfOperation::ProfilePosition)
            .expect("mode");
        self.drive.set_profile(velocity, acceleration, acceleration);
        self.pump();
    }

    /// A move; returns how long it took from the command to target reached.
    fn move_to(&mut self, target: i32, options: Move) -> Duration {
        let start = self.bench.now();
        self.drive.move_to(start, target, options).expect("move");
        let at = self.wait(Duration::from_secs(60), |e| {
            matches!(e, Event::TargetReached)
        });
        at.saturating_duration_since(start)
    }

    fn model_events(&mut self) -> Vec<cia402::Cia402Event> {
        self.bench
            .device_events
            .drain(..)
            .filter_map(|e| match e {
                SimEvent::Model(m) => Some(m),
                _ => None,
            })
            .collect()
    }
}

fn assert_about(actual: Duration, expected_s: f64, what: &str) {
    let diff = (actual.as_secs_f64() - expected_s).abs();
    assert!(
        diff < 0.03,
        "{what}: took {actual:?}, expected {expected_s} s"
    );
}

#[test]
fn enables_and_moves_absolute_in_the_time_of_the_trapezoid() {
    let mut rig = Rig::new(FULL);
    rig.enable();
    let states: Vec<_> = rig
        .events
        .iter()
        .filter_map(|(_, e)| match e {
            Event::StateChanged { to, .. } => *to,
            _ => None,
        })
        .collect();
    assert_eq!(
        states,
        [
            State::SwitchOnDisabled,
            State::ReadyToSwitchOn,
            State::SwitchedOn,
            State::OperationEnabled
        ]
    );
    assert_eq!(rig.upload_int(0x6061), 1, "mode display");
    rig.pp(10_000, 100_000);
    // 50000 at 10000/s with 100000/s² both ways: 5 s + 0.1 s.
    let took = rig.move_to(50_000, Move::default());
    assert_about(took, 5.1, "absolute move");
    assert_eq!(rig.upload_int(0x6064), 50_000);
    assert_eq!(rig.upload_int(0x6062), 50_000);
    assert_eq!(rig.upload_int(0x60F4), 0);
    assert!(rig.statusword().target_reached());
    // Short move, no cruise: d = v²/a → t = 2·sqrt(d/a) = 0.2 s for 1000.
    let took = rig.move_to(49_000, Move::default());
    assert_about(took, 0.2, "short move");
    assert_eq!(rig.upload_int(0x6064), 49_000);
}

#[test]
fn relative_moves_add_to_the_preceding_target() {
    let mut rig = Rig::new(FULL);
    rig.enable();
    rig.pp(20_000, 200_000);
    rig.move_to(10_000, Move::default());
    let relative = Move {
        relative: true,
        immediate: false,
    };
    let took = rig.move_to(5_000, relative);
    // 5000 at 20000/s, 200000/s²: 0.25 s + 0.1 s.
    assert_about(took, 0.35, "relative move");
    assert_eq!(rig.upload_int(0x6064), 15_000);
    rig.move_to(-20_000, relative);
    assert_eq!(rig.upload_int(0x6064), -5_000);
}

#[test]
fn change_set_immediately_replaces_the_running_move_and_halt_stops() {
    let mut rig = Rig::new(FULL);
    rig.enable();
    rig.pp(10_000, 100_000);
    let now = rig.bench.now();
    rig.drive
        .move_to(now, 90_000, Move::default())
        .expect("move");
    rig.wait(Duration::from_secs(1), |e| {
        matches!(e, Event::SetPointAcknowledged)
    });
    rig.bench.run_for(Duration::from_millis(500));
    rig.drive.halt();
    rig.pump();
    rig.bench.run_for(Duration::from_millis(300));
    let halted_at = rig.upload_int(0x6064);
    rig.bench.run_for(Duration::from_millis(100));
    assert_eq!(rig.upload_int(0x6064), halted_at, "halt stands still");
    assert!(halted_at > 3_000 && halted_at < 7_000, "{halted_at}");
    rig.drive.resume();
    rig.pump();
    let now = rig.bench.now();
    rig.drive.cancel_motion();
    rig.drive
        .move_to(
            now,
            20_000,
            Move {
                relative: false,
                immediate: true,
            },
        )
        .expect("move");
    rig.wait(Duration::from_secs(30), |e| {
        matches!(e, Event::TargetReached)
    });
    assert_eq!(rig.upload_int(0x6064), 20_000);
}

#[test]
fn profile_velocity_ramps_to_the_target_velocity_and_back_to_zero() {
    let mut rig = Rig::new(FULL);
    rig.enable();
    rig.drive
        .set_mode(ModeOfOperation::ProfileVelocity)
        .expect("mode");
    rig.drive.set_profile(0, 10_000, 20_000);
    rig.drive.set_velocity(2_000).expect("velocity");
    rig.pump();
    assert_eq!(rig.upload_int(0x6061), 3);
    rig.bench.run_for(Duration::from_millis(100));
    let v = rig.upload_int(0x606C);
    assert!((900..=1_100).contains(&v), "ramping: {v}");
    rig.bench.run_for(Duration::from_millis(400));
    assert_eq!(rig.upload_int(0x606C), 2_000);
    let sw = rig.statusword();
    assert!(sw.target_reached() && !sw.speed_zero(), "{sw:?}");
    // Ramp 0.2 s (200 units), then 0.3 s at 2000/s.
    let p = rig.upload_int(0x6064);
    assert!((p - 800).abs() <= 20, "{p}");
    rig.drive.set_velocity(0).expect("velocity");
    rig.pump();
    // 2000/s down with 20000/s²: 0.1 s.
    rig.bench.run_for(Duration::from_millis(110));
    assert_eq!(rig.upload_int(0x606C), 0);
    assert!(rig.statusword().speed_zero());
}

#[test]
fn homing_ends_at_the_home_offset() {
    let mut rig = Rig::new(FULL);
    rig.bench
        .download(node(), 0x607C, 0, &1_234i32.to_le_bytes())
        .expect("home offset");
    rig.enable();
    rig.pp(10_000, 100_000);
    rig.move_to(5_000, Move::default());
    let start = rig.bench.now();
    rig.drive.home(start, Some(1)).expect("home");
    let at = rig.wait(Duration::from_secs(5), |e| {
        matches!(e, Event::HomingAttained)
    });
    // Back to the switch at 0: 5000 at 10000/s: 0.5 s + 0.1 s.
    assert_about(at.saturating_duration_since(start), 0.6, "homing");
    assert_eq!(rig.upload_int(0x6064), 1_234);
    assert_eq!(rig.upload_int(0x6061), 6);
    let sw = rig.statusword();
    assert!(sw.homing_attained() && sw.target_reached(), "{sw:?}");
    // Homing on the current position (37) homes at once.
    rig.pp(10_000, 100_000);
    rig.move_to(3_000, Move::default());
    rig.bench
        .download(node(), 0x607C, 0, &0i32.to_le_bytes())
        .expect("home offset");
    let now = rig.bench.now();
    rig.drive.home(now, Some(37)).expect("home");
    rig.wait(Duration::from_millis(100), |e| {
        matches!(e, Event::HomingAttained)
    });
    assert_eq!(rig.upload_int(0x6064), 0);
}

#[test]
fn quick_stop_brakes_with_0x6085_then_disables() {
    let mut rig = Rig::new(FULL);
    rig.bench
        .download(node(), 0x6085, 0, &50_000u32.to_le_bytes())
        .expect("quick stop deceleration");
    rig.enable();
    rig.drive
        .set_mode(ModeOfOperation::ProfileVelocity)
        .expect("mode");
    rig.drive.set_profile(0, 100_000, 100_000);
    rig.drive.set_velocity(10_000).expect("velocity");
    rig.pump();
    rig.bench.run_for(Duration::from_millis(500));
    let before = rig.upload_int(0x6064);
    let now = rig.bench.now();
    rig.drive.quick_stop(now);
    rig.wait(Duration::from_secs(1), |e| matches!(e, Event::QuickStopped));
    assert_eq!(rig.drive.state(), Some(State::QuickStopActive));
    // 10000/s down with 50000/s²: 0.2 s, v²/2a = 1000 units.
    rig.bench.run_for(Duration::from_millis(250));
    assert_eq!(rig.statusword().state(), Some(State::SwitchOnDisabled));
    let travel = rig.upload_int(0x6064) - before;
    assert!((travel - 1_000).abs() <= 60, "braking distance {travel}");
}

#[test]
fn quick_stop_option_6_stays_in_quick_stop_active() {
    let mut rig = Rig::new(FULL);
    rig.bench
        .download(node(), 0x605A, 0, &6i16.to_le_bytes())
        .expect("option code");
    assert_eq!(
        rig.bench.download(node(), 0x605A, 0, &9i16.to_le_bytes()),
        Err(SdoError::RemoteAbort(AbortCode::InvalidValue))
    );
    rig.enable();
    let now = rig.bench.now();
    rig.drive.quick_stop(now);
    rig.wait(Duration::from_secs(1), |e| matches!(e, Event::QuickStopped));
    rig.bench.run_for(Duration::from_millis(200));
    assert_eq!(rig.statusword().state(), Some(State::QuickStopActive));
}

#[test]
fn targets_beyond_the_software_limits_are_clamped_with_bit_11() {
    let mut rig = Rig::new(FULL);
    rig.enable();
    rig.pp(100_000, 1_000_000);
    rig.move_to(250_000, Move::default());
    assert_eq!(rig.upload_int(0x6064), 100_000);
    assert!(rig.statusword().internal_limit_active());
    let events = rig.model_events();
    assert!(
        events.contains(&cia402::Cia402Event::TargetLimited {
            requested: 250_000,
            limited: 100_000
        }),
        "{events:?}"
    );
    rig.move_to(-50_000, Move::default());
    assert_eq!(rig.upload_int(0x6064), -50_000);
    assert!(!rig.statusword().internal_limit_active());
}

#[test]
fn a_lagging_axis_raises_the_following_error_bit() {
    let mut rig = Rig::new(FULL);
    rig.enable();
    rig.pp(10_000, 100_000);
    let now = rig.bench.now();
    rig.bench
        .device
        .with_model(now, |model, _| model.set_lag(Some(2_000.0)));
    rig.drive
        .move_to(now, 50_000, Move::default())
        .expect("move");
    let at = rig.wait(Duration::from_secs(2), |e| {
        matches!(e, Event::FollowingError)
    });
    // Error > 1000 after ~0.14 s (demand ahead by 8000·t - ...), + 50 ms.
    let after = at.saturating_duration_since(now).as_secs_f64();
    assert!(after > 0.1 && after < 0.4, "{after}");
    assert!(rig.statusword().following_error());
    assert!(rig.upload_int(0x60F4) > 1_000);
}

#[test]
fn faults_are_reset_by_enable() {
    let mut rig = Rig::new(FULL);
    rig.enable();
    let now = rig.bench.now();
    rig.bench
        .device
        .with_model(now, |model, ctx| model.inject_fault(ctx, 0x5530));
    rig.pump();
    assert_eq!(rig.drive.state(), Some(State::Fault));
    assert_eq!(rig.upload_int(0x603F), 0x5530);
    assert_eq!(rig.upload_int(0x1001), 1);
    rig.enable();
    assert_eq!(rig.upload_int(0x603F), 0);
    assert!(
        rig.bench
            .trace_lines()
            .iter()
            .any(|l| l == "087#3055010000000000")
    );
}

#[test]
fn a_minimal_table_enables_and_refuses_modes_it_cannot_run() {
    let mut rig = Rig::new(MINIMAL);
    rig.enable();
    assert_eq!(rig.statusword().state(), Some(State::OperationEnabled));
    // No 0x607A: profile position is refused, homing is not.
    assert_eq!(
        rig.bench.download(node(), 0x6060, 0, &[1]),
        Err(SdoError::RemoteAbort(AbortCode::InvalidValue))
    );
    assert_eq!(
        rig.bench.download(node(), 0x6060, 0, &[2]),
        Err(SdoError::RemoteAbort(AbortCode::InvalidValue))
    );
    rig.bench.download(node(), 0x6060, 0, &[6]).expect("homing");
    let now = rig.bench.now();
    rig.drive.home(now, None).expect("home");
    // No 0x6098 to write: the helper writes only 0x6060 and the controlword.
    rig.wait(Duration::from_secs(1), |e| {
        matches!(e, Event::HomingAttained)
    });
    assert!(!cia402::supports_mode(
        rig.bench.device.table(),
        ModeOfOperation::ProfileVelocity
    ));
}

#[test]
fn a_mode_the_drive_declares_but_does_not_run_is_taken_and_holds() {
    let mut rig = Rig::new(DECLARES_IP);
    rig.enable();
    // Interpolated position (7): declared by 0x6502 bit 6, not run.
    rig.bench
        .download(node(), 0x6060, 0, &[7])
        .expect("ip mode");
    rig.bench.run_for(Duration::from_millis(50));
    assert_eq!(rig.upload_int(0x6061), 7, "mode display");
    rig.bench
        .download(node(), 0x607A, 0, &5000i32.to_le_bytes())
        .expect("target");
    rig.bench.run_for(Duration::from_millis(200));
    assert_eq!(rig.upload_int(0x6064), 0, "the axis holds");
    assert_eq!(rig.statusword().state(), Some(State::OperationEnabled));
    // Cyclic synchronous velocity (9): not declared, refused.
    assert_eq!(
        rig.bench.download(node(), 0x6060, 0, &[9]),
        Err(SdoError::RemoteAbort(AbortCode::InvalidValue))
    );
    let table = rig.bench.device.table();
    assert!(cia402::declares_mode(
        table,
        ModeOfOperation::InterpolatedPosition
    ));
    // Profile position is run, not merely declared.
    assert!(!cia402::declares_mode(
        table,
        ModeOfOperation::ProfilePosition
    ));
    assert!(cia402::supports_mode(
        table,
        ModeOfOperation::ProfilePosition
    ));
}
