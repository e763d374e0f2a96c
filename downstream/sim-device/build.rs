//! Generates the `conveyor` module from the crate's own object table.

fn main() -> Result<(), eds2rust::Error> {
    eds2rust::Builder::new()
        .device("conveyor", "od/conveyor.yaml")
        // The table is ours: a warning is a mistake to fix.
        .strict(true)
        .generate()
}
