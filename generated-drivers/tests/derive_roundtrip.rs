//! Property tests of `#[derive(Pdo)]` structs with odd offsets, widths
//! shorter than their types, signed fields crossing byte boundaries and
//! gaps: every frame whose gap bits (and bits past the mapping) are zero is
//! `encode(decode(frame))`, any frame decodes as it does with those bits
//! cleared, and `decode(encode(value)) == value`. Wrong lengths are errors.

use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_drivers::runtime::Pdo;
use eds2rust_drivers::runtime::od::{Entry, Pdo as _, PdoLengthError};
use proptest::prelude::*;

/// 3 gap bits, 12 bits of the statusword, the signed mode display over a
/// byte boundary (bits 15..23), a signed 32-bit position at bit 23, 2 gap
/// bits: 57 bits, 8 bytes.
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 3, runtime = eds2rust_drivers::runtime)]
struct Odd {
    #[pdo(gap = 3)]
    head: (),
    #[pdo(entry = od::Statusword, bits = 12)]
    status: <od::Statusword as Entry>::Value,
    #[pdo(entry = od::ModesOfOperationDisplay)]
    mode: od::ModesOfOperationDisplayValue,
    #[pdo(entry = od::PositionActualValue)]
    position: od::PositionActualValueValue,
    #[pdo(gap = 2)]
    tail: (),
}

/// Bits carried by fields of `Odd` (not gaps, not past the mapping).
const ODD_FIELDS: u64 = ((1u64 << 55) - 1) & !0b111;

/// 5 bits of the controlword, then a 24-bit window of the (signed) target
/// velocity: an RPDO of 29 bits, LEN 4, no gaps.
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(rpdo = 2, runtime = eds2rust_drivers::runtime)]
struct Narrow {
    #[pdo(entry = od::Controlword, bits = 5)]
    control: <od::Controlword as Entry>::Value,
    #[pdo(entry = od::TargetVelocity, bits = 24)]
    velocity: od::TargetVelocityValue,
}

const NARROW_FIELDS: u64 = (1u64 << 29) - 1;

fn check<P: eds2rust_drivers::runtime::od::Pdo + Copy + PartialEq + core::fmt::Debug>(
    frame: [u8; 8],
    fields: u64,
) -> Result<(), TestCaseError> {
    let len = P::LEN;
    let raw = u64::from_le_bytes(frame);
    let cleared = (raw & fields).to_le_bytes();
    let value = P::decode(&frame[..len]).expect("right length");
    prop_assert_eq!(P::decode(&cleared[..len]), Ok(value));
    let mut out = [0u8; 8];
    prop_assert_eq!(value.encode_into(&mut out), len);
    prop_assert_eq!(&out[..len], &cleared[..len]);
    prop_assert_eq!(P::decode(&out[..len]), Ok(value));
    for wrong in (0..=8).filter(|&n| n != len) {
        prop_assert_eq!(
            P::decode(&frame[..wrong]),
            Err(PdoLengthError {
                expected: len,
                actual: wrong
            })
        );
    }
    Ok(())
}

proptest! {
    #[test]
    fn odd_offsets_and_gaps_round_trip(frame in any::<[u8; 8]>()) {
        check::<Odd>(frame, ODD_FIELDS)?;
    }

    #[test]
    fn narrow_windows_round_trip(frame in any::<[u8; 8]>()) {
        check::<Narrow>(frame, NARROW_FIELDS)?;
    }

    #[test]
    fn signed_fields_are_sign_extended(mode in any::<i8>(), position in any::<i32>()) {
        use eds2rust_drivers::runtime::od::Scalar;
        let word = (mode as u8 as u64) << 15 | (position as u32 as u64) << 23;
        let p = Odd::decode(&word.to_le_bytes()).expect("8 bytes");
        prop_assert_eq!(Scalar::to_raw(p.mode) as i8, mode);
        prop_assert_eq!(Scalar::to_raw(p.position) as i32, position);
        prop_assert_eq!(Odd::decode(&p.encode()), Ok(p));
    }
}

#[test]
fn layouts() {
    assert_eq!(Odd::LEN, 8);
    assert_eq!(
        Odd::MAPPING,
        [
            0x0001_0001,
            0x0001_0001,
            0x0001_0001,
            0x6041_000C,
            0x6061_0008,
            0x6064_0020,
            0x0001_0001,
            0x0001_0001
        ]
    );
    assert_eq!(Narrow::LEN, 4);
    assert_eq!(Narrow::MAPPING, [0x6040_0005, 0x60FF_0018]);
}
