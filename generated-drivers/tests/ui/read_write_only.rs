// Reading a write-only object (example drive 0x2001) does not compile.
use eds2rust_drivers::example::od::ResetTripCounter;
use eds2rust_drivers::runtime::od::decode_value;

fn main() {
    let _ = decode_value::<ResetTripCounter>(&[1]);
}
