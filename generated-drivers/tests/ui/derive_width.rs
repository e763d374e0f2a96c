// An INTEGER24 entry in an `i32` field: the struct's layout table would
// state 32 bits, so the derive asks for `bits = 24`. The entry is written
// by hand, as a device crate's generator would write it.
use eds2rust_drivers::runtime::od::{access, DataType, Entry, PdoMappable};
use eds2rust_drivers::runtime::Pdo;

pub struct PositionDemand24;
impl Entry for PositionDemand24 {
    const INDEX: u16 = 0x2100;
    const SUBINDEX: u8 = 0;
    const NAME: &'static str = "Position demand (24 bit)";
    const DATA_TYPE: DataType = DataType::Integer24;
    const PDO_MAPPABLE: bool = true;
    type Access = access::Ro;
    type Value = i32;
}
impl PdoMappable for PositionDemand24 {}

#[derive(Pdo)]
#[pdo(tpdo = 3, runtime = eds2rust_drivers::runtime)]
pub struct Unstated {
    #[pdo(entry = PositionDemand24)]
    pub demand: i32,
}

// With the width written out, it compiles.
#[derive(Pdo)]
#[pdo(tpdo = 4, runtime = eds2rust_drivers::runtime)]
pub struct Stated {
    #[pdo(entry = PositionDemand24, bits = 24)]
    pub demand: i32,
}

fn main() {}
