//! The `pdo` module: one struct per default PDO mapping, with `encode` into a
//! fixed array and `decode` from a slice by shifts and masks at the offsets
//! the mapping gives (any bit offset, widths 1–64, sign extension), COB-ID
//! helpers per node id, and the runtime's `Pdo` trait. The same code makes
//! the PDOs a network configures ([`Source::Network`]): the network's
//! mapping and communication values stand in the device's entries as
//! configured values, as in a DCF.

use std::collections::BTreeMap;

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::docs::{self, Doc};
use super::entries::EntryInfo;
use super::naming::{Case, NameId, Namespace};
use super::prim::{self, Prim};
use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::pdo::{MappedObject, MappingProblem, check_entry, is_mapping_object, raw_mapping};
use crate::ir::{DataType, Device, Object, PdoDirection, Value};

/// One field of a PDO: a mapped entry at a bit offset.
pub(crate) struct Field<'a> {
    target: MappedObject,
    pub(crate) offset: u32,
    pub(crate) width: u32,
    pub(crate) info: &'a EntryInfo,
    raw: Prim,
    entry_name: &'a str,
    data_type: DataType,
    pub(crate) name: NameId,
}

pub(crate) struct Layout<'a> {
    pub(crate) mapping: &'a Object,
    pub(crate) direction: PdoDirection,
    pub(crate) number: u16,
    pub(crate) fields: Vec<Field<'a>>,
    /// The dummy entries: offset, width, type.
    pub(crate) gaps: Vec<(u32, u32, DataType)>,
    /// The mapping entries in order, dummies included (`index << 16 | sub << 8 | bits`).
    entries: Vec<u32>,
    /// Mapped bits in all.
    pub(crate) total: u32,
}

/// One planned PDO struct: its layout, label, name and field names.
pub(crate) struct Planned<'a> {
    pub(crate) layout: Layout<'a>,
    label: Option<&'a crate::ir::PdoLabel>,
    pub(crate) ident: proc_macro2::Ident,
    pub(crate) fields: super::naming::Names,
}

/// Lays out every default PDO and resolves the names of the structs and
/// their fields, in the order `emit` writes them (and `api` lists them).
pub(crate) fn plan<'a>(
    device: &'a Device,
    infos: &'a BTreeMap<(u16, u8), EntryInfo>,
    diags: &mut Diagnostics,
) -> Vec<Planned<'a>> {
    let mut structs = Namespace::new("module `pdo`", Case::UpperCamel);
    let mut planned = Vec::new();
    for mapping in device
        .objects
        .values()
        .filter(|o| is_mapping_object(o.index))
    {
        let Some((layout, fields_ns)) = layout(device, mapping, infos, diags) else {
            continue;
        };
        let label = device
            .pdo_labels
            .iter()
            .find(|l| l.direction == layout.direction && l.number == layout.number);
        let prefix = match layout.direction {
            PdoDirection::Rpdo => "rpdo",
            PdoDirection::Tpdo => "tpdo",
        };
        let source = match label {
            Some(label) => format!("{prefix}{} {}", layout.number, label.name),
            None => format!("{prefix}{}", layout.number),
        };
        let id = structs.request(
            &source,
            &format!("x{:04X}", mapping.index),
            Some(&mapping.origin),
        );
        planned.push((layout, fields_ns, label, id));
    }
    let names = structs.resolve(diags);
    planned
        .into_iter()
        .map(|(layout, fields_ns, label, id)| Planned {
            fields: fields_ns.resolve(diags),
            ident: names.get(id),
            layout,
            label,
        })
        .collect()
}

/// Where the PDOs of the `pdo` module come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Source {
    /// The device file's defaults (mapping and communication defaults).
    Defaults,
    /// A network's configuration: the mapping and communication entries'
    /// configured values (`parameter_value`, as a DCF holds them) first.
    Network,
}

/// One generated PDO struct, for the code that refers to it (the network
/// module's process image).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Emitted {
    pub(crate) direction: PdoDirection,
    pub(crate) number: u16,
    pub(crate) ident: String,
    /// Data length in bytes.
    pub(crate) len: usize,
    /// Whether a field holds a float (no `Eq`, `Hash`).
    pub(crate) float: bool,
}

