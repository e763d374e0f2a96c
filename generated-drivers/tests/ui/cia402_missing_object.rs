// An application states the CiA 402 modes it uses; a device table without
// an object one of them needs does not compile. The LINAK actuator has no
// controlword at all.
use eds2rust_drivers::linak_techline::od;
use eds2rust_drivers::runtime::cia402::requirements::{Operation, assert_supported};

const _: () = assert_supported(od::OBJECTS, &[Operation::StateMachine, Operation::ProfilePosition]);

fn main() {}
