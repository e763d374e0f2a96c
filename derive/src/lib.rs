//! eds2rust-derive: `#[derive(Pdo)]`, a custom PDO mapping declared as a
//! plain struct whose fields name object-dictionary entries of a generated
//! device (re-exported by `eds2rust-runtime` as `eds2rust_runtime::Pdo`).
//!
//! ```ignore
//! #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
//! #[pdo(tpdo = 2)]
//! pub struct StatusPosition {
//!     #[pdo(entry = drive::od::Statusword)]
//!     pub status: <drive::od::Statusword as Entry>::Value,
//!     #[pdo(entry = drive::od::PositionActualValue)]
//!     pub position: i32,
//!     #[pdo(gap = 8)]
//!     pub reserved: (),
//! }
//! ```
//!
//! The expansion holds no codec of its own: decoding and encoding are the
//! runtime's `pdo::layout` functions (the same the generator's default-PDO
//! structs call), with offsets and widths computed in constants from the
//! entries' data types. What can only be known from the entry types
//! (mappability, direction, value type, sizes, the same object twice) is
//! checked by trait bounds with their own messages, spanned on the field;
//! what the syntax shows (an empty or tuple struct, generics, unknown keys,
//! `bits = 0`) is a `compile_error!` at its place. The macro never panics.
#![forbid(unsafe_code)]

mod expand;
mod layout_doc;
mod parse;

use proc_macro::TokenStream;

/// Derives `LEN`, `decode`, `encode`, the predefined COB-IDs and
/// `eds2rust_runtime::od::Pdo` for a struct of mapped entries. See the
/// crate documentation and docs/custom-pdos.md.
#[proc_macro_derive(Pdo, attributes(pdo))]
pub fn derive_pdo(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as syn::DeriveInput);
    match parse::pdo(&input) {
        Ok(pdo) => expand::expand(&pdo).into(),
        Err(e) => e.to_compile_error().into(),
    }
}
