//! `od::OBJECTS`: every entry of the device as plain data (the runtime's
//! `od::ObjectInfo`), for code that works on the whole dictionary at run
//! time, such as device simulators.

use proc_macro2::TokenStream;
use quote::quote;

use super::entries::data_type_tokens;
use crate::ir::{Access, Device, Literal, ObjectKind, Value};

/// The `OBJECTS` constant, sorted by index and subindex.
pub(crate) fn emit(device: &Device, rt: &TokenStream) -> TokenStream {
    let mut rows = Vec::new();
    for object in device.objects.values() {
        for entry in object.entries.values() {
            let index = super::prim::hex(u128::from(object.index));
            let sub = proc_macro2::Literal::u8_unsuffixed(entry.subindex);
            let name = if matches!(object.kind, ObjectKind::Var | ObjectKind::Domain) {
                &object.name
            } else {
                &entry.name
            };
            let data_type = data_type_tokens(rt, entry.data_type);
            let access = match entry.access {
                Access::Ro => quote!(Ro),
                Access::Wo => quote!(Wo),
                Access::Rw => quote!(Rw),
                Access::Rwr => quote!(Rwr),
                Access::Rww => quote!(Rww),
                Access::Const => quote!(Const),
            };
            let mappable = entry.pdo_mappable;
            let default = option(entry.default.as_ref().and_then(|l| default_tokens(l, rt)));
            let low = option(
                entry
                    .low_limit
                    .as_ref()
                    .and_then(|l| number_tokens(&l.value, rt)),
            );
            let high = option(
                entry
                    .high_limit
                    .as_ref()
                    .and_then(|l| number_tokens(&l.value, rt)),
            );
            rows.push(quote! {
                #rt::od::ObjectInfo {
                    index: #index,
                    subindex: #sub,
                    name: #name,
                    data_type: #data_type,
                    access: #rt::od::AccessRight::#access,
                    pdo_mappable: #mappable,
                    default: #default,
                    low_limit: #low,
                    high_limit: #high,
                }
            });
        }
    }
    quote! {
        #[doc = " Every entry as plain data (index, subindex, name, type, access, default, limits), sorted by index and subindex."]
        pub const OBJECTS: &[#rt::od::ObjectInfo] = &[#(#rows,)*];
    }
}

fn option(tokens: Option<TokenStream>) -> TokenStream {
    match tokens {
        Some(t) => quote!(::core::option::Option::Some(#t)),
        None => quote!(::core::option::Option::None),
    }
}

fn int_tokens(v: i128) -> TokenStream {
    let lit = proc_macro2::Literal::u128_unsuffixed(v.unsigned_abs());
    if v < 0 { quote!(-#lit) } else { quote!(#lit) }
}

fn number_tokens(value: &Value, rt: &TokenStream) -> Option<TokenStream> {
    match value {
        Value::Integer(v) => {
            let v = int_tokens(*v);
            Some(quote!(#rt::od::Number::Int(#v)))
        }
        Value::Real(f) if f.is_finite() => {
            let lit = proc_macro2::Literal::f64_unsuffixed(f.abs());
            let v = if *f < 0.0 {
                quote!(-#lit)
            } else {
                quote!(#lit)
            };
            Some(quote!(#rt::od::Number::Real(#v)))
        }
        _ => None,
    }
}

fn default_tokens(literal: &Literal, rt: &TokenStream) -> Option<TokenStream> {
    match &literal.value {
        Value::Integer(v) if literal.plus_node_id => {
            let v = int_tokens(*v);
            Some(quote!(#rt::od::DefaultValue::NodeRelative(#v)))
        }
        Value::Text(text) => {
            let bytes = proc_macro2::Literal::byte_string(text.as_bytes());
            Some(quote!(#rt::od::DefaultValue::Bytes(#bytes)))
        }
        Value::Bytes(bytes) => {
            let bytes = proc_macro2::Literal::byte_string(bytes);
            Some(quote!(#rt::od::DefaultValue::Bytes(#bytes)))
        }
        value => {
            let number = number_tokens(value, rt)?;
            Some(quote!(#rt::od::DefaultValue::Number(#number)))
        }
    }
}
