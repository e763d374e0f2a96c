//! The CiA 402 master helper (`Drive`) against the device state machine
//! (`DeviceStateMachine`): writes go to the device as a CANopen node would
//! decode them (little-endian object values), statuswords come back after
//! every exchange, both clocks are driven to their deadlines.

use std::time::Duration;

use eds2rust_runtime::Instant;
use eds2rust_runtime::cia402::{
    Controlword, DeviceConfig, DeviceEvent, DeviceStateMachine, Drive, DriveConfig, Event,
    ModeOfOperation, Move, State, Step, Write,
};

/// The device's objects besides the controlword, as written.
#[derive(Debug, Default)]
struct Objects {
    target_position: Option<i32>,
    homing_method: Option<i8>,
    target_velocity: Option<i32>,
    csp_targets: Vec<i32>,
}

struct Rig {
    now: Instant,
    drive: Drive,
    device: DeviceStateMachine,
    objects: Objects,
    controlwords: Vec<u16>,
    events: Vec<Event>,
    transitions: Vec<u8>,
    device_events: Vec<DeviceEvent>,
    /// While set, the device takes no controlword (a stuck drive).
    ignore_controlwords: bool,
}

impl Rig {
    fn new(device: DeviceConfig) -> Rig {
        let now = Instant::from_millis(1);
        let mut rig = Rig {
            now,
            drive: Drive::new(DriveConfig::default()),
            device: DeviceStateMachine::new(now, device),
            objects: Objects::default(),
            controlwords: Vec::new(),
            events: Vec::new(),
            transitions: Vec::new(),
            device_events: Vec::new(),
            ignore_controlwords: false,
        };
        rig.exchange();
        rig
    }

    /// An enabled drive in `mode`, records cleared.
    fn enabled(device: DeviceConfig, mode: ModeOfOperation) -> Rig {
        let mut rig = Rig::new(device);
        rig.drive.enable(rig.now);
        rig.drive.set_mode(mode).unwrap();
        rig.exchange();
        assert_eq!(rig.device.state(), State::OperationEnabled);
        assert!(rig.take_events().contains(&Event::Enabled));
        rig.controlwords.clear();
        rig.transitions.clear();
        rig.device_events.clear();
        rig
    }

    /// The node decodes one write.
    fn apply(&mut self, write: Write) {
        let bytes = write.value.to_le_bytes();
        assert_eq!(write.sub, 0);
        let i32_value = || i32::from_le_bytes(bytes.as_slice().try_into().unwrap());
        match write.index {
            0x6040 => {
                let cw = u16::from_le_bytes(bytes.as_slice().try_into().unwrap());
                self.controlwords.push(cw);
                if !self.ignore_controlwords {
                    self.device.apply_controlword(self.now, Controlword(cw));
                }
            }
            0x6060 => {
                let [mode] = bytes.as_slice().try_into().unwrap();
                self.device.set_mode(ModeOfOperation::from_i8(mode as i8));
            }
            0x6098 => {
                let [method] = bytes.as_slice().try_into().unwrap();
                self.objects.homing_method = Some(method as i8);
            }
            0x607A => {
                let target = i32_value();
                self.objects.target_position = Some(target);
                self.objects.csp_targets.push(target);
            }
            0x60FF => self.objects.target_velocity = Some(i32_value()),
            other => panic!("unexpected write to {other:#06x}"),
        }
    }

    /// Writes to the device, statusword back, until two rounds in a row
    /// write nothing (a statusword may queue writes for the next round).
    fn exchange(&mut self) {
        let mut idle_rounds = 0;
        for _ in 0..100 {
            let mut busy = false;
            while let Some(write) = self.drive.poll_write() {
                busy = true;
                self.apply(write);
            }
            if self.device.poll_timeout().is_some_and(|t| t <= self.now) {
                self.device.handle_timeout(self.now);
            }
            self.drive
                .update_statusword(self.now, self.device.statusword());
            if self.drive.poll_timeout().is_some_and(|t| t <= self.now) {
                self.drive.handle_timeout(self.now);
                busy = true;
            }
            while let Some(event) = self.device.poll_event() {
                if let DeviceEvent::Transition { number, .. } = event {
                    self.transitions.push(number);
                } else {
                    self.device_events.push(event);
                }
            }
            self.events
                .extend(std::iter::from_fn(|| self.drive.poll_event()));
            idle_rounds = if busy { 0 } else { idle_rounds + 1 };
            if idle_rounds == 2 {
                return;
            }
        }
        panic!("the exchange does not settle");
    }

