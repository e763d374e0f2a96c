//! `Drive` against hand-written statuswords; expected writes as the bytes
//! CiA 402 puts in the objects.

use core::time::Duration;

use super::*;
use crate::cores::testing::ms;

/// Every pending write as (index, sub-index, little-endian bytes).
fn writes(d: &mut Drive) -> Vec<(u16, u8, Vec<u8>)> {
    core::iter::from_fn(|| d.poll_write())
        .map(|w| (w.index, w.sub, w.value.to_le_bytes().to_vec()))
        .collect()
}

fn events(d: &mut Drive) -> Vec<Event> {
    core::iter::from_fn(|| d.poll_event()).collect()
}

fn cw(value: u16) -> (u16, u8, Vec<u8>) {
    (0x6040, 0, value.to_le_bytes().to_vec())
}

fn sw(d: &mut Drive, now: Instant, value: u16) {
    d.update_statusword(now, Statusword(value));
}

/// A drive in Operation enabled with `mode`, queues drained.
fn enabled(mode: ModeOfOperation) -> Drive {
    let mut d = Drive::new(DriveConfig::default());
    sw(&mut d, ms(0), 0x0237);
    d.set_mode(mode).unwrap();
    writes(&mut d);
    events(&mut d);
    d
}

#[test]
fn enable_from_switch_on_disabled() {
    let mut d = Drive::new(DriveConfig::default());
    d.enable(ms(0));
    assert_eq!(writes(&mut d), []);
    assert_eq!(d.sequence_step(), Some(Step::Statusword));
    assert_eq!(d.poll_timeout(), Some(ms(1000)));
    sw(&mut d, ms(10), 0x0250);
    assert_eq!(writes(&mut d), [cw(0x0006)]);
    assert_eq!(d.poll_timeout(), Some(ms(1010)));
    // The same state again (a cyclic TPDO) changes nothing.
    sw(&mut d, ms(15), 0x0250);
    assert_eq!(writes(&mut d), []);
    sw(&mut d, ms(20), 0x0231);
    assert_eq!(writes(&mut d), [cw(0x0007)]);
    sw(&mut d, ms(30), 0x0233);
    assert_eq!(writes(&mut d), [cw(0x000F)]);
    assert_eq!(d.poll_timeout(), Some(ms(2030)));
    sw(&mut d, ms(40), 0x0237);
    assert_eq!(writes(&mut d), []);
    assert_eq!(d.poll_timeout(), None);
    use State as S;
    assert_eq!(
        events(&mut d),
        [
            Event::StateChanged {
                from: None,
                to: Some(S::SwitchOnDisabled)
            },
            Event::StateChanged {
                from: Some(S::SwitchOnDisabled),
                to: Some(S::ReadyToSwitchOn)
            },
            Event::StateChanged {
                from: Some(S::ReadyToSwitchOn),
                to: Some(S::SwitchedOn)
            },
            Event::StateChanged {
                from: Some(S::SwitchedOn),
                to: Some(S::OperationEnabled)
            },
            Event::Enabled,
        ]
    );
    // Already enabled: at once.
    d.enable(ms(50));
    assert_eq!(
        (writes(&mut d), events(&mut d)),
        (vec![], vec![Event::Enabled])
    );
}

#[test]
fn enable_from_fault_resets_with_a_rising_edge() {
    let mut d = Drive::new(DriveConfig::default());
    sw(&mut d, ms(0), 0x0218);
    assert!(events(&mut d).contains(&Event::FaultDetected));
    d.enable(ms(0));
    assert_eq!(writes(&mut d), [cw(0x0000), cw(0x0080)]);
    assert_eq!(d.sequence_step(), Some(Step::FaultReset));
    sw(&mut d, ms(5), 0x0250);
    assert_eq!(writes(&mut d), [cw(0x0006)]);
    assert!(events(&mut d).contains(&Event::FaultCleared));
    // Quick stop active on the way: disable voltage first.
    sw(&mut d, ms(6), 0x0217);
    assert_eq!(writes(&mut d), [cw(0x0000)]);
    assert_eq!(d.sequence_step(), Some(Step::DisableVoltage));
}

