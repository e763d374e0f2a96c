//! Generates the seed machine's network from eds/machine/bus.yml through
//! the builder a downstream crate's build script uses.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    eds2rust::Builder::new()
        .network("machine", "../eds/machine/bus.yml")
        // The seed files are ours: any warning is a mistake to fix.
        .strict(true)
        .generate()?;
    Ok(())
}
