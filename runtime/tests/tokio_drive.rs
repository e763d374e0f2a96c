//! `tokio::Master::drive` under tokio's paused clock, against the simulated
//! CiA 402 drive of `cia402_master.rs` (node 0x20, its time read from the
//! paused clock) served on a task: the same requests as the blocking
//! master (cyclic synchronous position at its period), a dropped request
//! cancelled with the next one running, and a missing object refused
//! before any frame.
#![cfg(feature = "tokio")]

use std::sync::{Arc, Mutex};
use std::time::Duration;

use eds2rust_runtime::cia402::{DeviceConfig, Event, ModeOfOperation, Move, State};
use eds2rust_runtime::master;
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::server::{SdoServer, ServerConfig};
use eds2rust_runtime::tokio::{self as driver, Deadline, Master};
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use tokio::task::JoinHandle;

#[path = "cia402_master/sim.rs"]
#[allow(dead_code)]
mod sim;

use sim::{DeviceNode, DriveStore, FULL, NO_VELOCITY, Sim, fast_config as config, states};

const NODE: u8 = 0x20;

fn node() -> NodeId {
    NodeId::new(NODE).unwrap()
}

/// Bus, drive task, master with its driver task, and a monitor port.
struct Rig {
    _bus: VirtualBus,
    master: Master,
    sim: Arc<Mutex<Sim>>,
    device: JoinHandle<()>,
    driver: JoinHandle<std::io::Result<()>>,
    monitor: VirtualPort,
}

impl Rig {
    fn new() -> Rig {
        let bus = VirtualBus::new();
        let monitor = bus.attach();
        let clock = driver::clock();
        let sim = Arc::new(Mutex::new(Sim::new(clock.clone(), DeviceConfig::default())));
        let shared = Arc::clone(&sim);
        let mut port = bus.attach();
        let device = tokio::spawn(async move {
            let mut node = DeviceNode {
                sdo: SdoServer::new(
                    ServerConfig::new(Channel::default_for(node())),
                    DriveStore(Arc::clone(&shared)),
                ),
                sim: shared,
                tpdo: None,
                out: None,
            };
            let pending = std::future::pending();
            let _ = driver::serve(
                &mut port,
                &clock,
                &mut node,
                pending,
                Deadline::NEVER,
                |()| {},
            )
            .await;
        });
        let core = master::Master::new(NodeId::new(1).unwrap(), None);
        let (master, run) = Master::new(bus.attach(), core);
        let driver = tokio::spawn(run.run());
        Rig {
            _bus: bus,
            master,
            sim,
            device,
            driver,
            monitor,
        }
    }

    fn position(&self) -> i64 {
        self.sim.lock().unwrap().position
    }

    /// Frames seen by the monitor since the last call.
    fn frames(&self) -> usize {
        std::iter::from_fn(|| self.monitor.try_recv()).count()
    }

    /// Frames seen by the monitor since the last call, not counting an SDO
    /// read of 0x6041 made first: the driver takes requests in order, so
    /// once the read's answer is in, every frame queued before it has gone
    /// out (no waiting for time to pass).
    async fn frames_before_a_round_trip(&self) -> usize {
        self.master.upload(node(), 0x6041, 0).await.unwrap();
        // The read's request and answer.
        self.frames() - 2
    }

    async fn stop(self) {
        drop(self.master);
        self.driver.await.unwrap().unwrap();
        self.device.abort();
    }
}

