//! Device state machine transitions, statusword values written out by hand.

use super::*;
use crate::cia402::words::Command;

fn cw(command: Command) -> Controlword {
    Controlword::from(command)
}

const T0: Instant = Instant::from_millis(1);

fn transitions(device: &mut DeviceStateMachine) -> Vec<(u8, State)> {
    core::iter::from_fn(|| device.poll_event())
        .filter_map(|e| match e {
            DeviceEvent::Transition { number, to, .. } => Some((number, to)),
            _ => None,
        })
        .collect()
}

fn enabled(config: DeviceConfig) -> DeviceStateMachine {
    let mut d = DeviceStateMachine::new(T0, config);
    d.apply_controlword(T0, Controlword(0x0006));
    d.apply_controlword(T0, Controlword(0x0007));
    d.apply_controlword(T0, Controlword(0x000F));
    assert_eq!(d.state(), State::OperationEnabled);
    transitions(&mut d);
    d
}

#[test]
fn start_up_transitions_0_and_1() {
    let config = DeviceConfig {
        start_up: Duration::from_millis(50),
        ..DeviceConfig::default()
    };
    let mut d = DeviceStateMachine::new(T0, config);
    assert_eq!(d.state(), State::NotReadyToSwitchOn);
    assert_eq!(d.statusword(), Statusword(0x0210));
    assert_eq!(d.poll_timeout(), Some(Instant::from_millis(51)));
    // Commands are ignored while not ready.
    d.apply_controlword(T0, Controlword(0x0006));
    assert_eq!(d.state(), State::NotReadyToSwitchOn);
    d.handle_timeout(Instant::from_millis(51));
    assert_eq!(d.statusword(), Statusword(0x0250));
    assert_eq!(
        transitions(&mut d),
        [(0, State::NotReadyToSwitchOn), (1, State::SwitchOnDisabled)]
    );
    assert_eq!(d.poll_timeout(), None);
    // Immediate start-up.
    let mut d = DeviceStateMachine::new(T0, DeviceConfig::default());
    assert_eq!(d.state(), State::SwitchOnDisabled);
    assert_eq!(transitions(&mut d).len(), 2);
}

#[test]
fn enable_and_back_down() {
    let mut d = DeviceStateMachine::new(T0, DeviceConfig::default());
    transitions(&mut d);
    // Switch on is not allowed from Switch on disabled.
    d.apply_controlword(T0, Controlword(0x0007));
    assert_eq!(d.state(), State::SwitchOnDisabled);
    d.apply_controlword(T0, cw(Command::Shutdown));
    assert_eq!(d.statusword(), Statusword(0x0231));
    d.apply_controlword(T0, cw(Command::SwitchOn));
    assert_eq!(d.statusword(), Statusword(0x0233));
    d.apply_controlword(T0, cw(Command::EnableOperation));
    assert_eq!(d.statusword(), Statusword(0x0237));
    d.apply_controlword(T0, cw(Command::DisableOperation));
    assert_eq!(d.state(), State::SwitchedOn);
    d.apply_controlword(T0, Controlword(0x000E)); // shutdown, bit 3 = x
    assert_eq!(d.state(), State::ReadyToSwitchOn);
    d.apply_controlword(T0, cw(Command::EnableOperation)); // 3 + 4
    assert_eq!(d.state(), State::OperationEnabled);
    d.apply_controlword(T0, cw(Command::Shutdown));
    assert_eq!(d.state(), State::ReadyToSwitchOn);
    d.apply_controlword(T0, Controlword(0x0005)); // disable voltage: bit 1 = 0
    assert_eq!(d.state(), State::SwitchOnDisabled);
    assert_eq!(
        transitions(&mut d),
        [
            (2, State::ReadyToSwitchOn),
            (3, State::SwitchedOn),
            (4, State::OperationEnabled),
            (5, State::SwitchedOn),
            (6, State::ReadyToSwitchOn),
            (3, State::SwitchedOn),
            (4, State::OperationEnabled),
            (8, State::ReadyToSwitchOn),
            (7, State::SwitchOnDisabled),
        ]
    );
}

