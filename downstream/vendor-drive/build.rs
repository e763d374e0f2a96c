use std::path::PathBuf;

fn main() -> Result<(), eds2rust::Error> {
    // The vendor file is read where it lies (the shared EDS corpus beside
    // the eds2rust checkout); a user points at their own copy.
    let dcf = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/eds-corpus/files/elmo_gold-drive_ros-test-utils.dcf");
    eds2rust::Builder::new()
        .device("drive", dcf)
        // Maps 0x2012 (UNSIGNED64) with its full 64 bits; see the overlay.
        .overlay("od/drive_fixes.yaml")
        // Two of the vendor's objects are both named "digital inputs"; the
        // generator qualifies both, which is what we want here.
        .allow("gen::name-collision")
        .generate()
}
