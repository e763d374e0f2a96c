//! `od::OBJECTS`: every entry of the device as plain data (the runtime's
//! `od::ObjectInfo`), for code that works on the whole dictionary at run
//! time, such as device simulators.

use proc_macro2::{Ident, TokenStream};
use quote::quote;

use super::entries::data_type_tokens;
use super::naming;
use crate::ir::{Access, DataType, Device, Entry, Literal, Object, ObjectKind, Value};

/// The `OBJECTS` constant, sorted by index and subindex: one
/// `ObjectInfo::new(..)` per entry, so that each entry is a line or two
/// (the variants of the runtime's enums imported into the constant's
/// block). The rows come apart from the rest so that a table of a million
/// rows is formatted a part at a time (`format.rs`).
pub(crate) fn emit<'a>(device: &'a Device, rt: &TokenStream) -> Table<'a> {
    let mut used = Used::default();
    let mut len = 0;
    for (object, entry) in entries(device) {
        row(object, entry, &mut used);
        len += 1;
    }
    // Only what the rows use is imported (an unused import warns).
    let option: Vec<Ident> = [("None", used.none), ("Some", used.some)]
        .into_iter()
        .filter(|(_, used)| *used)
        .map(|(name, _)| naming::ident(name))
        .collect();
    let option = (!option.is_empty()).then(|| quote!(use ::core::option::Option::{#(#option),*};));
    let mut od = vec![quote!(AccessRight::*), quote!(DataType::*)];
    if used.default {
        od.push(quote!(DefaultValue::*));
    }
    if used.number {
        od.push(quote!(Number::*));
    }
    od.push(quote!(ObjectInfo as O));
    Table {
        device,
        rt: rt.clone(),
        option,
        od,
        len,
    }
}

/// Every entry of the table, in its order.
fn entries(device: &Device) -> impl Iterator<Item = (&Object, &Entry)> {
    device
        .objects
        .values()
        .flat_map(|object| object.entries.values().map(move |entry| (object, &**entry)))
}

/// The `O::new(..)` expression of one entry; `used` gets what it needs imported.
fn row(object: &Object, entry: &Entry, used: &mut Used) -> TokenStream {
    let index = super::prim::hex(u128::from(object.index));
    let sub = proc_macro2::Literal::u8_unsuffixed(entry.subindex);
    let name = if matches!(object.kind, ObjectKind::Var | ObjectKind::Domain) {
        &object.name
    } else {
        &entry.name
    };
    let data_type = data_type_variant(entry.data_type);
    let access = match entry.access {
        Access::Ro => quote!(Ro),
        Access::Wo => quote!(Wo),
        Access::Rw => quote!(Rw),
        Access::Rwr => quote!(Rwr),
        Access::Rww => quote!(Rww),
        Access::Const => quote!(Const),
    };
    let mappable = entry.pdo_mappable;
    let mut row = quote!(O::new(#index, #sub, #name, #data_type, #access, #mappable));
    if let Some((default, number)) = entry.default.as_ref().and_then(default_tokens) {
        used.default = true;
        used.number |= number;
        row.extend(quote!(.with_default(#default)));
    }
    let limit = |l: &Option<Literal>| l.as_ref().and_then(|l| number_tokens(&l.value));
    let (low, high) = (limit(&entry.low_limit), limit(&entry.high_limit));
    if low.is_some() || high.is_some() {
        used.number = true;
        used.some = true;
        used.none |= low.is_none() || high.is_none();
        let (low, high) = (option(low), option(high));
        row.extend(quote!(.with_limits(#low, #high)));
    }
    row
}

/// The parts of `OBJECTS`: the rows are made when asked for, a part at a
/// time, so that the tokens of a table of a million rows are never held
/// at once.
pub(crate) struct Table<'a> {
    device: &'a Device,
    rt: TokenStream,
    option: Option<TokenStream>,
    od: Vec<TokenStream>,
    /// How many rows.
    pub len: usize,
}

impl Table<'_> {
    /// One `O::new(..)` expression per entry, in order.
    pub(crate) fn rows(&self) -> impl Iterator<Item = TokenStream> + '_ {
        entries(self.device).map(|(object, entry)| row(object, entry, &mut Used::default()))
    }

    /// The constant with `rows` as its elements: with all of
    /// [`Table::rows`], the whole constant.
    pub(crate) fn item(&self, rows: &[TokenStream]) -> TokenStream {
        let doc = " Every entry as plain data (index, subindex, name, type, access, default, limits), sorted by index and subindex.";
        let rt = &self.rt;
        if rows.is_empty() {
            return quote! {
                #[doc = #doc]
                pub const OBJECTS: &[#rt::od::ObjectInfo] = &[];
            };
        }
        let (option, od) = (&self.option, &self.od);
        quote! {
            #[doc = #doc]
            pub const OBJECTS: &[#rt::od::ObjectInfo] = {
                #option
                use #rt::od::{#(#od),*};
                &[#(#rows,)*]
            };
        }
    }
}

/// The imports the rows need.
#[derive(Default)]
struct Used {
    /// `DefaultValue` variants.
    default: bool,
    /// `Number` variants.
    number: bool,
    some: bool,
    none: bool,
}

/// The `DataType` variant of a data type, as imported into `OBJECTS`.
fn data_type_variant(data_type: DataType) -> TokenStream {
    let path = data_type_tokens(&quote!(rt), data_type);
    // `rt::od::DataType::Unsigned8` without its path.
    let tokens: Vec<proc_macro2::TokenTree> = path.into_iter().collect();
    let last_ident = tokens
        .iter()
        .rposition(|t| matches!(t, proc_macro2::TokenTree::Ident(_)))
        .expect("a variant");
    tokens[last_ident..].iter().cloned().collect()
}

fn option(tokens: Option<TokenStream>) -> TokenStream {
    match tokens {
        Some(t) => quote!(Some(#t)),
        None => quote!(None),
    }
}

fn int_tokens(v: i128) -> TokenStream {
    let lit = proc_macro2::Literal::u128_unsuffixed(v.unsigned_abs());
    if v < 0 { quote!(-#lit) } else { quote!(#lit) }
}

fn number_tokens(value: &Value) -> Option<TokenStream> {
    match value {
        Value::Integer(v) => {
            let v = int_tokens(*v);
            Some(quote!(Int(#v)))
        }
        Value::Real(f) if f.is_finite() => {
            let lit = proc_macro2::Literal::f64_unsuffixed(f.abs());
            let v = if *f < 0.0 {
                quote!(-#lit)
            } else {
                quote!(#lit)
            };
            Some(quote!(Real(#v)))
        }
        _ => None,
    }
}

/// A default's `DefaultValue`, and whether it is a `Number`.
fn default_tokens(literal: &Literal) -> Option<(TokenStream, bool)> {
    match &literal.value {
        Value::Integer(v) if literal.plus_node_id => {
            let v = int_tokens(*v);
            Some((quote!(NodeRelative(#v)), false))
        }
        Value::Text(text) => {
            let bytes = proc_macro2::Literal::byte_string(text.as_bytes());
            Some((quote!(Bytes(#bytes)), false))
        }
        Value::Bytes(bytes) => {
            let bytes = proc_macro2::Literal::byte_string(bytes);
            Some((quote!(Bytes(#bytes)), false))
        }
        value => {
            let number = number_tokens(value)?;
            Some((quote!(Number(#number)), true))
        }
    }
}
