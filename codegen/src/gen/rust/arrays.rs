//! The elements of an ARRAY as one type indexed by sub-index:
//! `PreDefinedErrorField<const SUB: u8 = 0>` implements the runtime's
//! `Entry` for every `SUB` (the sub-index checked against the array's range
//! when the type is used) and, as `PreDefinedErrorField` alone, `Array`
//! (the range, for elements chosen at run time). The plan (which ARRAYs
//! and which subs) is `od_plan`'s; this module writes it out.

use std::collections::BTreeMap;

use proc_macro2::{Ident, TokenStream};
use quote::quote;

use super::docs::{self, Doc};
use super::entries::{self, Ctx, rooted};
use super::naming::Names;
use super::od_plan::EntryPlan;
use super::prim::Prim;
use super::values::{self, Plan};
use crate::ir::{Entry, Literal, Object, Origin};

/// The items of one indexed type: the struct, its `Entry`, `Array` and
/// (when mappable) `PdoMappable` impls, its defaults and its value type.
pub(super) fn items(
    cx: &mut Ctx,
    object: &Object,
    plan: &EntryPlan,
    names: &Names,
    module: &[Ident],
) -> TokenStream {
    let rt = cx.rt;
    let first = plan.entry;
    let elements = &plan.elements;
    let ident = names.get(plan.zst);
    let (low, high) = plan.subs();
    let errors = cx.errors;
    let depth = module.len();
    let error_path = |i: usize| {
        rooted(
            &[super::naming::ident("errors"), errors[i].code_ident.clone()],
            depth,
        )
    };
    let value_ty = values::type_tokens(&plan.value, names, rt, &error_path);
    let index = super::prim::hex(u128::from(object.index));
    let (low_lit, high_lit) = (
        proc_macro2::Literal::u8_unsuffixed(low),
        proc_macro2::Literal::u8_unsuffixed(high),
    );
    let names_form = NameForm::of(elements);
    let name = names_form.common(object);
    let data_type = entries::data_type_tokens(rt, first.data_type);
    let access = entries::access_tokens(rt, first.access);
    let mappable = first.pdo_mappable;
    // PDO_MAPPABLE false is the trait's default.
    let mappable_const = mappable.then(|| {
        quote!(
            const PDO_MAPPABLE: bool = true;
        )
    });
    let doc =
        doc(cx, object, plan, &ident, &names_form).tokens_with_alias(name, &ident.to_string());
    let derives = super::derives::attr(super::derives::ENTRY, false);
    let mut out = quote! {
        #doc
        #derives
        pub struct #ident<const SUB: u8 = 0>;
        impl<const SUB: u8> #rt::od::Entry for #ident<SUB> {
            const INDEX: u16 = #index;
            const SUBINDEX: u8 = #rt::od::array_subindex::<#ident>(SUB);
            const NAME: &'static str = #name;
            const DATA_TYPE: #rt::od::DataType = #data_type;
            #mappable_const
            type Access = #access;
            type Value = #value_ty;
        }
        impl #rt::od::Array for #ident {
            const FIRST: u8 = #low_lit;
            const LAST: u8 = #high_lit;
        }
    };
    if mappable && Prim::of(first.data_type).is_some() {
        out.extend(quote!(impl<const SUB: u8> #rt::od::PdoMappable for #ident<SUB> {}));
    }
    if let Some(default) = default_tokens(elements, &plan.value, &value_ty, rt, &ident) {
        out.extend(quote! {
            impl<const SUB: u8> #ident<SUB> {
                #[doc = " The element's default value (EDS `DefaultValue`, YAML `default`)."]
                pub const DEFAULT: #value_ty = #default;
            }
        });
    }
    let mut vcx = values::Ctx {
        rt,
        diags: cx.diags,
    };
    out.extend(values::emit(&mut vcx, first, &plan.value, names));
    out
}

