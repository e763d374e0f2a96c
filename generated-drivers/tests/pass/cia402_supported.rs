// The generated table of a CiA 402 drive passes the compile-time check of
// the modes the application uses; the run-time check names what a mode
// the device lacks needs.
use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_drivers::runtime::cia402::requirements::{Operation, assert_supported};

const _: () = assert_supported(
    od::OBJECTS,
    &[Operation::StateMachine, Operation::ProfilePosition, Operation::ProfileVelocity, Operation::Homing],
);

fn main() {
    let linak = eds2rust_drivers::linak_techline::od::OBJECTS;
    let e = Operation::StateMachine.check(linak).unwrap_err();
    assert_eq!(
        e.to_string(),
        "the CiA 402 state machine needs 0x6040 Controlword, which this device does not have"
    );
}
