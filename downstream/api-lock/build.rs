//! Generates the `linak` module from the repository's LINAK TECHLINE table
//! and writes the listing of its API beside it (`linak.api` in OUT_DIR),
//! which tests/api.rs locks in a snapshot.

use std::path::{Path, PathBuf};

const TABLE: &str = "../../eds/linak_techline.yaml";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    eds2rust::Builder::new().device("linak", TABLE).generate()?;
    let listing = eds2rust::build::api_listing_files(
        Path::new(TABLE),
        &[],
        &eds2rust::read::Options::default(),
    )
    .map_err(|diagnostics| diagnostics.render())?;
    let out = PathBuf::from(std::env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
    std::fs::write(out.join("linak.api"), listing.text)?;
    Ok(())
}