    /// Runs the clock forward by `duration`, stopping at every deadline.
    fn run_for(&mut self, duration: Duration) {
        let end = self.now + duration;
        loop {
            let next = [self.drive.poll_timeout(), self.device.poll_timeout()]
                .into_iter()
                .flatten()
                .filter(|&t| t <= end)
                .min();
            self.now = next.unwrap_or(end).max(self.now);
            self.exchange();
            if next.is_none() {
                return;
            }
        }
    }

    fn take_events(&mut self) -> Vec<Event> {
        std::mem::take(&mut self.events)
    }
}

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

#[test]
fn enable_from_switch_on_disabled_after_start_up() {
    let mut rig = Rig::new(DeviceConfig {
        start_up: ms(30),
        ..DeviceConfig::default()
    });
    assert_eq!(rig.drive.state(), Some(State::NotReadyToSwitchOn));
    rig.drive.enable(rig.now);
    rig.exchange();
    assert_eq!(rig.drive.sequence_step(), Some(Step::StartUp));
    rig.run_for(ms(100));
    assert_eq!(rig.controlwords, [0x0006, 0x0007, 0x000F]);
    assert_eq!(rig.transitions, [0, 1, 2, 3, 4]);
    assert_eq!(rig.events.last(), Some(&Event::Enabled));
    assert_eq!(rig.device.statusword().0 & 0x6F, 0x27);
    assert_eq!(rig.drive.poll_timeout(), None);
}

#[test]
fn enable_from_fault_with_fault_reset() {
    let mut rig = Rig::new(DeviceConfig {
        fault_reaction: Some(ms(20)),
        ..DeviceConfig::default()
    });
    rig.device.raise_fault(rig.now, 0x2310);
    rig.exchange();
    assert_eq!(rig.drive.state(), Some(State::FaultReactionActive));
    rig.drive.enable(rig.now);
    rig.exchange();
    assert_eq!(rig.drive.sequence_step(), Some(Step::FaultReaction));
    rig.run_for(ms(50));
    assert_eq!(rig.controlwords, [0x0000, 0x0080, 0x0006, 0x0007, 0x000F]);
    assert_eq!(rig.transitions, [0, 1, 13, 14, 15, 2, 3, 4]);
    let events = rig.take_events();
    let position = |e: Event| events.iter().position(|&x| x == e).unwrap();
    assert!(position(Event::FaultDetected) < position(Event::FaultCleared));
    assert_eq!(events.last(), Some(&Event::Enabled));
    assert_eq!(rig.device.fault_code(), None);
}

#[test]
fn persistent_fault_gives_up_after_the_attempts() {
    let mut rig = Rig::new(DeviceConfig::default());
    rig.device.set_fault_persists(true);
    rig.device.raise_fault(rig.now, 0x5000);
    rig.exchange();
    rig.drive.enable(rig.now);
    rig.run_for(ms(10_000));
    assert_eq!(
        rig.controlwords,
        [0x0000, 0x0080, 0x0000, 0x0080, 0x0000, 0x0080]
    );
    assert_eq!(
        rig.events.last(),
        Some(&Event::Timeout {
            step: Step::FaultReset,
            state: Some(State::Fault)
        })
    );
    // The cause is gone: a new enable succeeds.
    rig.device.set_fault_persists(false);
    rig.drive.enable(rig.now);
    rig.exchange();
    assert_eq!(rig.events.last(), Some(&Event::Enabled));
}

