//! `#[derive(Pdo)]` on the Interroll drive's generated objects: a custom
//! TPDO (statusword, mode display, a gap, position) and RPDO (controlword,
//! target velocity), their layout, mapping and codec, against frames worked
//! out by hand from CiA 301's layout (little endian, fields in mapping
//! order from bit 0).

use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_runtime::od::{Entry, NodeId, Pdo as _, PdoDirection, PdoLengthError, Scalar};
use eds2rust_runtime::pdo::PdoCobId;
use eds2rust_runtime::{CanId, Pdo};

#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 2)]
pub struct StatusPosition {
    #[pdo(entry = od::Statusword)]
    pub status: <od::Statusword as Entry>::Value,
    #[pdo(entry = od::ModesOfOperationDisplay)]
    pub mode: od::ModesOfOperationDisplayValue,
    #[pdo(gap = 8)]
    pub reserved: (),
    #[pdo(entry = od::PositionActualValue)]
    pub position: od::PositionActualValueValue,
}

#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(rpdo = 1)]
pub struct ControlVelocity {
    #[pdo(entry = od::Controlword)]
    pub control: <od::Controlword as Entry>::Value,
    #[pdo(entry = od::TargetVelocity)]
    pub velocity: od::TargetVelocityValue,
}

/// A field of 4 bits of a 32-bit object, and a signed 12-bit window.
#[derive(Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 5)]
pub struct Short {
    #[pdo(entry = od::PositionActualValue, bits = 12)]
    pub low: od::PositionActualValueValue,
    #[pdo(gap = 3)]
    pub gap: (),
    #[pdo(entry = od::Statusword, bits = 1)]
    pub ready: <od::Statusword as Entry>::Value,
}

#[test]
fn layout_mapping_and_cob_ids() {
    assert_eq!(StatusPosition::LEN, 8);
    assert_eq!(
        StatusPosition::MAPPING,
        [0x6041_0010, 0x6061_0008, 0x0005_0008, 0x6064_0020]
    );
    assert_eq!(StatusPosition::DIRECTION, PdoDirection::Tpdo);
    assert_eq!(
        (
            StatusPosition::COMMUNICATION_INDEX,
            StatusPosition::MAPPING_INDEX
        ),
        (0x1801, 0x1A01)
    );
    let node = NodeId::new(5).unwrap();
    assert_eq!(StatusPosition::cob_id(node), PdoCobId(0x285));
    assert_eq!(StatusPosition::can_id(node), CanId::Standard(0x285));
    assert_eq!(StatusPosition::default_cob_id(node), Some(PdoCobId(0x285)));
    assert_eq!(ControlVelocity::cob_id(node), PdoCobId(0x205));
    assert_eq!(ControlVelocity::MAPPING, [0x6040_0010, 0x60FF_0020]);
    assert_eq!(ControlVelocity::LEN, 6);
    // Above 4 there is no predefined COB-ID.
    assert_eq!(Short::default_cob_id(node), None);
    assert_eq!(
        Short::MAPPING,
        [
            0x6064_000C,
            0x0001_0001,
            0x0001_0001,
            0x0001_0001,
            0x6041_0001
        ]
    );
    assert_eq!(Short::LEN, 2);
}

#[test]
fn frames_decode_and_encode_by_hand() {
    // Statusword 0x0637, mode display -3 (0xFD), gap, position -2 (0xFFFFFFFE).
    let frame = [0x37, 0x06, 0xFD, 0x00, 0xFE, 0xFF, 0xFF, 0xFF];
    let p = StatusPosition::decode(&frame).unwrap();
    assert_eq!(p.status.to_raw(), 0x0637);
    assert_eq!(Scalar::to_raw(p.mode) as i8, -3);
    assert_eq!(Scalar::to_raw(p.position) as i32, -2);
    assert_eq!(p.encode(), frame);
    assert_eq!(
        StatusPosition::decode(&frame[..7]),
        Err(PdoLengthError {
            expected: 8,
            actual: 7
        })
    );
    // 12 bits of the position (0xABC, negative: sign-extended), 3 gap bits,
    // 1 bit of the statusword.
    let short = Short::decode(&[0xBC, 0x8A]).unwrap();
    assert_eq!(Scalar::to_raw(short.low) as i32, 0xABC - 0x1000);
    assert_eq!(short.ready.to_raw(), 1);
    assert_eq!(short.encode(), [0xBC, 0x8A]);
    let c = ControlVelocity {
        control: <od::Controlword as Entry>::Value::from_raw(0x000F),
        velocity: od::TargetVelocityValue::from_raw(1000),
    };
    assert_eq!(c.encode(), [0x0F, 0x00, 0xE8, 0x03, 0x00, 0x00]);
    assert_eq!(ControlVelocity::decode(&c.encode()), Ok(c));
}
