//! `blocking::Master::drive` over the virtual bus against a simulated CiA
//! 402 drive (node 0x20) served in a thread: the runtime's SDO server over
//! a store that wraps `DeviceStateMachine` and a small motion model, and
//! optionally a TPDO with the statusword every 5 ms. A monitor port
//! counts the frames on the bus.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::Duration;

use eds2rust_runtime::blocking::{self, Error, Master};
use eds2rust_runtime::cia402::requirements::{Operation, Problem};
use eds2rust_runtime::cia402::session::StatuswordPdo;
use eds2rust_runtime::cia402::{
    DeviceConfig, Event, ModeOfOperation, Move, OperationError, SessionConfig, State, Step,
};
use eds2rust_runtime::master;
use eds2rust_runtime::od::{DataType, NodeId, ObjectInfo};
use eds2rust_runtime::pdo::PdoCobId;
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::server::{SdoServer, ServerConfig};
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use eds2rust_runtime::{CanId, Frame};

#[path = "cia402_master/sim.rs"]
mod sim;

const NODE: u8 = 0x20;

use sim::{DeviceNode, DriveStore, FULL, NO_VELOCITY, SETTLE, Sim, fast_config, ro, rw, states};

fn node() -> NodeId {
    NodeId::new(NODE).unwrap()
}

struct Rig {
    master: Master<VirtualPort>,
    monitor: VirtualPort,
    sim: Arc<Mutex<Sim>>,
    stop: Arc<AtomicBool>,
    device: Option<thread::JoinHandle<()>>,
    _bus: VirtualBus,
}

impl Rig {
    fn new(config: DeviceConfig, tpdo: bool) -> Rig {
        let bus = VirtualBus::new();
        let clock = Clock::new();
        let sim = Arc::new(Mutex::new(Sim::new(clock.clone(), config)));
        let stop = Arc::new(AtomicBool::new(false));
        let mut port = bus.attach();
        let (shared, halt, device_clock) = (sim.clone(), stop.clone(), clock.clone());
        let device = thread::spawn(move || {
            let mut node = DeviceNode {
                sdo: SdoServer::new(
                    ServerConfig::new(Channel::default_for(node())),
                    DriveStore(shared.clone()),
                ),
                sim: shared,
                tpdo: tpdo.then(|| (Duration::from_millis(5), device_clock.now())),
                out: None,
            };
            blocking::serve(&mut port, &device_clock, &mut node, &halt, None, |()| {}).unwrap();
        });
        let core = master::Master::new(NodeId::new(1).unwrap(), None);
        let mut master = Master::with_clock(bus.attach(), core, clock);
        master.start().unwrap();
        let monitor = bus.attach();
        Rig {
            master,
            monitor,
            sim,
            stop,
            device: Some(device),
            _bus: bus,
        }
    }

    fn sim(&self) -> std::sync::MutexGuard<'_, Sim> {
        self.sim.lock().unwrap()
    }

    /// Frames seen by the monitor since the last call.
    fn frames(&self) -> usize {
        std::iter::from_fn(|| self.monitor.try_recv()).count()
    }
}

impl Drop for Rig {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.device.take() {
            let _ = t.join();
        }
    }
}

#[test]
fn enable_resets_a_fault_and_reports_each_transition() {
    let mut rig = Rig::new(DeviceConfig::default(), false);
    {
        let mut sim = rig.sim();
        let now = sim.clock.now();
        sim.device.raise_fault(now, 0x7500);
    }
    let mut drive = rig.master.drive(node(), &FULL, fast_config()).unwrap();
    drive.enable().unwrap();
    assert_eq!(drive.state(), Some(State::OperationEnabled));
    let events = drive.take_events();
    assert_eq!(
        states(&events),
        [
            State::Fault,
            State::SwitchOnDisabled,
            State::ReadyToSwitchOn,
            State::SwitchedOn,
            State::OperationEnabled
        ]
    );
    let kinds: Vec<Event> = events.iter().map(|(_, e)| *e).collect();
    assert!(kinds.contains(&Event::FaultDetected));
    assert!(kinds.contains(&Event::FaultCleared));
    assert_eq!(kinds.last(), Some(&Event::Enabled));
    drop(drive);
    assert_eq!(rig.sim().controlwords, [0x00, 0x80, 0x06, 0x07, 0x0F]);
}

