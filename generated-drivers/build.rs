//! Generates one module per seed device from the YAML tables in `eds/`,
//! through the same builder a downstream crate's build script uses, and the
//! list of generated value types tests/value_roundtrip.rs checks.

#[path = "build_roundtrip.rs"]
mod roundtrip;

const DEVICES: &[&str] = &[
    "zimmer_acs",
    "linak_techline",
    "interroll_ec5000bi",
    "example",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    eds2rust::Builder::new()
        .device("zimmer_acs", "../eds/zimmer_acs.yaml")
        .device("linak_techline", "../eds/linak_techline.yaml")
        .device("interroll_ec5000bi", "../eds/interroll_ec5000bi.yaml")
        // The README's example EDS: a plain EDS with no semantic layer.
        .device("example", "../eds/example.eds")
        // The seed tables are ours: any warning is a mistake to fix.
        .strict(true)
        .generate()?;
    let out_dir =
        std::path::PathBuf::from(std::env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
    roundtrip::write_cases(&out_dir, DEVICES)?;
    println!("cargo::rerun-if-changed=build_roundtrip.rs");
    Ok(())
}
