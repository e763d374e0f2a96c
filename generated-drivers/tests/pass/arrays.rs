// An ARRAY's elements are one type indexed by sub-index: the element at a
// constant sub-index is an entry like any other, and the run-time form
// checks the sub-index and iterates over the valid ones.
use eds2rust_drivers::interroll_ec5000bi::od::pre_defined_error_field::PreDefinedErrorField;
use eds2rust_drivers::linak_techline::od::consumer_heartbeat_time::{
    ConsumerHeartbeatTime, ConsumerHeartbeatTimeValue,
};
use eds2rust_drivers::runtime::od::{Array, Element, Entry, decode_value, encode_value};

fn main() {
    // Compile-time form: sub 1 of LINAK's consumer heartbeat times (rw).
    assert_eq!(<ConsumerHeartbeatTime<1> as Entry>::INDEX, 0x1016);
    assert_eq!(<ConsumerHeartbeatTime<1> as Entry>::SUBINDEX, 1);
    let mut buf = [0u8; 8];
    let value = ConsumerHeartbeatTimeValue::from_raw(0x0001_00C8);
    assert_eq!(encode_value::<ConsumerHeartbeatTime<1>>(value, &mut buf), Ok(4));
    assert_eq!(buf[..4], [0xC8, 0x00, 0x01, 0x00]);
    // Run-time form: the range, the checked constructor, iteration.
    assert_eq!((ConsumerHeartbeatTime::FIRST, ConsumerHeartbeatTime::LAST), (1, 1));
    assert!(Element::<ConsumerHeartbeatTime>::new(0).is_none());
    assert!(Element::<ConsumerHeartbeatTime>::new(2).is_none());
    let all: Vec<u8> = Element::<PreDefinedErrorField>::all().map(|e| e.subindex()).collect();
    assert_eq!(all, (PreDefinedErrorField::FIRST..=PreDefinedErrorField::LAST).collect::<Vec<_>>());
    assert_eq!(Element::<PreDefinedErrorField>::count(), all.len());
    let third = Element::<PreDefinedErrorField>::new(3).expect("in range");
    assert_eq!((third.index(), third.subindex()), (0x1003, 3));
    assert_eq!(third.to_string(), "0x1003.3");
    // Elements decode like any entry (the value type is shared).
    let code = decode_value::<PreDefinedErrorField<3>>(&[0x10, 0x32, 0, 0]).unwrap();
    assert_eq!(code.to_raw(), 0x3210);
}
