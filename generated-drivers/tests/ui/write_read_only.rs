// Writing a read-only object (LINAK feedback position, 0x2001 sub 1) does not compile.
use eds2rust_drivers::linak_techline::od::feedback;
use eds2rust_drivers::runtime::od::encode_value;

fn main() {
    let mut buf = [0u8; 8];
    let value = feedback::PositionValue::from_raw(26);
    let _ = encode_value::<feedback::Position>(value, &mut buf);
}