#[test]
fn stuck_device_times_out_in_the_step_it_is_stuck_in() {
    let mut rig = Rig::new(DeviceConfig::default());
    rig.ignore_controlwords = true;
    let start = rig.now;
    rig.drive.enable(rig.now);
    rig.run_for(ms(5000));
    assert_eq!(rig.controlwords, [0x0006]);
    assert_eq!(
        rig.take_events(),
        [
            Event::StateChanged {
                from: None,
                to: Some(State::SwitchOnDisabled)
            },
            Event::Timeout {
                step: Step::Shutdown,
                state: Some(State::SwitchOnDisabled)
            }
        ]
    );
    assert_eq!(rig.now, start + ms(5000));
    // Stuck in Switched on: the enable-operation step (2 s) times out.
    rig.ignore_controlwords = false;
    rig.device.apply_controlword(rig.now, Controlword(0x0006));
    rig.device.apply_controlword(rig.now, Controlword(0x0007));
    rig.exchange();
    rig.take_events();
    rig.ignore_controlwords = true;
    let start = rig.now;
    rig.drive.enable(rig.now);
    rig.run_for(ms(1999));
    assert_eq!(rig.take_events(), []);
    rig.run_for(ms(1));
    assert_eq!(rig.now, start + ms(2000));
    assert_eq!(
        rig.take_events(),
        [Event::Timeout {
            step: Step::EnableOperation,
            state: Some(State::SwitchedOn)
        }]
    );
}

#[test]
fn pp_moves_with_the_handshake() {
    let mut rig = Rig::enabled(DeviceConfig::default(), ModeOfOperation::ProfilePosition);
    assert_eq!(rig.device.mode(), ModeOfOperation::ProfilePosition);
    // Absolute, not immediate.
    rig.drive.move_to(rig.now, 1000, Move::default()).unwrap();
    rig.exchange();
    assert_eq!(rig.objects.target_position, Some(1000));
    assert_eq!(
        rig.device_events,
        [DeviceEvent::NewSetPoint {
            immediate: false,
            relative: false
        }]
    );
    assert_eq!(rig.controlwords, [0x001F, 0x000F]);
    assert!(!rig.device.statusword().set_point_acknowledge());
    assert_eq!(rig.take_events(), [Event::SetPointAcknowledged]);
    rig.run_for(ms(100));
    assert_eq!(rig.take_events(), []);
    rig.device.set_target_reached(true);
    rig.exchange();
    assert_eq!(rig.take_events(), [Event::TargetReached]);
    // Relative and immediate, replacing a move that has not arrived.
    rig.device_events.clear();
    rig.controlwords.clear();
    rig.drive.move_to(rig.now, 400, Move::default()).unwrap();
    rig.exchange();
    let options = Move {
        relative: true,
        immediate: true,
    };
    rig.drive.move_to(rig.now, -250, options).unwrap();
    rig.exchange();
    assert_eq!(rig.objects.target_position, Some(-250));
    assert_eq!(rig.controlwords, [0x001F, 0x000F, 0x007F, 0x006F]);
    assert_eq!(
        rig.device_events,
        [
            DeviceEvent::NewSetPoint {
                immediate: false,
                relative: false
            },
            DeviceEvent::NewSetPoint {
                immediate: true,
                relative: true
            }
        ]
    );
    rig.device.set_position_following_error(true);
    rig.exchange();
    rig.device.set_position_following_error(false);
    rig.device.set_target_reached(true);
    rig.exchange();
    assert_eq!(
        rig.take_events(),
        [
            Event::SetPointAcknowledged,
            Event::SetPointAcknowledged,
            Event::FollowingError,
            Event::TargetReached
        ]
    );
    // Never arriving: the target-reached step times out.
    rig.drive.move_to(rig.now, 5, Move::default()).unwrap();
    rig.run_for(ms(61_000));
    assert_eq!(
        rig.take_events(),
        [
            Event::SetPointAcknowledged,
            Event::Timeout {
                step: Step::TargetReached,
                state: Some(State::OperationEnabled)
            }
        ]
    );
}

