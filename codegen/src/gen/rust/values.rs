//! Value types from the semantic layer: enumerations with a fallback,
//! numbers with special values (LINAK-style commands), bit-field structs with
//! const getters and setters, and scaled newtypes with unit conversions.
//!
//! Every generated value type has `const fn from_raw(raw) -> Self` and
//! `const fn to_raw(self) -> raw` that round-trip every raw value, and
//! implements the runtime's `Scalar`. The emitters live in [`super::enums`],
//! [`super::bits`] and [`super::scaled`].

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::docs::{self, Doc};
use super::naming::{NameId, Names, Namespace};
use super::prim::{self, Prim};
pub(crate) use super::value_parts::Ctx;
use super::value_parts::value_doc;
use crate::ir::{Entry, Semantics};

/// The value type chosen for an entry, with its names requested.
pub(crate) enum Plan {
    /// A primitive (`u16`, `f32`, ...): no semantics or none that apply.
    Prim(Prim),
    /// No fixed size: a marker type of the runtime (`bytes::VisibleString`).
    Bytes(&'static str),
    /// The error enum of a device error table (index into the error plans).
    Error(usize),
    /// A newtype over the raw value (`name`) whose meaning is an enum over
    /// named values (`kind`; and a numeric range, when `number`).
    Enum {
        name: NameId,
        kind: NameId,
        raw: Prim,
        /// The newtype of the numeric part, when it has a unit or scale.
        number: Option<NameId>,
    },
    /// A bit-field struct; `fields` holds the enum name of fields with values.
    Bits {
        name: NameId,
        raw: Prim,
        fields: Vec<Option<NameId>>,
        state: Option<NameId>,
    },
    /// A newtype with unit and scale.
    Scaled { name: NameId, raw: Prim },
    /// A type of the runtime that CiA 301 fixes (`od::standard::PdoCobId`),
    /// generated nowhere.
    Runtime { path: &'static str, raw: Prim },
}

impl Plan {
    /// Every name the plan requested in the entry's scope.
    #[cfg(any(feature = "diff", all(feature = "api", feature = "network")))]
    pub(crate) fn names(&self) -> Vec<NameId> {
        match self {
            Plan::Prim(_) | Plan::Bytes(_) | Plan::Error(_) | Plan::Runtime { .. } => Vec::new(),
            Plan::Enum {
                name, kind, number, ..
            } => [Some(*name), Some(*kind), *number]
                .into_iter()
                .flatten()
                .collect(),
            Plan::Bits {
                name,
                fields,
                state,
                ..
            } => std::iter::once(*name)
                .chain(fields.iter().flatten().copied())
                .chain(*state)
                .collect(),
            Plan::Scaled { name, .. } => vec![*name],
        }
    }
}

/// What an entry's value type names are made of: its source name, or a
/// fixed name (canonical or pinned) that they follow, fixed too.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Name<'a> {
    Source(&'a str),
    Fixed(&'a str),
}

/// Chooses the value type of `entry` and requests its names in `ns` (the
/// namespace of the module the entry's zero-sized type lives in).
pub(crate) fn plan(
    entry: &Entry,
    name: Name<'_>,
    error_plan: Option<usize>,
    ns: &mut Namespace,
) -> Plan {
    let Some(raw) = Prim::of(entry.data_type) else {
        return Plan::Bytes(bytes_marker(entry));
    };
    let s = &entry.semantics;
    let key = format!("sub {}", entry.subindex);
    let req = |ns: &mut Namespace, suffix: &str| match name {
        Name::Source(source) => {
            ns.request(&format!("{source} {suffix}"), &key, Some(&entry.origin))
        }
        Name::Fixed(fixed) => {
            ns.request_fixed(&format!("{fixed} {suffix}"), &key, Some(&entry.origin))
        }
    };
    if raw.is_integer() {
        if let Some(index) = error_plan {
            return Plan::Error(index);
        }
        if s.values.is_some() {
            let name = req(ns, "value");
            let kind = req(ns, "kind");
            let number = (has_unit(s) && s.values.as_ref().is_some_and(|v| v.numeric.is_some()))
                .then(|| req(ns, "number"));
            return Plan::Enum {
                name,
                kind,
                raw,
                number,
            };
        }
        if !s.bits.is_empty() || !s.patterns.is_empty() {
            let name = req(ns, "value");
            let fields = s
                .bits
                .iter()
                .map(|f| {
                    f.values
                        .as_ref()
                        .map(|_| req(ns, f.rust_name.as_deref().unwrap_or(&f.name)))
                })
                .collect();
            let state = (!s.patterns.is_empty()).then(|| req(ns, "state"));
            return Plan::Bits {
                name,
                raw,
                fields,
                state,
            };
        }
    }
    if raw != Prim::Bool && has_unit(s) {
        return Plan::Scaled {
            name: req(ns, "value"),
            raw,
        };
    }
    Plan::Prim(raw)
}

fn has_unit(s: &Semantics) -> bool {
    s.unit.is_some() || s.scale.is_some() || s.offset.is_some()
}

fn bytes_marker(entry: &Entry) -> &'static str {
    use crate::ir::DataType::*;
    match entry.data_type {
        VisibleString => "VisibleString",
        OctetString => "OctetString",
        UnicodeString => "UnicodeString",
        Domain => "Domain",
        _ => "Opaque",
    }
}

/// The Rust type of the plan's values, as a path relative to the entry's module.
pub(crate) fn type_tokens(
    plan: &Plan,
    names: &Names,
    rt: &TokenStream,
    error_path: &dyn Fn(usize) -> TokenStream,
) -> TokenStream {
    match plan {
        Plan::Prim(p) => p.tokens(),
        Plan::Bytes(marker) => {
            let marker = format_ident!("{marker}");
            quote!(#rt::od::bytes::#marker)
        }
        Plan::Error(index) => error_path(*index),
        Plan::Enum { name, .. } | Plan::Bits { name, .. } | Plan::Scaled { name, .. } => {
            let name = names.get(*name);
            quote!(#name)
        }
        Plan::Runtime { path, .. } => {
            let path: TokenStream = path.parse().expect("a runtime path is Rust");
            quote!(#rt::#path)
        }
    }
}

/// The runtime's value type for `entry` of object `index`, when CiA 301
/// fixes one and the entry keeps the standard's meaning.
pub(crate) fn runtime_plan(
    canonical: crate::profiles::Canonical,
    index: u16,
    entry: &Entry,
) -> Option<Plan> {
    let ty = canonical.runtime_value(index, entry)?;
    let raw = Prim::of(entry.data_type)?;
    (raw.tokens().to_string() == ty.raw).then_some(Plan::Runtime { path: ty.path, raw })
}

/// The items of an entry's value type (nothing for primitives, bytes and
/// error enums, which live elsewhere).
pub(crate) fn emit(cx: &mut Ctx, entry: &Entry, plan: &Plan, names: &Names) -> TokenStream {
    let s = &entry.semantics;
    match plan {
        Plan::Prim(_) | Plan::Bytes(_) | Plan::Error(_) | Plan::Runtime { .. } => {
            TokenStream::new()
        }
        Plan::Scaled { name, raw } => {
            let mut doc = value_doc(entry, "The value");
            unit_doc(&mut doc, s);
            let name = names.get(*name);
            let mut out = super::scaled::scaled(cx.rt, &name, *raw, s, None, &doc);
            out.extend(scalar_impl(cx.rt, &name, *raw));
            out
        }
        Plan::Enum {
            name,
            kind,
            raw,
            number,
        } => {
            let table = s.values.as_ref().expect("planned only with a value table");
            let name = names.get(*name);
            let kind = names.get(*kind);
            let mut out = TokenStream::new();
            let number_ty = match number {
                Some(number) => {
                    let number = names.get(*number);
                    let mut doc = value_doc(entry, "The numeric part of the value");
                    unit_doc(&mut doc, s);
                    out.extend(super::scaled::scaled(
                        cx.rt,
                        &number,
                        *raw,
                        s,
                        table.numeric,
                        &doc,
                    ));
                    quote!(#number)
                }
                None => raw.tokens(),
            };
            let doc = value_doc(entry, "The meaning of the value");
            let (kind_items, consts) = super::enums::value_enum(
                cx,
                &kind,
                *raw,
                table,
                &doc,
                Some((&number_ty, number.is_some())),
                &entry.name,
            );
            out.extend(kind_items);
            let doc = value_doc(entry, "The value");
            let number = table.numeric.map(|_| (&number_ty, number.is_some()));
            out.extend(super::enums::raw_newtype(
                cx,
                &name,
                &kind,
                *raw,
                &doc,
                number,
                &consts,
                &entry.name,
            ));
            out.extend(scalar_impl(cx.rt, &name, *raw));
            out
        }
        Plan::Bits {
            name,
            raw,
            fields,
            state,
        } => {
            let name = names.get(*name);
            let mut out = TokenStream::new();
            let mut field_enums = Vec::new();
            for (field, enum_name) in s.bits.iter().zip(fields) {
                match (enum_name, &field.values) {
                    (Some(enum_name), Some(table)) => {
                        let enum_ident = names.get(*enum_name);
                        let field_raw = Prim::int(false, field.width);
                        let mut doc = Doc::new();
                        doc.para(format!(
                            "Values of the bit field **{}** of {}.",
                            docs::text(&field.name),
                            docs::text(&entry.name)
                        ));
                        if let Some(text) = &field.text {
                            doc.source_para(text);
                        }
                        doc.origin(&field.origin);
                        let number_ty = field_raw.tokens();
                        let (items, _) = super::enums::value_enum(
                            cx,
                            &enum_ident,
                            field_raw,
                            table,
                            &doc,
                            Some((&number_ty, false)),
                            &field.name,
                        );
                        out.extend(items);
                        field_enums.push(Some(enum_ident));
                    }
                    _ => field_enums.push(None),
                }
            }
            let state = state.map(|id| names.get(id));
            out.extend(super::bits::bit_struct(
                cx,
                entry,
                &name,
                *raw,
                &field_enums,
                state.as_ref(),
            ));
            out.extend(scalar_impl(cx.rt, &name, *raw));
            out
        }
    }
}

fn unit_doc(doc: &mut Doc, s: &Semantics) {
    let unit = s.unit.as_deref().map(docs::text).unwrap_or_default();
    let mut line = format!("Physical value = raw × {}", s.scale.unwrap_or(1.0));
    if let Some(offset) = s.offset {
        line.push_str(&format!(" + {offset}"));
    }
    if !unit.is_empty() {
        line.push_str(&format!(", in {unit}"));
    }
    doc.para(format!(
        "{line} (`value()` and `from_value()` of the runtime's `od::Scaled`)."
    ));
}

/// `impl Scalar` for a generated type with inherent `from_raw`/`to_raw`.
pub(crate) fn scalar_impl(rt: &TokenStream, name: &Ident, raw: Prim) -> TokenStream {
    let ty = raw.tokens();
    let to = prim::to_bits(raw, quote!(Self::to_raw(self)));
    let from = match raw {
        Prim::F32 => quote!(f32::from_bits(raw as u32)),
        Prim::F64 => quote!(f64::from_bits(raw)),
        Prim::Bool => quote!(raw & 1 != 0),
        Prim::U64 => quote!(raw),
        _ => quote!(raw as #ty),
    };
    quote! {
        impl #rt::od::Scalar for #name {
            #[inline(always)]
            fn to_raw(self) -> u64 {
                #to
            }
            #[inline(always)]
            fn from_raw(raw: u64) -> Self {
                Self::from_raw(#from)
            }
        }
    }
}

/// `From` both ways between a generated value type and the runtime type
/// the standard gives the entry (`cia402::Statusword`): the same raw value,
/// so the conversions compile to nothing. Nothing when the value type is
/// not generated or its raw type differs from the runtime type's.
pub(crate) fn runtime_conversions(
    rt: &TokenStream,
    plan: &Plan,
    names: &Names,
    ty: crate::profiles::RuntimeType,
) -> TokenStream {
    let (Plan::Enum { name, raw, .. } | Plan::Bits { name, raw, .. }) = plan else {
        return TokenStream::new();
    };
    if raw.tokens().to_string() != ty.raw {
        return TokenStream::new();
    }
    let name = names.get(*name);
    let path: TokenStream = ty.path.parse().expect("a runtime path is Rust");
    let raw_ty = raw.tokens();
    let (into_rt, from_rt) = if ty.newtype {
        (
            quote!(#rt::#path(value.to_raw())),
            quote!(Self::from_raw(value.0)),
        )
    } else {
        (
            quote!(#rt::#path::from(value.to_raw())),
            quote!(Self::from_raw(#raw_ty::from(value))),
        )
    };
    let doc = format!(" The runtime's `{}`: the same raw value.", ty.path);
    quote! {
        impl ::core::convert::From<#name> for #rt::#path {
            #[doc = #doc]
            #[inline]
            fn from(value: #name) -> Self { #into_rt }
        }
        impl ::core::convert::From<#rt::#path> for #name {
            #[doc = " The same raw value as the runtime's type."]
            #[inline]
            fn from(value: #rt::#path) -> Self { #from_rt }
        }
    }
}
