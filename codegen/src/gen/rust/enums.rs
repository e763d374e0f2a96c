//! Value tables: an enum of meanings (named values and ranges, an optional
//! `Number(..)` variant for the numeric range, and the fallback (`other`)
//! carrying the raw value, so that every raw value round-trips) and, for
//! entries, a newtype over the raw value that classifies on demand
//! (`kind()`), so that PDO decoding and encoding stay shifts and masks.

use proc_macro2::{Ident, TokenStream};
use quote::quote;

use super::docs::{self, Doc};
use super::naming::{Case, NameId, Namespace};
use super::prim::Prim;
use super::value_parts::Ctx;
use crate::ir::ValueTable;

struct Variant<'a> {
    name: NameId,
    source: String,
    text: Option<&'a str>,
    /// Single raw values and inclusive ranges this variant stands for.
    members: Vec<(i128, i128)>,
    /// Carries the raw value (ranges, merged names, the fallback).
    carries: bool,
    /// The variant's name is a `rust_name:` pin.
    pinned: bool,
}

/// A named single value of a table, as a constant of the raw newtype.
pub(crate) struct UnitValue {
    pub(crate) variant: Ident,
    pub(crate) source: String,
    pub(crate) raw: i128,
    /// The variant's name was pinned: the constant follows it.
    pub(crate) pinned: bool,
}

