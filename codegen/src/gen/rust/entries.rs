//! The `od` module: one zero-sized type per entry, implementing the
//! runtime's `Entry` (index, subindex, data type, access right and value type
//! as associated items) and, when mappable, `PdoMappable`. VAR objects are
//! types in `od`; ARRAY and RECORD objects are modules in `od` holding one
//! type per sub-entry. Value types are generated beside their entry.

use proc_macro2::{Ident, TokenStream};
use quote::quote;

use super::docs::{self, Doc};
use super::errors::ErrorPlan;
use super::naming::Names;
use super::od_plan;
use super::prim::Prim;
use super::values::{self, Plan};
use crate::diag::Diagnostics;
use crate::ir::{Access, DataType, Device, Entry, Literal, Object, ObjectKind, Value};

/// What other generators need to know of an entry's generated types.
#[derive(Debug, Clone)]
pub(crate) struct EntryInfo {
    /// Path of the value type from the root, `None` for a primitive.
    pub(crate) value: Option<Vec<Ident>>,
    /// The raw type, `None` when the entry has no fixed size.
    pub(crate) raw: Option<Prim>,
    /// The entry's Rust name when it is fixed (canonical or pinned), for
    /// the names made from it (PDO fields): `PositionActualValue`.
    pub(crate) rust_name: Option<String>,
}

impl EntryInfo {
    /// The value type as written in a module `depth` levels below the root.
    pub(crate) fn value_tokens(&self, depth: usize) -> TokenStream {
        match (&self.value, self.raw) {
            (Some(path), _) => rooted(path, depth),
            (None, Some(raw)) => raw.tokens(),
            (None, None) => quote!(()),
        }
    }
}

/// `super::super::a::b` for `path` seen from `depth` levels down.
pub(crate) fn rooted(path: &[Ident], depth: usize) -> TokenStream {
    let supers = (0..depth).map(|_| quote!(super::));
    quote!(#(#supers)* #(#path)::*)
}

pub(crate) struct Ctx<'a> {
    pub(crate) device: &'a Device,
    pub(crate) rt: &'a TokenStream,
    pub(crate) errors: &'a [ErrorPlan],
    pub(crate) diags: &'a mut Diagnostics,
}

