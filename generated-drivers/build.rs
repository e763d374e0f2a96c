//! Generates one module per seed device from the YAML tables in `eds/`,
//! through the same builder a downstream crate's build script uses.

fn main() -> Result<(), eds2rust::Error> {
    eds2rust::Builder::new()
        .device("zimmer_acs", "../eds/zimmer_acs.yaml")
        .device("linak_techline", "../eds/linak_techline.yaml")
        .device("interroll_ec5000bi", "../eds/interroll_ec5000bi.yaml")
        // The README's example EDS: a plain EDS with no semantic layer.
        .device("example", "../eds/example.eds")
        // The seed tables are ours: any warning is a mistake to fix.
        .strict(true)
        .generate()
}
