//! The generated API of the device, locked: a device update that renames,
//! retypes, adds or removes an item, or changes a named value, a bit field
//! or a PDO layout fails here with a diff of the lines that changed
//! (`cargo insta review` accepts it). With `CI` set, insta writes nothing
//! and fails on a mismatch.

use api_lock::linak;
use eds2rust_runtime::od::Scaled;

#[test]
fn the_generated_api_is_locked() {
    insta::assert_snapshot!("linak_api", api_lock::API);
}

/// The listing names what the code has: a few of its lines, used.
#[test]
fn listed_items_are_usable() {
    let frame = [0x10, 0x27, 0, 0, 0, 0, 0, 0];
    let feedback = linak::pdo::Tpdo1Feedback::decode(&frame).expect("8 bytes");
    let position = feedback.position.number().expect("a position");
    assert!((position.value() - 1000.0).abs() < 1e-9);
    assert!(api_lock::API.contains(
        "pdo::Tpdo1Feedback\t0x1A00\ttpdo 1\t8 bytes\tposition@0..16:od::feedback::PositionValue"
    ));
    let stop = linak::od::command::PositionValue::STOP;
    assert_eq!(stop.to_raw(), 0xFB03);
    assert!(api_lock::API.contains("0xFB03 \"stop\""));
}