#[test]
fn fault_reset_attempts_are_bounded() {
    let mut d = Drive::new(DriveConfig::default());
    sw(&mut d, ms(0), 0x0218);
    d.fault_reset(ms(0));
    for attempt in 1..=3u64 {
        assert_eq!(
            writes(&mut d),
            [cw(0x0000), cw(0x0080)],
            "attempt {attempt}"
        );
        let deadline = d.poll_timeout().unwrap();
        assert_eq!(deadline, ms(attempt * 1000));
        d.handle_timeout(deadline);
    }
    assert_eq!(writes(&mut d), []);
    let e = events(&mut d);
    assert_eq!(
        e.last(),
        Some(&Event::Timeout {
            step: Step::FaultReset,
            state: Some(State::Fault)
        })
    );
    assert_eq!(d.poll_timeout(), None);
    // A fault that comes back after each reset: Failed once used up.
    let mut d = Drive::new(DriveConfig::default());
    sw(&mut d, ms(0), 0x0218);
    d.enable(ms(0));
    for _ in 0..3 {
        assert_eq!(writes(&mut d), [cw(0x0000), cw(0x0080)]);
        sw(&mut d, ms(1), 0x0250);
        assert_eq!(writes(&mut d), [cw(0x0006)]);
        sw(&mut d, ms(2), 0x0218);
    }
    assert_eq!(writes(&mut d), []);
    assert_eq!(
        events(&mut d).last(),
        Some(&Event::Failed {
            step: Step::FaultReset,
            state: Some(State::Fault)
        })
    );
}

#[test]
fn each_enable_step_times_out_with_its_name() {
    let config = DriveConfig::default().with_timeout(Step::SwitchOn, Duration::from_millis(30));
    let mut d = Drive::new(config);
    sw(&mut d, ms(0), 0x0231);
    d.enable(ms(0));
    assert_eq!(writes(&mut d), [cw(0x0007)]);
    d.handle_timeout(ms(29));
    assert_eq!(d.poll_timeout(), Some(ms(30)));
    d.handle_timeout(ms(30));
    assert_eq!(
        events(&mut d).last(),
        Some(&Event::Timeout {
            step: Step::SwitchOn,
            state: Some(State::ReadyToSwitchOn)
        })
    );
    assert_eq!((d.sequence_step(), d.poll_timeout()), (None, None));
    // Not ready to switch on: the drive must finish its start-up.
    let mut d = Drive::new(DriveConfig::default());
    sw(&mut d, ms(0), 0x0200);
    d.enable(ms(0));
    assert_eq!(writes(&mut d), []);
    d.handle_timeout(ms(5000));
    assert!(events(&mut d).contains(&Event::Timeout {
        step: Step::StartUp,
        state: Some(State::NotReadyToSwitchOn)
    }));
    // No statusword at all.
    let mut d = Drive::new(DriveConfig::default());
    d.enable(ms(0));
    d.handle_timeout(ms(1000));
    assert_eq!(
        events(&mut d),
        [Event::Timeout {
            step: Step::Statusword,
            state: None
        }]
    );
}

#[test]
fn disable_and_quick_stop() {
    let mut d = enabled(ModeOfOperation::ProfilePosition);
    d.quick_stop(ms(0));
    assert_eq!(writes(&mut d), [cw(0x0002)]);
    sw(&mut d, ms(1), 0x0217);
    assert!(events(&mut d).contains(&Event::QuickStopped));
    d.disable(ms(2));
    assert_eq!(writes(&mut d), [cw(0x0000)]);
    sw(&mut d, ms(3), 0x0250);
    assert!(events(&mut d).contains(&Event::Disabled));
    // Nothing to do without voltage.
    d.disable(ms(4));
    d.quick_stop(ms(4));
    assert_eq!(writes(&mut d), []);
    assert_eq!(events(&mut d), [Event::Disabled, Event::QuickStopped]);
    // Quick stop from Switched on goes to Switch on disabled.
    sw(&mut d, ms(5), 0x0233);
    d.quick_stop(ms(5));
    assert_eq!(writes(&mut d), [cw(0x0002)]);
    sw(&mut d, ms(6), 0x0250);
    assert!(events(&mut d).contains(&Event::QuickStopped));
}

