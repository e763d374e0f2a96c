// A write-only object does not go into a TPDO: the device reads what it
// transmits by TPDO. No seed device has a write-only object that is also
// PDO-mappable (the example drive's write-only 0x2001 "Reset trip counter"
// has PDOMapping=0, which `not_mappable_in_pdo` covers), so this one is
// declared as generated code would declare it.
use eds2rust_drivers::runtime::od::{DataType, Entry, PdoMappable, access, tpdo_mapping_entry};

pub struct ResetTripCounter;
impl Entry for ResetTripCounter {
    const INDEX: u16 = 0x2001;
    const SUBINDEX: u8 = 0;
    const NAME: &'static str = "Reset trip counter";
    const DATA_TYPE: DataType = DataType::Unsigned8;
    const PDO_MAPPABLE: bool = true;
    type Access = access::Wo;
    type Value = u8;
}
impl PdoMappable for ResetTripCounter {}

const TPDO1: [u32; 1] = [tpdo_mapping_entry::<ResetTripCounter>()];

fn main() {
    let _ = TPDO1;
}
