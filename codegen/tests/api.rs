//! The API listing (`eds2rust::r#gen::rust::api_listing`): snapshots of the
//! seed devices and of a few corpus files, every listed path an item of the
//! generated code, and the same bytes every time.

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

use eds2rust::build::api_listing_files;
use eds2rust::r#gen::rust::{Options, api_listing, generate};
use eds2rust::ir::Device;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path)
}

const SEEDS: [&str; 3] = [
    "eds/zimmer_acs.yaml",
    "eds/linak_techline.yaml",
    "eds/interroll_ec5000bi.yaml",
];

/// Corpus files with records and default PDOs between them.
const CORPUS: [&str; 2] = ["cia402_sample.eds", "canopennode_demodevice.eds"];

/// The corpus directory, or `None` after one `NOT RUN:` line.
fn corpus(what: &str) -> Option<PathBuf> {
    let dir = repo("../shared/eds-corpus/files");
    if dir.is_dir() {
        return Some(dir);
    }
    // Written to stderr directly: the harness captures eprintln!.
    let _ = writeln!(
        std::io::stderr(),
        "NOT RUN: {what}: ../shared/eds-corpus is not beside this checkout"
    );
    None
}

fn device(path: &Path) -> Device {
    let loaded = eds2rust::build::load_device(path, &[], &eds2rust::read::Options::default());
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}:\n{}",
        path.display(),
        loaded.diagnostics.render()
    );
    loaded.device.expect("a device without errors")
}

fn listing(path: &Path) -> String {
    let device = device(path);
    match api_listing(&device, &Options::default()) {
        Ok(listing) => listing.text,
        Err(d) => panic!("{}:\n{}", path.display(), d.render()),
    }
}

fn snapshot_name(path: &Path) -> String {
    path.file_name()
        .expect("a file")
        .to_string_lossy()
        .replace(['.', '-'], "_")
}

#[test]
fn seed_devices() {
    for seed in SEEDS {
        let path = repo(seed);
        insta::assert_snapshot!(snapshot_name(&path), listing(&path));
    }
}

#[test]
fn corpus_files() {
    let Some(dir) = corpus("API listings of corpus files") else {
        return;
    };
    for name in CORPUS {
        let path = dir.join(name);
        insta::assert_snapshot!(snapshot_name(&path), listing(&path));
    }
    // A vendor EDS as the base of a YAML table that gives it value types.
    let path = repo("tests/overlays/cia402_stepper.yaml");
    // Its `base:` lies in ../shared, beside the checkout.
    let options = eds2rust::read::Options {
        allow_base_dirs: vec![dir.clone()],
        ..Default::default()
    };
    let listing = api_listing_files(&path, &[], &options)
        .unwrap_or_else(|d| panic!("{}:\n{}", path.display(), d.render()));
    insta::assert_snapshot!("esacademy_cia402_stepper_with_overlay", listing.text);
}

/// Every item path of a parsed file: `od::feedback::Position`, `pdo::…`.
fn item_paths(items: &[syn::Item], prefix: &str, out: &mut BTreeSet<String>) {
    for item in items {
        let ident = match item {
            syn::Item::Struct(s) => &s.ident,
            syn::Item::Enum(e) => &e.ident,
            syn::Item::Type(t) => &t.ident,
            syn::Item::Mod(m) => &m.ident,
            _ => continue,
        };
        let path = if prefix.is_empty() {
            ident.to_string()
        } else {
            format!("{prefix}::{ident}")
        };
        if let syn::Item::Mod(m) = item
            && let Some((_, inner)) = &m.content
        {
            item_paths(inner, &path, out);
        }
        out.insert(path);
    }
}

/// Checks that the first column and every `od::`/`errors::`/`pdo::` path
/// elsewhere in the listing name items of the generated code; returns how
/// many paths were checked.
fn check_paths(path: &Path) -> usize {
    let device = device(path);
    let code = generate(&device, &Options::default())
        .unwrap_or_else(|d| panic!("{}:\n{}", path.display(), d.render()))
        .code;
    let file = syn::parse_file(&code).expect("generated code parses");
    let mut items = BTreeSet::new();
    item_paths(&file.items, "", &mut items);
    let text = api_listing(&device, &Options::default())
        .expect("lists")
        .text;
    let mut checked = 0;
    for line in text.lines() {
        let columns: Vec<&str> = line.split('\t').collect();
        assert!(columns.len() >= 3, "{}: {line:?}", path.display());
        // An indexed type is listed with its parameter: `Type<SUB>`.
        let item = columns[0].strip_suffix("<SUB>").unwrap_or(columns[0]);
        assert!(
            items.contains(item),
            "{}: `{}` is not an item of the generated code",
            path.display(),
            columns[0]
        );
        checked += 1;
        for word in line.split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')) {
            let word = word.trim_matches(':');
            let is_path = ["od::", "errors::", "pdo::"]
                .iter()
                .any(|p| word.starts_with(p));
            if is_path {
                assert!(
                    items.contains(word),
                    "{}: `{word}` (in {line:?}) is not an item of the generated code",
                    path.display()
                );
                checked += 1;
            }
        }
    }
    checked
}

