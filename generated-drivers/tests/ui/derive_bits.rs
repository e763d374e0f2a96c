// `bits` maps the low bits of an entry: 17 bits of a 16-bit statusword do
// not exist, and 0 bits is no mapping.
use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_drivers::runtime::Pdo;
use eds2rust_drivers::runtime::od::Entry;

#[derive(Pdo)]
#[pdo(tpdo = 1, runtime = eds2rust_drivers::runtime)]
pub struct TooMany {
    #[pdo(entry = od::Statusword, bits = 17)]
    pub status: <od::Statusword as Entry>::Value,
}

#[derive(Pdo)]
#[pdo(tpdo = 2, runtime = eds2rust_drivers::runtime)]
pub struct Zero {
    #[pdo(entry = od::Statusword, bits = 0)]
    pub status: <od::Statusword as Entry>::Value,
}

fn main() {}
