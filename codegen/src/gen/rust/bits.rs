//! Bit-field structs: the raw value with a const getter and setter per
//! field (bool, narrow integer or the field's enum), the fields' physical
//! values, and masked-pattern states (CiA 402 statusword).

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::docs::{self, Doc};
use super::naming::{Case, NameId, Namespace};
use super::prim::{self, Prim};
use super::value_parts::{Ctx, value_doc};
use crate::ir::{BitField, Entry};

pub(crate) fn bit_struct(
    cx: &mut Ctx,
    entry: &Entry,
    name: &Ident,
    raw: Prim,
    field_enums: &[Option<Ident>],
    state: Option<&Ident>,
) -> TokenStream {
    let s = &entry.semantics;
    let uty = raw.unsigned().tokens();
    let mut methods = Namespace::new(format!("impl `{name}`"), Case::Snake);
    for fixed in ["from_raw", "to_raw", "state"] {
        methods.reserve(fixed);
    }
    let ids: Vec<NameId> = s
        .bits
        .iter()
        .map(|f| {
            let key = format!("bit {}", f.lsb);
            match &f.rust_name {
                Some(pin) => methods.request_pinned(pin, &key, Some(&f.origin)),
                None => methods.request(&f.name, &key, Some(&f.origin)),
            }
        })
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
                #[inline] pub const fn #m(self) -> bool {
                    #base & #mask == #value
                }
            });
            checks.push(quote!(if self.#m() { return ::core::option::Option::Some(#state::#v); }));
        }
        let doc = format!(
            " The named states of {} (masked patterns of the raw value).",
            docs::text(&entry.name)
        );
        let derives = super::derives::attr(super::derives::MEANING, false);
        extra.extend(quote! {
            #[doc = #doc]
            #derives
            pub enum #state { #(#defs,)* }
        });
        items.push(quote! {
            #[doc = " The first named state whose pattern matches, if any."]
            #[inline] pub const fn state(self) -> ::core::option::Option<#state> {
                #(#checks)*
                ::core::option::Option::None
            }
        });
    }
    let layout = if s.bits.is_empty() {
        TokenStream::new()
    } else {
        layout.tokens()
    };
    let doc = value_doc(entry, "The bit fields");
    struct_with(name, raw, doc.tokens(), layout, &items, extra)
}

fn struct_with(
    name: &Ident,
    raw: Prim,
    doc: TokenStream,
    layout: TokenStream,
    items: &[TokenStream],
    extra: TokenStream,
) -> TokenStream {
    let ty = raw.tokens();
    let raw_methods = super::value_parts::raw_methods(&ty);
    let derives = super::derives::value(raw);
    quote! {
        #doc
        #layout
        #derives
        pub struct #name(pub #ty);
        impl #name {
            #raw_methods
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
    let alias = super::naming::alias_allowed(&field.name, &getter.to_string()).then(|| {
        let source = &field.name;
        quote!(#[doc(alias = #source)])
    });
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
            #alias
            #[inline] pub const fn #getter(self) -> bool { #extract != 0 }
            #[doc = #set_doc]
            #[inline] pub const fn #setter(self, value: bool) -> Self { #ins }
        }
    } else if let Some(enum_ident) = enum_ident {
        let ins = insert(widen(quote!(value.to_raw()), field_prim));
        let get = narrow(extract.clone());
        quote! {
            #[doc = #doc]
            #alias
            #[inline] pub const fn #getter(self) -> #enum_ident { #enum_ident::from_raw(#get) }
            #[doc = #set_doc]
            #[inline] pub const fn #setter(self, value: #enum_ident) -> Self { #ins }
        }
    } else {
        let ins = insert(widen(quote!(value), field_prim));
        let get = narrow(extract.clone());
        quote! {
            #[doc = #doc]
            #alias
            #[inline] pub const fn #getter(self) -> #field_ty { #get }
            #[doc = #set_doc]
            #[inline] pub const fn #setter(self, value: #field_ty) -> Self { #ins }
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
        let s = super::scaled::f64_lit(scale);
        let raw_expr = if enum_ident.is_some() {
            quote!(self.#getter().to_raw())
        } else {
            quote!(self.#getter())
        };
        out.extend(quote! {
            #[doc = #doc]
            #[inline] pub const fn #value_fn(self) -> f64 { #raw_expr as f64 * #s }
        });
    }
    out
}
