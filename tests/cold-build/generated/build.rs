use std::path::PathBuf;

fn main() -> Result<(), eds2rust::Error> {
    // The vendor file is read where it lies: the shared EDS corpus beside
    // the eds2rust checkout (the benchmark does not run without it).
    let dcf = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../../shared/eds-corpus/files/elmo_gold-drive_ros-test-utils.dcf");
    eds2rust::Builder::new()
        .device("drive", dcf)
        // What the DCF warns about, allowed (downstream/vendor-drive fixes the
        // mapping with an overlay instead): [PreDefines] is a tool's private
        // section, two objects share a name, RPDO2 maps a 64-bit object with
        // 32 bits (and is left out).
        .allow("eds::unknown-section")
        .allow("gen::name-collision")
        .allow("eds::pdo-mapping")
        .allow("gen::pdo-skipped")
        .generate()
}
