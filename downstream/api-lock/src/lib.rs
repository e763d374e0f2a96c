//! The LINAK TECHLINE driver generated from `eds/linak_techline.yaml`, and
//! the listing of its API (`API`), locked by tests/api.rs.
#![no_std]

/// The generated driver.
pub mod linak {
    include!(concat!(env!("OUT_DIR"), "/linak.rs"));
}

/// The listing of the generated API of [`linak`], one line per public item
/// (`eds2rust api`, docs/api-listing.md).
pub const API: &str = include_str!(concat!(env!("OUT_DIR"), "/linak.api"));
