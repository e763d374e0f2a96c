// A PDO maps an object once.
use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_drivers::runtime::Pdo;
use eds2rust_drivers::runtime::od::Entry;

#[derive(Pdo)]
#[pdo(tpdo = 1, runtime = eds2rust_drivers::runtime)]
pub struct Twice {
    #[pdo(entry = od::Statusword)]
    pub status: <od::Statusword as Entry>::Value,
    #[pdo(entry = od::Statusword)]
    pub again: <od::Statusword as Entry>::Value,
}

fn main() {}