/// The `pdo` module's items (empty when the device has no PDO of `source`)
/// and what each struct is.
pub(crate) fn emit(
    device: &Device,
    infos: &BTreeMap<(u16, u8), EntryInfo>,
    source: Source,
    rt: &TokenStream,
    diags: &mut Diagnostics,
) -> (TokenStream, Vec<Emitted>) {
    let mut out = TokenStream::new();
    let mut emitted = Vec::new();
    for p in plan(device, infos, diags) {
        out.extend(emit_struct(
            device, &p.layout, &p.ident, p.label, &p.fields, source, rt,
        ));
        emitted.push(Emitted {
            direction: p.layout.direction,
            number: p.layout.number,
            ident: p.ident.to_string(),
            len: p.layout.total.div_ceil(8) as usize,
            float: p.layout.fields.iter().any(|f| f.raw.is_float()),
        });
    }
    (out, emitted)
}

fn warn(diags: &mut Diagnostics, mapping: &Object, message: String) {
    diags.push(Diagnostic {
        severity: Severity::Warning,
        code: "gen::pdo-skipped",
        file: mapping.origin.file.clone(),
        location: Location {
            line: Some(mapping.origin.line).filter(|&l| l > 0),
            ..Location::default()
        },
        message,
        notes: Vec::new(),
    });
}

fn layout<'a>(
    device: &'a Device,
    mapping: &'a Object,
    infos: &'a BTreeMap<(u16, u8), EntryInfo>,
    diags: &mut Diagnostics,
) -> Option<(Layout<'a>, Namespace)> {
    let (direction, number) = if mapping.index >= 0x1A00 {
        (PdoDirection::Tpdo, mapping.index - 0x1A00 + 1)
    } else {
        (PdoDirection::Rpdo, mapping.index - 0x1600 + 1)
    };
    let count = mapping
        .entries
        .get(&0)
        .map(Box::as_ref)
        .and_then(raw_mapping)
        .unwrap_or(u32::MAX);
    let name = format!("{direction:?}{number}").to_uppercase();
    let mut fields_ns = Namespace::new(
        format!("struct of {name} (0x{:04X})", mapping.index),
        Case::Snake,
    );
    let mut fields = Vec::new();
    let mut gaps = Vec::new();
    let mut entries = Vec::new();
    let mut offset = 0u32;
    for entry in mapping
        .entries
        .values()
        .filter(|e| e.subindex >= 1 && u32::from(e.subindex) <= count)
    {
        let Some(raw) = raw_mapping(entry).filter(|&r| r != 0) else {
            continue;
        };
        let target = MappedObject::from_raw(raw);
        entries.push(raw);
        let width = u32::from(target.bits);
        let problems = check_entry(device, raw);
        let fatal: Vec<&MappingProblem> = problems
            .iter()
            .filter(|p| !matches!(p, MappingProblem::NotMappable { .. }))
            .collect();
        if let Some(problem) = fatal.first() {
            warn(
                diags,
                mapping,
                format!("{name} is not generated: sub {} {problem}", entry.subindex),
            );
            return None;
        }
        if width == 0 {
            warn(
                diags,
                mapping,
                format!(
                    "{name} is not generated: sub {} maps 0 bits",
                    entry.subindex
                ),
            );
            return None;
        }
        if target.is_dummy() {
            gaps.push((offset, width, DataType::from_code(target.index)));
            offset += width;
            continue;
        }
        let Some(info) = infos.get(&(target.index, target.subindex)) else {
            warn(
                diags,
                mapping,
                format!(
                    "{name} is not generated: 0x{:04X} sub {} has no generated type",
                    target.index, target.subindex
                ),
            );
            return None;
        };
        let Some(raw_prim) = info.raw else {
            warn(
                diags,
                mapping,
                format!(
                    "{name} is not generated: 0x{:04X} sub {} has no fixed size",
                    target.index, target.subindex
                ),
            );
            return None;
        };
        let object = &device.objects[&target.index];
        let mapped = &object.entries[&target.subindex];
        let source = if matches!(
            object.kind,
            crate::ir::ObjectKind::Var | crate::ir::ObjectKind::Domain
        ) {
            &object.name
        } else {
            &mapped.name
        };
        // A standard or pinned entry's field follows its Rust name
        // (`position_actual_value` whatever the vendor calls 0x6064).
        let name_id = fields_ns.request(
            info.rust_name.as_deref().unwrap_or(source),
            &format!("x{:04X} sub {}", target.index, target.subindex),
            Some(&mapped.origin),
        );
        fields.push(Field {
            target,
            offset,
            width,
            info,
            raw: raw_prim,
            entry_name: source,
            data_type: mapped.data_type,
            name: name_id,
        });
        offset += width;
    }
    if offset > 64 {
        warn(
            diags,
            mapping,
            format!(
                "{name} is not generated: its mapping totals {offset} bits; a PDO carries at most 64"
            ),
        );
        return None;
    }
    if fields.is_empty() {
        return None;
    }
    Some((
        Layout {
            mapping,
            direction,
            number,
            fields,
            gaps,
            entries,
            total: offset,
        },
        fields_ns,
    ))
}

