// A custom PDO may only map PDO-mappable objects: the COB-ID of SYNC
// (0x1005) is not.
use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_drivers::runtime::Pdo;

#[derive(Pdo)]
#[pdo(tpdo = 1, runtime = eds2rust_drivers::runtime)]
pub struct Sync {
    #[pdo(entry = od::CobIdSync)]
    pub cob_id: od::CobIdSyncValue,
}

fn main() {}
