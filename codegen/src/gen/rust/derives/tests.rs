//! Every generated type derives the one list of its kind: checked on the
//! parsed code generated for the seed devices, the test fixtures, the
//! overlay example and every corpus file (../shared/eds-corpus, when it is
//! beside the checkout).

use std::collections::{BTreeMap, BTreeSet};
use std::io::Write;
use std::path::{Path, PathBuf};

use super::{ENTRY, MEANING, PDO, VALUE, names};
use crate::r#gen::rust::{Options, generate};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("codegen/ has a parent")
        .to_path_buf()
}

/// The inputs: seeds, fixtures, and (when present) the overlay example and
/// the corpus.
fn inputs() -> Vec<PathBuf> {
    let root = workspace();
    let mut inputs: Vec<PathBuf> = [
        "eds/zimmer_acs.yaml",
        "eds/linak_techline.yaml",
        "eds/interroll_ec5000bi.yaml",
        "codegen/tests/fixtures/hostile.eds",
        "codegen/tests/fixtures/shadowing.yaml",
    ]
    .iter()
    .map(|p| root.join(p))
    .collect();
    let corpus = root.join("../shared/eds-corpus/files");
    match std::fs::read_dir(&corpus) {
        Ok(dir) => {
            let mut files: Vec<PathBuf> = dir
                .map(|e| e.expect("directory entry").path())
                .filter(|p| p.is_file())
                .collect();
            files.sort();
            inputs.extend(files);
            inputs.push(root.join("tests/overlays/cia402_stepper.yaml"));
        }
        Err(_) => {
            // Written to stderr directly: the harness captures eprintln!.
            let _ = writeln!(
                std::io::stderr(),
                "NOT RUN: derives of the corpus's generated code: ../shared/eds-corpus is not beside this checkout"
            );
        }
    }
    inputs
}

/// The derive names of an item's attributes, in order.
fn derives(attrs: &[syn::Attribute]) -> Vec<String> {
    let mut out = Vec::new();
    for attr in attrs.iter().filter(|a| a.path().is_ident("derive")) {
        attr.parse_nested_meta(|meta| {
            let name = meta.path.segments.last().expect("a derive name");
            out.push(name.ident.to_string());
            Ok(())
        })
        .expect("a derive list");
    }
    out
}

/// The last path segment of a type (`od::x::PositionValue` → `PositionValue`).
fn last_segment(ty: &syn::Type) -> Option<String> {
    match ty {
        syn::Type::Path(p) => p.path.segments.last().map(|s| s.ident.to_string()),
        _ => None,
    }
}

const PRIMITIVES: &[&str] = &[
    "bool", "u8", "u16", "u32", "u64", "i8", "i16", "i32", "i64", "f32", "f64",
];