#[test]
fn every_listed_path_is_an_item_of_the_generated_code() {
    let mut inputs: Vec<PathBuf> = SEEDS.iter().map(|s| repo(s)).collect();
    inputs.push(repo("codegen/tests/fixtures/shadowing.yaml"));
    inputs.push(repo("codegen/tests/fixtures/hostile.eds"));
    if let Some(dir) = corpus("paths of the corpus's API listings") {
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .expect("corpus directory")
            .map(|e| e.expect("directory entry").path())
            .filter(|p| p.is_file())
            .collect();
        files.sort();
        for file in files {
            let loaded =
                eds2rust::build::load_device(&file, &[], &eds2rust::read::Options::default());
            let generates = loaded.device.as_ref().is_some_and(|d| {
                !loaded.diagnostics.has_errors() && generate(d, &Options::default()).is_ok()
            });
            if generates {
                inputs.push(file);
            }
        }
    }
    let mut total = 0;
    for input in &inputs {
        let checked = check_paths(input);
        assert!(checked > 0, "{}: nothing listed", input.display());
        total += checked;
    }
    assert!(total > 1000, "{total} paths checked");
}

#[test]
fn the_same_input_gives_the_same_bytes() {
    for seed in SEEDS {
        let path = repo(seed);
        let first = listing(&path);
        let second = listing(&path);
        assert_eq!(first, second, "{seed}");
        let from_files = api_listing_files(&path, &[], &eds2rust::read::Options::default())
            .unwrap_or_else(|d| panic!("{seed}:\n{}", d.render()))
            .text;
        assert_eq!(first, from_files, "{seed}: api_listing_files");
        let mut sorted: Vec<&str> = first.lines().collect();
        let len = sorted.len();
        sorted.dedup();
        assert_eq!(sorted.len(), len, "{seed}: no line twice");
    }
}

#[test]
fn lines_are_sorted_by_key_and_od_comes_first() {
    let text = listing(&repo("eds/linak_techline.yaml"));
    let sections: Vec<&str> = text
        .lines()
        .map(|l| l.split("::").next().unwrap_or(l))
        .collect();
    let mut order = sections.clone();
    order.dedup();
    assert_eq!(order, ["od", "pdo", "errors"]);
    let keys: Vec<(u16, i32)> = text
        .lines()
        .filter(|l| l.starts_with("od::"))
        .map(|l| {
            let key = l.split('\t').nth(1).expect("a key");
            let hex = key.trim_start_matches("0x");
            let (index, sub) = match hex.split_once('.') {
                // `1..254` for an indexed type: sorted by its first sub.
                Some((i, s)) => {
                    let first = s.split_once("..").map_or(s, |(first, _)| first);
                    (i, first.parse::<i32>().expect("decimal sub"))
                }
                None => (hex, -1),
            };
            (u16::from_str_radix(index, 16).expect("hex index"), sub)
        })
        .collect();
    assert!(keys.windows(2).all(|w| w[0] <= w[1]), "{keys:?}");
}

#[test]
fn a_changed_named_value_changes_one_line() {
    let path = repo("eds/linak_techline.yaml");
    let mut device = device(&path);
    let before = api_listing(&device, &Options::default())
        .expect("lists")
        .text;
    let named = device
        .objects
        .get_mut(&0x2000)
        .and_then(|o| o.entries.get_mut(&1))
        .and_then(|e| e.semantics.values.as_mut())
        .and_then(|v| v.named.iter_mut().find(|n| n.name == "stop"))
        .expect("LINAK's command position has `stop`");
    named.low = 0xFB07;
    named.high = 0xFB07;
    let after = api_listing(&device, &Options::default())
        .expect("lists")
        .text;
    let changed: Vec<(&str, &str)> = before
        .lines()
        .zip(after.lines())
        .filter(|(a, b)| a != b)
        .collect();
    assert_eq!(before.lines().count(), after.lines().count());
    assert_eq!(changed.len(), 1, "{changed:#?}");
    assert!(changed[0].1.contains("0xFB07 \"stop\""), "{changed:?}");
}

#[test]
fn input_errors_and_strict_warnings_are_returned() {
    let dir = std::env::temp_dir().join(format!("eds2rust-api-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let eds = dir.join("warns.eds");
    std::fs::write(&eds, "[1000]\nParameterName=x\nDataType=0x0007\n").expect("write");
    let lenient = api_listing_files(&eds, &[], &eds2rust::read::Options::default());
    let strict = api_listing_files(
        &eds,
        &[],
        &eds2rust::read::Options {
            strict: true,
            ..Default::default()
        },
    );
    let missing = api_listing_files(&dir.join("missing.eds"), &[], &Default::default());
    let _ = std::fs::remove_dir_all(&dir);
    let lenient = lenient.unwrap_or_else(|d| panic!("{}", d.render()));
    // 0x1000 is named by CiA 301 (`DeviceType`), not by its `ParameterName`.
    assert_eq!(lenient.text, "od::DeviceType\t0x1000\tu32\tro\t-\t-\n");
    assert!(
        lenient.warnings.warning_count() > 0,
        "the reader's warnings"
    );
    assert!(strict.expect_err("strict").has_errors());
    assert!(missing.expect_err("no such file").has_errors());
}
