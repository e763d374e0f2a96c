//! The simulated CiA 402 drive: `DeviceStateMachine` behind an SDO
//! server store, a small motion model, and an optional statusword TPDO.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use eds2rust_runtime::cia402::{
    Controlword, DeviceConfig, DeviceEvent, DeviceStateMachine, Event, ModeOfOperation,
    SessionConfig, State, Step,
};
use eds2rust_runtime::od::{AccessRight, DataType, ObjectInfo};
use eds2rust_runtime::sdo::AbortCode;
use eds2rust_runtime::sdo::server::{ObjectStore, SdoServer};
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::{CanId, Frame, Instant, Service};

use super::NODE;

/// Position units per millisecond in profile position.
pub const SPEED: u64 = 2;
/// Time a velocity change or homing takes.
pub const SETTLE: Duration = Duration::from_millis(40);

pub const fn rw(index: u16, name: &'static str, data_type: DataType) -> ObjectInfo {
    ObjectInfo::new(index, 0, name, data_type, AccessRight::Rw, true)
}

/// A read-only, mappable variable of the table.
pub const fn ro(index: u16, name: &'static str, data_type: DataType) -> ObjectInfo {
    ObjectInfo::new(index, 0, name, data_type, AccessRight::Ro, true)
}

/// The full table of the simulated drive.
pub static FULL: [ObjectInfo; 8] = [
    ro(0x603F, "Error code", DataType::Unsigned16),
    rw(0x6040, "Controlword", DataType::Unsigned16),
    ro(0x6041, "Statusword", DataType::Unsigned16),
    rw(0x6060, "Modes of operation", DataType::Integer8),
    rw(0x607A, "Target position", DataType::Integer32),
    rw(0x6098, "Homing method", DataType::Integer8),
    rw(0x60FF, "Target velocity", DataType::Integer32),
    ro(0x6061, "Modes of operation display", DataType::Integer8),
];

/// A table without 0x60FF (a drive without profile velocity).
pub static NO_VELOCITY: [ObjectInfo; 5] = [
    rw(0x6040, "Controlword", DataType::Unsigned16),
    ro(0x6041, "Statusword", DataType::Unsigned16),
    rw(0x6060, "Modes of operation", DataType::Integer8),
    rw(0x607A, "Target position", DataType::Integer32),
    rw(0x6098, "Homing method", DataType::Integer8),
];

/// The simulated drive.
pub struct Sim {
    pub clock: Clock,
    pub last: Instant,
    pub device: DeviceStateMachine,
    pub position: i64,
    /// The position a pp move heads for.
    pub goal: i64,
    pub target_position: i32,
    pub target_velocity: i32,
    pub velocity_at: Option<Instant>,
    pub homing_until: Option<Instant>,
    pub homing_method: i8,
    /// The axis does not move (moves never reach their target).
    pub stuck: bool,
    pub controlwords: Vec<u16>,
    pub set_points: Vec<(i32, bool, bool)>,
    pub csp_targets: Vec<i32>,
}

impl Sim {
    /// The drive reading `clock` (the std clock, or tokio's).
    pub fn new(clock: Clock, config: DeviceConfig) -> Sim {
        let at = clock.now();
        Sim {
            clock,
            last: at,
            device: DeviceStateMachine::new(at, config),
            position: 0,
            goal: 0,
            target_position: 0,
            target_velocity: 0,
            velocity_at: None,
            homing_until: None,
            homing_method: 0,
            stuck: false,
            controlwords: Vec::new(),
            set_points: Vec::new(),
            csp_targets: Vec::new(),
        }
    }

    /// The drive's time.
    pub fn now(&self) -> Instant {
        self.clock.now()
    }

    /// After homing with `method` and a cyclic synchronous position run
    /// through `targets`: the axis homed to 0, took the targets, and is in
    /// CSP mode.
    pub fn assert_homed_then_csp(&self, method: i8, targets: [i32; 3]) {
        assert_eq!(self.homing_method, method);
        assert_eq!(self.position, 0);
        assert_eq!(self.csp_targets, targets);
        assert_eq!(
            self.device.mode(),
            ModeOfOperation::CyclicSynchronousPosition
        );
    }

    /// Runs the device and the motion model to now.
    pub fn update(&mut self) {
        let now = self.now();
        if self.device.poll_timeout().is_some_and(|at| at <= now) {
            self.device.handle_timeout(now);
        }
        while let Some(event) = self.device.poll_event() {
            match event {
                DeviceEvent::NewSetPoint {
                    immediate,
                    relative,
                } => {
                    let value = i64::from(self.target_position);
                    self.goal = if relative { self.goal + value } else { value };
                    self.set_points
                        .push((self.target_position, relative, immediate));
                }
                DeviceEvent::HomingStarted => self.homing_until = Some(now + SETTLE),
                // Transitions and events of later versions need no motion.
                _ => {}
            }
        }
        let ms = now.saturating_duration_since(self.last).as_millis() as u64;
        let step = i64::try_from(ms * SPEED).unwrap_or(i64::MAX);
        self.last = now;
        let enabled = self.device.state() == State::OperationEnabled;
        match self.device.mode() {
            ModeOfOperation::ProfilePosition if enabled && !self.stuck => {
                let delta = (self.goal - self.position).clamp(-step, step);
                self.position += delta;
                self.device.set_target_reached(self.position == self.goal);
            }
            ModeOfOperation::ProfileVelocity => {
                let reached = self.velocity_at.is_some_and(|at| at <= now);
                self.device.set_target_reached(reached);
                self.device
                    .set_speed_zero(reached && self.target_velocity == 0);
            }
            ModeOfOperation::Homing
                if self.device.homing_active() && self.homing_until.is_some_and(|at| at <= now) =>
            {
                self.position = 0;
                self.goal = 0;
                self.device.homing_done(true);
            }
            _ => {}
        }
    }