#[test]
fn pp_move_absolute_not_immediate() {
    let mut d = enabled(ModeOfOperation::ProfilePosition);
    d.move_to(ms(0), 500, Move::default()).unwrap();
    assert_eq!(
        writes(&mut d),
        [(0x607A, 0, vec![0xF4, 0x01, 0, 0]), cw(0x001F)]
    );
    assert_eq!(d.motion_step(), Some(Step::SetPointAcknowledge));
    assert_eq!(d.move_to(ms(0), 1, Move::default()), Err(DriveError::Busy));
    // A stale statusword with target reached from before changes nothing.
    sw(&mut d, ms(1), 0x0637);
    sw(&mut d, ms(2), 0x1237);
    assert_eq!(writes(&mut d), [cw(0x000F)]);
    assert_eq!(events(&mut d), [Event::SetPointAcknowledged]);
    assert_eq!(d.motion_step(), Some(Step::TargetReached));
    assert_eq!(d.poll_timeout(), Some(ms(60_002)));
    sw(&mut d, ms(3), 0x0237);
    sw(&mut d, ms(50), 0x0637);
    assert_eq!(events(&mut d), [Event::TargetReached]);
    assert_eq!((d.motion_step(), d.poll_timeout()), (None, None));
}

#[test]
fn pp_move_relative_immediate_and_release_wait() {
    let mut d = enabled(ModeOfOperation::ProfilePosition);
    let options = Move {
        relative: true,
        immediate: true,
    };
    d.move_to(ms(0), -2, options).unwrap();
    assert_eq!(
        writes(&mut d),
        [(0x607A, 0, vec![0xFE, 0xFF, 0xFF, 0xFF]), cw(0x007F)]
    );
    sw(&mut d, ms(1), 0x1237);
    assert_eq!(writes(&mut d), [cw(0x006F)]);
    // A second move while the acknowledge is still set waits for it.
    d.move_to(ms(2), 7, Move::default()).unwrap();
    assert_eq!(writes(&mut d), []);
    assert_eq!(d.motion_step(), Some(Step::SetPointRelease));
    sw(&mut d, ms(3), 0x0237);
    assert_eq!(writes(&mut d), [(0x607A, 0, vec![7, 0, 0, 0]), cw(0x001F)]);
    // No acknowledge: timeout, bit 4 cleared for the next edge.
    d.handle_timeout(ms(1003));
    assert_eq!(writes(&mut d), [cw(0x000F)]);
    assert_eq!(
        events(&mut d).last(),
        Some(&Event::Timeout {
            step: Step::SetPointAcknowledge,
            state: Some(State::OperationEnabled)
        })
    );
}

#[test]
fn pp_requests_refused() {
    let mut d = Drive::new(DriveConfig::default());
    sw(&mut d, ms(0), 0x0233);
    assert_eq!(
        d.move_to(ms(0), 1, Move::default()),
        Err(DriveError::NotEnabled {
            state: Some(State::SwitchedOn)
        })
    );
    sw(&mut d, ms(0), 0x0237);
    assert_eq!(
        d.move_to(ms(0), 1, Move::default()),
        Err(DriveError::WrongMode { mode: None })
    );
    assert!(d.set_velocity(1).is_err());
    assert_eq!(writes(&mut d), []);
}

#[test]
fn leaving_operation_enabled_fails_the_move() {
    let mut d = enabled(ModeOfOperation::ProfilePosition);
    d.move_to(ms(0), 1, Move::default()).unwrap();
    sw(&mut d, ms(1), 0x1237);
    events(&mut d);
    sw(&mut d, ms(2), 0x021F);
    assert_eq!(
        events(&mut d),
        [
            Event::StateChanged {
                from: Some(State::OperationEnabled),
                to: Some(State::FaultReactionActive)
            },
            Event::FaultDetected,
            Event::Failed {
                step: Step::TargetReached,
                state: Some(State::FaultReactionActive)
            },
        ]
    );
    assert_eq!(d.poll_timeout(), None);
}

