use std::path::PathBuf;

fn main() -> Result<(), eds2rust::Error> {
    // The vendor file is read where it lies (the shared EDS corpus beside
    // the eds2rust checkout).
    let dcf = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/eds-corpus/files/lely_co-nmt-slave.dcf");
    eds2rust::Builder::new().device("slave", dcf).generate()
}