fn span_text(offset: u32, width: u32) -> (String, String) {
    let last = offset + width - 1;
    let bits = if width == 1 {
        offset.to_string()
    } else {
        format!("{offset}–{last}")
    };
    let bytes = if offset.is_multiple_of(8) && width.is_multiple_of(8) {
        if width == 8 {
            (offset / 8).to_string()
        } else {
            format!("{}–{}", offset / 8, last / 8)
        }
    } else {
        format!("{}.{}–{}.{}", offset / 8, offset % 8, last / 8, last % 8)
    };
    (bits, bytes)
}

fn emit_struct(
    device: &Device,
    layout: &Layout,
    ident: &proc_macro2::Ident,
    label: Option<&crate::ir::PdoLabel>,
    names: &super::naming::Names,
    source: Source,
    rt: &TokenStream,
) -> TokenStream {
    let len = layout.total.div_ceil(8) as usize;
    let len_lit = Literal::usize_unsuffixed(len);
    let (kind, direction) = match layout.direction {
        PdoDirection::Rpdo => ("RPDO", quote!(#rt::od::PdoDirection::Rpdo)),
        PdoDirection::Tpdo => ("TPDO", quote!(#rt::od::PdoDirection::Tpdo)),
    };
    let comm_index = layout.direction.communication_index(layout.number);
    let mut doc = Doc::new();
    let title = match label {
        Some(l) => format!("**{kind}{} {}**", layout.number, docs::text(&l.name)),
        None => format!("**{kind}{}**", layout.number),
    };
    doc.para(format!(
        "{title}: {len} data bytes, mapping 0x{:04X}, communication parameters 0x{comm_index:04X}.",
        layout.mapping.index
    ));
    if let Some(description) = label.and_then(|l| l.description.as_deref()) {
        doc.source_para(description);
    }
    let comm = device.objects.get(&comm_index);
    let comm_default = |sub: u8| {
        comm.and_then(|o| o.entries.get(&sub))
            .and_then(|e| match source {
                Source::Defaults => e.default.as_ref(),
                Source::Network => e.parameter_value.as_ref().or(e.default.as_ref()),
            })
    };
    let mut facts = Vec::new();
    if source == Source::Network
        && let Some(t) = comm_default(1)
    {
        facts.push(format!("COB-ID {}", docs::text(&t.text)));
    }
    if let Some(t) = comm_default(2) {
        facts.push(format!("transmission type {}", docs::text(&t.text)));
    }
    if source == Source::Network
        && let Some(t) = comm_default(3).filter(|_| layout.direction == PdoDirection::Tpdo)
    {
        facts.push(format!("inhibit time {} × 100 µs", docs::text(&t.text)));
    }
    if let Some(t) = comm_default(5).filter(|_| layout.direction == PdoDirection::Tpdo) {
        facts.push(format!("event timer {} ms", docs::text(&t.text)));
    }
    if !facts.is_empty() {
        let what = match source {
            Source::Defaults => "Defaults",
            Source::Network => "Configured by the network",
        };
        doc.para(format!("{what}: {}.", facts.join(", ")));
    }
    doc.para("| Bits | Bytes | Field | Object | Type |");
    doc.line("|---|---|---|---|---|");
    let mut rows: Vec<(u32, String)> = Vec::new();
    for f in &layout.fields {
        let (bits, bytes) = span_text(f.offset, f.width);
        rows.push((
            f.offset,
            format!(
                "| {bits} | {bytes} | `{}` | 0x{:04X} sub {} {} | {} |",
                names.text(f.name),
                f.target.index,
                f.target.subindex,
                docs::text(f.entry_name),
                f.data_type.name()
            ),
        ));
    }
    for &(offset, width, data_type) in &layout.gaps {
        let (bits, bytes) = span_text(offset, width);
        rows.push((
            offset,
            format!(
                "| {bits} | {bytes} | (gap) | dummy | {} |",
                data_type.name()
            ),
        ));
    }
    rows.sort();
    for (_, row) in rows {
        doc.line(row);
    }
    doc.origin(&layout.mapping.origin);
    let doc = match label {
        Some(l) => doc.tokens_with_alias(&l.name, &ident.to_string()),
        None => doc.tokens(),
    };

    let mut defs = Vec::new();
    let mut decodes = Vec::new();
    let mut encodes = Vec::new();
    let mut float = false;
    for f in &layout.fields {
        let name = names.get(f.name);
        let ty = f.info.value_tokens(1);
        float |= f.raw.is_float();
        let (bits, bytes) = span_text(f.offset, f.width);
        let field_doc = format!(
            " **{}** (0x{:04X} sub {}): bits {bits}, bytes {bytes}.",
            docs::text(f.entry_name),
            f.target.index,
            f.target.subindex
        );
        let alias = super::naming::alias_allowed(f.entry_name, names.text(f.name)).then(|| {
            let source = f.entry_name;
            quote!(#[doc(alias = #source)])
        });
        defs.push(quote!(#[doc = #field_doc] #alias pub #name: #ty));
        // The one PDO codec (the runtime's `pdo::layout`, which
        // `#[derive(Pdo)]` expands to as well), with constant offsets.
        let offset = Literal::u32_unsuffixed(f.offset);
        let width = Literal::u32_unsuffixed(f.width);
        let signed = f.raw.is_signed();
        decodes.push(quote! {
            #name: <#ty as #rt::od::Scalar>::from_raw(
                #rt::pdo::layout::get(word, #offset, #width, #signed)
            )
        });
        encodes.push(quote! {
            word = #rt::pdo::layout::put(word, #offset, #width, #rt::od::Scalar::to_raw(self.#name));
        });
    }
    // The highest field first: the compiler merges adjacent fields from
    // the top of the word into one load more readily that way.
    encodes.reverse();
    let derives = super::derives::attr(super::derives::PDO, float);
    let cob_default = comm_default(1);
    let cob = cob_id_items(cob_default, source, rt);
    let default_cob_id = default_cob_id_fn(cob_default, rt);
    let mapping_lits = layout.entries.iter().map(|&e| prim::hex(u128::from(e)));
    let number = Literal::u16_unsuffixed(layout.number);
    let comm_lit = prim::hex(u128::from(comm_index));
    let map_lit = prim::hex(u128::from(layout.mapping.index));
    let decode_doc =
        format!(" Decodes the data of a frame; it must be exactly {len} bytes. Never panics.");
    let encode_doc = format!(" The {len} data bytes of the frame.");
    quote! {
        #doc
        #derives
        pub struct #ident {
            #(#defs,)*
        }
        impl #ident {
            #[doc = " Data length in bytes."]
            pub const LEN: usize = #len_lit;
            #cob
            #[doc = #decode_doc]
            #[inline] pub fn decode(data: &[u8]) -> ::core::result::Result<Self, #rt::od::PdoLengthError> {
                let word = #rt::pdo::layout::load::<#len_lit>(data)?;
                ::core::result::Result::Ok(Self { #(#decodes,)* })
            }
            #[doc = #encode_doc]
            #[inline] pub fn encode(&self) -> [u8; #len_lit] {
                let mut word = 0u64;
                #(#encodes)*
                #rt::pdo::layout::store::<#len_lit>(word)
            }
        }
        impl #rt::od::Pdo for #ident {
            const DIRECTION: #rt::od::PdoDirection = #direction;
            const NUMBER: u16 = #number;
            const COMMUNICATION_INDEX: u16 = #comm_lit;
            const MAPPING_INDEX: u16 = #map_lit;
            const LEN: usize = #len_lit;
            const MAPPING: &'static [u32] = &[#(#mapping_lits,)*];
            #default_cob_id
            #[inline] fn decode(data: &[u8]) -> ::core::result::Result<Self, #rt::od::PdoLengthError> {
                Self::decode(data)
            }
            #[inline] fn encode_into(&self, out: &mut [u8; 8]) -> usize {
                for (o, b) in out.iter_mut().zip(self.encode()) {
                    *o = b;
                }
                #len_lit
            }
        }
    }
}

/// `od::Pdo::default_cob_id` from the communication parameter's default.
fn default_cob_id_fn(default: Option<&crate::ir::Literal>, rt: &TokenStream) -> TokenStream {
    let value = default.and_then(|literal| match literal.value {
        Value::Integer(v) => u32::try_from(v).ok().map(|v| (v, literal.plus_node_id)),
        _ => None,
    });
    let body = match value {
        Some((_, true)) => quote!(::core::option::Option::Some(Self::cob_id(node_id))),
        Some((_, false)) => quote!({
            let _ = node_id;
            ::core::option::Option::Some(Self::COB_ID)
        }),
        None => quote!({
            let _ = node_id;
            ::core::option::Option::None
        }),
    };
    quote! {
        #[inline] fn default_cob_id(node_id: #rt::od::NodeId) -> ::core::option::Option<#rt::od::standard::PdoCobId> {
            #body
        }
    }
}

