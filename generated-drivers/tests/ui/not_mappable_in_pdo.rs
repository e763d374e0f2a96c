// The producer heartbeat time (LINAK 0x1017) is not PDO-mappable: it has no
// PDO mapping entry.
use eds2rust_drivers::linak_techline::od::ProducerHeartbeatTime;
use eds2rust_drivers::runtime::od::tpdo_mapping_entry;

const MAPPED: u32 = tpdo_mapping_entry::<ProducerHeartbeatTime>();

fn main() {
    let _ = MAPPED;
}