#[test]
fn homing_success_and_error() {
    let mut rig = Rig::enabled(DeviceConfig::default(), ModeOfOperation::ProfilePosition);
    rig.drive.home(rig.now, Some(17)).unwrap();
    rig.exchange();
    assert_eq!(rig.device.mode(), ModeOfOperation::Homing);
    assert_eq!(rig.objects.homing_method, Some(17));
    assert_eq!(rig.device_events, [DeviceEvent::HomingStarted]);
    assert!(rig.device.homing_active());
    rig.run_for(ms(500));
    rig.device.homing_done(true);
    rig.exchange();
    assert_eq!(rig.take_events(), [Event::HomingAttained]);
    assert_eq!(rig.controlwords, [0x001F, 0x000F]);
    // Again, failing.
    rig.drive.home(rig.now, None).unwrap();
    rig.exchange();
    assert_eq!(rig.device_events.len(), 2);
    rig.device.homing_done(false);
    rig.exchange();
    assert_eq!(rig.take_events(), [Event::HomingError]);
    assert_eq!(rig.controlwords, [0x001F, 0x000F, 0x001F, 0x000F]);
}

#[test]
fn quick_stop_then_enable_again() {
    let mut rig = Rig::enabled(
        DeviceConfig {
            quick_stop: Some(ms(50)),
            ..DeviceConfig::default()
        },
        ModeOfOperation::ProfilePosition,
    );
    rig.drive.move_to(rig.now, 10, Move::default()).unwrap();
    rig.exchange();
    rig.drive.quick_stop(rig.now);
    rig.exchange();
    assert_eq!(rig.device.state(), State::QuickStopActive);
    assert_eq!(rig.controlwords, [0x001F, 0x000F, 0x0002]);
    let events = rig.take_events();
    assert_eq!(events.last(), Some(&Event::QuickStopped));
    assert!(!events.iter().any(|e| matches!(e, Event::Failed { .. })));
    rig.run_for(ms(50));
    assert_eq!(rig.device.state(), State::SwitchOnDisabled);
    assert_eq!(rig.transitions, [11, 12]);
    rig.drive.enable(rig.now);
    rig.exchange();
    assert_eq!(rig.take_events().last(), Some(&Event::Enabled));
    // Option code 6 stays in Quick stop active: enable leaves it through
    // Switch on disabled.
    let mut rig = Rig::enabled(
        DeviceConfig {
            quick_stop_option_code: 6,
            ..DeviceConfig::default()
        },
        ModeOfOperation::ProfilePosition,
    );
    rig.drive.quick_stop(rig.now);
    rig.run_for(ms(1000));
    assert_eq!(rig.device.state(), State::QuickStopActive);
    rig.drive.enable(rig.now);
    rig.exchange();
    assert_eq!(rig.controlwords, [0x0002, 0x0000, 0x0006, 0x0007, 0x000F]);
    assert_eq!(rig.transitions, [11, 12, 2, 3, 4]);
    assert_eq!(rig.take_events().last(), Some(&Event::Enabled));
}

#[test]
fn fault_during_a_move_fails_it() {
    let mut rig = Rig::enabled(DeviceConfig::default(), ModeOfOperation::ProfilePosition);
    rig.drive.move_to(rig.now, 10, Move::default()).unwrap();
    rig.exchange();
    rig.take_events();
    rig.device.raise_fault(rig.now, 0x8611);
    rig.exchange();
    let events = rig.take_events();
    assert!(events.contains(&Event::FaultDetected));
    assert!(events.contains(&Event::Failed {
        step: Step::TargetReached,
        state: Some(State::Fault)
    }));
    rig.drive.disable(rig.now);
    rig.exchange();
    assert_eq!(rig.take_events(), [Event::Disabled]);
}

#[test]
fn cyclic_synchronous_position_and_velocity() {
    let mut rig = Rig::enabled(
        DeviceConfig::default(),
        ModeOfOperation::CyclicSynchronousPosition,
    );
    assert!(rig.device.statusword().drive_follows_command());
    for cycle in 0..5 {
        rig.drive.set_csp_target(cycle * 10);
        rig.run_for(ms(1));
    }
    assert_eq!(rig.objects.csp_targets, [0, 10, 20, 30, 40]);
    rig.drive
        .set_mode(ModeOfOperation::ProfileVelocity)
        .unwrap();
    rig.drive.set_velocity(1500).unwrap();
    rig.exchange();
    assert_eq!(rig.objects.target_velocity, Some(1500));
    rig.drive.halt();
    rig.exchange();
    assert!(rig.device.controlword().halt());
    assert_eq!(rig.controlwords, [0x010F]);
}