/// `cob_id(node_id)`/`can_id(node_id)` for a `$NODEID`-relative default,
/// `COB_ID`/`CAN_ID` for a fixed one, nothing without a default: the COB-ID
/// entry as the runtime's `od::standard::PdoCobId`, the identifier on the
/// bus as its `CanId`.
fn cob_id_items(
    default: Option<&crate::ir::Literal>,
    source: Source,
    rt: &TokenStream,
) -> TokenStream {
    let Some(literal) = default else {
        return TokenStream::new();
    };
    let Value::Integer(value) = literal.value else {
        return TokenStream::new();
    };
    let Ok(value) = u32::try_from(value) else {
        return TokenStream::new();
    };
    // `cob_id(node_id)` adds the node id: only when every node id fits.
    if literal.plus_node_id && value > u32::MAX - 127 {
        return TokenStream::new();
    }
    let value_lit = prim::hex(u128::from(value));
    let text = docs::text(&literal.text);
    if literal.plus_node_id {
        let doc = format!(
            " The default COB-ID entry value for a node: {text} (bit 31 set means the PDO is disabled)."
        );
        quote! {
            #[doc = #doc]
            #[inline] pub const fn cob_id(node_id: #rt::od::NodeId) -> #rt::od::standard::PdoCobId {
                #rt::od::standard::PdoCobId::from_raw(#value_lit + node_id.get() as u32)
            }
            #[doc = " The CAN identifier of the default COB-ID for a node."]
            #[inline] pub const fn can_id(node_id: #rt::od::NodeId) -> #rt::CanId {
                Self::cob_id(node_id).can_id()
            }
        }
    } else {
        let (doc, can_doc) = match source {
            Source::Defaults => (
                format!(
                    " The default COB-ID entry value, {text} (bit 31 set means the PDO is disabled)."
                ),
                " The CAN identifier of the default COB-ID.",
            ),
            Source::Network => (
                format!(" The COB-ID entry value the network configures, {text}."),
                " The CAN identifier the network configures.",
            ),
        };
        quote! {
            #[doc = #doc]
            pub const COB_ID: #rt::od::standard::PdoCobId = #rt::od::standard::PdoCobId::from_raw(#value_lit);
            #[doc = #can_doc]
            pub const CAN_ID: #rt::CanId = Self::COB_ID.can_id();
        }
    }
}
