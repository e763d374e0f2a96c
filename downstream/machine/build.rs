//! Generates the typed network of the machine from its bus file: a module
//! per node (`axis`, `actuator`, `conveyor`) and `network`.

fn main() -> Result<(), eds2rust::Error> {
    eds2rust::Builder::new()
        .network("machine", "../../eds/machine/bus.yml")
        // The bus file is ours: a warning is a mistake to fix.
        .strict(true)
        .generate()
}