/// An enum over a value table: named values, optionally `Number(..)` for the
/// numeric range, and the fallback `other` carrying the raw value. Also
/// returns the variants that stand for one raw value.
pub(crate) fn value_enum(
    cx: &mut Ctx,
    name: &Ident,
    raw: Prim,
    table: &ValueTable,
    doc: &Doc,
    number: Option<(&TokenStream, bool)>,
    owner: &str,
) -> (TokenStream, Vec<UnitValue>) {
    let ty = raw.tokens();
    let mut ns = Namespace::new(format!("enum `{name}` ({owner})"), Case::UpperCamel);
    if table.numeric.is_some() {
        ns.reserve("Number");
    }
    let mut variants: Vec<Variant> = Vec::new();
    for named in &table.named {
        match variants.iter_mut().find(|v| v.source == named.name) {
            Some(v) => {
                v.members.push((named.low, named.high));
                v.carries = true;
            }
            None => variants.push(Variant {
                name: match &named.rust_name {
                    Some(pin) => {
                        ns.request_pinned(pin, &format!("raw {}", named.low), Some(&named.origin))
                    }
                    None => ns.request(
                        &named.name,
                        &format!("raw {}", named.low),
                        Some(&named.origin),
                    ),
                },
                pinned: named.rust_name.is_some(),
                source: named.name.clone(),
                text: named.text.as_deref(),
                members: vec![(named.low, named.high)],
                carries: named.is_range(),
            }),
        }
    }
    // The fallback exists only when some raw value is left for it: a variant
    // no raw value reads back as would not round-trip.
    let fallback = if covers_all(table, raw) {
        None
    } else {
        Some(
            match variants.iter().position(|v| v.source == table.other) {
                Some(i) => {
                    variants[i].carries = true;
                    i
                }
                None => {
                    variants.push(Variant {
                        name: ns.request(&table.other, "other", None),
                        source: table.other.clone(),
                        text: None,
                        members: Vec::new(),
                        carries: true,
                        pinned: false,
                    });
                    variants.len() - 1
                }
            },
        )
    };
    let names = ns.resolve(cx.diags);
    let units = variants
        .iter()
        .filter(|v| !v.carries)
        .filter_map(|v| {
            v.members.first().map(|&(low, _)| UnitValue {
                variant: names.get(v.name),
                source: v.source.clone(),
                raw: low,
                pinned: v.pinned,
            })
        })
        .collect();
    let (number_ty, number_scaled) = number.unwrap_or((&ty, false));
    let mut defs = Vec::new();
    let mut from_arms = Vec::new();
    let mut to_arms = Vec::new();
    let mut name_arms = Vec::new();
    if let Some((low, high)) = table.numeric {
        defs.push(quote! {
            #[doc = " A number (see the numeric range in the type's documentation)."]
            Number(#number_ty)
        });
        let (l, h) = (raw.lit(low), raw.lit(high));
        let wrap = if number_scaled {
            quote!(Self::Number(#number_ty::from_raw(raw)))
        } else {
            quote!(Self::Number(raw))
        };
        from_arms.push(quote!(#l..=#h => #wrap));
        to_arms.push(if number_scaled {
            quote!(Self::Number(n) => n.to_raw())
        } else {
            quote!(Self::Number(n) => n)
        });
        name_arms.push(quote!(Self::Number(_) => "number"));
    }
    for (i, v) in variants.iter().enumerate() {
        let ident = names.get(v.name);
        let mut doc = Doc::new();
        let raws: Vec<String> = v
            .members
            .iter()
            .map(|&(l, h)| {
                if l == h {
                    format!("{l:#X}")
                } else {
                    format!("{l:#X}..={h:#X}")
                }
            })
            .collect();
        let mut head = format!("**{}**", docs::text(&v.source));
        if !raws.is_empty() {
            head.push_str(&format!(" (raw {})", raws.join(", ")));
        }
        if Some(i) == fallback {
            head.push_str(if raws.is_empty() {
                ": every raw value not covered by another variant"
            } else {
                "; also every raw value not covered by another variant"
            });
        }
        doc.para(head);
        if let Some(text) = v.text {
            doc.source_para(text);
        }
        let doc = doc.tokens_with_alias(&v.source, names.text(v.name));
        defs.push(if v.carries {
            quote!(#doc #ident(#ty))
        } else {
            quote!(#doc #ident)
        });
        for &(low, high) in &v.members {
            let (l, h) = (raw.lit(low), raw.lit(high));
            let pattern = if low == high {
                quote!(#l)
            } else {
                quote!(#l..=#h)
            };
            from_arms.push(if v.carries {
                quote!(#pattern => Self::#ident(raw))
            } else {
                quote!(#pattern => Self::#ident)
            });
        }
        if v.carries {
            to_arms.push(quote!(Self::#ident(raw) => raw));
        } else if let Some(&(low, _)) = v.members.first() {
            let l = raw.lit(low);
            to_arms.push(quote!(Self::#ident => #l));
        }
        let source = &v.source;
        name_arms.push(if v.carries {
            quote!(Self::#ident(_) => #source)
        } else {
            quote!(Self::#ident => #source)
        });
    }
    let text_arms: Vec<TokenStream> = variants
        .iter()
        .map(|v| {
            let ident = names.get(v.name);
            let text = v.text.unwrap_or(&v.source);
            if v.carries {
                quote!(Self::#ident(_) => #text)
            } else {
                quote!(Self::#ident => #text)
            }
        })
        .chain(table.numeric.map(|_| quote!(Self::Number(_) => "number")))
        .collect();
    if let Some(fallback) = fallback {
        let fallback_ident = names.get(variants[fallback].name);
        from_arms.push(quote!(_ => Self::#fallback_ident(raw)));
    }
    let has_float = number_scaled && raw.is_float();
    let derives = super::derives::attr(super::derives::MEANING, has_float);
    let doc = doc.tokens();
    let items = quote! {
        #doc
        #derives
        pub enum #name {
            #(#defs,)*
        }
        impl #name {
            #[doc = " The meaning of a raw value; every raw value has one."]
            #[inline] pub const fn from_raw(raw: #ty) -> Self {
                match raw {
                    #(#from_arms,)*
                }
            }
            #[doc = " The raw value on the bus."]
            #[inline] pub const fn to_raw(self) -> #ty {
                match self {
                    #(#to_arms,)*
                }
            }
            #[doc = " The name in the source."]
            #[inline] pub const fn name(self) -> &'static str {
                match self {
                    #(#name_arms,)*
                }
            }
            #[doc = " The source's text for the value (its name when there is none)."]
            #[inline] pub const fn text(self) -> &'static str {
                match self {
                    #(#text_arms,)*
                }
            }
        }
    };
    (items, units)
}

/// The value type of an entry with a value table: the raw value, with
/// `kind()` giving its meaning (`kind` enum), a constant per named single
/// value, and `number()` for the numeric range.
#[allow(clippy::too_many_arguments)]
pub(crate) fn raw_newtype(
    cx: &mut Ctx,
    name: &Ident,
    kind: &Ident,
    raw: Prim,
    doc: &Doc,
    number: Option<(&TokenStream, bool)>,
    units: &[UnitValue],
    owner: &str,
) -> TokenStream {
    let ty = raw.tokens();
    let mut ns = Namespace::new(format!("impl `{name}` ({owner})"), Case::ShoutySnake);
    let ids: Vec<NameId> = units
        .iter()
        .map(|u| {
            let key = format!("raw {}", u.raw);
            if u.pinned {
                ns.request_fixed(&u.variant.to_string(), &key, None)
            } else {
                ns.request(&u.source, &key, None)
            }
        })
        .collect();
    let names = ns.resolve(cx.diags);
    let consts = units.iter().zip(&ids).map(|(u, id)| {
        let c = names.get(*id);
        let v = &u.variant;
        let lit = raw.lit(u.raw);
        let doc = format!(" [`{kind}::{v}`] (raw {:#X}).", u.raw);
        let alias = super::naming::alias_allowed(&u.source, names.text(*id)).then(|| {
            let source = &u.source;
            quote!(#[doc(alias = #source)])
        });
        quote!(#[doc = #doc] #alias pub const #c: Self = Self(#lit);)
    });
    let number_fns = number.map(|(number_ty, scaled)| {
        let to = if scaled {
            quote!(n.to_raw())
        } else {
            quote!(n)
        };
        quote! {
            #[doc = " The number, when the raw value is in the numeric range."]
            #[inline]
            pub const fn number(self) -> ::core::option::Option<#number_ty> {
                match self.kind() {
                    #kind::Number(n) => ::core::option::Option::Some(n),
                    _ => ::core::option::Option::None,
                }
            }
            #[doc = " The value of a number."]
            #[inline]
            pub const fn from_number(n: #number_ty) -> Self {
                Self(#to)
            }
        }
    });
    let doc = doc.tokens();
    let kind_doc =
        format!(" The meaning of the raw value (every raw value has one, see [`{kind}`]).");
    let raw_methods = super::value_parts::raw_methods(&ty);
    let derives = super::derives::value(raw);
    quote! {
        #doc
        #derives
        pub struct #name(pub #ty);
        impl #name {
            #(#consts)*
            #raw_methods
            #[doc = #kind_doc]
            #[inline]
            pub const fn kind(self) -> #kind {
                #kind::from_raw(self.0)
            }
            #[doc = " The value with this meaning."]
            #[inline]
            pub const fn from_kind(kind: #kind) -> Self {
                Self(kind.to_raw())
            }
            #[doc = " The name in the source of the value's meaning."]
            #[inline]
            pub const fn name(self) -> &'static str {
                self.kind().name()
            }
            #[doc = " The source's text for the value's meaning."]
            #[inline]
            pub const fn text(self) -> &'static str {
                self.kind().text()
            }
            #number_fns
        }
        impl ::core::convert::From<#kind> for #name {
            #[inline]
            fn from(kind: #kind) -> Self {
                Self::from_kind(kind)
            }
        }
        impl ::core::convert::From<#name> for #kind {
            #[inline]
            fn from(value: #name) -> Self {
                value.kind()
            }
        }
    }
}

/// Whether the numeric range and the named values of `table` cover every
/// raw value of `raw`, leaving nothing to the fallback (`other`).
pub(crate) fn covers_all(table: &ValueTable, raw: Prim) -> bool {
    let mut intervals: Vec<(i128, i128)> = table
        .numeric
        .into_iter()
        .chain(table.named.iter().map(|n| (n.low, n.high)))
        .collect();
    covers(&mut intervals, raw.range())
}

/// Whether the inclusive intervals cover `range` completely.
fn covers(intervals: &mut [(i128, i128)], range: (i128, i128)) -> bool {
    intervals.sort_unstable();
    let mut next = range.0;
    for &(low, high) in intervals.iter() {
        if low > next {
            return false;
        }
        if high >= next {
            if high >= range.1 {
                return true;
            }
            next = high + 1;
        }
    }
    false
}