#[test]
fn disable_voltage_and_quick_stop_from_each_state() {
    let mut d = enabled(DeviceConfig::default());
    d.apply_controlword(T0, Controlword(0x000D)); // bit 1 = 0
    assert_eq!(transitions(&mut d), [(9, State::SwitchOnDisabled)]);
    d.apply_controlword(T0, Controlword(0x0006));
    d.apply_controlword(T0, Controlword(0x0007));
    d.apply_controlword(T0, Controlword(0x000B)); // quick stop: bit 2 = 0
    assert_eq!(
        transitions(&mut d),
        [
            (2, State::ReadyToSwitchOn),
            (3, State::SwitchedOn),
            (10, State::SwitchOnDisabled)
        ]
    );
    d.apply_controlword(T0, Controlword(0x0006));
    d.apply_controlword(T0, Controlword(0x0002));
    assert_eq!(
        transitions(&mut d),
        [(2, State::ReadyToSwitchOn), (7, State::SwitchOnDisabled)]
    );
}

#[test]
fn quick_stop_ends_in_switch_on_disabled() {
    let config = DeviceConfig {
        quick_stop: Some(Duration::from_millis(20)),
        ..DeviceConfig::default()
    };
    let mut d = enabled(config);
    d.apply_controlword(T0, cw(Command::QuickStop));
    assert_eq!(d.statusword(), Statusword(0x0217));
    // Enable operation does not leave it with option code 2.
    d.apply_controlword(T0, cw(Command::EnableOperation));
    assert_eq!(d.state(), State::QuickStopActive);
    assert_eq!(d.poll_timeout(), Some(Instant::from_millis(21)));
    d.handle_timeout(Instant::from_millis(21));
    assert_eq!(d.statusword(), Statusword(0x0250));
    assert_eq!(
        transitions(&mut d),
        [(11, State::QuickStopActive), (12, State::SwitchOnDisabled)]
    );
    // Explicit end of the ramp.
    let config = DeviceConfig {
        quick_stop: None,
        ..DeviceConfig::default()
    };
    let mut d = enabled(config);
    d.apply_controlword(T0, cw(Command::QuickStop));
    assert_eq!(d.poll_timeout(), None);
    d.complete_quick_stop(T0);
    assert_eq!(d.state(), State::SwitchOnDisabled);
    // Disable voltage ends it too.
    let mut d = enabled(DeviceConfig {
        quick_stop: None,
        ..DeviceConfig::default()
    });
    d.apply_controlword(T0, cw(Command::QuickStop));
    d.apply_controlword(T0, cw(Command::DisableVoltage));
    assert_eq!(
        transitions(&mut d),
        [(11, State::QuickStopActive), (12, State::SwitchOnDisabled)]
    );
}

#[test]
fn quick_stop_option_6_stays_and_transition_16() {
    let config = DeviceConfig {
        quick_stop_option_code: 6,
        ..DeviceConfig::default()
    };
    let mut d = enabled(config);
    d.apply_controlword(T0, cw(Command::QuickStop));
    d.complete_quick_stop(T0);
    assert_eq!(d.poll_timeout(), None);
    assert_eq!(d.state(), State::QuickStopActive);
    d.apply_controlword(T0, cw(Command::EnableOperation));
    assert_eq!(
        transitions(&mut d),
        [(11, State::QuickStopActive), (16, State::OperationEnabled)]
    );
}

#[test]
fn fault_reaction_fault_and_reset() {
    let config = DeviceConfig {
        fault_reaction: Some(Duration::from_millis(10)),
        ..DeviceConfig::default()
    };
    let mut d = enabled(config);
    d.raise_fault(T0, 0x2310);
    assert_eq!(d.statusword(), Statusword(0x021F));
    assert_eq!(d.fault_code(), Some(0x2310));
    // Nothing leaves Fault reaction active but its end.
    d.apply_controlword(T0, Controlword(0x0006));
    d.apply_controlword(T0, Controlword(0x0080));
    assert_eq!(d.state(), State::FaultReactionActive);
    d.handle_timeout(Instant::from_millis(11));
    assert_eq!(d.statusword(), Statusword(0x0218));
    // Bit 7 already set: no rising edge yet.
    d.apply_controlword(T0, Controlword(0x0080));
    assert_eq!(d.state(), State::Fault);
    d.apply_controlword(T0, Controlword(0x0000));
    d.apply_controlword(T0, Controlword(0x0080));
    assert_eq!(d.statusword(), Statusword(0x0250));
    assert_eq!(d.fault_code(), None);
    assert_eq!(
        transitions(&mut d),
        [
            (13, State::FaultReactionActive),
            (14, State::Fault),
            (15, State::SwitchOnDisabled)
        ]
    );
    // With bit 7 set, Shutdown bits are not a command.
    d.apply_controlword(T0, Controlword(0x0086));
    assert_eq!(d.state(), State::SwitchOnDisabled);
}

