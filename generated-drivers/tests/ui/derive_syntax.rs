// What the derive refuses by its syntax, each at its place: an empty
// struct, a tuple struct, generics, an unknown key, a field without an
// attribute, a PDO number out of range, a struct without direction.
use eds2rust_drivers::interroll_ec5000bi::od;
use eds2rust_drivers::runtime::Pdo;

#[derive(Pdo)]
#[pdo(tpdo = 1)]
pub struct Empty {}

#[derive(Pdo)]
#[pdo(tpdo = 1)]
pub struct Tuple(u16);

#[derive(Pdo)]
#[pdo(tpdo = 1)]
pub struct Generic<T> {
    #[pdo(entry = od::Statusword)]
    pub status: T,
}

#[derive(Pdo)]
#[pdo(tpdo = 1)]
pub struct Unknown {
    #[pdo(entry = od::Statusword, offset = 3)]
    pub status: u16,
}

#[derive(Pdo)]
#[pdo(tpdo = 1)]
pub struct Bare {
    pub status: u16,
}

#[derive(Pdo)]
#[pdo(tpdo = 513)]
pub struct Number {
    #[pdo(entry = od::Statusword)]
    pub status: u16,
}

#[derive(Pdo)]
pub struct NoDirection {
    #[pdo(entry = od::Statusword)]
    pub status: u16,
}

fn main() {}
