//! eds2rust-derive: procedural macros for eds2rust.
//!
//! This crate will hold the `#[derive(Pdo)]` macro: a user declares a custom PDO
//! mapping as a plain struct whose fields name object-dictionary objects of a
//! generated driver; the macro checks mappability and total size (at most 64
//! bits) at compile time, with errors spanned on the offending field, and emits
//! `encode`/`decode` plus the SDO writes that configure the mapping on the
//! device. Nothing is implemented yet.
#![forbid(unsafe_code)]
