//! Scaled newtypes: the raw value with its unit, scale and offset; the
//! conversions to and from the physical value are the runtime's
//! (`od::Scaled`).

use proc_macro2::{Ident, TokenStream};
use quote::quote;

use super::docs::Doc;
use super::prim::Prim;
use crate::ir::Semantics;

pub(crate) fn f64_lit(value: f64) -> TokenStream {
    let lit = proc_macro2::Literal::f64_unsuffixed(if value.is_finite() { value } else { 0.0 });
    if value < 0.0 {
        let lit = proc_macro2::Literal::f64_unsuffixed(-value);
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

/// A newtype over the raw value implementing the runtime's `od::Scaled`
/// with its unit, scale, offset and numeric range (constants equal to the
/// trait's defaults are left out); `numeric` limits `from_value` to the range
/// that means a number (the other raws are special).
pub(crate) fn scaled(
    rt: &TokenStream,
    name: &Ident,
    raw: Prim,
    s: &Semantics,
    numeric: Option<(i128, i128)>,
    doc: &Doc,
) -> TokenStream {
    let ty = raw.tokens();
    let doc = doc.tokens();
    let scale = s
        .scale
        .filter(|v| v.is_finite() && *v != 0.0)
        .unwrap_or(1.0);
    let offset = s.offset.filter(|v| v.is_finite()).unwrap_or(0.0);
    let mut consts = TokenStream::new();
    if let Some(unit) = s.unit.as_deref().filter(|u| !u.is_empty()) {
        consts.extend(quote!(const UNIT: &'static str = #unit;));
    }
    if scale != 1.0 {
        let scale = f64_lit(scale);
        consts.extend(quote!(const SCALE: f64 = #scale;));
    }
    if offset != 0.0 {
        let offset = f64_lit(offset);
        consts.extend(quote!(const OFFSET: f64 = #offset;));
    }
    if !raw.is_float() {
        let (low, high) = numeric.unwrap_or(raw.range());
        let (min, max) = raw.range();
        if low != min {
            let low = raw.lit(low);
            consts.extend(quote!(const MIN_RAW: #ty = #low;));
        }
        if high != max {
            let high = raw.lit(high);
            consts.extend(quote!(const MAX_RAW: #ty = #high;));
        }
    }
    let derives = super::derives::value(raw);
    let raw_methods = super::value_parts::raw_methods(&ty);
    quote! {
        #doc
        #derives
        pub struct #name(pub #ty);
        impl #name {
            #raw_methods
        }
        impl #rt::od::Scaled for #name {
            type Raw = #ty;
            #consts
            fn from_raw(raw: #ty) -> Self {
                Self(raw)
            }
            fn to_raw(self) -> #ty {
                self.0
            }
        }
    }
}