/// How the elements are named in the source.
enum NameForm<'a> {
    /// All the same.
    Same(&'a str),
    /// A common stem and a number counting with the sub-index (`Pre-defined
    /// error field1` at sub 1): name = stem + (sub + offset).
    Numbered { stem: &'a str, offset: i32 },
    /// Anything else: listed sub by sub.
    Irregular,
}

impl<'a> NameForm<'a> {
    fn of(elements: &[&'a Entry]) -> NameForm<'a> {
        let first = &elements[0].name;
        if elements.iter().all(|e| e.name == *first) {
            return NameForm::Same(first);
        }
        let split = |name: &'a str| {
            let stem = name.trim_end_matches(|c: char| c.is_ascii_digit());
            let number: i32 = name[stem.len()..].parse().ok()?;
            // `01` would not come back from the number: not this form.
            (format!("{stem}{number}") == name).then_some((stem, number))
        };
        let Some((stem, number)) = split(first) else {
            return NameForm::Irregular;
        };
        let offset = number - i32::from(elements[0].subindex);
        let numbered = elements.iter().all(|e| {
            // A number near i32::MAX in a name: no overflow, no pattern.
            let expected = i32::from(e.subindex).checked_add(offset);
            expected.is_some_and(|n| split(&e.name) == Some((stem, n)))
        });
        if numbered {
            NameForm::Numbered { stem, offset }
        } else {
            NameForm::Irregular
        }
    }

    /// The name the elements share (the `NAME` of the type): the name, the
    /// stem without trailing separators, or the object's name.
    fn common(&self, object: &'a Object) -> &'a str {
        match self {
            NameForm::Same(name) => name,
            NameForm::Numbered { stem, .. } => {
                let trimmed = stem.trim_end_matches([' ', '_', '-', '#']);
                if trimmed.is_empty() { stem } else { trimmed }
            }
            NameForm::Irregular => &object.name,
        }
    }
}

fn doc(cx: &Ctx, object: &Object, plan: &EntryPlan, ident: &Ident, form: &NameForm) -> Doc {
    let first = plan.entry;
    let elements = &plan.elements;
    let (low, high) = plan.subs();
    let mut doc = Doc::new();
    let common = form.common(object);
    let title = match form {
        NameForm::Irregular => format!("The elements of **{}**", docs::text(&object.name)),
        _ if common == object.name => format!("The elements of **{}**", docs::text(common)),
        _ => format!("**{}** of {}", docs::text(common), docs::text(&object.name)),
    };
    doc.para(format!(
        "{title} (0x{:04X} subs {low} to {high}, {}, {}{}): one type indexed by sub-index.",
        object.index,
        first.data_type.name(),
        docs::access_words(first.access),
        if first.pdo_mappable {
            ", PDO-mappable"
        } else {
            ""
        }
    ));
    doc.para(format!(
        "`{ident}<N>` is the element at sub N; a sub-index outside {low} to {high} does not \
         compile. `{ident}` alone names the array, for elements chosen at run time: \
         `Element::<{ident}>::new(sub)` (checked) and `Element::<{ident}>::all()`."
    ));
    entries::standard_para(cx, object, &mut doc);
    match form {
        NameForm::Same(_) => {}
        NameForm::Numbered { stem, offset } => {
            let (a, b) = (elements[0], elements[elements.len() - 1]);
            doc.para(format!(
                "Named `{}` (sub {}) to `{}` (sub {}): `{}` and the sub-index{}.",
                docs::text(&a.name),
                a.subindex,
                docs::text(&b.name),
                b.subindex,
                docs::text(stem),
                match offset {
                    0 => String::new(),
                    o if *o > 0 => format!(" plus {o}"),
                    o => format!(" minus {}", -o),
                }
            ));
        }
        NameForm::Irregular => {}
    }
    let descriptions: Vec<Option<&String>> = elements
        .iter()
        .map(|e| e.semantics.description.as_ref())
        .collect();
    if descriptions.iter().all(|d| *d == descriptions[0]) {
        if let Some(d) = descriptions[0] {
            doc.source_para(d);
        }
    } else {
        for (e, d) in elements.iter().zip(&descriptions) {
            if let Some(d) = d {
                doc.para(format!("Sub {}: {}", e.subindex, docs::text(d.trim())));
            }
        }
    }
    doc.unit(&first.semantics);
    let last = elements[elements.len() - 1];
    if last.origin == first.origin {
        facts(&mut doc, elements, form, &first.origin);
    } else {
        // Each element's section: the first and the last say where.
        let end = if last.origin.file == first.origin.file {
            format!("line {}", last.origin.line)
        } else {
            format!("{}:{}", last.origin.file, last.origin.line)
        };
        let origin = Origin {
            file: format!(
                "{}:{} (sub {}) to {end} (sub {})",
                first.origin.file, first.origin.line, first.subindex, last.subindex
            ),
            line: 0,
        };
        facts(&mut doc, elements, form, &origin);
    }
    doc
}

/// Defaults and limits: the value most elements have, and a table of the
/// subs that differ (and of every name, when the names follow no pattern).
fn facts(doc: &mut Doc, elements: &[&Entry], form: &NameForm, origin: &Origin) {
    let text = |l: &Option<Literal>| l.as_ref().map(|l| docs::text(&l.text));
    let columns: [(&str, Vec<Option<String>>); 3] = [
        (
            "Default",
            elements.iter().map(|e| text(&e.default)).collect(),
        ),
        (
            "Low limit",
            elements.iter().map(|e| text(&e.low_limit)).collect(),
        ),
        (
            "High limit",
            elements.iter().map(|e| text(&e.high_limit)).collect(),
        ),
    ];
    let mut sentences = Vec::new();
    let mut table_columns = Vec::new();
    for (title, values) in &columns {
        let common = most_common(values);
        let differs = values.iter().any(|v| *v != common);
        match (&common, differs) {
            (Some(v), false) => sentences.push(format!("{title}: {v}")),
            (None, false) => {}
            (Some(v), true) => {
                sentences.push(format!(
                    "{title}: {v}, where the table below says nothing else"
                ));
                table_columns.push((title, values, common.clone()));
            }
            (None, true) => {
                sentences.push(format!(
                    "{title}: none, where the table below says nothing else"
                ));
                table_columns.push((title, values, common.clone()));
            }
        }
    }
    doc.facts_and_origin(&sentences, origin);
    let irregular = matches!(form, NameForm::Irregular);
    if !irregular && table_columns.is_empty() {
        return;
    }
    let mut header = String::from("| Sub |");
    let mut rule = String::from("|---|");
    if irregular {
        header.push_str(" Name |");
        rule.push_str("---|");
    }
    for (title, _, _) in &table_columns {
        header.push_str(&format!(" {title} |"));
        rule.push_str("---|");
    }
    doc.para(header);
    doc.line(rule);
    for (i, e) in elements.iter().enumerate() {
        let differs = table_columns.iter().any(|(_, v, c)| v[i] != *c);
        if !irregular && !differs {
            continue;
        }
        let mut row = format!("| {} |", e.subindex);
        if irregular {
            row.push_str(&format!(" {} |", docs::text(&e.name)));
        }
        for (_, values, _) in &table_columns {
            row.push_str(&format!(" {} |", values[i].as_deref().unwrap_or("none")));
        }
        doc.line(row);
    }
}

/// The value most elements have (the earliest of equals on a tie).
fn most_common<T: Ord + Clone>(values: &[T]) -> T {
    let mut counts: BTreeMap<&T, (usize, usize)> = BTreeMap::new();
    for (i, v) in values.iter().enumerate() {
        counts.entry(v).or_insert((0, i)).0 += 1;
    }
    counts
        .into_iter()
        .max_by(|(_, (ca, ia)), (_, (cb, ib))| ca.cmp(cb).then(ib.cmp(ia)))
        .map(|(v, _)| v.clone())
        .expect("an array has elements")
}

/// `DEFAULT` of the elements when each has one that fits its type: one
/// value, or a `match` on the sub-index (range-checked) with the most
/// common value as the fallback arm.
fn default_tokens(
    elements: &[&Entry],
    plan: &Plan,
    value_ty: &TokenStream,
    rt: &TokenStream,
    ident: &Ident,
) -> Option<TokenStream> {
    let tokens: Vec<TokenStream> = elements
        .iter()
        .map(|e| entries::default_tokens(e, plan, value_ty))
        .collect::<Option<_>>()?;
    // Compared by their text: equal tokens print the same.
    let texts: Vec<String> = tokens.iter().map(|t| t.to_string()).collect();
    let common = most_common(&texts);
    let common_tokens = tokens[texts
        .iter()
        .position(|t| *t == common)
        .expect("one of them")]
    .clone();
    if texts.iter().all(|t| *t == common) {
        return Some(common_tokens);
    }
    let mut arms: BTreeMap<&String, (Vec<u8>, &TokenStream)> = BTreeMap::new();
    for ((e, text), tokens) in elements.iter().zip(&texts).zip(&tokens) {
        if *text != common {
            arms.entry(text)
                .or_insert((Vec::new(), tokens))
                .0
                .push(e.subindex);
        }
    }
    let mut arms: Vec<(Vec<u8>, &TokenStream)> = arms.into_values().collect();
    arms.sort_by(|a, b| a.0.cmp(&b.0));
    let arms = arms.iter().map(|(subs, value)| {
        let patterns = runs(subs).into_iter().map(|(a, b)| {
            let (la, lb) = (
                proc_macro2::Literal::u8_unsuffixed(a),
                proc_macro2::Literal::u8_unsuffixed(b),
            );
            if a == b {
                quote!(#la)
            } else {
                quote!(#la..=#lb)
            }
        });
        quote!(#(#patterns)|* => #value,)
    });
    let common = common_tokens;
    Some(quote! {
        match #rt::od::array_subindex::<#ident>(SUB) {
            #(#arms)*
            _ => #common,
        }
    })
}

/// Sorted sub-indices as runs of consecutive ones: `[1, 2, 3, 7]` →
/// `[(1, 3), (7, 7)]` (a match arm writes a run as a range).
fn runs(subs: &[u8]) -> Vec<(u8, u8)> {
    let mut out: Vec<(u8, u8)> = Vec::new();
    for &s in subs {
        match out.last_mut() {
            Some((_, end)) if u16::from(*end) + 1 == u16::from(s) => *end = s,
            _ => out.push((s, s)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{NameForm, runs};
    use crate::ir::{Access, DataType, Entry};

    fn element(sub: u8, name: &str) -> Entry {
        let mut e = Entry::highest_subindex(0, Default::default());
        e.subindex = sub;
        e.name = name.to_string();
        e.data_type = DataType::Unsigned32;
        e.access = Access::Ro;
        e
    }

    #[test]
    fn element_names_are_read_without_overflow() {
        let numbered = [element(1, "Field 1"), element(2, "Field 2")];
        let refs: Vec<&Entry> = numbered.iter().collect();
        assert!(matches!(
            NameForm::of(&refs),
            NameForm::Numbered {
                stem: "Field ",
                offset: 0
            }
        ));
        // Numbers at the end of i32: irregular, never a panic.
        let huge = [element(1, "X2147483647"), element(2, "X2147483648")];
        let refs: Vec<&Entry> = huge.iter().collect();
        assert!(matches!(NameForm::of(&refs), NameForm::Irregular));
        let huge = [
            element(1, "X2147483646"),
            element(2, "X2147483647"),
            element(3, "X0"),
        ];
        let refs: Vec<&Entry> = huge.iter().collect();
        assert!(matches!(NameForm::of(&refs), NameForm::Irregular));
    }

    #[test]
    fn consecutive_subs_become_runs() {
        assert_eq!(runs(&[1, 2, 3, 7, 9, 10]), [(1, 3), (7, 7), (9, 10)]);
        assert_eq!(runs(&[254, 255]), [(254, 255)]);
        assert_eq!(runs(&[]), []);
    }
}
