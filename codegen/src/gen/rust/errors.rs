//! Error tables: per device error table an enum of its codes with the
//! source's texts, and a newtype over the raw code (the value type of the
//! entries that report such codes) that classifies on demand (`kind()`).

use proc_macro2::{Ident, TokenStream};
use quote::quote;

use super::docs::{self, Doc};
use super::naming::{Case, Namespace};
use super::prim::{self, Prim};
use crate::diag::Diagnostics;
use crate::ir::{Device, ErrorTable, ErrorTableKind};

/// The generated enum of one error table.
pub(crate) struct ErrorPlan {
    pub(crate) table: usize,
    /// The enum of the codes.
    pub(crate) ident: Ident,
    /// The newtype over a raw code.
    pub(crate) code_ident: Ident,
    /// The code type: wide enough for every code and every entry that
    /// refers to the table.
    pub(crate) raw: Prim,
}

/// Names the enums (in module `errors`) and sizes their code types.
pub(crate) fn plan(device: &Device, diags: &mut Diagnostics) -> Vec<ErrorPlan> {
    let mut ns = Namespace::new("module `errors`", Case::UpperCamel);
    ns.reserve_constructor_names();
    let ids: Vec<_> = device
        .error_tables
        .iter()
        .map(|t| {
            (
                ns.request(&t.name, "table", Some(&t.origin)),
                ns.request(&format!("{} code", t.name), "table", Some(&t.origin)),
            )
        })
        .collect();
    let names = ns.resolve(diags);
    device
        .error_tables
        .iter()
        .enumerate()
        .zip(ids)
        .map(|((i, table), (id, code_id))| {
            let mut bits = match table.kind {
                ErrorTableKind::Emcy => 16,
                ErrorTableKind::SdoAbort => 32,
                ErrorTableKind::Device => 8,
            };
            let widest_code = table.codes.iter().map(|c| c.code).max().unwrap_or(0);
            bits = bits.max(32 - widest_code.leading_zeros());
            for object in device.objects.values() {
                for entry in object.entries.values() {
                    if entry.semantics.error_table.as_deref() == Some(table.name.as_str())
                        && let Some(p) = Prim::of(entry.data_type).filter(|p| p.is_integer())
                    {
                        bits = bits.max(match p.unsigned() {
                            Prim::U8 => 8,
                            Prim::U16 => 16,
                            Prim::U32 => 32,
                            _ => 64,
                        });
                    }
                }
            }
            ErrorPlan {
                table: i,
                ident: names.get(id),
                code_ident: names.get(code_id),
                raw: Prim::int(false, bits),
            }
        })
        .collect()
}

/// The `errors` module's items.
pub(crate) fn emit(
    device: &Device,
    plans: &[ErrorPlan],
    rt: &TokenStream,
    diags: &mut Diagnostics,
) -> TokenStream {
    let mut out = TokenStream::new();
    for plan in plans {
        out.extend(emit_table(
            &device.error_tables[plan.table],
            plan,
            rt,
            diags,
        ));
    }
    out
}

