//! The `od` module as a whole: the plan of its names walked object by
//! object, VAR entries as types at its root, ARRAY and RECORD objects as
//! modules holding their entries (arrays.rs for indexed elements,
//! entries.rs for the others), and what the PDOs need to know of each
//! entry.

use std::collections::BTreeMap;

use proc_macro2::TokenStream;
use quote::quote;

use super::docs::{self, Doc};
use super::entries::{Ctx, EntryInfo, entry_items, info, standard_para};
use super::od_plan;
use crate::ir::ObjectKind;

/// The `od` module's items, and the info of every entry by (index, subindex).
/// The items of the `od` module, given to `sink` one group of items per
/// object as they are made (so that they are formatted and dropped one at a
/// time: see `format.rs`), and what the PDOs need to know of each entry.
pub(crate) fn emit(
    cx: &mut Ctx,
    sink: &mut dyn FnMut(TokenStream),
) -> BTreeMap<(u16, u8), EntryInfo> {
    let od = od_plan::plan(cx.device, cx.errors, cx.diags);
    let mut infos = BTreeMap::new();
    for root in &od.root {
        let (object, e) = (root.object, &root.entry);
        let ident = od.root_names.get(e.zst);
        let path = vec![super::naming::ident("od")];
        sink(entry_items(
            cx,
            object,
            e.entry,
            &ident,
            &e.value,
            &od.root_names,
            &path,
            &object.name,
        ));
        infos.insert(
            (object.index, e.entry.subindex),
            info(cx, &path, e, &od.root_names),
        );
    }
    for m in &od.modules {
        let (object, module) = (m.object, &m.module);
        let path = vec![super::naming::ident("od"), module.clone()];
        let mut inner = TokenStream::new();
        for e in &m.entries {
            if e.is_indexed() {
                inner.extend(super::arrays::items(cx, object, e, &m.names, &path));
                let info = info(cx, &path, e, &m.names);
                for element in &e.elements {
                    infos.insert((object.index, element.subindex), info.clone());
                }
                continue;
            }
            let ident = m.names.get(e.zst);
            inner.extend(entry_items(
                cx,
                object,
                e.entry,
                &ident,
                &e.value,
                &m.names,
                &path,
                &e.entry.name,
            ));
            infos.insert(
                (object.index, e.entry.subindex),
                info(cx, &path, e, &m.names),
            );
        }
        let mut doc = Doc::new();
        doc.para(format!(
            "**{}**: object 0x{:04X}, {} with {} entries.",
            docs::text(&object.name),
            object.index,
            match object.kind {
                ObjectKind::Array => "ARRAY",
                _ => "RECORD",
            },
            object.entries.len()
        ));
        standard_para(cx, object, &mut doc);
        doc.origin(&object.origin);
        let doc = doc.tokens_with_alias(&object.name, &module.to_string());
        let index = super::prim::hex(u128::from(object.index));
        sink(quote! {
            #doc
            pub mod #module {
                use super::rt;
                #[doc = " The object's index."]
                pub const INDEX: u16 = #index;
                #inner
            }
        });
    }
    infos
}