    pub fn statusword(&mut self) -> u16 {
        self.update();
        self.device.statusword().0
    }
}

/// The SDO server's store: the drive's objects.
pub struct DriveStore(pub Arc<Mutex<Sim>>);

fn value<const N: usize>(data: &[u8]) -> Result<[u8; N], AbortCode> {
    data.try_into().map_err(|_| AbortCode::LengthMismatch)
}

impl ObjectStore for DriveStore {
    fn read(&mut self, index: u16, sub: u8, out: &mut Vec<u8>) -> Result<(), AbortCode> {
        let mut sim = self.0.lock().unwrap();
        if sub != 0 {
            return Err(AbortCode::SubindexDoesNotExist);
        }
        match index {
            0x6041 => out.extend(sim.statusword().to_le_bytes()),
            0x603F => out.extend(sim.device.fault_code().unwrap_or(0).to_le_bytes()),
            0x6061 => out.push(sim.device.mode().as_i8() as u8),
            0x6040 => out.extend(sim.device.controlword().0.to_le_bytes()),
            _ => return Err(AbortCode::ObjectDoesNotExist),
        }
        Ok(())
    }

    fn check_write(&mut self, index: u16, sub: u8, _: Option<usize>) -> Result<(), AbortCode> {
        match (index, sub) {
            (0x6040 | 0x6060 | 0x607A | 0x6098 | 0x60FF, 0) => Ok(()),
            (0x6041 | 0x603F | 0x6061, 0) => Err(AbortCode::WriteReadOnly),
            _ => Err(AbortCode::ObjectDoesNotExist),
        }
    }

    fn write(&mut self, index: u16, _: u8, data: &[u8]) -> Result<(), AbortCode> {
        let mut sim = self.0.lock().unwrap();
        sim.update();
        let now = sim.now();
        match index {
            0x6040 => {
                let cw = u16::from_le_bytes(value(data)?);
                sim.controlwords.push(cw);
                sim.device.apply_controlword(now, Controlword(cw));
            }
            0x6060 => {
                let [mode] = value(data)?;
                sim.device.set_mode(ModeOfOperation::from_i8(mode as i8));
            }
            0x607A => {
                let target = i32::from_le_bytes(value(data)?);
                sim.target_position = target;
                sim.csp_targets.push(target);
            }
            0x6098 => sim.homing_method = i8::from_le_bytes(value(data)?),
            0x60FF => {
                sim.target_velocity = i32::from_le_bytes(value(data)?);
                sim.velocity_at = Some(now + SETTLE);
                sim.device.set_target_reached(false);
            }
            _ => return Err(AbortCode::ObjectDoesNotExist),
        }
        sim.update();
        Ok(())
    }
}

/// The device node: SDO server, and a statusword TPDO when `tpdo` is set.
pub struct DeviceNode {
    pub sdo: SdoServer<DriveStore>,
    pub sim: Arc<Mutex<Sim>>,
    pub tpdo: Option<(Duration, Instant)>,
    pub out: Option<Frame>,
}

impl Service for DeviceNode {
    type Event = ();
    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        self.sdo.handle_frame(now, frame);
    }
    fn handle_timeout(&mut self, now: Instant) {
        if self.sdo.poll_timeout().is_some_and(|at| at <= now) {
            self.sdo.handle_timeout(now);
        }
        if let Some((period, at)) = self.tpdo
            && at <= now
        {
            let sw = self.sim.lock().unwrap().statusword();
            let id = 0x180 + u16::from(NODE);
            self.out = Frame::new(CanId::Standard(id), &sw.to_le_bytes()).ok();
            self.tpdo = Some((period, now + period));
        }
    }
    fn poll_transmit(&mut self) -> Option<Frame> {
        self.sdo.poll_transmit().or_else(|| self.out.take())
    }
    fn poll_event(&mut self) -> Option<()> {
        while self.sdo.poll_event().is_some() {}
        None
    }
    fn poll_timeout(&self) -> Option<Instant> {
        eds2rust_runtime::time::earliest(self.sdo.poll_timeout(), self.tpdo.map(|(_, at)| at))
    }
}

/// The states the drive's events went through.
pub fn states(events: &[(Instant, Event)]) -> Vec<State> {
    events
        .iter()
        .filter_map(|(_, e)| match e {
            Event::StateChanged { to: Some(to), .. } => Some(*to),
            _ => None,
        })
        .collect()
}

/// The helper's defaults with short fault-reset and target timeouts.
pub fn fast_config() -> SessionConfig {
    let mut config = SessionConfig::default();
    config.drive = config
        .drive
        .with_timeout(Step::FaultReset, Duration::from_millis(60))
        .with_timeout(Step::TargetReached, Duration::from_secs(3));
    config
}
