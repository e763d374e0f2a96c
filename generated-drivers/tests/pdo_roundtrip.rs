//! Property tests: every default PDO of the seed devices round-trips any
//! value. Every field of these PDOs covers whole raw values (no gaps, no
//! 8-bit booleans), so every frame of the right length is a value and
//! `encode(decode(frame)) == frame`; since every value comes from some frame,
//! that also gives `decode(encode(value)) == value`. Any other length is an
//! error value, never a panic.

use core::fmt::Debug;

use eds2rust_drivers::runtime::od::{Pdo, PdoLengthError};
use eds2rust_drivers::{
    example, interroll_ec5000bi as interroll, linak_techline as linak, zimmer_acs as zimmer,
};
use proptest::prelude::*;

fn round_trip<P: Pdo + PartialEq + Debug>(frame: &[u8]) -> Result<(), TestCaseError> {
    let value = P::decode(frame).map_err(|e| TestCaseError::fail(format!("{e}")))?;
    let mut out = [0u8; 8];
    let len = value.encode_into(&mut out);
    prop_assert_eq!(len, P::LEN);
    prop_assert_eq!(&out[..len], frame);
    let again = P::decode(&out[..len]).map_err(|e| TestCaseError::fail(format!("{e}")))?;
    prop_assert_eq!(again, value);
    Ok(())
}

fn wrong_length<P: Pdo + Debug>(frame: &[u8]) -> Result<(), TestCaseError> {
    match P::decode(frame) {
        Ok(v) if frame.len() == P::LEN => drop(v),
        Ok(v) => {
            return Err(TestCaseError::fail(format!(
                "{} bytes decoded to {v:?}",
                frame.len()
            )));
        }
        Err(e) => prop_assert_eq!(
            e,
            PdoLengthError {
                expected: P::LEN,
                actual: frame.len()
            }
        ),
    }
    Ok(())
}

macro_rules! pdo_properties {
    ($($name:ident: $pdo:ty,)*) => {$(
        mod $name {
            use super::*;
            proptest! {
                #![proptest_config(ProptestConfig { cases: 2048, failure_persistence: None, ..ProptestConfig::default() })]
                #[test]
                fn any_frame_round_trips(frame in proptest::collection::vec(any::<u8>(), <$pdo as Pdo>::LEN)) {
                    round_trip::<$pdo>(&frame)?;
                }
                #[test]
                fn any_length_is_handled(frame in proptest::collection::vec(any::<u8>(), 0..=16)) {
                    wrong_length::<$pdo>(&frame)?;
                }
            }
        }
    )*};
}

pdo_properties! {
    linak_rpdo1: linak::pdo::Rpdo1Command,
    linak_tpdo1: linak::pdo::Tpdo1Feedback,
    linak_tpdo2: linak::pdo::Tpdo2ParallelFeedback,
    zimmer_rpdo1: zimmer::pdo::Rpdo1ControlAndTargetPosition,
    zimmer_rpdo2: zimmer::pdo::Rpdo2ProfileVelocity,
    zimmer_tpdo1: zimmer::pdo::Tpdo1StatusAndPosition,
    zimmer_tpdo2: zimmer::pdo::Tpdo2Velocity,
    zimmer_tpdo3: zimmer::pdo::Tpdo3FollowingErrorAndTorque,
    interroll_rpdo1: interroll::pdo::Rpdo1VelocityCommand,
    interroll_rpdo2: interroll::pdo::Rpdo2PositionCommand,
    interroll_rpdo3: interroll::pdo::Rpdo3TargetVelocityCommand,
    interroll_tpdo1: interroll::pdo::Tpdo1Status,
    interroll_tpdo2: interroll::pdo::Tpdo2Position,
    interroll_tpdo3: interroll::pdo::Tpdo3Velocity,
}

/// The example drive's TPDO1 maps the 16-bit statusword, an 8-bit dummy
/// gap and the INTEGER32 position actual value: the value is sign-extended
/// at its offset and the gap is ignored on decode and zero on encode.
#[test]
fn signed_fields_are_sign_extended_and_gaps_skipped() {
    let frame = [0x37, 0x06, 0xAA, 0xFE, 0xFF, 0xFF, 0xFF];
    let tpdo = example::pdo::Tpdo1::decode(&frame).expect("7 bytes");
    assert_eq!(tpdo.statusword.to_raw(), 0x0637);
    // The built-in CiA 402 meaning: the runtime's statusword, the same bits.
    let state = eds2rust_runtime::cia402::Statusword::from(tpdo.statusword).state();
    assert_eq!(
        state,
        Some(eds2rust_runtime::cia402::State::OperationEnabled)
    );
    assert!(tpdo.statusword.is_operation_enabled());
    assert_eq!(tpdo.position_actual_value, -2);
    assert_eq!(tpdo.encode(), [0x37, 0x06, 0x00, 0xFE, 0xFF, 0xFF, 0xFF]);
    let max = example::pdo::Tpdo1 {
        statusword: example::od::StatuswordValue::from_raw(0xFFFF),
        position_actual_value: i32::MIN,
    };
    assert_eq!(example::pdo::Tpdo1::decode(&max.encode()), Ok(max));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2048, failure_persistence: None, ..ProptestConfig::default() })]
    /// Values with gaps in the layout: decode(encode(v)) == v for any v.
    #[test]
    fn example_values_round_trip(statusword in any::<u16>(), position in any::<i32>()) {
        let statusword = example::od::StatuswordValue::from_raw(statusword);
        let v = example::pdo::Tpdo1 { statusword, position_actual_value: position };
        prop_assert_eq!(example::pdo::Tpdo1::decode(&v.encode()), Ok(v));
    }
}