#[tokio::test(start_paused = true)]
async fn enable_with_fault_reset_moves_and_quick_stop() {
    let rig = Rig::new();
    {
        let mut sim = rig.sim.lock().unwrap();
        let now = sim.now();
        sim.device.raise_fault(now, 0x7500);
    }
    let mut drive = rig.master.drive(node(), &FULL, config()).unwrap();
    drive.enable().await.unwrap();
    assert_eq!(drive.state(), Some(State::OperationEnabled));
    assert_eq!(
        states(&drive.take_events()),
        [
            State::Fault,
            State::SwitchOnDisabled,
            State::ReadyToSwitchOn,
            State::SwitchedOn,
            State::OperationEnabled
        ]
    );

    let started = tokio::time::Instant::now();
    drive.move_to(200, Move::default()).await.unwrap();
    assert_eq!(rig.position(), 200);
    // 2 units per ms of the paused clock: about 100 ms, polled every 10.
    let took = started.elapsed();
    assert!(
        (Duration::from_millis(100)..Duration::from_millis(150)).contains(&took),
        "{took:?}"
    );
    let relative = Move {
        relative: true,
        immediate: false,
    };
    drive.move_to(-80, relative).await.unwrap();
    assert_eq!(rig.position(), 120);
    assert_eq!(
        drive.session().drive().mode(),
        Some(ModeOfOperation::ProfilePosition)
    );
    let kinds: Vec<Event> = drive.take_events().into_iter().map(|(_, e)| e).collect();
    assert_eq!(
        kinds.iter().filter(|e| **e == Event::TargetReached).count(),
        2
    );

    drive.quick_stop().await.unwrap();
    assert!(
        matches!(
            drive.state(),
            Some(State::QuickStopActive | State::SwitchOnDisabled)
        ),
        "{:?}",
        drive.state()
    );
    drop(drive);
    assert_eq!(
        rig.sim.lock().unwrap().set_points,
        [(200, false, false), (-80, true, false)]
    );
    rig.stop().await;
}

#[tokio::test(start_paused = true)]
async fn a_dropped_move_is_cancelled_and_the_next_request_runs() {
    let rig = Rig::new();
    rig.sim.lock().unwrap().stuck = true;
    let mut drive = rig.master.drive(node(), &FULL, config()).unwrap();
    drive.enable().await.unwrap();
    let gave_up = tokio::time::timeout(
        Duration::from_millis(200),
        drive.move_to(500, Move::default()),
    )
    .await;
    assert!(gave_up.is_err(), "the stuck axis arrived: {gave_up:?}");
    assert_eq!(drive.session().request(), None, "the request was cancelled");
    // The session and the SDO channel are free: the next requests run.
    drive.disable().await.unwrap();
    assert_eq!(drive.state(), Some(State::SwitchOnDisabled));
    assert_eq!(rig.sim.lock().unwrap().position, 0);
    drop(drive);
    rig.stop().await;
}

#[tokio::test(start_paused = true)]
async fn a_missing_object_is_refused_before_any_frame() {
    let rig = Rig::new();
    let mut drive = rig.master.drive(node(), &NO_VELOCITY, config()).unwrap();
    rig.frames_before_a_round_trip().await;
    let e = drive.set_velocity(100).await.unwrap_err();
    assert_eq!(
        e.to_string(),
        "profile velocity needs 0x60FF Target velocity, which this device does not have"
    );
    assert_eq!(
        rig.frames_before_a_round_trip().await,
        0,
        "frames were sent for a refused request"
    );
    drop(drive);
    rig.stop().await;
}

#[tokio::test(start_paused = true)]
async fn homing_then_cyclic_synchronous_position_every_period() {
    let rig = Rig::new();
    rig.sim.lock().unwrap().position = 77;
    let mut drive = rig.master.drive(node(), &FULL, config()).unwrap();
    drive.enable().await.unwrap();
    drive.home(Some(35)).await.unwrap();
    let started = tokio::time::Instant::now();
    drive
        .run_csp(Duration::from_millis(10), [10, 20, 30])
        .await
        .unwrap();
    // Three periods of the paused clock.
    assert_eq!(started.elapsed(), Duration::from_millis(30));
    let kinds: Vec<Event> = drive.take_events().into_iter().map(|(_, e)| e).collect();
    assert!(kinds.contains(&Event::HomingAttained));
    drop(drive);
    rig.sim
        .lock()
        .unwrap()
        .assert_homed_then_csp(35, [10, 20, 30]);
    rig.stop().await;
}