#[test]
fn a_fault_that_stays_gives_its_error_code() {
    let mut rig = Rig::new(DeviceConfig::default(), false);
    {
        let mut sim = rig.sim();
        let now = sim.clock.now();
        sim.device.raise_fault(now, 0x2310);
        sim.device.set_fault_persists(true);
    }
    let mut drive = rig.master.drive(node(), &FULL, fast_config()).unwrap();
    let e = drive.enable().unwrap_err();
    assert!(
        matches!(
            e,
            Error::Cia402(OperationError::Fault {
                step: Step::FaultReset,
                state: State::Fault,
                code: Some(0x2310)
            })
        ),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        "drive in Fault with error code 0x2310 while waiting for the drive to leave Fault after a fault reset"
    );
    // Three reset attempts (bit 7 low, then high).
    drop(drive);
    assert_eq!(rig.sim().controlwords, [0, 0x80, 0, 0x80, 0, 0x80]);
}

#[test]
fn profile_position_absolute_relative_and_immediate() {
    let mut rig = Rig::new(DeviceConfig::default(), false);
    let sim = rig.sim.clone();
    let position = || sim.lock().unwrap().position;
    let mut drive = rig.master.drive(node(), &FULL, fast_config()).unwrap();
    drive.enable().unwrap();
    drive.move_to(200, Move::default()).unwrap();
    assert_eq!(position(), 200);
    let relative = Move {
        relative: true,
        immediate: false,
    };
    drive.move_to(-80, relative).unwrap();
    assert_eq!(position(), 120);
    let immediate = Move {
        relative: false,
        immediate: true,
    };
    drive.move_to(150, immediate).unwrap();
    assert_eq!(position(), 150);
    let kinds: Vec<Event> = drive.take_events().into_iter().map(|(_, e)| e).collect();
    let count = |event: Event| kinds.iter().filter(|e| **e == event).count();
    assert_eq!(count(Event::SetPointAcknowledged), 3);
    assert_eq!(count(Event::TargetReached), 3);
    assert_eq!(
        drive.session().drive().mode(),
        Some(ModeOfOperation::ProfilePosition)
    );
    drop(drive);
    let sim = rig.sim();
    assert_eq!(
        sim.set_points,
        [(200, false, false), (-80, true, false), (150, false, true)]
    );
    assert_eq!(sim.device.mode(), ModeOfOperation::ProfilePosition);
}

#[test]
fn a_move_that_never_arrives_times_out_naming_the_step() {
    let mut rig = Rig::new(DeviceConfig::default(), false);
    rig.sim().stuck = true;
    let mut config = fast_config();
    config.drive = config
        .drive
        .with_timeout(Step::TargetReached, Duration::from_millis(100));
    let mut drive = rig.master.drive(node(), &FULL, config).unwrap();
    drive.enable().unwrap();
    let e = drive.move_to(50, Move::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "timed out waiting for target reached (statusword bit 10); the drive is in Operation enabled"
    );
    // The helper is free again: the next request runs.
    drive.disable().unwrap();
}

#[test]
fn profile_velocity_waits_for_target_reached() {
    let mut rig = Rig::new(DeviceConfig::default(), false);
    let sim = rig.sim.clone();
    let mut drive = rig.master.drive(node(), &FULL, fast_config()).unwrap();
    // Before enable: refused by the state check, nothing written.
    let e = drive.set_velocity(100).unwrap_err();
    assert!(
        matches!(e, Error::Cia402(OperationError::Refused(_))),
        "{e}"
    );
    drive.enable().unwrap();
    let start = drive.master().now();
    drive.set_velocity(500).unwrap();
    assert!(drive.master().now().saturating_duration_since(start) >= SETTLE);
    {
        let sim = sim.lock().unwrap();
        assert_eq!(sim.target_velocity, 500);
        assert_eq!(sim.device.mode(), ModeOfOperation::ProfileVelocity);
    }
    drive.set_velocity(0).unwrap();
    let sw = drive.statusword().unwrap();
    assert!(sw.target_reached() && sw.speed_zero());
    assert_eq!(sim.lock().unwrap().target_velocity, 0);
}

#[test]
fn quick_stop_then_enable_then_disable() {
    let config = DeviceConfig {
        quick_stop: Some(Duration::from_millis(30)),
        ..DeviceConfig::default()
    };
    let mut rig = Rig::new(config, false);
    let mut drive = rig.master.drive(node(), &FULL, fast_config()).unwrap();
    drive.enable().unwrap();
    drive.quick_stop().unwrap();
    assert!(matches!(
        drive.state(),
        Some(State::QuickStopActive | State::SwitchOnDisabled)
    ));
    drive.enable().unwrap();
    drive.disable().unwrap();
    assert_eq!(drive.state(), Some(State::SwitchOnDisabled));
    drop(drive);
    assert_eq!(rig.sim().device.state(), State::SwitchOnDisabled);
    let cws = rig.sim().controlwords.clone();
    assert!(cws.contains(&0x02), "{cws:x?}");
    assert_eq!(cws.last(), Some(&0x00));
}

