//! Golden tests from the LINAK manual's start-up trace (node 32, p. 28):
//! the TPDO1 frames decode through the generated types to the values the
//! manual states, and the commands encode to the frames it shows.

use eds2rust_drivers::linak_techline::{self as linak, errors::LinakErrors, od, pdo};
use eds2rust_runtime::CanId;
use eds2rust_runtime::od::{NodeId, PdoLengthError, Scaled};
use eds2rust_runtime::pdo::PdoCobId;

fn node32() -> NodeId {
    NodeId::new(linak::DEFAULT_NODE_ID).expect("32 is a node id")
}

fn position_mm(p: od::feedback::PositionValue) -> f64 {
    match p.kind() {
        od::feedback::PositionKind::Number(n) => n.value(),
        other => panic!("position is not a number: {other:?}"),
    }
}

fn current_a(c: od::feedback::CurrentValue) -> f64 {
    match c.kind() {
        od::feedback::CurrentKind::Number(n) => n.value(),
        od::feedback::CurrentKind::NotRunning => 0.0,
        other => panic!("current is not a number: {other:?}"),
    }
}

fn speed_mm_s(s: od::feedback::SpeedValue) -> f64 {
    s.number().expect("speed is a number").value()
}

#[test]
fn cob_ids_of_node_32_are_the_traces() {
    assert_eq!(pdo::Tpdo1Feedback::can_id(node32()), CanId::Standard(0x1A0));
    assert_eq!(pdo::Rpdo1Command::can_id(node32()), CanId::Standard(0x220));
    assert_eq!(linak::DEFAULT_BIT_RATE_KBIT, 250);
    // $NODEID-relative defaults of other entries: EMCY and the SDO server.
    assert_eq!(od::CobIdEmcy::default_for(node32()).to_raw(), 0xA0);
    assert_eq!(
        od::sdo_server_parameter::CobIdClientToServer::default_for(node32()),
        0x620
    );
    assert_eq!(
        od::sdo_server_parameter::CobIdServerToClient::default_for(node32()),
        0x5A0
    );
}

#[test]
fn pdo_mappings_are_the_manuals() {
    use eds2rust_runtime::od::Pdo;
    // TPDO1: position u16, current u8, status flags u8, error code u8,
    // speed u16, AUX inputs u8 (0x2001 sub 1..6), 8 bytes.
    assert_eq!(
        <pdo::Tpdo1Feedback as Pdo>::MAPPING,
        &[
            0x2001_0110,
            0x2001_0208,
            0x2001_0308,
            0x2001_0408,
            0x2001_0510,
            0x2001_0608
        ]
    );
    assert_eq!(
        <pdo::Tpdo1Feedback as Pdo>::default_cob_id(node32()),
        Some(PdoCobId(0x1A0))
    );
    assert_eq!(<pdo::Rpdo1Command as Pdo>::MAPPING.len(), 7);
    assert_eq!(
        <pdo::Rpdo1Command as Pdo>::default_cob_id(node32()),
        Some(PdoCobId(0x220))
    );
}

/// "1A0 00 00 00 81 01 00 00 C0": TPDO1 before the first Stop command.
const STARTUP: [u8; 8] = [0x00, 0x00, 0x00, 0x81, 0x01, 0x00, 0x00, 0xC0];
/// "1A0 1A 00 06 88 00 31 00 C0": running out, 2.6 mm.
const RUNNING_OUT: [u8; 8] = [0x1A, 0x00, 0x06, 0x88, 0x00, 0x31, 0x00, 0xC0];

/// What a TPDO1 of the trace reports by the manual.
struct Feedback {
    frame: [u8; 8],
    position_mm: f64,
    /// `None`: not running.
    current_a: Option<f64>,
    /// End stop in, end stop out, running out, running in.
    flags: [bool; 4],
    error: LinakErrors,
    speed_mm_s: f64,
}

/// The TPDO1 frames of the trace, in its order.
const TPDO1_FRAMES: [(&str, Feedback); 5] = [
    (
        "start-up, power-up lock",
        Feedback {
            frame: STARTUP,
            position_mm: 0.0,
            current_a: None,
            flags: [true, false, false, false],
            error: LinakErrors::PowerUpLock,
            speed_mm_s: 0.0,
        },
    ),
    (
        "running out at 2.6 mm",
        Feedback {
            frame: RUNNING_OUT,
            position_mm: 2.6,
            current_a: Some(1.5),
            flags: [false, false, true, false],
            error: LinakErrors::NoError,
            speed_mm_s: 4.9,
        },
    ),
    (
        // "1A0 F7 01 00 82 00 00 00 C0"
        "end stop outwards reached, 50.3 mm",
        Feedback {
            frame: [0xF7, 0x01, 0x00, 0x82, 0x00, 0x00, 0x00, 0xC0],
            position_mm: 50.3,
            current_a: None,
            flags: [false, true, false, false],
            error: LinakErrors::NoError,
            speed_mm_s: 0.0,
        },
    ),
    (
        // "1A0 60 00 06 90 00 32 00 C0"
        "running in at 9.6 mm",
        Feedback {
            frame: [0x60, 0x00, 0x06, 0x90, 0x00, 0x32, 0x00, 0xC0],
            position_mm: 9.6,
            current_a: Some(1.5),
            flags: [false, false, false, true],
            error: LinakErrors::NoError,
            speed_mm_s: 5.0,
        },
    ),
    (
        // "1A0 00 00 00 81 00 00 00 C0"
        "end stop inwards, 0 mm, no error",
        Feedback {
            frame: [0x00, 0x00, 0x00, 0x81, 0x00, 0x00, 0x00, 0xC0],
            position_mm: 0.0,
            current_a: None,
            flags: [true, false, false, false],
            error: LinakErrors::NoError,
            speed_mm_s: 0.0,
        },
    ),
];

