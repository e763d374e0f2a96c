//! The blocking and tokio drivers stay in step: the public methods of the
//! handle types both have (`Master`, `SdoClient`, `DriveHandle`) and the
//! free functions of `blocking` and `tokio` are listed from the sources and
//! compared, name and parameter names in order. A method one driver has and
//! the other lacks, or whose parameters differ, fails this test unless
//! `driver_api.allowed` (next to this file) lists it with its reason.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The handle types compared; free functions are listed under `fn`.
const TYPES: [&str; 3] = ["Master", "SdoClient", "DriveHandle"];

/// `(type, method)` to its parameter names, `self` left out.
type Listing = BTreeMap<(String, String), Vec<String>>;

fn runtime_src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../runtime/src/drivers")
}

/// `name.rs` and every `.rs` under `name/`, tests left out.
fn driver_files(name: &str) -> Vec<PathBuf> {
    let src = runtime_src();
    let mut files = vec![src.join(format!("{name}.rs"))];
    let mut dirs = vec![src.join(name)];
    while let Some(dir) = dirs.pop() {
        let entries = fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        for entry in entries {
            let path = entry.expect("a directory entry").path();
            let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
            if stem == "tests" {
                continue;
            }
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

fn param_names(sig: &syn::Signature) -> Vec<String> {
    sig.inputs
        .iter()
        .filter_map(|arg| match arg {
            syn::FnArg::Receiver(_) => None,
            syn::FnArg::Typed(t) => Some(match &*t.pat {
                syn::Pat::Ident(p) => p.ident.to_string(),
                _ => "_".to_string(),
            }),
        })
        .collect()
}

fn is_pub(vis: &syn::Visibility) -> bool {
    matches!(vis, syn::Visibility::Public(_))
}

fn collect(items: &[syn::Item], top: bool, out: &mut Listing) {
    for item in items {
        match item {
            syn::Item::Fn(f) if top && is_pub(&f.vis) => {
                let key = ("fn".to_string(), f.sig.ident.to_string());
                out.insert(key, param_names(&f.sig));
            }
            syn::Item::Impl(imp) if imp.trait_.is_none() => {
                let syn::Type::Path(path) = &*imp.self_ty else {
                    continue;
                };
                let Some(last) = path.path.segments.last() else {
                    continue;
                };
                let ty = last.ident.to_string();
                if !TYPES.contains(&ty.as_str()) {
                    continue;
                }
                for item in &imp.items {
                    if let syn::ImplItem::Fn(f) = item
                        && is_pub(&f.vis)
                    {
                        let key = (ty.clone(), f.sig.ident.to_string());
                        out.insert(key, param_names(&f.sig));
                    }
                }
            }
            syn::Item::Mod(m) if m.ident != "tests" => {
                if let Some((_, items)) = &m.content {
                    collect(items, false, out);
                }
            }
            _ => {}
        }
    }
}

fn listing(driver: &str) -> Listing {
    let mut out = Listing::new();
    for path in driver_files(driver) {
        let text = fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let file = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        // Only the driver's top file declares its free functions.
        let top = path.file_stem().is_some_and(|s| s == driver);
        collect(&file.items, top, &mut out);
    }
    out
}

/// Every difference, one line each: `Type::method blocking-only`,
/// `tokio-only`, or `params (blocking ..) (tokio ..)`.
fn differences(blocking: &Listing, tokio: &Listing) -> BTreeSet<String> {
    let name = |(ty, method): &(String, String)| format!("{ty}::{method}");
    let mut diffs = BTreeSet::new();
    for (key, params) in blocking {
        match tokio.get(key) {
            None => {
                diffs.insert(format!("{} blocking-only", name(key)));
            }
            Some(other) if other != params => {
                diffs.insert(format!("{} params", name(key)));
            }
            Some(_) => {}
        }
    }
    for key in tokio.keys().filter(|k| !blocking.contains_key(*k)) {
        diffs.insert(format!("{} tokio-only", name(key)));
    }
    diffs
}

/// The allowed differences: `Type::method kind: reason` lines; `#` starts
/// a comment.
fn allowed() -> BTreeMap<String, String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/driver_api.allowed");
    let text = fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut out = BTreeMap::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let Some((entry, reason)) = line.split_once(": ") else {
            panic!("driver_api.allowed:{}: `{line}` has no `: reason`", n + 1);
        };
        assert!(
            !reason.trim().is_empty(),
            "driver_api.allowed:{}: `{entry}` gives no reason",
            n + 1
        );
        out.insert(entry.trim().to_string(), reason.trim().to_string());
    }
    out
}

#[test]
fn blocking_and_tokio_drivers_have_the_same_public_api() {
    let blocking = listing("blocking");
    let tokio = listing("tokio");
    // The listing found what it should: a broken parse lists nothing.
    for ty in TYPES {
        assert!(
            blocking.keys().any(|(t, _)| t == ty) && tokio.keys().any(|(t, _)| t == ty),
            "no public methods of {ty} found in both drivers"
        );
    }
    assert!(blocking.contains_key(&("fn".into(), "run".into())));
    let found = differences(&blocking, &tokio);
    let allowed = allowed();
    let unlisted: Vec<&String> = found.iter().filter(|d| !allowed.contains_key(*d)).collect();
    let stale: Vec<&String> = allowed.keys().filter(|a| !found.contains(*a)).collect();
    let show = |key: &str| {
        let (ty_method, _) = key.split_once(' ').unwrap_or((key, ""));
        let (ty, method) = ty_method.split_once("::").unwrap_or(("", ty_method));
        let k = (ty.to_string(), method.to_string());
        format!(
            "{key}: blocking {:?}, tokio {:?}",
            blocking.get(&k),
            tokio.get(&k)
        )
    };
    assert!(
        unlisted.is_empty(),
        "the drivers differ where driver_api.allowed does not say why; add the \
         missing method to the other driver, or list the difference with its reason:\n{}",
        unlisted
            .iter()
            .map(|d| show(d))
            .collect::<Vec<_>>()
            .join("\n")
    );
    assert!(
        stale.is_empty(),
        "driver_api.allowed lists differences that are gone; remove them:\n{}",
        stale
            .iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
}