#[test]
fn persistent_fault_refuses_reset() {
    let mut d = DeviceStateMachine::new(T0, DeviceConfig::default());
    d.set_fault_persists(true);
    d.raise_fault(T0, 0x5000);
    assert_eq!(d.state(), State::Fault);
    d.apply_controlword(T0, Controlword(0x0000));
    d.apply_controlword(T0, Controlword(0x0080));
    assert_eq!(d.state(), State::Fault);
    d.set_fault_persists(false);
    d.apply_controlword(T0, Controlword(0x0000));
    d.apply_controlword(T0, Controlword(0x0080));
    assert_eq!(d.state(), State::SwitchOnDisabled);
    // Explicit end of the fault reaction.
    let mut d = DeviceStateMachine::new(
        T0,
        DeviceConfig {
            fault_reaction: None,
            ..DeviceConfig::default()
        },
    );
    d.raise_fault(T0, 1);
    assert_eq!(
        (d.state(), d.poll_timeout()),
        (State::FaultReactionActive, None)
    );
    d.raise_fault(T0, 2);
    assert_eq!(d.fault_code(), Some(2));
    d.complete_fault_reaction(T0);
    assert_eq!(d.state(), State::Fault);
}

#[test]
fn profile_position_handshake() {
    let mut d = enabled(DeviceConfig::default());
    d.set_mode(ModeOfOperation::ProfilePosition);
    d.set_target_reached(true);
    assert_eq!(d.statusword(), Statusword(0x0637));
    d.apply_controlword(T0, Controlword(0x007F)); // new set-point, immediate, relative
    assert_eq!(d.statusword(), Statusword(0x1237));
    assert_eq!(
        d.poll_event(),
        Some(DeviceEvent::NewSetPoint {
            immediate: true,
            relative: true
        })
    );
    // Bit 4 held: no new set-point.
    d.apply_controlword(T0, Controlword(0x001F));
    assert_eq!(d.poll_event(), None);
    d.apply_controlword(T0, Controlword(0x000F));
    assert_eq!(d.statusword(), Statusword(0x0237));
    d.set_position_following_error(true);
    d.set_target_reached(true);
    assert_eq!(d.statusword(), Statusword(0x2637));
    // Not acknowledged outside Operation enabled.
    d.apply_controlword(T0, Controlword(0x0007));
    d.apply_controlword(T0, Controlword(0x0017));
    assert_eq!(d.poll_event().map(|_| ()), Some(()));
    assert_eq!(d.poll_event(), None);
    assert!(!d.statusword().set_point_acknowledge());
}

#[test]
fn homing_and_mode_bits() {
    let mut d = enabled(DeviceConfig::default());
    d.set_mode(ModeOfOperation::Homing);
    d.apply_controlword(T0, Controlword(0x001F));
    assert_eq!(d.poll_event(), Some(DeviceEvent::HomingStarted));
    assert!(d.homing_active());
    assert_eq!(d.statusword(), Statusword(0x0237));
    d.homing_done(true);
    assert_eq!(d.statusword(), Statusword(0x1637));
    d.apply_controlword(T0, Controlword(0x000F));
    d.apply_controlword(T0, Controlword(0x001F));
    assert_eq!(d.statusword(), Statusword(0x0237));
    d.homing_done(false);
    assert_eq!(d.statusword(), Statusword(0x2637));
    d.set_mode(ModeOfOperation::CyclicSynchronousPosition);
    d.set_target_reached(false);
    assert_eq!(d.statusword(), Statusword(0x1237));
    d.set_mode(ModeOfOperation::ProfileVelocity);
    assert_eq!(d.statusword(), Statusword(0x1237));
    d.set_speed_zero(false);
    d.set_warning(true);
    d.set_internal_limit(true);
    assert_eq!(d.statusword(), Statusword(0x0AB7));
    assert_eq!(d.mode(), ModeOfOperation::ProfileVelocity);
}