#[test]
fn homing_and_cyclic_synchronous_position() {
    let mut rig = Rig::new(DeviceConfig::default(), false);
    rig.sim().position = 77;
    let mut drive = rig.master.drive(node(), &FULL, fast_config()).unwrap();
    drive.enable().unwrap();
    drive.home(Some(35)).unwrap();
    drive
        .run_csp(Duration::from_millis(10), [10, 20, 30])
        .unwrap();
    let kinds: Vec<Event> = drive.take_events().into_iter().map(|(_, e)| e).collect();
    assert!(kinds.contains(&Event::HomingAttained));
    drop(drive);
    rig.sim().assert_homed_then_csp(35, [10, 20, 30]);
}

#[test]
fn missing_objects_are_refused_before_any_frame() {
    let mut rig = Rig::new(DeviceConfig::default(), false);
    // The device sends only answers, so the bus is quiet from here on
    // unless the master sends. Delivery on the virtual bus is immediate, so
    // what the master sent is in the monitor's queue when its call returns.
    assert_eq!(rig.frames(), 0);
    let config = SessionConfig::default()
        .with_required(&[Operation::ProfilePosition, Operation::ProfileVelocity]);
    let e = rig.master.drive(node(), &NO_VELOCITY, config).unwrap_err();
    assert_eq!(
        e.to_string(),
        "profile velocity needs 0x60FF Target velocity, which this device does not have"
    );
    let Error::Cia402(OperationError::Missing(missing)) = e else {
        panic!("{e:?}");
    };
    assert_eq!(missing.operation, Operation::ProfileVelocity);
    assert_eq!(missing.requirement.index, 0x60FF);
    assert_eq!(missing.problem, Problem::Absent);

    // Created without the requirement, the call itself refuses.
    let mut drive = rig
        .master
        .drive(node(), &NO_VELOCITY, SessionConfig::default())
        .unwrap();
    let e = drive.set_velocity(10).unwrap_err();
    assert!(matches!(e, Error::Cia402(OperationError::Missing(_))));
    assert!(drive.set_profile(1, 2, 3).is_err());
    assert_eq!(drive.session().request(), None);
    drop(drive);
    assert_eq!(rig.frames(), 0);
    // The state machine itself needs 0x6040 and 0x6041.
    let e = rig
        .master
        .drive(node(), &FULL[3..], SessionConfig::default());
    assert_eq!(
        e.unwrap_err().to_string(),
        "the CiA 402 state machine needs 0x6040 Controlword, which this device does not have"
    );
}

#[test]
fn statuswords_from_a_tpdo_without_polling() {
    let mut rig = Rig::new(DeviceConfig::default(), true);
    let can_id = CanId::Standard(0x180 + u16::from(NODE));
    rig.master
        .core_mut()
        .pdo_rx
        .watch(PdoCobId::new(can_id), 2, None)
        .unwrap();
    let config = fast_config()
        .with_poll_period(None)
        .with_statusword_pdo(StatuswordPdo { can_id, offset: 0 });
    let mut drive = rig.master.drive(node(), &FULL, config).unwrap();
    drive.enable().unwrap();
    drive.move_to(40, Move::default()).unwrap();
    drop(drive);
    // No upload of 0x6041: only downloads went to the SDO server.
    assert_eq!(rig.sim().position, 40);
    let seen: Vec<Frame> = std::iter::from_fn(|| rig.monitor.try_recv()).collect();
    let uploads = seen
        .iter()
        .filter(|f| f.standard_id() == Some(0x600 + u16::from(NODE)) && f.data()[0] == 0x40)
        .count();
    assert_eq!(uploads, 0);
    assert!(seen.iter().any(|f| f.id() == can_id));
}

#[test]
fn an_sdo_abort_names_the_object() {
    // The table claims the motion profile objects, the drive has none.
    static CLAIMS_MORE: [ObjectInfo; 5] = [
        rw(0x6040, "Controlword", DataType::Unsigned16),
        ro(0x6041, "Statusword", DataType::Unsigned16),
        rw(0x6081, "Profile velocity", DataType::Unsigned32),
        rw(0x6083, "Profile acceleration", DataType::Unsigned32),
        rw(0x6084, "Profile deceleration", DataType::Unsigned32),
    ];
    let mut rig = Rig::new(DeviceConfig::default(), false);
    let mut drive = rig
        .master
        .drive(node(), &CLAIMS_MORE, fast_config())
        .unwrap();
    let e = drive.set_profile(1, 2, 3).unwrap_err();
    assert_eq!(
        e.to_string(),
        "SDO transfer of 0x6081:0 with node 32: the SDO peer aborted the transfer: 0x06020000 (object does not exist in the object dictionary)"
    );
    assert!(matches!(
        e,
        Error::Sdo {
            index: 0x6081,
            sub: 0,
            ..
        }
    ));
    // The session is free for the next request.
    drive.enable().unwrap();
}
