//! The plan of the `od` module: which entry gets which Rust name and which
//! value type. The one place these are decided: the emitter (`entries`)
//! writes the plan out as code, and readers of the generated API (the
//! `diff` module, through [`device_names`]) read the same plan without
//! generating anything.

#[cfg(any(feature = "diff", all(feature = "api", feature = "network")))]
use std::collections::BTreeMap;

use proc_macro2::Ident;

#[cfg(any(feature = "diff", all(feature = "api", feature = "network")))]
use super::errors;
use super::errors::ErrorPlan;
use super::naming::{self, Case, NameId, Names, Namespace};
use super::values::{self, Plan};
use crate::diag::Diagnostics;
use crate::ir::{Device, Entry, Object, ObjectKind};
use crate::profiles::Canonical;

/// One entry's names: its zero-sized type and its value type's plan.
pub(crate) struct EntryPlan<'d> {
    /// The entry; for an indexed type, its first element (every element has
    /// the same type facts and semantics).
    pub(crate) entry: &'d Entry,
    pub(crate) zst: NameId,
    pub(crate) value: Plan,
    /// For the elements of an ARRAY as one type indexed by sub-index
    /// (`PreDefinedErrorField<SUB>`): every element, in sub-index order, a
    /// contiguous run. Empty for a type of one entry.
    pub(crate) elements: Vec<&'d Entry>,
    /// Whether `zst` is a fixed name (canonical or pinned), which other
    /// names made from the entry (PDO fields) follow instead of the source.
    pub(crate) fixed_name: bool,
}

impl EntryPlan<'_> {
    /// The sub-indices the type stands for: `(first, last)`.
    pub(crate) fn subs(&self) -> (u8, u8) {
        match (self.elements.first(), self.elements.last()) {
            (Some(first), Some(last)) => (first.subindex, last.subindex),
            _ => (self.entry.subindex, self.entry.subindex),
        }
    }

    pub(crate) fn is_indexed(&self) -> bool {
        !self.elements.is_empty()
    }
}

/// A VAR (or DOMAIN) object: its entry's types live in `od` itself.
pub(crate) struct RootPlan<'d> {
    pub(crate) object: &'d Object,
    pub(crate) entry: EntryPlan<'d>,
}

/// An ARRAY or RECORD object: a module in `od` with one type per sub.
pub(crate) struct ModulePlan<'d> {
    pub(crate) object: &'d Object,
    pub(crate) module: Ident,
    /// The module name shared with another source name, when that made it
    /// qualified.
    #[cfg_attr(
        not(any(feature = "diff", all(feature = "api", feature = "network"))),
        allow(dead_code)
    )]
    pub(crate) module_collided: Option<String>,
    pub(crate) entries: Vec<EntryPlan<'d>>,
    /// The names of the module's scope.
    pub(crate) names: Names,
}

pub(crate) struct OdPlan<'d> {
    pub(crate) root: Vec<RootPlan<'d>>,
    /// The names of `od`'s own scope (root types and their value types).
    pub(crate) root_names: Names,
    pub(crate) modules: Vec<ModulePlan<'d>>,
}

/// The error plan an entry's codes come from, by position in `errors`.
pub(crate) fn error_plan(device: &Device, errors: &[ErrorPlan], entry: &Entry) -> Option<usize> {
    let name = entry.semantics.error_table.as_deref()?;
    errors
        .iter()
        .position(|p| device.error_tables[p.table].name == name)
}

