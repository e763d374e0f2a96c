// A field has its entry's value type: the position actual value is not an
// i16.
use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_drivers::runtime::Pdo;

#[derive(Pdo)]
#[pdo(tpdo = 1, runtime = eds2rust_drivers::runtime)]
pub struct Position {
    #[pdo(entry = od::PositionActualValue)]
    pub position: i16,
}

fn main() {}
