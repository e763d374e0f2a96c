// The correct counterparts of the compile-fail cases compile and behave.
use eds2rust_drivers::example::od::ResetTripCounter;
use eds2rust_drivers::linak_techline::od::{self, command, feedback};
use eds2rust_drivers::runtime::od::{Entry, decode_value, encode_value, tpdo_mapping_entry};

const FEEDBACK_POSITION: u32 = tpdo_mapping_entry::<feedback::Position>();

fn main() {
    assert_eq!(FEEDBACK_POSITION, 0x2001_0110);
    let mut buf = [0u8; 8];
    // Write the command position (rww) with its typed value.
    let n = encode_value::<command::Position>(command::PositionValue::STOP, &mut buf).unwrap();
    assert_eq!(&buf[..n], &[0x03, 0xFB]);
    // Read the feedback position (ro) from SDO upload data.
    let p = decode_value::<feedback::Position>(&[0x1A, 0x00]).unwrap();
    assert_eq!(p.number(), Some(feedback::PositionNumber(26)));
    assert_eq!(p.kind(), feedback::PositionKind::Number(feedback::PositionNumber(26)));
    // Write the write-only object; read the read/write heartbeat time.
    assert_eq!(encode_value::<ResetTripCounter>(1, &mut buf), Ok(1));
    assert_eq!(decode_value::<od::ProducerHeartbeatTime>(&[0xE8, 0x03]).map(|v| v.to_raw()), Ok(1000));
    assert_eq!(<feedback::Position as Entry>::INDEX, 0x2001);
    assert_eq!(<feedback::Position as Entry>::SUBINDEX, 1);
}