mod random {
    use super::*;
    use proptest::prelude::*;

    #[derive(Debug, Clone)]
    enum Input {
        Enable,
        Disable,
        QuickStop,
        FaultReset,
        SetMode(i8),
        MoveTo(i32, bool, bool),
        Home(Option<i8>),
        Halt(bool),
        Csp(i32),
        Statusword(u16),
        Controlword(u16),
        Fault(u16, bool),
        MotionModel(bool, bool, bool),
        Wait(u16),
    }

    fn input() -> impl Strategy<Value = Input> {
        prop_oneof![
            Just(Input::Enable),
            Just(Input::Disable),
            Just(Input::QuickStop),
            Just(Input::FaultReset),
            any::<i8>().prop_map(Input::SetMode),
            (any::<i32>(), any::<bool>(), any::<bool>())
                .prop_map(|(t, r, i)| Input::MoveTo(t, r, i)),
            any::<Option<i8>>().prop_map(Input::Home),
            any::<bool>().prop_map(Input::Halt),
            any::<i32>().prop_map(Input::Csp),
            any::<u16>().prop_map(Input::Statusword),
            any::<u16>().prop_map(Input::Controlword),
            (any::<u16>(), any::<bool>()).prop_map(|(c, p)| Input::Fault(c, p)),
            (any::<bool>(), any::<bool>(), any::<bool>())
                .prop_map(|(a, b, c)| Input::MotionModel(a, b, c)),
            (0u16..3000).prop_map(Input::Wait),
        ]
    }

    proptest! {
        #[test]
        fn drive_and_device_never_panic_or_hang(
            inputs in proptest::collection::vec(input(), 1..60),
            option_code in -2i16..10,
        ) {
            let mut rig = Rig::new(DeviceConfig {
                start_up: ms(5),
                fault_reaction: Some(ms(7)),
                quick_stop: Some(ms(11)),
                quick_stop_option_code: option_code,
                ..DeviceConfig::default()
            });
            for input in inputs {
                let now = rig.now;
                match input {
                    Input::Enable => rig.drive.enable(now),
                    Input::Disable => rig.drive.disable(now),
                    Input::QuickStop => rig.drive.quick_stop(now),
                    Input::FaultReset => rig.drive.fault_reset(now),
                    Input::SetMode(m) => {
                        let _ = rig.drive.set_mode(ModeOfOperation::from_i8(m));
                    }
                    Input::MoveTo(target, relative, immediate) => {
                        let _ = rig.drive.move_to(now, target, Move { relative, immediate });
                    }
                    Input::Home(method) => {
                        let _ = rig.drive.home(now, method);
                    }
                    Input::Halt(true) => rig.drive.halt(),
                    Input::Halt(false) => rig.drive.resume(),
                    Input::Csp(target) => rig.drive.set_csp_target(target),
                    // A statusword from elsewhere (a stale or foreign TPDO).
                    Input::Statusword(sw) => rig
                        .drive
                        .update_statusword(now, eds2rust_runtime::cia402::Statusword(sw)),
                    Input::Controlword(cw) => rig.device.apply_controlword(now, Controlword(cw)),
                    Input::Fault(code, persists) => {
                        rig.device.set_fault_persists(persists);
                        rig.device.raise_fault(now, code);
                    }
                    Input::MotionModel(reached, following, homed) => {
                        rig.device.set_target_reached(reached);
                        rig.device.set_position_following_error(following);
                        if rig.device.homing_active() {
                            rig.device.homing_done(homed);
                        }
                    }
                    Input::Wait(millis) => rig.run_for(ms(u64::from(millis))),
                }
                rig.exchange();
                let sw = rig.device.statusword();
                prop_assert_eq!(State::from_statusword(sw.0), Some(rig.device.state()));
                for deadline in [rig.drive.poll_timeout(), rig.device.poll_timeout()]
                    .into_iter()
                    .flatten()
                {
                    prop_assert!(deadline > rig.now);
                }
            }
        }
    }
}
