//! What the value-type emitters (values.rs and the bit-field, enum and
//! scaled types it dispatches to) share: their context, the documentation
//! head of a value type, and the raw-value methods of a newtype.

use proc_macro2::TokenStream;
use quote::quote;

use super::docs::{self, Doc};
use crate::ir::Entry;

/// Everything the value-type emitters need of their surroundings.
pub(crate) struct Ctx<'a> {
    pub(crate) rt: &'a TokenStream,
    pub(crate) diags: &'a mut crate::diag::Diagnostics,
}

/// The documentation head of the value type of `entry`.
pub(crate) fn value_doc(entry: &Entry, what: &str) -> Doc {
    let mut doc = Doc::new();
    doc.para(format!("{what} of **{}**.", docs::text(&entry.name)));
    if let Some(description) = &entry.semantics.description {
        doc.source_para(description);
    }
    doc.origin(&entry.origin);
    doc
}

/// `from_raw`/`to_raw` of a newtype over the raw value (`Self(pub raw)`).
pub(crate) fn raw_methods(ty: &TokenStream) -> TokenStream {
    quote! {
        #[doc = " The value with this raw form."]
        #[inline]
        pub const fn from_raw(raw: #ty) -> Self {
            Self(raw)
        }
        #[doc = " The raw form on the bus."]
        #[inline]
        pub const fn to_raw(self) -> #ty {
            self.0
        }
    }
}
