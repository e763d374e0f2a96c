// The elements of a read-only array cannot be written, chosen at compile
// time or at run time: Zimmer's error history (0x1003 subs 1 to 4) is ro.
use eds2rust_drivers::runtime::od::{Element, encode_value};
use eds2rust_drivers::zimmer_acs::errors::ZimmerErrorsCode;
use eds2rust_drivers::zimmer_acs::od::pre_defined_error_field::PreDefinedErrorField;

fn main() {
    let mut buf = [0u8; 8];
    let _ = encode_value::<PreDefinedErrorField<1>>(ZimmerErrorsCode::from_raw(0), &mut buf);
    let second = Element::<PreDefinedErrorField>::new(2).unwrap();
    let _ = second.rpdo_mapping_entry();
}