/// Requests and resolves every name of `od`; name collisions are reported
/// into `diags`.
pub(crate) fn plan<'d>(
    device: &'d Device,
    errors: &[ErrorPlan],
    diags: &mut Diagnostics,
) -> OdPlan<'d> {
    let objects: Vec<&Object> = device
        .objects
        .values()
        .filter(|o| !matches!(o.kind, ObjectKind::DefType | ObjectKind::DefStruct))
        .filter(|o| !o.entries.is_empty())
        .collect();
    let is_var = |o: &Object| matches!(o.kind, ObjectKind::Var | ObjectKind::Domain);
    let canonical = Canonical::of(device);
    // Names in `od`: types of VAR objects (and their value types), modules of
    // the others. Standard objects take their canonical name; no vendor
    // name may take one of those.
    let mut types = Namespace::new("module `od`", Case::UpperCamel);
    types.reserve_constructor_names();
    types.reserve_canonical(canonical.reserved());
    let mut modules = Namespace::new("module `od`", Case::Snake);
    modules.reserve_canonical(canonical.reserved());
    // The alias of the runtime crate in every generated module.
    modules.reserve(super::RUNTIME_ALIAS);
    let mut root = Vec::new();
    let mut module_ids = Vec::new();
    for object in objects {
        let key = format!("x{:04X}", object.index);
        let fixed = canonical.object(object.index);
        if is_var(object) {
            let entry = object.entries.values().next().expect("non-empty");
            // A pin (`rust_name:`) wins over the canonical and the source name.
            let pin = entry.rust_name.as_deref().or(object.rust_name.as_deref());
            let (zst, name) = request_entry(
                &mut types,
                (pin, fixed.as_deref()),
                (&object.name, &entry.name),
                &key,
                &object.origin,
            );
            let fixed_name = matches!(name, values::Name::Fixed(_));
            let value = values::plan(entry, name, error_plan(device, errors, entry), &mut types);
            root.push(RootPlan {
                object,
                entry: EntryPlan {
                    entry,
                    zst,
                    value,
                    elements: Vec::new(),
                    fixed_name,
                },
            });
        } else {
            let id = match (&object.rust_name, &fixed) {
                (Some(pin), _) => modules.request_pinned(pin, &key, Some(&object.origin)),
                (None, Some(name)) => modules.request_fixed(name, &key, Some(&object.origin)),
                (None, None) => modules.request(&object.name, &key, Some(&object.origin)),
            };
            module_ids.push((object, id, fixed.is_some()));
        }
    }
    let root_names = types.resolve(diags);
    let module_names = modules.resolve(diags);
    let modules = module_ids
        .into_iter()
        .map(|(object, id, standard)| {
            let module = module_names.get(id);
            let mut ns = Namespace::new(format!("module `od::{module}`"), Case::UpperCamel);
            ns.reserve_constructor_names();
            let elements = indexed_elements(object, &canonical, standard);
            let singles = object
                .entries
                .values()
                .filter(|e| !elements.iter().any(|el| el.subindex == e.subindex));
            let mut entries: Vec<EntryPlan> = singles
                .map(|entry| {
                    let key = format!("sub {}", entry.subindex);
                    let fixed = standard
                        .then(|| canonical.sub(object.index, entry.subindex))
                        .flatten();
                    let (zst, name) = request_entry(
                        &mut ns,
                        (entry.rust_name.as_deref(), fixed.as_deref()),
                        (&entry.name, &entry.name),
                        &key,
                        &entry.origin,
                    );
                    let fixed_name = matches!(name, values::Name::Fixed(_));
                    let value = values::runtime_plan(canonical, object.index, entry)
                        .unwrap_or_else(|| {
                            values::plan(entry, name, error_plan(device, errors, entry), &mut ns)
                        });
                    EntryPlan {
                        entry,
                        zst,
                        value,
                        elements: Vec::new(),
                        fixed_name,
                    }
                })
                .collect();
            if let Some(&first) = elements.first() {
                // The indexed type is named like its object, whatever its
                // elements are called: the object's pin, canonical or
                // source name.
                let (first_sub, last_sub) = (first.subindex, elements[elements.len() - 1].subindex);
                let key = format!("subs {first_sub}..{last_sub}");
                // The module's pin is snake case; the type takes it in
                // UpperCamelCase, as fixed (a collision with it is the
                // module pin's, reported there).
                let camel_pin = object
                    .rust_name
                    .as_deref()
                    .map(|pin| naming::sanitize(pin, Case::UpperCamel));
                let canonical_name = canonical.object(object.index);
                let fixed = camel_pin.as_deref().or(canonical_name.as_deref());
                let (zst, name) = match fixed {
                    Some(name) => (
                        ns.request_fixed(name, &key, Some(&object.origin)),
                        values::Name::Fixed(name),
                    ),
                    None => (
                        ns.request(&object.name, &key, Some(&object.origin)),
                        values::Name::Source(&object.name),
                    ),
                };
                let value = values::plan(first, name, error_plan(device, errors, first), &mut ns);
                entries.push(EntryPlan {
                    entry: first,
                    zst,
                    value,
                    elements,
                    // Elements are told apart by their own names.
                    fixed_name: false,
                });
            }
            ns.reserve("INDEX");
            let names = ns.resolve(diags);
            ModulePlan {
                object,
                module,
                module_collided: module_names.collided(id).map(str::to_string),
                entries,
                names,
            }
        })
        .collect();
    OdPlan {
        root,
        root_names,
        modules,
    }
}

