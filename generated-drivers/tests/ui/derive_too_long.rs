// A PDO holds 64 bits: three 32-bit objects do not fit, and the error is
// at the field that crosses bit 64.
use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_drivers::runtime::Pdo;

#[derive(Pdo)]
#[pdo(tpdo = 1, runtime = eds2rust_drivers::runtime)]
pub struct Everything {
    #[pdo(entry = od::PositionActualValue)]
    pub position: od::PositionActualValueValue,
    #[pdo(entry = od::VelocityActualValue)]
    pub velocity: od::VelocityActualValueValue,
    #[pdo(entry = od::TargetVelocity)]
    pub target: od::TargetVelocityValue,
}

fn main() {}
