// An RPDO is written into the device's objects: the statusword (ro) cannot
// be in one.
use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_drivers::runtime::Pdo;
use eds2rust_drivers::runtime::od::Entry;

#[derive(Pdo)]
#[pdo(rpdo = 1, runtime = eds2rust_drivers::runtime)]
pub struct Command {
    #[pdo(entry = od::Controlword)]
    pub control: <od::Controlword as Entry>::Value,
    #[pdo(entry = od::Statusword)]
    pub status: <od::Statusword as Entry>::Value,
}

fn main() {}
