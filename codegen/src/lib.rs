//! eds2rust: reads CANopen object dictionaries and generates typed Rust.
//!
//! Pipeline (one stage per module):
//! - [`eds`]: EDS/DCF text (CiA 306) → [`ir::Device`], with diagnostics;
//! - [`ir`]: the object-dictionary model, plain data;
//! - [`dump`]: IR → JSON for tools and tests;
//! - [`diag`]: diagnostics with file, line, section and key.

pub mod diag;
pub mod dump;
pub mod eds;
pub mod ir;
