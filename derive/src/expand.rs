//! The expansion of `#[derive(Pdo)]`: constants of the layout computed
//! from the entries' data types, the codec as calls of the runtime's
//! `pdo::layout`, `od::Pdo`, and the checks as trait bounds spanned on
//! each field.

use proc_macro2::{Literal, TokenStream};
use quote::{quote, quote_spanned};

use crate::parse::{Direction, FieldKind, Pdo};

pub(crate) fn expand(pdo: &Pdo) -> TokenStream {
    let rt = &pdo.runtime;
    let name = pdo.ident;
    let n = pdo.fields.len();
    let n_lit = Literal::usize_unsuffixed(n);
    let entry = |k: &FieldKind| match k {
        FieldKind::Entry { path, .. } => Some(path.clone()),
        FieldKind::Gap(_) => None,
    };
    let widths = pdo.fields.iter().map(|f| match &f.kind {
        FieldKind::Entry { path, bits } => {
            let bits = match bits {
                Some(b) => {
                    let b = Literal::u32_unsuffixed(*b);
                    quote!(::core::option::Option::Some(#b))
                }
                None => quote!(::core::option::Option::None),
            };
            quote!(#rt::pdo::layout::width(<#path as #rt::od::Entry>::DATA_TYPE, #bits))
        }
        FieldKind::Gap(bits) => {
            let b = Literal::u32_unsuffixed(*bits);
            quote!(#b)
        }
    });
    let keys = pdo.fields.iter().map(|f| match entry(&f.kind) {
        Some(path) => quote! {
            #rt::pdo::derive::key(
                <#path as #rt::od::Entry>::INDEX,
                <#path as #rt::od::Entry>::SUBINDEX,
            )
        },
        None => quote!(#rt::pdo::derive::NO_KEY),
    });
    let counts = pdo.fields.iter().map(|f| match &f.kind {
        FieldKind::Entry { .. } => {
            quote!(#rt::pdo::derive::entry_count(::core::option::Option::None))
        }
        FieldKind::Gap(bits) => {
            let b = Literal::u32_unsuffixed(*bits);
            quote!(#rt::pdo::derive::entry_count(::core::option::Option::Some(#b)))
        }
    });
    let count = quote!(0 #(+ #counts)*);
    let pushes = pdo.fields.iter().enumerate().map(|(i, f)| {
        let i = Literal::usize_unsuffixed(i);
        let target = match entry(&f.kind) {
            Some(path) => quote! {
                ::core::option::Option::Some((
                    <#path as #rt::od::Entry>::INDEX,
                    <#path as #rt::od::Entry>::SUBINDEX,
                ))
            },
            None => quote!(::core::option::Option::None),
        };
        quote!(n = #rt::pdo::derive::push_entries(&mut out, n, #target, #name::__PDO_WIDTHS[#i]);)
    });
    let decodes = pdo.fields.iter().enumerate().map(|(i, f)| {
        let ident = f.ident;
        let ty = f.ty;
        let i = Literal::usize_unsuffixed(i);
        match entry(&f.kind) {
            Some(path) => quote! {
                #ident: <#ty as #rt::od::Scalar>::from_raw(#rt::pdo::layout::get(
                    word,
                    #name::__PDO_OFFSETS[#i],
                    #name::__PDO_WIDTHS[#i],
                    <#path as #rt::od::Entry>::DATA_TYPE.is_signed(),
                ))
            },
            None => quote!(#ident: ()),
        }
    });
    // The highest field first, as the generator writes it: the compiler
    // merges adjacent fields from the top of the word into one load more
    // readily that way.
    let encodes = pdo.fields.iter().enumerate().rev().filter_map(|(i, f)| {
        let ident = f.ident;
        let i = Literal::usize_unsuffixed(i);
        entry(&f.kind).map(|_| {
            quote! {
                word = #rt::pdo::layout::put(
                    word,
                    #name::__PDO_OFFSETS[#i],
                    #name::__PDO_WIDTHS[#i],
                    #rt::od::Scalar::to_raw(self.#ident),
                );
            }
        })
    });
    let checks = checks(pdo);
    let number = Literal::u16_unsuffixed(pdo.number);
    let (direction, tpdo, comm_base) = match pdo.direction {
        Direction::Tpdo => (quote!(#rt::od::PdoDirection::Tpdo), true, 0x1800u16),
        Direction::Rpdo => (quote!(#rt::od::PdoDirection::Rpdo), false, 0x1400u16),
    };
    let comm = Literal::u16_unsuffixed(comm_base + pdo.number - 1);
    let map = Literal::u16_unsuffixed(comm_base + 0x200 + pdo.number - 1);
    let kind = if tpdo { "TPDO" } else { "RPDO" };
    let cob = if pdo.number <= 4 {
        let doc = format!(
            " The COB-ID of {kind}{} in the predefined connection set for a node.",
            pdo.number
        );
        quote! {
            #[doc = #doc]
            #[inline]
            pub const fn cob_id(node_id: #rt::od::NodeId) -> #rt::od::standard::PdoCobId {
                match #rt::pdo::derive::predefined_cob_id(#tpdo, #number, node_id.get()) {
                    ::core::option::Option::Some(id) => id,
                    ::core::option::Option::None => #rt::od::standard::PdoCobId::from_raw(0),
                }
            }
            #[doc = " The CAN identifier of [`Self::cob_id`]."]
            #[inline]
            pub const fn can_id(node_id: #rt::od::NodeId) -> #rt::CanId {
                Self::cob_id(node_id).can_id()
            }
        }
    } else {
        TokenStream::new()
    };
    let layout_doc = crate::layout_doc::lines(pdo);
    let len_doc = format!(" Data length in bytes of {kind}{}.", pdo.number);
    quote! {
        #(#[doc = #layout_doc])*
        impl #name {
            #[doc = #len_doc]
            pub const LEN: usize = #rt::pdo::layout::len(#rt::pdo::derive::total(#name::__PDO_WIDTHS));
            #[doc(hidden)]
            const __PDO_WIDTHS: [u32; #n_lit] = [#(#widths),*];
            #[doc(hidden)]
            const __PDO_OFFSETS: [u32; #n_lit] = #rt::pdo::derive::offsets(#name::__PDO_WIDTHS);
            #[doc(hidden)]
            const __PDO_KEYS: [u32; #n_lit] = [#(#keys),*];
            #[doc(hidden)]
            const __PDO_MAPPING: [u32; #count] = {
                let mut out = [0u32; #count];
                let mut n = 0usize;
                #(#pushes)*
                let _ = n;
                out
            };
            #cob
            #[doc = " Decodes the data of a frame; it must be exactly [`Self::LEN`] bytes. Never panics."]
            #[inline]
            pub fn decode(data: &[u8]) -> ::core::result::Result<Self, #rt::od::PdoLengthError> {
                let word = #rt::pdo::layout::load::<{ #name::LEN }>(data)?;
                ::core::result::Result::Ok(Self { #(#decodes,)* })
            }
            #[doc = " The [`Self::LEN`] data bytes of the frame."]
            #[inline]
            pub fn encode(&self) -> [u8; #name::LEN] {
                let mut word = 0u64;
                #(#encodes)*
                #rt::pdo::layout::store::<{ #name::LEN }>(word)
            }
        }
        impl #rt::od::Pdo for #name {
            const DIRECTION: #rt::od::PdoDirection = #direction;
            const NUMBER: u16 = #number;
            const COMMUNICATION_INDEX: u16 = #comm;
            const MAPPING_INDEX: u16 = #map;
            const LEN: usize = #name::LEN;
            const MAPPING: &'static [u32] = &#name::__PDO_MAPPING;
            #[inline]
            fn default_cob_id(
                node_id: #rt::od::NodeId,
            ) -> ::core::option::Option<#rt::od::standard::PdoCobId> {
                #rt::pdo::derive::predefined_cob_id(#tpdo, #number, node_id.get())
            }
            #[inline]
            fn decode(data: &[u8]) -> ::core::result::Result<Self, #rt::od::PdoLengthError> {
                #name::decode(data)
            }
            #[inline]
            fn encode_into(&self, out: &mut [u8; 8]) -> usize {
                for (o, b) in out.iter_mut().zip(self.encode()) {
                    *o = b;
                }
                #name::LEN
            }
        }
        const _: () = {
            #[allow(dead_code, clippy::all)]
            fn __eds2rust_pdo_checks() {
                #checks
            }
        };
    }
}

/// The checks of every field, each spanned on the field's attribute so the
/// compiler's message points there.
fn checks(pdo: &Pdo) -> TokenStream {
    let rt = &pdo.runtime;
    let name = pdo.ident;
    let mut out = TokenStream::new();
    for (i, f) in pdo.fields.iter().enumerate() {
        let span = f.span;
        let i = Literal::usize_unsuffixed(i);
        // The runtime's path as written at the field, so that an error's
        // span (which starts at the path) is the field's.
        let rt = respan(quote!(#rt), span);
        let d = quote!(#rt::pdo::derive);
        // Where the mapping crosses bit 64: the field that does is the one
        // reported.
        // About the field as a whole: at its name.
        let at_field = f.ident.span();
        let rt_field = respan(quote!(#rt), at_field);
        let df = quote!(#rt_field::pdo::derive);
        out.extend(quote_spanned! {at_field=>
            #df::fits::<#df::Check<{ #df::fits_at(#name::__PDO_OFFSETS[#i], #name::__PDO_WIDTHS[#i]) }>>();
        });
        let FieldKind::Entry { path, bits } = &f.kind else {
            continue;
        };
        let ty = f.ty;
        let direction = match pdo.direction {
            Direction::Tpdo => quote_spanned!(span=> #rt::od::tpdo_mapping_entry::<#path>()),
            Direction::Rpdo => quote_spanned!(span=> #rt::od::rpdo_mapping_entry::<#path>()),
        };
        let ty_span = syn::spanned::Spanned::span(ty);
        out.extend(quote_spanned! {span=>
            let _ = #direction;
            #d::fixed_size::<#d::Check<{ #d::type_bits(<#path as #rt::od::Entry>::DATA_TYPE) > 0 }>>();
        });
        out.extend(quote_spanned! {at_field=>
            #df::mapped_once::<#df::Check<{ #df::first_of_its_key(#name::__PDO_KEYS, #i) }>>();
        });
        out.extend(quote_spanned! {ty_span=>
            #d::value_of::<#path, #ty>();
        });
        match (bits, crate::layout_doc::natural_bits(ty)) {
            (Some(bits), _) => {
                let b = Literal::u32_unsuffixed(*bits);
                out.extend(quote_spanned! {span=>
                    #d::bits_fit::<#d::Check<{ #b <= #d::type_bits(<#path as #rt::od::Entry>::DATA_TYPE) }>>();
                });
            }
            // The layout table states the primitive type's width: it must
            // be the entry's. (When the type is not the entry's value type
            // at all, `value_of` says so and this check stays quiet.)
            (None, Some(natural)) => {
                let n = Literal::u32_unsuffixed(natural);
                out.extend(quote_spanned! {ty_span=>
                    #d::width_as_documented::<#d::Check<{
                        #d::type_bits(<#path as #rt::od::Entry>::DATA_TYPE) == #n
                            || ::core::mem::size_of::<<#path as #rt::od::Entry>::Value>() * 8 != #n
                    }>>();
                });
            }
            (None, None) => {}
        }
    }
    out
}

/// `tokens` with every span set to `span` (groups included).
fn respan(tokens: TokenStream, span: proc_macro2::Span) -> TokenStream {
    tokens
        .into_iter()
        .map(|mut t| {
            if let proc_macro2::TokenTree::Group(g) = &t {
                let mut group = proc_macro2::Group::new(g.delimiter(), respan(g.stream(), span));
                group.set_span(span);
                t = proc_macro2::TokenTree::Group(group);
            } else {
                t.set_span(span);
            }
            t
        })
        .collect()
}
