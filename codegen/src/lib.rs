//! eds2rust: reads CANopen object dictionaries and generates typed Rust.
//!
//! This is the library a build script depends on; the `eds2rust` command
//! line is the `eds2rust-cli` crate.
//!
//! Pipeline (one stage per module):
//! - [`eds`]: EDS/DCF text (CiA 306) → [`ir::Device`], with diagnostics;
//! - [`table`]: YAML object tables (whole devices and overlays on an EDS) → [`ir::Device`];
//! - [`read`]: what both readers share (options, the result of reading);
//! - [`input`]: either of the two, chosen by file extension;
//! - [`ir`]: the object-dictionary model, plain data;
//! - `dump` (feature `json`): IR → JSON for tools and tests;
//! - `gen` (`r#gen`: `gen` is a reserved word in Rust 2024): IR → files: an EDS (CiA 306) export, product variants applied;
//! - [`diff`]: a semantic diff of two devices, each change classified
//!   breaking, additive or compatible (`eds2rust diff`);
//! - [`diag`]: diagnostics with file, line, section and key;
//! - [`build`]: the build-script API ([`Builder`], in the shape of
//!   prost-build) and the pure [`generate`]: input + overlays → Rust source.
#![forbid(unsafe_code)]

pub mod bounded;
pub mod build;
pub mod diag;
#[cfg(feature = "diff")]
pub mod diff;
#[cfg(feature = "json")]
pub mod dump;
pub mod eds;
pub mod r#gen;
pub mod input;
pub mod ir;
#[cfg(feature = "network")]
pub mod network;
pub mod profiles;
pub mod read;
#[cfg(feature = "yaml")]
pub mod table;
pub mod text;

pub use build::{Builder, Error, generate};
