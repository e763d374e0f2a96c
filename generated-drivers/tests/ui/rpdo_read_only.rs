// A read-only object (the Zimmer statusword, 0x6041, ro and PDO-mappable)
// does not go into an RPDO: the device writes what it receives by RPDO.
use eds2rust_drivers::runtime::od::rpdo_mapping_entry;
use eds2rust_drivers::zimmer_acs::od::Statusword;

const RPDO1: [u32; 1] = [rpdo_mapping_entry::<Statusword>()];

fn main() {
    let _ = RPDO1;
}
