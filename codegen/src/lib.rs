//! eds2rust: reads CANopen object dictionaries and generates typed Rust.
//!
//! This is the library a build script depends on; the `eds2rust` command
//! line is the `eds2rust-cli` crate.
//!
//! Pipeline (one stage per module):
//! - [`eds`]: EDS/DCF text (CiA 306) → [`ir::Device`], with diagnostics;
//! - `table` (feature `yaml`): YAML object tables (whole devices and overlays on an EDS) → [`ir::Device`];
//! - [`read`]: what both readers share (options, the result of reading);
//! - [`input`]: either of the two, chosen by file extension;
//! - [`ir`]: the object-dictionary model, plain data;
//! - `dump` (feature `json`): IR → JSON for tools and tests;
//! - `gen` (`r#gen`: `gen` is a reserved word in Rust 2024): IR → files: Rust,
//!   an EDS (CiA 306) export (feature `export`), product variants applied;
//! - `network` (feature `network`): bus files read, configured, generated;
//! - `diff` (feature `diff`): a semantic diff of two devices, each change
//!   classified breaking, additive or compatible (`eds2rust diff`);
//! - [`diag`]: diagnostics with file, line, section and key;
//! - [`build`]: the build-script API ([`Builder`], in the shape of
//!   prost-build) and the pure [`generate`]: input + overlays → Rust source.
//!
//! Features: none by default, so that a build script generating from
//! EDS/DCF files compiles no serde, no YAML reader and no network code.
//! Opt-in: `yaml` (YAML tables and overlays), `network` (bus files,
//! `Builder::network`), and what only the command line uses: `serde`,
//! `json`, `diff`, `api`, `export`, `network-check`, and `cli` for all of
//! them (Cargo.toml says what each adds; docs/build-api.md, "Features").
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
