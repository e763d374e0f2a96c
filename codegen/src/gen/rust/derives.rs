//! The derives of every generated type, in one place: each kind of type has
//! one list, used by every generator that emits that kind (see
//! docs/generated-code.md, "Derives").

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// Value types: the newtypes over a raw value `X(pub raw)` that entries and
/// PDO fields hold (`<Entry>Value` of a value table, a bit-field struct or a
/// scaled value; `<Entry>Number`; `errors::<Table>Code`). Equality, hashing
/// and ordering are those of the raw value; `Default` is raw 0, as for the
/// primitive value types (an entry's default value is `<Entry>::DEFAULT`).
pub(crate) const VALUE: &[&str] = &[
    "Debug",
    "Clone",
    "Copy",
    "PartialEq",
    "Eq",
    "Hash",
    "PartialOrd",
    "Ord",
    "Default",
];

/// Meanings: the enums of a value table (`<Entry>Kind`, the enum of a bit
/// field), of bit-field patterns (`<Entry>State`) and of error tables.
pub(crate) const MEANING: &[&str] = &["Debug", "Clone", "Copy", "PartialEq", "Eq", "Hash"];

/// Entries: the zero-sized type of each object-dictionary entry.
pub(crate) const ENTRY: &[&str] = &[
    "Debug",
    "Clone",
    "Copy",
    "PartialEq",
    "Eq",
    "Hash",
    "Default",
];

/// PDO structs: one field per mapped entry.
pub(crate) const PDO: &[&str] = &["Debug", "Clone", "Copy", "PartialEq", "Eq", "Hash"];

/// What a type holding an `f32`/`f64` cannot derive.
pub(crate) const NOT_WITH_FLOAT: &[&str] = &["Eq", "Hash", "Ord"];

/// The derives of `list` for a type that holds a float (`float`) or not.
pub(crate) fn names(list: &[&'static str], float: bool) -> Vec<&'static str> {
    list.iter()
        .copied()
        .filter(|d| !(float && NOT_WITH_FLOAT.contains(d)))
        .collect()
}

/// `#[derive(..)]` of `list` (see [`names`]).
pub(crate) fn attr(list: &[&'static str], float: bool) -> TokenStream {
    let derives = names(list, float).into_iter().map(|d| format_ident!("{d}"));
    quote!(#[derive(#(#derives),*)])
}

/// The derives of a value type over a raw value of `raw`.
pub(crate) fn value(raw: super::prim::Prim) -> TokenStream {
    attr(VALUE, raw.is_float())
}

#[cfg(test)]
mod tests;