/// Every struct and enum of a file, in nested modules too.
fn collect<'f>(items: &'f [syn::Item], out: &mut Vec<&'f syn::Item>) {
    for item in items {
        match item {
            syn::Item::Mod(m) => {
                if let Some((_, items)) = &m.content {
                    collect(items, out);
                }
            }
            syn::Item::Struct(_) | syn::Item::Enum(_) => out.push(item),
            _ => {}
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Kind {
    Value,
    Meaning,
    Entry,
    Pdo,
}

/// (kind, holds a float) → the derive lists seen, with one example each.
type Seen = BTreeMap<(Kind, bool), BTreeMap<Vec<String>, String>>;

/// The derive lists of every struct and enum generated for `path`; `false`
/// when the input does not read or generate (other tests report those).
fn survey(path: &Path, seen: &mut Seen) -> bool {
    // The overlay example's `base:` lies in ../shared, beside the checkout.
    let options = crate::input::Options {
        allow_base_dirs: vec![workspace().join("../shared")],
        ..crate::input::Options::default()
    };
    let loaded = crate::input::read_device(path, &options);
    let Some(device) = loaded.device.filter(|_| !loaded.diagnostics.has_errors()) else {
        return false;
    };
    let Ok(output) = generate(&device, &Options::default()) else {
        return false;
    };
    let file = syn::parse_file(&output.code)
        .unwrap_or_else(|e| panic!("{}: generated code does not parse: {e}", path.display()));
    let mut items = Vec::new();
    collect(&file.items, &mut items);
    // Value types over a float, by name, for the types that hold them.
    let mut float_types: BTreeSet<String> = ["f32", "f64"].map(String::from).into();
    for item in &items {
        if let syn::Item::Struct(s) = item
            && let syn::Fields::Unnamed(f) = &s.fields
            && f.unnamed.len() == 1
            && last_segment(&f.unnamed[0].ty).is_some_and(|t| t == "f32" || t == "f64")
        {
            float_types.insert(s.ident.to_string());
        }
    }
    let holds_float = |ty: &syn::Type| last_segment(ty).is_some_and(|t| float_types.contains(&t));
    for item in items {
        let (ident, attrs, key) = match item {
            syn::Item::Struct(s) => {
                let key = match &s.fields {
                    syn::Fields::Unit => (Kind::Entry, false),
                    syn::Fields::Unnamed(f)
                        if f.unnamed.len() == 1
                            && last_segment(&f.unnamed[0].ty)
                                .is_some_and(|t| PRIMITIVES.contains(&t.as_str())) =>
                    {
                        (Kind::Value, holds_float(&f.unnamed[0].ty))
                    }
                    syn::Fields::Named(f) => {
                        (Kind::Pdo, f.named.iter().any(|f| holds_float(&f.ty)))
                    }
                    syn::Fields::Unnamed(_) => {
                        panic!("{}: unexpected tuple struct {}", path.display(), s.ident)
                    }
                };
                (&s.ident, &s.attrs, key)
            }
            syn::Item::Enum(e) => {
                let float = e
                    .variants
                    .iter()
                    .flat_map(|v| v.fields.iter())
                    .any(|f| holds_float(&f.ty));
                (&e.ident, &e.attrs, (Kind::Meaning, float))
            }
            _ => unreachable!("only structs and enums are collected"),
        };
        seen.entry(key)
            .or_default()
            .entry(derives(attrs))
            .or_insert_with(|| format!("{ident} of {}", path.display()));
    }
    true
}

#[test]
fn every_generated_type_of_one_kind_derives_the_same_list() {
    let inputs = inputs();
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get().min(4));
    let results: Vec<(Seen, usize)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|w| {
                let inputs = &inputs;
                scope.spawn(move || {
                    let mut seen = Seen::new();
                    let files = inputs
                        .iter()
                        .skip(w)
                        .step_by(workers)
                        .filter(|p| survey(p, &mut seen))
                        .count();
                    (seen, files)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a survey worker panicked"))
            .collect()
    });
    let mut seen = Seen::new();
    let mut files = 0;
    for (part, n) in results {
        files += n;
        for (key, lists) in part {
            let all = seen.entry(key).or_default();
            for (list, example) in lists {
                all.entry(list).or_insert(example);
            }
        }
    }
    assert!(files >= 5, "only {files} inputs generated");
    let expected = |kind: Kind, float: bool| {
        let list = match kind {
            Kind::Value => VALUE,
            Kind::Meaning => MEANING,
            Kind::Entry => ENTRY,
            Kind::Pdo => PDO,
        };
        names(list, float)
    };
    for (&(kind, float), lists) in &seen {
        let want: Vec<String> = expected(kind, float)
            .into_iter()
            .map(String::from)
            .collect();
        let wrong: Vec<_> = lists.iter().filter(|(list, _)| **list != want).collect();
        assert!(
            wrong.is_empty(),
            "{kind:?} types (float: {float}) must derive {want:?}; these do not: {wrong:?}"
        );
    }
    for kind in [Kind::Value, Kind::Meaning, Kind::Entry, Kind::Pdo] {
        assert!(
            seen.contains_key(&(kind, false)),
            "no {kind:?} type generated: the test checks nothing for that kind"
        );
    }
}

#[test]
fn the_lists() {
    // A value type derives what an entry does, plus ordering.
    assert!(ENTRY.iter().all(|d| VALUE.contains(d)));
    assert_eq!(
        names(VALUE, true),
        [
            "Debug",
            "Clone",
            "Copy",
            "PartialEq",
            "PartialOrd",
            "Default"
        ]
    );
    assert_eq!(
        super::value(super::super::prim::Prim::U16).to_string(),
        "# [derive (Debug , Clone , Copy , PartialEq , Eq , Hash , PartialOrd , Ord , Default)]"
    );
}
