use super::*;
use crate::cia402::{Controlword, DeviceConfig, DeviceStateMachine, Move};
use crate::od::{AccessRight, DataType};

const fn info(index: u16) -> ObjectInfo {
    ObjectInfo::new(index, 0, "x", DataType::Unsigned16, AccessRight::Rw, false)
}

static PP_ONLY: [ObjectInfo; 5] = [
    info(0x603F),
    info(0x6040),
    info(0x6041),
    info(0x6060),
    info(0x607A),
];

/// Runs the session against the device until Done; the clock moves to
/// every wait.
fn run(
    session: &mut Session,
    device: &mut DeviceStateMachine,
    now: &mut Instant,
) -> Result<(), OperationError> {
    for _ in 0..1000 {
        match session.poll_action(*now) {
            Action::Write(w) => {
                let bytes = w.value.to_le_bytes();
                match w.index {
                    0x6040 => device.apply_controlword(
                        *now,
                        Controlword(u16::from_le_bytes([bytes[0], bytes[1]])),
                    ),
                    0x6060 => device.set_mode(ModeOfOperation::from_i8(bytes[0] as i8)),
                    _ => {}
                }
            }
            Action::Read(Read::Statusword) => {
                session.on_statusword(*now, &device.statusword().0.to_le_bytes());
            }
            Action::Read(Read::ErrorCode) => {
                let code = device.fault_code().map(u16::to_le_bytes);
                session.on_error_code(code.as_ref().map(|c| &c[..]));
            }
            Action::Wait(until) => *now = until,
            Action::Done(result) => return result,
        }
    }
    panic!("no end");
}

#[test]
fn missing_object_refused_before_anything() {
    let mut session = Session::new(&PP_ONLY, SessionConfig::default()).unwrap();
    let e = session
        .start(Instant::from_millis(1), Request::Velocity(5))
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "profile velocity needs 0x60FF Target velocity, which this device does not have"
    );
    assert_eq!(session.request(), None);
    assert_eq!(
        session.poll_action(Instant::from_millis(1)),
        Action::Done(Ok(()))
    );
    let config = SessionConfig {
        required: &[Operation::Homing],
        ..SessionConfig::default()
    };
    assert!(Session::new(&PP_ONLY, config).is_err());
}

#[test]
fn enable_move_and_persistent_fault() {
    let mut now = Instant::from_millis(1);
    let mut device = DeviceStateMachine::new(now, DeviceConfig::default());
    let mut session = Session::new(&PP_ONLY, SessionConfig::default()).unwrap();
    // A move before enable is refused by the helper.
    session
        .start(
            now,
            Request::Move {
                target: 5,
                options: Move::default(),
            },
        )
        .unwrap();
    assert!(matches!(
        run(&mut session, &mut device, &mut now),
        Err(OperationError::Refused(DriveError::NotEnabled { .. }))
    ));
    session.start(now, Request::Enable).unwrap();
    assert_eq!(run(&mut session, &mut device, &mut now), Ok(()));
    assert!(matches!(
        session
            .start(now, Request::Statusword)
            .and(session.start(now, Request::Enable)),
        Err(OperationError::Refused(DriveError::Busy))
    ));
    assert_eq!(run(&mut session, &mut device, &mut now), Ok(()));

    device.raise_fault(now, 0x2310);
    device.set_fault_persists(true);
    session.start(now, Request::Enable).unwrap();
    let e = run(&mut session, &mut device, &mut now).unwrap_err();
    assert_eq!(
        e,
        OperationError::Fault {
            step: Step::FaultReset,
            state: State::Fault,
            code: Some(0x2310)
        }
    );
    assert_eq!(
        e.to_string(),
        "drive in Fault with error code 0x2310 while waiting for the drive to leave Fault after a fault reset"
    );
    let events: Vec<Event> = core::iter::from_fn(|| session.poll_event()).collect();
    assert!(events.contains(&Event::FaultDetected));
}

#[test]
fn wrong_statusword_length_ends_the_request() {
    let now = Instant::from_millis(1);
    let mut session = Session::new(&PP_ONLY, SessionConfig::default()).unwrap();
    session.start(now, Request::Enable).unwrap();
    assert_eq!(session.poll_action(now), Action::Read(Read::Statusword));
    session.on_statusword(now, &[1, 2, 3]);
    assert_eq!(
        session.poll_action(now),
        Action::Done(Err(OperationError::BadStatusword { len: 3 }))
    );
    // Polling: the next upload is due one period later.
    session.start(now, Request::Statusword).unwrap();
    assert_eq!(session.poll_action(now), Action::Read(Read::Statusword));
    let later = now + Duration::from_millis(3);
    assert_eq!(
        session.poll_action(later),
        Action::Wait(now + Duration::from_millis(10))
    );
    assert!(!session.on_pdo(CanId::Standard(0x181), &[0x37, 0x02], later));
}
