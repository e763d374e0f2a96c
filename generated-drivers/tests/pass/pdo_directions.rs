// Directed PDO mapping entries: readable objects into TPDOs, writable ones
// into RPDOs, read-write ones into both, in constants; they agree with the
// default mappings the generator wrote for Zimmer's PDOs.
use eds2rust_drivers::linak_techline::od::{command, feedback};
use eds2rust_drivers::runtime::od::{
    NodeId, Pdo, PdoDirection, rpdo_mapping_entry, tpdo_mapping_entry,
};
use eds2rust_drivers::runtime::pdo::PdoConfig;
use eds2rust_drivers::zimmer_acs::{od, pdo};

// Zimmer RPDO1: controlword (rw) and target position (rw).
const RPDO1: [u32; 2] = [
    rpdo_mapping_entry::<od::Controlword>(),
    rpdo_mapping_entry::<od::TargetPosition>(),
];
// Zimmer TPDO1: statusword (ro) and actual position (ro).
const TPDO1: [u32; 2] = [
    tpdo_mapping_entry::<od::Statusword>(),
    tpdo_mapping_entry::<od::PositionActualValue>(),
];
// A read-write object goes both ways.
const CONTROLWORD_IN_TPDO: u32 = tpdo_mapping_entry::<od::Controlword>();
// LINAK: the command position is rww, the feedback position ro.
const LINAK_COMMAND: u32 = rpdo_mapping_entry::<command::Position>();
const LINAK_FEEDBACK: u32 = tpdo_mapping_entry::<feedback::Position>();

fn main() {
    assert_eq!(RPDO1, [0x6040_0010, 0x607A_0020]);
    assert_eq!(RPDO1, <pdo::Rpdo1ControlAndTargetPosition as Pdo>::MAPPING);
    assert_eq!(TPDO1, [0x6041_0010, 0x6064_0020]);
    assert_eq!(TPDO1, <pdo::Tpdo1StatusAndPosition as Pdo>::MAPPING);
    assert_eq!(CONTROLWORD_IN_TPDO, RPDO1[0]);
    assert_eq!(LINAK_COMMAND, 0x2000_0110);
    assert_eq!(LINAK_FEEDBACK, 0x2001_0110);
    let node = NodeId::new(5).unwrap();
    let cob_id = pdo::Tpdo1StatusAndPosition::cob_id(node);
    let config = PdoConfig::new(PdoDirection::Tpdo, 1, cob_id, &TPDO1).unwrap();
    assert_eq!(config.check(), Ok(()));
}