#[test]
fn halt_suppresses_target_reached() {
    let mut d = enabled(ModeOfOperation::ProfilePosition);
    d.move_to(ms(0), 1, Move::default()).unwrap();
    sw(&mut d, ms(1), 0x1237);
    sw(&mut d, ms(2), 0x0237);
    writes(&mut d);
    d.halt();
    assert_eq!(writes(&mut d), [cw(0x010F)]);
    sw(&mut d, ms(3), 0x0637); // standing still, not at the target
    d.resume();
    assert_eq!(writes(&mut d), [cw(0x000F)]);
    sw(&mut d, ms(4), 0x0637); // stale: from before the resume
    assert_eq!(events(&mut d), [Event::SetPointAcknowledged]);
    sw(&mut d, ms(5), 0x0237);
    sw(&mut d, ms(6), 0x0637);
    assert_eq!(events(&mut d), [Event::TargetReached]);
    // Commands keep halt.
    d.halt();
    d.disable(ms(7));
    assert_eq!(writes(&mut d), [cw(0x010F), cw(0x0100)]);
}

#[test]
fn homing_attained_and_error() {
    let mut d = enabled(ModeOfOperation::ProfilePosition);
    d.home(ms(0), Some(35)).unwrap();
    assert_eq!(
        writes(&mut d),
        [(0x6060, 0, vec![6]), (0x6098, 0, vec![35]), cw(0x001F)]
    );
    assert_eq!(d.home(ms(0), None), Err(DriveError::Busy));
    assert_eq!(d.set_mode(ModeOfOperation::Homing), Err(DriveError::Busy));
    // Bits from before the mode switch do not count.
    sw(&mut d, ms(1), 0x1637);
    assert_eq!(events(&mut d), []);
    sw(&mut d, ms(2), 0x0237);
    sw(&mut d, ms(3), 0x1637);
    assert_eq!(events(&mut d), [Event::HomingAttained]);
    assert_eq!(writes(&mut d), [cw(0x000F)]);
    // Again in homing mode with clear bits: the next statusword counts.
    sw(&mut d, ms(4), 0x0637);
    d.home(ms(5), None).unwrap();
    assert_eq!(writes(&mut d), [cw(0x001F)]);
    sw(&mut d, ms(6), 0x2637);
    assert_eq!(events(&mut d), [Event::HomingError]);
    assert_eq!(writes(&mut d), [cw(0x000F)]);
    // Timeout.
    d.home(ms(10), None).unwrap();
    writes(&mut d);
    d.handle_timeout(ms(120_010));
    assert_eq!(writes(&mut d), [cw(0x000F)]);
    assert_eq!(
        events(&mut d),
        [Event::Timeout {
            step: Step::Homing,
            state: Some(State::OperationEnabled)
        }]
    );
}

#[test]
fn following_error_velocity_csp_and_profile() {
    let mut d = enabled(ModeOfOperation::CyclicSynchronousPosition);
    sw(&mut d, ms(1), 0x3237);
    sw(&mut d, ms(2), 0x3237);
    assert_eq!(events(&mut d), [Event::FollowingError]);
    d.set_csp_target(10);
    d.set_csp_target(-1);
    assert_eq!(writes(&mut d), [(0x607A, 0, vec![0xFF, 0xFF, 0xFF, 0xFF])]);
    d.set_csp_target(3);
    assert_eq!(writes(&mut d), [(0x607A, 0, vec![3, 0, 0, 0])]);
    d.set_mode(ModeOfOperation::ProfileVelocity).unwrap();
    d.set_velocity(-1000).unwrap();
    d.set_profile(100, 0x0102_0304, 5);
    assert_eq!(
        writes(&mut d),
        [
            (0x6060, 0, vec![3]),
            (0x60FF, 0, vec![0x18, 0xFC, 0xFF, 0xFF]),
            (0x6081, 0, vec![100, 0, 0, 0]),
            (0x6083, 0, vec![4, 3, 2, 1]),
            (0x6084, 0, vec![5, 0, 0, 0]),
        ]
    );
    // Bit 13 in pv mode is not a following error.
    sw(&mut d, ms(3), 0x0237);
    sw(&mut d, ms(4), 0x2237);
    assert_eq!(events(&mut d), []);
}

#[test]
fn unknown_statusword_pattern() {
    let mut d = Drive::new(DriveConfig::default());
    sw(&mut d, ms(0), 0x0237);
    sw(&mut d, ms(1), 0x0001);
    assert_eq!(d.state(), None);
    assert_eq!(
        events(&mut d).last(),
        Some(&Event::StateChanged {
            from: Some(State::OperationEnabled),
            to: None
        })
    );
}