/// Requests an entry type's name by the one precedence rule: its
/// `rust_name:` pin, else its canonical name, else its source name
/// (`sources.0`); returns it with the name its value types are made from
/// (the pin, the canonical name, or `sources.1`).
fn request_entry<'a>(
    ns: &mut Namespace,
    (pin, canonical): (Option<&'a str>, Option<&'a str>),
    sources: (&str, &'a str),
    key: &str,
    origin: &crate::ir::Origin,
) -> (NameId, values::Name<'a>) {
    match (pin, canonical) {
        (Some(pin), _) => (
            ns.request_pinned(pin, key, Some(origin)),
            values::Name::Fixed(pin),
        ),
        (None, Some(name)) => (
            ns.request_fixed(name, key, Some(origin)),
            values::Name::Fixed(name),
        ),
        (None, None) => (
            ns.request(sources.0, key, Some(origin)),
            values::Name::Source(sources.1),
        ),
    }
}

/// The elements of an ARRAY (or of a standard object whose subs the
/// standard defines as one list: the PDO mapping parameters, whatever
/// object code the source gives) that become one type indexed by
/// sub-index: every sub from 1 up, when they are a contiguous run that shares data
/// type, access right, PDO mappability and meaning (unit, scale, named
/// values, bit fields, error table; descriptions may differ) and none has a
/// `rust_name:` pin. Subs with a canonical name of their own come first and
/// keep their types (0x1010's `SaveAllParameters`, …; the elements are the
/// manufacturer's subs after them). Otherwise none: the subs keep one type
/// each, like a RECORD's.
fn indexed_elements<'d>(
    object: &'d Object,
    canonical: &Canonical,
    standard: bool,
) -> Vec<&'d Entry> {
    let list = object.kind == ObjectKind::Array || (standard && canonical.is_list(object.index));
    if !list {
        return Vec::new();
    }
    // Subs the standard names keep their own types; the elements are the
    // subs after them (0x1029: sub 1 `CommunicationError`, subs 2 and up
    // the profile's or vendor's errors).
    let named = |e: &Entry| standard && canonical.sub(object.index, e.subindex).is_some();
    let elements: Vec<&Entry> = object
        .entries
        .values()
        .map(Box::as_ref)
        .filter(|e| e.subindex >= 1)
        .skip_while(|e| named(e))
        .collect();
    let Some(first) = elements.first() else {
        return Vec::new();
    };
    let contiguous = elements
        .iter()
        .zip(u16::from(first.subindex)..)
        .all(|(e, sub)| u16::from(e.subindex) == sub);
    let meaning = |e: &Entry| meaning(&e.semantics);
    let first_meaning = meaning(first);
    let uniform = elements.iter().all(|e| {
        e.data_type == first.data_type
            && e.access == first.access
            && e.pdo_mappable == first.pdo_mappable
            && e.rust_name.is_none()
            && !named(e)
            && meaning(e) == first_meaning
    });
    if contiguous && uniform {
        elements
    } else {
        Vec::new()
    }
}

/// What a value means, without the words around it: the semantics without
/// description and origins.
fn meaning(s: &crate::ir::Semantics) -> crate::ir::Semantics {
    let mut s = s.clone();
    s.description = None;
    let plain = crate::ir::Origin::default;
    let values = |t: &mut Option<crate::ir::ValueTable>| {
        for v in t.iter_mut().flat_map(|t| t.named.iter_mut()) {
            v.origin = plain();
        }
    };
    values(&mut s.values);
    for b in &mut s.bits {
        b.origin = plain();
        values(&mut b.values);
    }
    for p in &mut s.patterns {
        p.origin = plain();
    }
    s
}

