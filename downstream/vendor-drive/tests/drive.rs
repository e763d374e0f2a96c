//! The generated API as a user sees it: typed entries and PDO structs.

use eds2rust_runtime::CanId;
use eds2rust_runtime::cia402;
use eds2rust_runtime::od::{Entry, NodeId, Pdo};
use vendor_drive::drive::{od, pdo};

#[test]
fn typed_entries() {
    assert_eq!(<od::Statusword as Entry>::INDEX, 0x6041);
    assert_eq!(<od::Statusword as Entry>::SUBINDEX, 0);
}

#[test]
fn tpdo1_decodes_statusword_mode_and_timestamp() {
    let frame = [0x37, 0x02, 0x01, 0x78, 0x56, 0x34, 0x12];
    let tpdo = pdo::Tpdo1::decode(&frame).unwrap();
    // The vendor DCF says nothing of the statusword's bits or the modes:
    // they are the built-in CiA 402 meaning, and the statusword is the
    // runtime's `cia402::Statusword` at no cost.
    assert_eq!(tpdo.statusword.to_raw(), 0x0237);
    assert!(tpdo.statusword.is_operation_enabled());
    let status = cia402::Statusword::from(tpdo.statusword);
    assert_eq!(status.state(), Some(cia402::State::OperationEnabled));
    assert_eq!(tpdo.modes_of_operation_display.to_raw(), 1);
    assert_eq!(
        cia402::ModeOfOperation::from(tpdo.modes_of_operation_display),
        cia402::ModeOfOperation::ProfilePosition
    );
    assert_eq!(tpdo.timestamp, 0x1234_5678);
    assert_eq!(tpdo.encode(), frame);
    assert!(pdo::Tpdo1::decode(&frame[..6]).is_err());
    let node = NodeId::new(3).unwrap();
    assert_eq!(
        pdo::Tpdo1::default_cob_id(node).map(|cob| cob.can_id()),
        Some(CanId::Standard(0x183))
    );
}

#[test]
fn the_overlay_fix_gives_rpdo2_its_struct() {
    // 0x2012 is mapped with its 64 bits now, so RPDO2 is generated.
    assert_eq!(<pdo::Rpdo2 as Pdo>::LEN, 8);
    assert_eq!(<pdo::Rpdo2 as Pdo>::MAPPING, [0x2012_0040]);
}
