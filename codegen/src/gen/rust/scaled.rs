//! Scaled newtypes: the raw value with its unit, scale and offset, and exact
//! conversions to and from the physical value.

use proc_macro2::{Ident, TokenStream};
use quote::quote;

use super::docs::{self, Doc};
use super::prim::Prim;
use crate::ir::Semantics;

/// How to compute `raw × scale` exactly where possible: dividing by an
/// integer when the scale is its reciprocal (0.1 → ÷ 10) gives the correctly
/// rounded decimal (26 → 2.6, not 2.6000000000000005).
enum Factor {
    Divide(f64),
    Multiply,
}

fn factor(scale: f64) -> Factor {
    let reciprocal = 1.0 / scale;
    let rounded = reciprocal.round();
    if scale.abs() < 1.0 && rounded != 0.0 && (reciprocal - rounded).abs() < 1e-9 * rounded.abs() {
        Factor::Divide(rounded)
    } else {
        Factor::Multiply
    }
}

pub(crate) fn f64_lit(value: f64) -> TokenStream {
    let lit = proc_macro2::Literal::f64_unsuffixed(if value.is_finite() { value } else { 0.0 });
    if value < 0.0 {
        let lit = proc_macro2::Literal::f64_unsuffixed(-value);
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

/// A newtype over the raw value with unit conversions. `numeric` limits
/// `from_value` to the range that means a number (the other raws are special).
pub(crate) fn scaled(
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
    let unit = s.unit.clone().unwrap_or_default();
    let unit_doc = if unit.is_empty() {
        String::new()
    } else {
        format!(" in {}", docs::text(&unit))
    };
    let scale_lit = f64_lit(scale);
    let offset_lit = f64_lit(offset);
    let (to_value, to_steps) = match factor(scale) {
        Factor::Divide(k) => {
            let k = f64_lit(k);
            (
                quote!(self.0 as f64 / #k),
                quote!((value - Self::OFFSET) * #k),
            )
        }
        Factor::Multiply => (
            quote!(self.0 as f64 * Self::SCALE),
            quote!((value - Self::OFFSET) / Self::SCALE),
        ),
    };
    let value_fn_doc = format!(
        " The physical value{unit_doc}: raw × {scale}{}.",
        if offset != 0.0 {
            format!(" + {offset}")
        } else {
            String::new()
        }
    );
    let derives = super::derives::value(raw);
    let from_value = if raw.is_float() {
        quote! {
            #[doc = " The raw value for a physical value (no rounding: the raw type is a float)."]
            #[inline] pub const fn from_value(value: f64) -> Self {
                Self((#to_steps) as #ty)
            }
        }
    } else {
        let (low, high) = numeric.unwrap_or(raw.range());
        let (low_lit, high_lit) = (raw.lit(low), raw.lit(high));
        let doc = format!(
            " The raw value nearest to `value`{unit_doc}, or `None` when that is outside {low}..={high} (or `value` is NaN)."
        );
        quote! {
            #[doc = #doc]
            #[inline] pub const fn from_value(value: f64) -> ::core::option::Option<Self> {
                let steps = #to_steps;
                if !(steps > (Self::MIN_RAW as f64) - 1.0 && steps < (Self::MAX_RAW as f64) + 1.0) {
                    return ::core::option::Option::None;
                }
                let truncated = steps as i128;
                let fraction = steps - truncated as f64;
                let rounded = if fraction >= 0.5 {
                    truncated + 1
                } else if fraction <= -0.5 {
                    truncated - 1
                } else {
                    truncated
                };
                if rounded < Self::MIN_RAW as i128 || rounded > Self::MAX_RAW as i128 {
                    return ::core::option::Option::None;
                }
                ::core::option::Option::Some(Self(rounded as #ty))
            }
            #[doc = " The lowest raw value that is a number."]
            pub const MIN_RAW: #ty = #low_lit;
            #[doc = " The highest raw value that is a number."]
            pub const MAX_RAW: #ty = #high_lit;
        }
    };
    let raw_methods = super::values::raw_methods(&ty);
    quote! {
        #doc
        #derives
        pub struct #name(pub #ty);
        impl #name {
            #[doc = " The unit of [`Self::value`]."]
            pub const UNIT: &'static str = #unit;
            #[doc = " Physical value of one raw step."]
            pub const SCALE: f64 = #scale_lit;
            #[doc = " Physical value of raw 0."]
            pub const OFFSET: f64 = #offset_lit;
            #raw_methods
            #[doc = #value_fn_doc]
            #[inline] pub const fn value(self) -> f64 {
                #to_value + Self::OFFSET
            }
            #from_value
        }
    }
}
