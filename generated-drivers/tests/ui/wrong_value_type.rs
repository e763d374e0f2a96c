// The LINAK command position takes its generated value type, not a raw u16:
// a forgotten scale or a special value passed as a number does not compile.
use eds2rust_drivers::linak_techline::od::command;
use eds2rust_drivers::runtime::od::encode_value;

fn main() {
    let mut buf = [0u8; 8];
    let _ = encode_value::<command::Position>(26u16, &mut buf);
}