/// The path of an entry's value type as planned (`u16`,
/// `od::command::PositionValue`, `errors::LinakErrorsCode`,
/// `bytes::VisibleString`); `module` is the entry's module (`od::feedback`).
#[cfg(any(feature = "api", feature = "diff"))]
pub(crate) fn value_type_path(
    plan: &Plan,
    module: &str,
    names: &Names,
    errors: &[ErrorPlan],
) -> String {
    match plan {
        Plan::Prim(p) => p.tokens().to_string(),
        Plan::Bytes(marker) => format!("bytes::{marker}"),
        Plan::Error(i) => format!("errors::{}", errors[*i].code_ident),
        Plan::Enum { name, .. } | Plan::Bits { name, .. } | Plan::Scaled { name, .. } => {
            format!("{module}::{}", names.text(*name))
        }
        Plan::Runtime { path, .. } => format!("runtime::{path}"),
    }
}

/// The Rust names one device's generated code gives its entries: for a
/// reader of the generated API (the `diff` module) without generating it.
#[cfg(any(feature = "diff", all(feature = "api", feature = "network")))]
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct DeviceNames {
    /// By (index, subindex): the entry's zero-sized type (`od::Statusword`,
    /// `od::feedback::Position`) and its value type (`u16`,
    /// `od::command::PositionValue`, `errors::LinakErrorsCode`,
    /// `bytes::VisibleString`).
    pub(crate) entries: BTreeMap<(u16, u8), (String, String)>,
    /// By index, for ARRAY/RECORD objects: their module (`od::feedback`).
    pub(crate) modules: BTreeMap<u16, String>,
    /// By error table name: its enum (`errors::LinakErrors`).
    pub(crate) error_tables: BTreeMap<String, String>,
    /// By (index, subindex): the names in `od` (its type, value type or
    /// module) that were qualified because another source name in `od`
    /// became the same; only an object sharing one of them can change the
    /// entry's path by going away.
    pub(crate) collided: BTreeMap<(u16, u8), Vec<String>>,
}

/// The names of every generated entry of `device`, from the same plan the
/// generator writes out.
#[cfg(any(feature = "diff", all(feature = "api", feature = "network")))]
pub(crate) fn device_names(device: &Device) -> DeviceNames {
    let mut diags = Diagnostics::new();
    let error_plans = errors::plan(device, &mut diags);
    let od = plan(device, &error_plans, &mut diags);
    let value_type = |plan: &Plan, module: &str, names: &Names| {
        value_type_path(plan, module, names, &error_plans)
    };
    let mut out = DeviceNames::default();
    for root in &od.root {
        let e = &root.entry;
        let shared: Vec<String> = std::iter::once(e.zst)
            .chain(e.value.names())
            .filter_map(|id| od.root_names.collided(id).map(str::to_string))
            .collect();
        if !shared.is_empty() {
            out.collided
                .insert((root.object.index, e.entry.subindex), shared);
        }
        out.entries.insert(
            (root.object.index, e.entry.subindex),
            (
                format!("od::{}", od.root_names.text(e.zst)),
                value_type(&e.value, "od", &od.root_names),
            ),
        );
    }
    for m in &od.modules {
        let module = format!("od::{}", m.module);
        for e in &m.entries {
            let value = value_type(&e.value, &module, &m.names);
            let ty = m.names.text(e.zst);
            let subs: Vec<(u8, String)> = if e.is_indexed() {
                e.elements
                    .iter()
                    .map(|el| (el.subindex, format!("{module}::{ty}<{}>", el.subindex)))
                    .collect()
            } else {
                vec![(e.entry.subindex, format!("{module}::{ty}"))]
            };
            for (sub, path) in subs {
                if let Some(shared) = m.module_collided.as_ref() {
                    out.collided
                        .insert((m.object.index, sub), vec![shared.clone()]);
                }
                out.entries
                    .insert((m.object.index, sub), (path, value.clone()));
            }
        }
        out.modules.insert(m.object.index, module);
    }
    for plan in &error_plans {
        out.error_tables.insert(
            device.error_tables[plan.table].name.clone(),
            format!("errors::{}", plan.ident),
        );
    }
    out
}

#[cfg(test)]
mod tests;