fn emit_table(
    table: &ErrorTable,
    plan: &ErrorPlan,
    rt: &TokenStream,
    diags: &mut Diagnostics,
) -> TokenStream {
    let name = &plan.ident;
    let ty = plan.raw.tokens();
    let mut ns = Namespace::new(format!("enum `errors::{name}`"), Case::UpperCamel);
    ns.reserve("Unknown");
    let ids: Vec<_> = table
        .codes
        .iter()
        .map(|c| ns.request(&c.name, &format!("code {:#X}", c.code), Some(&c.origin)))
        .collect();
    let names = ns.resolve(diags);
    let mut defs = Vec::new();
    let mut from_arms = Vec::new();
    let mut to_arms = Vec::new();
    let mut name_arms = Vec::new();
    let mut text_arms = Vec::new();
    let mut reaction_arms = Vec::new();
    let mut remedy_arms = Vec::new();
    for (code, id) in table.codes.iter().zip(&ids) {
        let v = names.get(*id);
        let lit = prim::hex(u128::from(code.code));
        let mut doc = Doc::new();
        doc.para(format!("**{:#X}** {}", code.code, docs::text(&code.name)));
        if let Some(text) = &code.text {
            doc.source_para(text);
        }
        if let Some(reaction) = &code.reaction {
            doc.para(format!("Reaction: {}", docs::text(reaction)));
        }
        if let Some(remedy) = &code.remedy {
            doc.para(format!("Remedy: {}", docs::text(remedy)));
        }
        doc.origin(&code.origin);
        let doc = doc.tokens_with_alias(&code.name, names.text(*id));
        defs.push(quote!(#doc #v));
        from_arms.push(quote!(#lit => Self::#v));
        to_arms.push(quote!(Self::#v => #lit));
        let source = &code.name;
        name_arms.push(quote!(Self::#v => #source));
        let text = code.text.as_deref().unwrap_or(&code.name);
        text_arms.push(quote!(Self::#v => #text));
        if let Some(reaction) = &code.reaction {
            reaction_arms.push(quote!(Self::#v => ::core::option::Option::Some(#reaction)));
        }
        if let Some(remedy) = &code.remedy {
            remedy_arms.push(quote!(Self::#v => ::core::option::Option::Some(#remedy)));
        }
    }
    let kind = match table.kind {
        ErrorTableKind::Emcy => "EMCY error codes",
        ErrorTableKind::Device => "device error codes",
        ErrorTableKind::SdoAbort => "SDO abort codes",
    };
    let mut doc = Doc::new();
    doc.para(format!("**{}**: {kind}.", docs::text(&table.name)));
    if let Some(description) = &table.description {
        doc.source_para(description);
    }
    doc.origin(&table.origin);
    let doc = doc.tokens_with_alias(&table.name, &name.to_string());
    let optional = |arms: &[TokenStream]| {
        if arms.is_empty() {
            quote!(::core::option::Option::None)
        } else {
            quote!(match self { #(#arms,)* _ => ::core::option::Option::None })
        }
    };
    let reaction = optional(&reaction_arms);
    let remedy = optional(&remedy_arms);
    let code_name = &plan.code_ident;
    let scalar = super::values::scalar_impl(rt, code_name, plan.raw);
    let code_doc = format!(
        " A raw code of [`{name}`], as entries report it; [`Self::kind`] gives its meaning."
    );
    let display_width = match plan.raw {
        Prim::U8 => 2usize,
        Prim::U16 => 4,
        _ => 8,
    };
    let raw_methods = super::value_parts::raw_methods(&ty);
    let meaning_derives = super::derives::attr(super::derives::MEANING, false);
    let value_derives = super::derives::value(plan.raw);
    quote! {
        #doc
        #meaning_derives
        pub enum #name {
            #(#defs,)*
            #[doc = " A code the table does not list."]
            Unknown(#ty),
        }
        impl #name {
            #[doc = " The meaning of a code; every code has one."]
            #[inline] pub const fn from_code(code: #ty) -> Self {
                match code {
                    #(#from_arms,)*
                    other => Self::Unknown(other),
                }
            }
            #[doc = " The code on the bus."]
            #[inline] pub const fn code(self) -> #ty {
                match self {
                    #(#to_arms,)*
                    Self::Unknown(code) => code,
                }
            }
            #[doc = " The code's name in the source (`\"unknown\"` for an unlisted code)."]
            #[inline] pub const fn name(self) -> &'static str {
                match self {
                    #(#name_arms,)*
                    Self::Unknown(_) => "unknown",
                }
            }
            #[doc = " The source's text for the code (its name when there is none)."]
            #[inline] pub const fn text(self) -> &'static str {
                match self {
                    #(#text_arms,)*
                    Self::Unknown(_) => "code not listed in the error table",
                }
            }
            #[doc = " What the device does, as the source says."]
            #[inline] pub const fn reaction(self) -> ::core::option::Option<&'static str> {
                #reaction
            }
            #[doc = " What to do about it, as the source says."]
            #[inline] pub const fn remedy(self) -> ::core::option::Option<&'static str> {
                #remedy
            }
        }
        impl ::core::fmt::Display for #name {
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                write!(f, "{:#0width$X} {}", self.code(), self.text(), width = #display_width + 2)
            }
        }
        impl #rt::od::ErrorTable for #name {
            #[inline]
            fn lookup(code: u64) -> ::core::option::Option<Self> {
                match <#ty as ::core::convert::TryFrom<u64>>::try_from(code) {
                    ::core::result::Result::Ok(code) => ::core::option::Option::Some(Self::from_code(code)),
                    ::core::result::Result::Err(_) => ::core::option::Option::None,
                }
            }
            #[inline]
            fn code(self) -> u64 {
                self.code() as u64
            }
            #[inline]
            fn is_known(self) -> bool {
                !::core::matches!(self, Self::Unknown(_))
            }
            #[inline]
            fn name(self) -> &'static str {
                self.name()
            }
            #[inline]
            fn text(self) -> &'static str {
                self.text()
            }
            #[inline]
            fn reaction(self) -> ::core::option::Option<&'static str> {
                self.reaction()
            }
            #[inline]
            fn remedy(self) -> ::core::option::Option<&'static str> {
                self.remedy()
            }
        }
        #[doc = #code_doc]
        #value_derives
        pub struct #code_name(pub #ty);
        impl #code_name {
            #raw_methods
            #[doc = " The meaning of the code."]
            #[inline] pub const fn kind(self) -> #name {
                #name::from_code(self.0)
            }
            #[doc = " The code of a meaning."]
            #[inline] pub const fn from_kind(kind: #name) -> Self {
                Self(kind.code())
            }
        }
        impl ::core::convert::From<#name> for #code_name {
            #[inline]
            fn from(kind: #name) -> Self {
                Self::from_kind(kind)
            }
        }
        impl ::core::convert::From<#code_name> for #name {
            #[inline]
            fn from(code: #code_name) -> Self {
                code.kind()
            }
        }
        impl ::core::fmt::Display for #code_name {
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                ::core::fmt::Display::fmt(&self.kind(), f)
            }
        }
        #scalar
    }
}