pub(crate) fn info(cx: &Ctx, module: &[Ident], e: &od_plan::EntryPlan, names: &Names) -> EntryInfo {
    let rust_name = e.fixed_name.then(|| names.text(e.zst).to_string());
    let (value, raw) = match &e.value {
        Plan::Prim(p) | Plan::Runtime { raw: p, .. } => (None, Some(*p)),
        Plan::Bytes(_) => (None, None),
        Plan::Error(i) => {
            let plan = &cx.errors[*i];
            (
                Some(vec![
                    super::naming::ident("errors"),
                    plan.code_ident.clone(),
                ]),
                Some(plan.raw),
            )
        }
        Plan::Enum { name, raw, .. }
        | Plan::Bits { name, raw, .. }
        | Plan::Scaled { name, raw } => {
            let mut path = module.to_vec();
            path.push(names.get(*name));
            (Some(path), Some(*raw))
        }
    };
    EntryInfo {
        value,
        raw,
        rust_name,
    }
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn entry_items(
    cx: &mut Ctx,
    object: &Object,
    entry: &Entry,
    ident: &Ident,
    plan: &Plan,
    names: &Names,
    module: &[Ident],
    source_name: &str,
) -> TokenStream {
    let rt = cx.rt;
    let depth = module.len();
    let errors = cx.errors;
    let error_path = |i: usize| {
        rooted(
            &[super::naming::ident("errors"), errors[i].code_ident.clone()],
            depth,
        )
    };
    let value_ty = values::type_tokens(plan, names, rt, &error_path);
    let var = matches!(object.kind, ObjectKind::Var | ObjectKind::Domain);
    let index = super::prim::hex(u128::from(object.index));
    let sub = proc_macro2::Literal::u8_unsuffixed(entry.subindex);
    let name = &entry.name;
    let data_type = data_type_tokens(rt, entry.data_type);
    let access = access_tokens(rt, entry.access);
    let mappable = entry.pdo_mappable;
    let fixed = Prim::of(entry.data_type).is_some();
    let mut out = TokenStream::new();
    let mut doc = entry_doc(object, entry, var);
    if var {
        standard_para(cx, object, &mut doc);
    }
    let doc = doc.tokens_with_alias(source_name, &ident.to_string());
    let derives = super::derives::attr(super::derives::ENTRY, false);
    // SUBINDEX 0 and PDO_MAPPABLE false are the trait's defaults.
    let sub_const = (entry.subindex != 0).then(|| quote!(const SUBINDEX: u8 = #sub;));
    let mappable_const = mappable.then(|| {
        quote!(
            const PDO_MAPPABLE: bool = true;
        )
    });
    out.extend(quote! {
        #doc
        #derives
        pub struct #ident;
        impl #rt::od::Entry for #ident {
            const INDEX: u16 = #index;
            #sub_const
            const NAME: &'static str = #name;
            const DATA_TYPE: #rt::od::DataType = #data_type;
            #mappable_const
            type Access = #access;
            type Value = #value_ty;
        }
    });
    if mappable && fixed {
        out.extend(quote!(impl #rt::od::PdoMappable for #ident {}));
    }
    if let Some(default) = default_tokens(entry, plan, &value_ty) {
        out.extend(quote! {
            impl #ident {
                #[doc = " The default value (EDS `DefaultValue`, YAML `default`)."]
                pub const DEFAULT: #value_ty = #default;
            }
        });
    }
    if let Some(default_for) = node_default_tokens(rt, entry, plan, &value_ty) {
        out.extend(quote!(impl #ident { #default_for }));
    }
    let mut vcx = values::Ctx {
        rt,
        diags: cx.diags,
    };
    out.extend(values::emit(&mut vcx, entry, plan, names));
    let canonical = crate::profiles::Canonical::of(cx.device);
    if let Some(ty) = canonical.runtime_type(object.index, entry.subindex) {
        out.extend(values::runtime_conversions(rt, plan, names, ty));
    }
    out
}

/// For a standard object: where its Rust name comes from.
pub(super) fn standard_para(cx: &Ctx, object: &Object, doc: &mut Doc) {
    if let Some(text) = crate::profiles::Canonical::of(cx.device).text(object.index) {
        doc.para(format!(
            "Standard object *{}*: named by its CiA name, whatever the source calls it.",
            docs::text(&text)
        ));
    }
}

fn entry_doc(object: &Object, entry: &Entry, var: bool) -> Doc {
    let mut doc = Doc::new();
    let title = if var || entry.name == object.name {
        format!("**{}**", docs::text(&entry.name))
    } else {
        format!(
            "**{}** of {}",
            docs::text(&entry.name),
            docs::text(&object.name)
        )
    };
    doc.para(format!(
        "{title} ({}).",
        docs::entry_facts(object.index, entry, var)
    ));
    if let Some(description) = &entry.semantics.description {
        doc.source_para(description);
    }
    doc.unit(&entry.semantics);
    let literal = |l: &Literal| docs::text(&l.text);
    let mut facts = Vec::new();
    if let Some(d) = &entry.default {
        facts.push(format!("Default: {}", literal(d)));
    }
    if let Some(l) = &entry.low_limit {
        facts.push(format!("Low limit: {}", literal(l)));
    }
    if let Some(h) = &entry.high_limit {
        facts.push(format!("High limit: {}", literal(h)));
    }
    doc.facts_and_origin(&facts, &entry.origin);
    doc
}

pub(super) fn default_tokens(
    entry: &Entry,
    plan: &Plan,
    value_ty: &TokenStream,
) -> Option<TokenStream> {
    let literal = entry.default.as_ref()?;
    if literal.plus_node_id {
        return None;
    }
    let raw = match plan {
        Plan::Prim(p) => *p,
        Plan::Bytes(_) => return None,
        Plan::Error(_)
        | Plan::Enum { .. }
        | Plan::Bits { .. }
        | Plan::Scaled { .. }
        | Plan::Runtime { .. } => {
            let raw_prim = Prim::of(entry.data_type)?;
            let lit = raw_literal(&literal.value, raw_prim)?;
            return Some(quote!(#value_ty::from_raw(#lit)));
        }
    };
    raw_literal(&literal.value, raw)
}

/// `default_for(node_id)` for a `$NODEID`-relative default of an integer
/// entry (COB-IDs of EMCY, SDO and PDOs), when every node id fits the type.
fn node_default_tokens(
    rt: &TokenStream,
    entry: &Entry,
    plan: &Plan,
    value_ty: &TokenStream,
) -> Option<TokenStream> {
    let literal = entry.default.as_ref().filter(|l| l.plus_node_id)?;
    let raw = match plan {
        Plan::Prim(raw) => *raw,
        Plan::Enum { .. } | Plan::Bits { .. } | Plan::Scaled { .. } | Plan::Runtime { .. } => {
            Prim::of(entry.data_type)?
        }
        Plan::Bytes(_) | Plan::Error(_) => return None,
    };
    let Value::Integer(offset) = literal.value else {
        return None;
    };
    let (low, high) = raw.range();
    if !raw.is_integer() || offset < low || offset + 127 > high {
        return None;
    }
    let ty = raw.tokens();
    let lit = raw.lit(offset);
    let doc = format!(
        " The default value for a node: {}.",
        docs::text(&literal.text)
    );
    let body = match plan {
        Plan::Prim(_) => quote!(#lit + node_id.get() as #ty),
        _ => quote!(#value_ty::from_raw(#lit + node_id.get() as #ty)),
    };
    Some(quote! {
        #[doc = #doc]
        #[inline] pub const fn default_for(node_id: #rt::od::NodeId) -> #value_ty {
            #body
        }
    })
}

fn raw_literal(value: &Value, raw: Prim) -> Option<TokenStream> {
    match (value, raw) {
        (Value::Integer(v), Prim::Bool) => match v {
            0 => Some(quote!(false)),
            1 => Some(quote!(true)),
            _ => None,
        },
        (Value::Integer(v), p) if p.is_integer() => {
            let (low, high) = p.range();
            (low..=high).contains(v).then(|| p.lit(*v))
        }
        // An f32 is written as the shortest text that reads back as the same
        // f32 (1.2, not its f64 widening 1.2000000476837158).
        (Value::Real(f), Prim::F32) if (*f as f32).is_finite() => {
            let lit = proc_macro2::Literal::f32_unsuffixed(f.abs() as f32);
            Some(if *f < 0.0 {
                quote!(-#lit)
            } else {
                quote!(#lit)
            })
        }
        (Value::Real(f), Prim::F64) if f.is_finite() => {
            let lit = proc_macro2::Literal::f64_unsuffixed(f.abs());
            Some(if *f < 0.0 {
                quote!(-#lit)
            } else {
                quote!(#lit)
            })
        }
        (Value::Integer(v), Prim::F32 | Prim::F64) if v.unsigned_abs() < (1 << 53) => {
            let lit = proc_macro2::Literal::f64_unsuffixed(v.unsigned_abs() as f64);
            Some(if *v < 0 { quote!(-#lit) } else { quote!(#lit) })
        }
        _ => None,
    }
}

pub(super) fn access_tokens(rt: &TokenStream, access: Access) -> TokenStream {
    match access {
        Access::Ro => quote!(#rt::od::access::Ro),
        Access::Wo => quote!(#rt::od::access::Wo),
        Access::Rw => quote!(#rt::od::access::Rw),
        Access::Rwr => quote!(#rt::od::access::Rwr),
        Access::Rww => quote!(#rt::od::access::Rww),
        Access::Const => quote!(#rt::od::access::Const),
    }
}

pub(super) fn data_type_tokens(rt: &TokenStream, data_type: DataType) -> TokenStream {
    use DataType::*;
    let variant = match data_type {
        Boolean => quote!(Boolean),
        Integer8 => quote!(Integer8),
        Integer16 => quote!(Integer16),
        Integer24 => quote!(Integer24),
        Integer32 => quote!(Integer32),
        Integer40 => quote!(Integer40),
        Integer48 => quote!(Integer48),
        Integer56 => quote!(Integer56),
        Integer64 => quote!(Integer64),
        Unsigned8 => quote!(Unsigned8),
        Unsigned16 => quote!(Unsigned16),
        Unsigned24 => quote!(Unsigned24),
        Unsigned32 => quote!(Unsigned32),
        Unsigned40 => quote!(Unsigned40),
        Unsigned48 => quote!(Unsigned48),
        Unsigned56 => quote!(Unsigned56),
        Unsigned64 => quote!(Unsigned64),
        Real32 => quote!(Real32),
        Real64 => quote!(Real64),
        VisibleString => quote!(VisibleString),
        OctetString => quote!(OctetString),
        UnicodeString => quote!(UnicodeString),
        TimeOfDay => quote!(TimeOfDay),
        TimeDifference => quote!(TimeDifference),
        Domain => quote!(Domain),
        Other(code) => {
            let code = super::prim::hex(u128::from(code));
            quote!(Other(#code))
        }
    };
    quote!(#rt::od::DataType::#variant)
}