#[test]
fn tpdo1_frames_decode_to_the_manuals_values() {
    for (what, expected) in TPDO1_FRAMES {
        let fb = pdo::Tpdo1Feedback::decode(&expected.frame).unwrap();
        assert_eq!(position_mm(fb.position), expected.position_mm, "{what}");
        match expected.current_a {
            Some(amps) => assert_eq!(current_a(fb.current), amps, "{what}"),
            None => assert_eq!(
                fb.current,
                od::feedback::CurrentValue::NOT_RUNNING,
                "{what}"
            ),
        }
        let s = fb.status_flags;
        let flags = [
            s.end_stop_in(),
            s.end_stop_out(),
            s.running_out(),
            s.running_in(),
        ];
        assert_eq!(flags, expected.flags, "{what}");
        assert!(s.always_set(), "{what}");
        assert_eq!(fb.error_code.kind(), expected.error, "{what}");
        assert_eq!(speed_mm_s(fb.speed), expected.speed_mm_s, "{what}");
    }
}

#[test]
fn startup_frame_reports_power_up_lock() {
    let fb = pdo::Tpdo1Feedback::decode(&STARTUP).unwrap();
    assert_eq!(fb.error_code.to_raw(), 1);
    assert_eq!(
        fb.error_code.kind().remedy(),
        Some("Send Stop (0xFB03) or Clear error (0xFB00)")
    );
}

#[test]
fn running_out_frame_reports_the_aux_inputs() {
    // AUX byte 0xC0: inputs 1-3 at 0-25 % VCC, input 4 at 76-100 % (level 3 × 25 %).
    let fb = pdo::Tpdo1Feedback::decode(&RUNNING_OUT).unwrap();
    assert_eq!(fb.aux_inputs.input_level_1(), 0);
    assert_eq!(fb.aux_inputs.input_level_3(), 0);
    assert_eq!(fb.aux_inputs.input_level_4(), 3);
    assert_eq!(fb.aux_inputs.input_level_4_value(), 75.0);
}

fn command(position: od::command::PositionValue) -> pdo::Rpdo1Command {
    use od::command::*;
    pdo::Rpdo1Command {
        position,
        current_limit: CurrentLimitValue::DEFAULT,
        speed: SpeedValue::DEFAULT,
        soft_start: SoftStartValue::DEFAULT,
        soft_stop: SoftStopValue::DEFAULT,
        reserved_6: 0,
        reserved_7: 0,
    }
}

#[test]
fn commands_encode_to_the_trace_frames() {
    use od::command::PositionValue;
    let stop = [0x03, 0xFB, 0xFB, 0xFB, 0xFB, 0xFB, 0x00, 0x00];
    let run_out = [0x01, 0xFB, 0xFB, 0xFB, 0xFB, 0xFB, 0x00, 0x00];
    let run_in = [0x02, 0xFB, 0xFB, 0xFB, 0xFB, 0xFB, 0x00, 0x00];
    assert_eq!(command(PositionValue::STOP).encode(), stop);
    assert_eq!(command(PositionValue::RUN_OUT).encode(), run_out);
    assert_eq!(command(PositionValue::RUN_IN).encode(), run_in);
    // And back: the frames decode to those commands.
    assert_eq!(
        pdo::Rpdo1Command::decode(&stop).unwrap(),
        command(PositionValue::STOP)
    );
    assert_eq!(
        pdo::Rpdo1Command::decode(&run_in).unwrap().position,
        PositionValue::RUN_IN
    );
}

#[test]
fn position_setpoint_in_millimetres() {
    use od::command::{PositionKind, PositionNumber, PositionValue};
    let target = PositionNumber::from_value(12.3).expect("in range");
    assert_eq!(target.to_raw(), 123);
    let frame = command(PositionValue::from_number(target)).encode();
    assert_eq!(frame[..2], [123, 0]);
    // 0xFB00 and up are commands, not positions: out of the numeric range.
    assert_eq!(PositionNumber::from_value(6425.6), None);
    assert_eq!(PositionNumber::from_value(-0.1), None);
    assert_eq!(PositionNumber::from_value(f64::NAN), None);
    assert_eq!(PositionValue::from_raw(0xFB00), PositionValue::CLEAR_ERROR);
    assert_eq!(PositionValue::CLEAR_ERROR.kind(), PositionKind::ClearError);
    assert_eq!(
        PositionValue::from_raw(0xFB07).kind(),
        PositionKind::Invalid(0xFB07)
    );
}

#[test]
fn short_and_long_frames_are_errors() {
    assert_eq!(
        pdo::Tpdo1Feedback::decode(&[0x00; 7]),
        Err(PdoLengthError {
            expected: 8,
            actual: 7
        })
    );
    assert_eq!(
        pdo::Tpdo1Feedback::decode(&[0x00; 9]),
        Err(PdoLengthError {
            expected: 8,
            actual: 9
        })
    );
    assert!(pdo::Rpdo1Command::decode(&[]).is_err());
}
