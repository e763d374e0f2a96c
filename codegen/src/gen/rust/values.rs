//! Value types from the semantic layer: enumerations with a fallback,
//! numbers with special values (LINAK-style commands), bit-field structs with
//! const getters and setters, and scaled newtypes with unit conversions.
//!
//! Every generated value type has `const fn from_raw(raw) -> Self` and
//! `const fn to_raw(self) -> raw` that round-trip every raw value, and
//! implements the runtime's `Scalar`.

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::docs::{self, Doc};
use super::naming::{Case, NameId, Names, Namespace};
use super::prim::{self, Prim};
use crate::ir::{BitField, Entry, Semantics, ValueTable};

/// The value type chosen for an entry, with its names requested.
pub(crate) enum Plan {
    /// A primitive (`u16`, `f32`, ...): no semantics or none that apply.
    Prim(Prim),
    /// No fixed size: a marker type of the runtime (`bytes::VisibleString`).
    Bytes(&'static str),
    /// The error enum of a device error table (index into the error plans).
    Error(usize),
    /// An enum over named values (and a numeric range, when `number`).
    Enum {
        name: NameId,
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
}

/// Chooses the value type of `entry` and requests its names in `ns` (the
/// namespace of the module the entry's zero-sized type lives in).
pub(crate) fn plan(entry: &Entry, error_plan: Option<usize>, ns: &mut Namespace) -> Plan {
    let Some(raw) = Prim::of(entry.data_type) else {
        return Plan::Bytes(bytes_marker(entry));
    };
    let s = &entry.semantics;
    let key = format!("sub {}", entry.subindex);
    let req = |ns: &mut Namespace, suffix: &str| {
        ns.request(
            &format!("{} {suffix}", entry.name),
            &key,
            Some(&entry.origin),
        )
    };
    if raw.is_integer() {
        if let Some(index) = error_plan {
            return Plan::Error(index);
        }
        if s.values.is_some() {
            let name = req(ns, "value");
            let number = (has_unit(s) && s.values.as_ref().is_some_and(|v| v.numeric.is_some()))
                .then(|| req(ns, "number"));
            return Plan::Enum { name, raw, number };
        }
        if !s.bits.is_empty() || !s.patterns.is_empty() {
            let name = req(ns, "value");
            let fields = s
                .bits
                .iter()
                .map(|f| f.values.as_ref().map(|_| req(ns, &f.name)))
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
    }
}

/// Everything the value-type emitters need of their surroundings.
pub(crate) struct Ctx<'a> {
    pub(crate) rt: &'a TokenStream,
    pub(crate) diags: &'a mut crate::diag::Diagnostics,
}

/// The items of an entry's value type (nothing for primitives, bytes and
/// error enums, which live elsewhere).
pub(crate) fn emit(cx: &mut Ctx, entry: &Entry, plan: &Plan, names: &Names) -> TokenStream {
    let s = &entry.semantics;
    match plan {
        Plan::Prim(_) | Plan::Bytes(_) | Plan::Error(_) => TokenStream::new(),
        Plan::Scaled { name, raw } => {
            let mut doc = value_doc(entry, "The value");
            unit_doc(&mut doc, s);
            let name = names.get(*name);
            let mut out = scaled(&name, *raw, s, None, &doc);
            out.extend(scalar_impl(cx.rt, &name, *raw));
            out
        }
        Plan::Enum { name, raw, number } => {
            let table = s.values.as_ref().expect("planned only with a value table");
            let name = names.get(*name);
            let mut out = TokenStream::new();
            let number_ty = match number {
                Some(number) => {
                    let number = names.get(*number);
                    let mut doc = value_doc(entry, "The numeric part of the value");
                    unit_doc(&mut doc, s);
                    out.extend(scaled(&number, *raw, s, table.numeric, &doc));
                    quote!(#number)
                }
                None => raw.tokens(),
            };
            let doc = value_doc(entry, "The value");
            out.extend(value_enum(
                cx,
                &name,
                *raw,
                table,
                &doc,
                Some((&number_ty, number.is_some())),
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
                        out.extend(value_enum(
                            cx,
                            &enum_ident,
                            field_raw,
                            table,
                            &doc,
                            Some((&number_ty, false)),
                            &field.name,
                        ));
                        field_enums.push(Some(enum_ident));
                    }
                    _ => field_enums.push(None),
                }
            }
            let state = state.map(|id| names.get(id));
            out.extend(bit_struct(
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

fn value_doc(entry: &Entry, what: &str) -> Doc {
    let mut doc = Doc::new();
    doc.para(format!("{what} of **{}**.", docs::text(&entry.name)));
    if let Some(description) = &entry.semantics.description {
        doc.source_para(description);
    }
    doc.origin(&entry.origin);
    doc
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
    doc.para(format!("{line}."));
}

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

fn f64_lit(value: f64) -> TokenStream {
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
fn scaled(
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
    let derives = if raw.is_float() {
        quote!(#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)])
    } else {
        quote!(#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)])
    };
    let from_value = if raw.is_float() {
        quote! {
            #[doc = " The raw value for a physical value (no rounding: the raw type is a float)."]
            pub const fn from_value(value: f64) -> Self {
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
            pub const fn from_value(value: f64) -> Option<Self> {
                let steps = #to_steps;
                if !(steps > (Self::MIN_RAW as f64) - 1.0 && steps < (Self::MAX_RAW as f64) + 1.0) {
                    return None;
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
                    return None;
                }
                Some(Self(rounded as #ty))
            }
            #[doc = " The lowest raw value that is a number."]
            pub const MIN_RAW: #ty = #low_lit;
            #[doc = " The highest raw value that is a number."]
            pub const MAX_RAW: #ty = #high_lit;
        }
    };
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
            #[doc = " The value with this raw form."]
            pub const fn from_raw(raw: #ty) -> Self {
                Self(raw)
            }
            #[doc = " The raw form on the bus."]
            pub const fn to_raw(self) -> #ty {
                self.0
            }
            #[doc = #value_fn_doc]
            pub const fn value(self) -> f64 {
                #to_value + Self::OFFSET
            }
            #from_value
        }
    }
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
            #[inline]
            fn to_raw(self) -> u64 {
                #to
            }
            #[inline]
            fn from_raw(raw: u64) -> Self {
                Self::from_raw(#from)
            }
        }
    }
}

struct Variant<'a> {
    name: NameId,
    source: String,
    text: Option<&'a str>,
    /// Single raw values and inclusive ranges this variant stands for.
    members: Vec<(i128, i128)>,
    /// Carries the raw value (ranges, merged names, the fallback).
    carries: bool,
}

/// An enum over a value table: named values, optionally `Number(..)` for the
/// numeric range, and the fallback `other` carrying the raw value.
fn value_enum(
    cx: &mut Ctx,
    name: &Ident,
    raw: Prim,
    table: &ValueTable,
    doc: &Doc,
    number: Option<(&TokenStream, bool)>,
    owner: &str,
) -> TokenStream {
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
                name: ns.request(
                    &named.name,
                    &format!("raw {}", named.low),
                    Some(&named.origin),
                ),
                source: named.name.clone(),
                text: named.text.as_deref(),
                members: vec![(named.low, named.high)],
                carries: named.is_range(),
            }),
        }
    }
    let fallback = match variants.iter().position(|v| v.source == table.other) {
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
            });
            variants.len() - 1
        }
    };
    let names = ns.resolve(cx.diags);
    let (number_ty, number_scaled) = number.unwrap_or((&ty, false));
    let mut defs = Vec::new();
    let mut from_arms = Vec::new();
    let mut to_arms = Vec::new();
    let mut name_arms = Vec::new();
    let mut covered: Vec<(i128, i128)> = Vec::new();
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
        covered.push((low, high));
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
        if i == fallback {
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
            covered.push((low, high));
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
    let fallback_ident = names.get(variants[fallback].name);
    if !covers(&mut covered, raw.range()) {
        from_arms.push(quote!(_ => Self::#fallback_ident(raw)));
    }
    let has_float = number_scaled && raw.is_float();
    let derives = if has_float {
        quote!(#[derive(Debug, Clone, Copy, PartialEq)])
    } else {
        quote!(#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)])
    };
    let doc = doc.tokens();
    quote! {
        #doc
        #derives
        pub enum #name {
            #(#defs,)*
        }
        impl #name {
            #[doc = " The meaning of a raw value; every raw value has one."]
            pub const fn from_raw(raw: #ty) -> Self {
                match raw {
                    #(#from_arms,)*
                }
            }
            #[doc = " The raw value on the bus."]
            pub const fn to_raw(self) -> #ty {
                match self {
                    #(#to_arms,)*
                }
            }
            #[doc = " The name in the source."]
            pub const fn name(self) -> &'static str {
                match self {
                    #(#name_arms,)*
                }
            }
            #[doc = " The source's text for the value (its name when there is none)."]
            pub const fn text(self) -> &'static str {
                match self {
                    #(#text_arms,)*
                }
            }
        }
    }
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

fn bit_struct(
    cx: &mut Ctx,
    entry: &Entry,
    name: &Ident,
    raw: Prim,
    field_enums: &[Option<Ident>],
    state: Option<&Ident>,
) -> TokenStream {
    let s = &entry.semantics;
    let ty = raw.tokens();
    let uty = raw.unsigned().tokens();
    let mut methods = Namespace::new(format!("impl `{name}`"), Case::Snake);
    for fixed in ["from_raw", "to_raw", "state"] {
        methods.reserve(fixed);
    }
    let ids: Vec<NameId> = s
        .bits
        .iter()
        .map(|f| methods.request(&f.name, &format!("bit {}", f.lsb), Some(&f.origin)))
        .collect();
    let pattern_ids: Vec<NameId> = s
        .patterns
        .iter()
        .map(|p| methods.request(&format!("is {}", p.name), "pattern", Some(&p.origin)))
        .collect();
    let method_names = methods.resolve(cx.diags);
    let mut items = Vec::new();
    let mut layout = Doc::new();
    layout.line(String::new());
    layout.line("| Bits | Field | Meaning |");
    layout.line("|---|---|---|");
    for ((field, id), enum_ident) in s.bits.iter().zip(&ids).zip(field_enums) {
        let getter = method_names.get(*id);
        let setter = format_ident!("with_{}", method_names.text(*id).trim_end_matches('_'));
        let bits_text = if field.width == 1 {
            format!("{}", field.lsb)
        } else {
            format!("{}–{}", field.lsb, field.lsb + field.width - 1)
        };
        layout.line(format!(
            "| {bits_text} | `{}` | {} |",
            method_names.text(*id),
            docs::text(field.text.as_deref().unwrap_or(&field.name))
        ));
        items.push(bit_field_methods(
            field,
            &getter,
            &setter,
            raw,
            enum_ident.as_ref(),
        ));
    }
    let mut extra = TokenStream::new();
    if let Some(state) = state {
        let mut variants = Namespace::new(format!("enum `{state}`"), Case::UpperCamel);
        let var_ids: Vec<NameId> = s
            .patterns
            .iter()
            .map(|p| variants.request(&p.name, &format!("mask {:#X}", p.mask), Some(&p.origin)))
            .collect();
        let var_names = variants.resolve(cx.diags);
        let base = if raw.is_signed() {
            quote!((self.0 as #uty))
        } else {
            quote!(self.0)
        };
        let mut defs = Vec::new();
        let mut checks = Vec::new();
        for ((p, vid), mid) in s.patterns.iter().zip(&var_ids).zip(&pattern_ids) {
            let v = var_names.get(*vid);
            let m = method_names.get(*mid);
            let mask = prim::hex(u128::from(p.mask));
            let value = prim::hex(u128::from(p.value));
            let mut doc = Doc::new();
            doc.para(format!(
                "**{}**: raw & {:#X} == {:#X}.",
                docs::text(&p.name),
                p.mask,
                p.value
            ));
            if let Some(text) = &p.text {
                doc.source_para(text);
            }
            let doc_tokens = doc.tokens_with_alias(&p.name, var_names.text(*vid));
            defs.push(quote!(#doc_tokens #v));
            let method_doc = format!(
                " Whether the value matches the pattern **{}** (raw & {:#X} == {:#X}).",
                docs::text(&p.name),
                p.mask,
                p.value
            );
            items.push(quote! {
                #[doc = #method_doc]
                pub const fn #m(self) -> bool {
                    #base & #mask == #value
                }
            });
            checks.push(quote!(if self.#m() { return Some(#state::#v); }));
        }
        let doc = format!(
            " The named states of {} (masked patterns of the raw value).",
            docs::text(&entry.name)
        );
        extra.extend(quote! {
            #[doc = #doc]
            #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
            pub enum #state { #(#defs,)* }
        });
        items.push(quote! {
            #[doc = " The first named state whose pattern matches, if any."]
            pub const fn state(self) -> Option<#state> {
                #(#checks)*
                None
            }
        });
    }
    let layout = if s.bits.is_empty() {
        TokenStream::new()
    } else {
        layout.tokens()
    };
    let doc = value_doc(entry, "The bit fields");
    struct_with(name, &ty, doc.tokens(), layout, &items, extra)
}

fn struct_with(
    name: &Ident,
    ty: &TokenStream,
    doc: TokenStream,
    layout: TokenStream,
    items: &[TokenStream],
    extra: TokenStream,
) -> TokenStream {
    quote! {
        #doc
        #layout
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
        pub struct #name(pub #ty);
        impl #name {
            #[doc = " The value with this raw form."]
            pub const fn from_raw(raw: #ty) -> Self {
                Self(raw)
            }
            #[doc = " The raw form on the bus."]
            pub const fn to_raw(self) -> #ty {
                self.0
            }
            #(#items)*
        }
        #extra
    }
}

fn bit_field_methods(
    field: &BitField,
    getter: &Ident,
    setter: &Ident,
    raw: Prim,
    enum_ident: Option<&Ident>,
) -> TokenStream {
    let ty = raw.tokens();
    let uty = raw.unsigned().tokens();
    let lsb = proc_macro2::Literal::u32_unsuffixed(field.lsb);
    let mask = prim::hex((1u128 << field.width) - 1);
    let field_prim = Prim::int(false, field.width);
    let field_ty = field_prim.tokens();
    let bits_text = if field.width == 1 {
        format!("Bit {}", field.lsb)
    } else {
        format!("Bits {}–{}", field.lsb, field.lsb + field.width - 1)
    };
    let mut doc = format!(" {bits_text}: {}", docs::text(&field.name));
    if let Some(text) = &field.text {
        doc.push_str(&format!(" — {}", docs::text(text)));
    }
    let set_doc = format!(" A copy with `{getter}` set.");
    // The raw value as its unsigned type (a cast only for signed raws).
    let base = if raw.is_signed() {
        quote!((self.0 as #uty))
    } else {
        quote!(self.0)
    };
    let shifted = if field.lsb == 0 {
        base.clone()
    } else {
        quote!((#base >> #lsb))
    };
    let bare = quote!(#shifted & #mask);
    let extract = quote!((#bare));
    // `value` (already of the unsigned raw type) placed into the field.
    let insert = |value: TokenStream| {
        let placed = if field.lsb == 0 {
            quote!((#value & #mask))
        } else {
            quote!(((#value & #mask) << #lsb))
        };
        let cleared = if field.lsb == 0 {
            quote!(#base & !#mask)
        } else {
            quote!(#base & !(#mask << #lsb))
        };
        if raw.is_signed() {
            quote!(Self((#cleared | #placed) as #ty))
        } else {
            quote!(Self(#cleared | #placed))
        }
    };
    let widen = |value: TokenStream, from: Prim| {
        if from == raw.unsigned() {
            value
        } else {
            quote!((#value as #uty))
        }
    };
    let narrow = |value: TokenStream| {
        if field_prim == raw.unsigned() {
            bare.clone()
        } else {
            quote!(#value as #field_ty)
        }
    };
    let mut out = if field.width == 1 {
        let ins = insert(quote!((value as #uty)));
        quote! {
            #[doc = #doc]
            pub const fn #getter(self) -> bool { #extract != 0 }
            #[doc = #set_doc]
            pub const fn #setter(self, value: bool) -> Self { #ins }
        }
    } else if let Some(enum_ident) = enum_ident {
        let ins = insert(widen(quote!(value.to_raw()), field_prim));
        let get = narrow(extract.clone());
        quote! {
            #[doc = #doc]
            pub const fn #getter(self) -> #enum_ident { #enum_ident::from_raw(#get) }
            #[doc = #set_doc]
            pub const fn #setter(self, value: #enum_ident) -> Self { #ins }
        }
    } else {
        let ins = insert(widen(quote!(value), field_prim));
        let get = narrow(extract.clone());
        quote! {
            #[doc = #doc]
            pub const fn #getter(self) -> #field_ty { #get }
            #[doc = #set_doc]
            pub const fn #setter(self, value: #field_ty) -> Self { #ins }
        }
    };
    if let Some(scale) = field.scale.filter(|s| s.is_finite()) {
        let value_fn = format_ident!("{}_value", getter.to_string().trim_end_matches('_'));
        let unit = field
            .unit
            .as_deref()
            .map(|u| format!(" in {}", docs::text(u)))
            .unwrap_or_default();
        let doc = format!(" The field's physical value{unit}: raw × {scale}.");
        let s = f64_lit(scale);
        let raw_expr = if enum_ident.is_some() {
            quote!(self.#getter().to_raw())
        } else {
            quote!(self.#getter())
        };
        out.extend(quote! {
            #[doc = #doc]
            pub const fn #value_fn(self) -> f64 { #raw_expr as f64 * #s }
        });
    }
    out
}
