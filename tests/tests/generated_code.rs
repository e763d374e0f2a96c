//! The generated code, end to end:
//! - insta snapshots of the generated source of the three seed devices, the
//!   hostile fixture and a chosen set of corpus files, plus per file the
//!   generator's warnings one per line, so that a change of naming
//!   collisions shows up in review;
//! - every corpus file, the seeds and the hostile fixture generated into one
//!   scratch `#![no_std]` crate under the target directory, checked by
//!   `cargo clippy -- -D warnings`;
//! - the hostile fixture (codegen/tests/fixtures/hostile.eds): its free text
//!   reaches the generated code only inside string literals.
//!
//! Every input is read through `read_bytes` with a stable display name
//! ("eds/<file>", "eds-corpus/files/<file>", ...), never an absolute path:
//! origins in the generated rustdoc use it, so the snapshots do not depend on
//! where the checkout is.

use std::collections::BTreeSet;
use std::ops::Range;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use eds2rust::diag::Diagnostics;
use eds2rust::r#gen::rust::{Options, Output, generate};
use eds2rust::input::{InputKind, Options as ReadOptions};
use eds2rust_tests::{corpus_files, target_dir, workspace_root};
use proc_macro2::{TokenStream, TokenTree};

/// The seed devices, in eds/ of the workspace.
const SEEDS: &[&str] = &[
    "zimmer_acs.yaml",
    "linak_techline.yaml",
    "interroll_ec5000bi.yaml",
];

/// The hostile fixture, relative to the workspace root (also its display name).
const HOSTILE: &str = "codegen/tests/fixtures/hostile.eds";

/// A YAML table whose free text holds what an EDS cannot: bidirectional-text
/// controls, NUL, ESC and other control characters, line breaks in names.
const HOSTILE_YAML: &str = "codegen/tests/fixtures/hostile.yaml";

/// A YAML table whose objects, values and error table are named like the core
/// items generated code uses (`Option`, `Some`, `Result`, `From`, `core`):
/// compiled with the rest, it shows those names cannot shadow them.
const SHADOWING: &str = "codegen/tests/fixtures/shadowing.yaml";

/// A YAML table whose objects, subs, bit fields and named values have
/// `rust_name:` pins: compiled with the rest.
const PINNED: &str = "codegen/tests/fixtures/rust_name.yaml";

/// Corpus files (../shared/eds-corpus/files) whose generated code is
/// snapshotted, chosen for variety.
const CORPUS_SNAPSHOTS: &[&str] = &[
    // A CiA 402 drive: ESAcademy stepper; DOMAIN entries, 8 default PDOs
    // (the base of tests/overlays/cia402_stepper.yaml). Its 8 name
    // collisions ("Standard error field") went with arrays as one type.
    "esacademy_cia402-stepper-node8.eds",
    // A CiA 401 generic I/O node: ARRAYs of digital/analogue channels, 8 PDOs.
    "esacademy_cia401-io-node3.eds",
    // A DCF: ParameterValue, DeviceComissioning, lowercase hex section names.
    "tmc5160_slave.dcf",
    // CompactSubObj, INTEGER24/40/48/56 and UNSIGNED24.., `Sub` section case,
    // many reader warnings.
    "python-canopen_sample.eds",
    // Default PDO mappings with dummy entries (DummyUsage; gaps in the layout).
    "technosoft_ipos-d-v1.04.eds",
    // Not UTF-8: read as Windows-1252/Latin-1 (byte 0x94 in [Comments]).
    "faulhaber_cc_605.3150.51-V.eds",
    // The smallest file: 137 bytes, one ARRAY object, no identity.
    "node-canopen_sample-tiny.eds",
    // CANopenNode's repeated sub names (their collisions went with arrays
    // as one indexed type).
    "canopennode_ds301-profile.eds",
    // gen::name-collision warnings: two objects named alike.
    "marathon_test-product.eds",
    // A vendor motor controller with 8 default PDOs and many vendor objects.
    "roboteq_motor-controller_v60.eds",
    // Every data type, including the odd-sized integers; UTF-8 non-ASCII text.
    "python-canopen_datatypes.eds",
    // A lely DCF with CompactSubObj on RECORDs (lely's extension).
    "lely_cocatd.dcf",
    // A RECORD-only simulator file with reader warnings and REAL32 values.
    "emsiso_emdi-2-l30b_sim.eds",
];

/// What came of one input.
enum Generated {
    /// The reader reported errors; nothing was generated.
    ReadFailed(Diagnostics),
    /// The generator returned `Err`.
    Failed(Diagnostics),
    Ok(Output),
}

/// Reads `path` under the name `display` (by extension: EDS/DCF or YAML
/// table) and generates its code with the default options.
fn generate_input(display: &str, path: &Path) -> Generated {
    let bytes =
        std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let options = ReadOptions::default();
    let loaded = match InputKind::of(path) {
        InputKind::Eds => eds2rust::eds::read_bytes(display, &bytes, &options),
        InputKind::Table => {
            let dir = path.parent().expect("an input file has a parent directory");
            eds2rust::table::read_bytes(display, &bytes, dir, &options)
        }
    };
    let device = match loaded.device {
        Some(device) if !loaded.diagnostics.has_errors() => device,
        _ => return Generated::ReadFailed(loaded.diagnostics),
    };
    match generate(&device, &Options::default()) {
        Ok(output) => Generated::Ok(output),
        Err(diagnostics) => Generated::Failed(diagnostics),
    }
}

/// `generate_input` for an input that must read and generate cleanly.
fn expect_generated(display: &str, path: &Path) -> Output {
    match generate_input(display, path) {
        Generated::Ok(output) => output,
        Generated::ReadFailed(d) => panic!("{display}: the reader reports errors:\n{}", d.render()),
        Generated::Failed(d) => panic!("{display}: generation failed:\n{}", d.render()),
    }
}

/// A file name as a lowercase identifier part: every other character is `_`.
fn ident_part(file_name: &str) -> String {
    file_name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect()
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .expect("an input path names a file")
        .to_string_lossy()
        .into_owned()
}

/// The warnings one per line (their `Display`), after a count.
fn render_warnings(warnings: &Diagnostics) -> String {
    let mut out = format!("generator warnings: {}\n", warnings.len());
    for diagnostic in warnings.iter() {
        out.push_str(&diagnostic.to_string());
        out.push('\n');
    }
    out
}

/// Asserts every `(name, description, content)` snapshot; all are checked
/// before failing, so that one run shows every changed snapshot.
fn check_snapshots(snapshots: &[(String, String, String)]) {
    let mut changed = Vec::new();
    for (name, description, content) in snapshots {
        let checked = catch_unwind(AssertUnwindSafe(|| {
            insta::with_settings!({ description => description.as_str(), omit_expression => true }, {
                insta::assert_snapshot!(name.as_str(), content.as_str());
            });
        }));
        if checked.is_err() {
            changed.push(name.as_str());
        }
    }
    assert!(
        changed.is_empty(),
        "changed or missing snapshots: {}",
        changed.join(", ")
    );
}

/// Adds the snapshots of one input: `<stem>_warnings` (the generator's
/// warnings) and `<stem>` (the generated code).
fn push_snapshots(
    snapshots: &mut Vec<(String, String, String)>,
    stem: &str,
    display: &str,
    output: Output,
) {
    snapshots.push((
        format!("{stem}_warnings"),
        format!("generator warnings of {display}"),
        render_warnings(&output.warnings),
    ));
    snapshots.push((
        stem.to_string(),
        format!("generated code of {display}"),
        output.code,
    ));
}

/// The seeds' generated code and generator warnings.
#[test]
fn seed_snapshots() {
    let mut snapshots = Vec::new();
    for seed in SEEDS {
        let output = expect_generated(
            &format!("eds/{seed}"),
            &workspace_root().join("eds").join(seed),
        );
        push_snapshots(
            &mut snapshots,
            &format!("seed_{}", ident_part(seed)),
            &format!("eds/{seed}"),
            output,
        );
    }
    check_snapshots(&snapshots);
}

/// The chosen corpus files' generated code and generator warnings.
#[test]
fn corpus_snapshots() {
    let Some(files) = corpus_files("generated-code snapshots of corpus files") else {
        return;
    };
    let mut snapshots = Vec::new();
    let mut collisions = 0;
    for name in CORPUS_SNAPSHOTS {
        let path = files
            .iter()
            .find(|p| file_name(p) == *name)
            .unwrap_or_else(|| panic!("{name} is not in the corpus; update CORPUS_SNAPSHOTS"));
        let display = format!("eds-corpus/files/{name}");
        let output = expect_generated(&display, path);
        collisions += output
            .warnings
            .iter()
            .filter(|d| d.code == "gen::name-collision")
            .count();
        push_snapshots(
            &mut snapshots,
            &format!("corpus_{}", ident_part(name)),
            &display,
            output,
        );
    }
    assert!(
        collisions > 0,
        "no chosen corpus file reports gen::name-collision any more; choose one that does"
    );
    check_snapshots(&snapshots);
}

/// Writes `bytes` to `path` only when they differ from the file's, so that
/// cargo sees no change on a rerun. Returns whether it wrote.
fn write_if_changed(path: &Path, bytes: &[u8]) -> bool {
    if std::fs::read(path).is_ok_and(|old| old == bytes) {
        return false;
    }
    std::fs::write(path, bytes).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
    true
}

/// Writes the scratch crate `<target>/generated-check/crate`: one module per
/// `(module, code)`, depending on the runtime by absolute path, with its own
/// `[workspace]` and a copy of the workspace's Cargo.lock. Module files of
/// earlier runs that are not in `modules` are removed. Returns its directory
/// and how many source files were (re)written.
fn write_scratch_crate(modules: &[(String, String)]) -> (PathBuf, usize) {
    let dir = target_dir().join("generated-check").join("crate");
    let src = dir.join("src");
    std::fs::create_dir_all(&src)
        .unwrap_or_else(|e| panic!("cannot create {}: {e}", src.display()));
    let runtime = workspace_root().join("runtime");
    let runtime = runtime.to_str().expect("the workspace path is UTF-8");
    assert!(
        !runtime.contains('\''),
        "a TOML literal string cannot hold `'`: {runtime}"
    );
    let manifest = format!(
        "# Written by eds2rust-tests (tests/tests/generated_code.rs); rewritten on every run.\n\
         [package]\nname = \"generated-check\"\nversion = \"0.0.0\"\nedition = \"2024\"\npublish = false\n\n\
         [dependencies]\neds2rust-runtime = {{ path = '{runtime}' }}\n\n\
         # Not part of the eds2rust workspace around it.\n[workspace]\n"
    );
    write_if_changed(&dir.join("Cargo.toml"), manifest.as_bytes());
    let lock =
        std::fs::read(workspace_root().join("Cargo.lock")).expect("the workspace has a Cargo.lock");
    write_if_changed(&dir.join("Cargo.lock"), &lock);

    let mut lib = String::from(
        "//! Every input of eds2rust-tests' compile check, one module each\n\
         //! (written by tests/tests/generated_code.rs).\n#![no_std]\n",
    );
    let mut wanted = BTreeSet::new();
    let mut written = 0;
    for (module, code) in modules {
        let file = format!("{module}.rs");
        lib.push_str(&format!(
            "pub mod {module} {{\n    include!(\"{file}\");\n}}\n"
        ));
        written += usize::from(write_if_changed(&src.join(&file), code.as_bytes()));
        wanted.insert(file);
    }
    written += usize::from(write_if_changed(&src.join("lib.rs"), lib.as_bytes()));
    for entry in std::fs::read_dir(&src).expect("the scratch src directory is listable") {
        let path = entry.expect("directory entry").path();
        let name = file_name(&path);
        if name.starts_with("m_") && name.ends_with(".rs") && !wanted.contains(&name) {
            std::fs::remove_file(&path)
                .unwrap_or_else(|e| panic!("cannot remove {}: {e}", path.display()));
        }
    }
    (dir, written)
}

/// Runs `cargo clippy --offline --quiet -- -D warnings` in `dir` with a target
/// directory of its own (never the outer cargo's, whose lock it would wait
/// for). `Err` with cargo's output when it fails, or when clippy is missing.
fn clippy(dir: &Path) -> Result<(), String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let output = Command::new(&cargo)
        .args(["clippy", "--offline", "--quiet", "--", "-D", "warnings"])
        .current_dir(dir)
        .env(
            "CARGO_TARGET_DIR",
            target_dir().join("generated-check").join("target"),
        )
        // One crate of ~500k lines: incremental caches take some 3 GB and do
        // not save the whole-crate lint pass; an unchanged crate is fresh anyway.
        .env("CARGO_INCREMENTAL", "0")
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", Path::new(&cargo).display()));
    let stderr = String::from_utf8_lossy(&output.stderr);
    if stderr.contains("no such command") {
        return Err(format!(
            "cargo clippy is not installed (rustup component add clippy); the compile check needs it:\n{stderr}"
        ));
    }
    if !output.status.success() {
        return Err(format!(
            "cargo clippy -D warnings failed on the generated code in {} ({}):\n{}{stderr}",
            dir.display(),
            output.status,
            String::from_utf8_lossy(&output.stdout),
        ));
    }
    Ok(())
}

/// Every corpus file, the seeds and the hostile, shadowing and pinned fixtures compile
/// together, clippy-clean. Without ../shared the seeds and the fixtures still do.
#[test]
fn generated_code_compiles_under_clippy() {
    let started = Instant::now();
    let mut inputs: Vec<(String, PathBuf)> = SEEDS
        .iter()
        .map(|seed| {
            (
                format!("eds/{seed}"),
                workspace_root().join("eds").join(seed),
            )
        })
        .collect();
    inputs.push((HOSTILE.to_string(), workspace_root().join(HOSTILE)));
    inputs.push((
        HOSTILE_YAML.to_string(),
        workspace_root().join(HOSTILE_YAML),
    ));
    inputs.push((SHADOWING.to_string(), workspace_root().join(SHADOWING)));
    inputs.push((PINNED.to_string(), workspace_root().join(PINNED)));
    let own = inputs.len();
    if let Some(files) = corpus_files(
        "generated-code compile check of the corpus (the seeds and the fixtures still ran)",
    ) {
        inputs.extend(
            files
                .into_iter()
                .map(|p| (format!("eds-corpus/files/{}", file_name(&p)), p)),
        );
    }

    let (mut modules, mut failures, mut read_failed) = (Vec::new(), Vec::new(), Vec::new());
    let mut names = BTreeSet::new();
    let mut lines = 0;
    let mut largest = (0, String::new());
    for (i, (display, path)) in inputs.iter().enumerate() {
        match generate_input(display, path) {
            Generated::Ok(output) => {
                let module = format!("m_{}", ident_part(&file_name(path)));
                assert!(
                    names.insert(module.clone()),
                    "two inputs give module `{module}`"
                );
                let count = output.code.lines().count();
                lines += count;
                if count > largest.0 {
                    largest = (count, display.clone());
                }
                modules.push((module, output.code));
            }
            Generated::Failed(d) => failures.push(format!("{display}:\n{}", d.render())),
            // Our own inputs must read cleanly; a corpus file whose reader
            // reports errors is only counted (tests/tests/corpus.rs covers reading).
            Generated::ReadFailed(d) if i < own => {
                failures.push(format!("{display} (reading):\n{}", d.render()))
            }
            Generated::ReadFailed(d) => {
                read_failed.push(format!("{display}: {} reader errors", d.error_count()))
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} inputs failed to generate:\n{}",
        failures.len(),
        inputs.len(),
        failures.join("\n")
    );
    let generated = started.elapsed();
    for line in &read_failed {
        println!("not generated (reader errors): {line}");
    }

    println!(
        "{} files generated ({} not generated: reader errors), {lines} generated lines \
         (largest: {} with {}), in {generated:.1?}",
        modules.len(),
        read_failed.len(),
        largest.1,
        largest.0,
    );
    // A generated file is read in review: arrays are one indexed type,
    // OBJECTS one line per entry and the PDO parameters' standard value
    // types the runtime's, so no input comes near this (the largest corpus
    // file gives about 20,100 lines, 1,000 of them the built-in meanings of
    // ten CiA 301 objects; it gave 66,000 with a type per array element and
    // 30,000 with generated types for the 32 PDOs' parameters).
    assert!(
        largest.0 < 22_000,
        "{} generates {} lines; a generated file should stay under 22,000",
        largest.1,
        largest.0
    );
    let (dir, written) = write_scratch_crate(&modules);
    let checking = Instant::now();
    let result = clippy(&dir);
    println!(
        "cargo clippy in {}: {:.1?} ({written} source files rewritten)",
        dir.display(),
        checking.elapsed()
    );
    if let Err(message) = result {
        panic!("{message}");
    }
}

/// Texts of the hostile fixture that must reach the generated code only
/// inside string literals (doc strings, `NAME` and identity constants).
const MARKERS: &[&str] = &[
    "*/",
    "/*",
    "\"]; }",
    "{ }",
    "#[cfg(any())]",
    "#[derive(Evil)]",
    "#[no_mangle]",
    "fn evil",
    "\\",
    "🚀",
    "Größe",
    "°C",
    "µs",
];

/// The string literals (byte range in the source, value) and identifiers of
/// `tokens`. Doc comments are `#[doc = "..."]` attributes whose literal spans
/// the whole comment.
fn collect_tokens(
    tokens: TokenStream,
    literals: &mut Vec<(Range<usize>, String)>,
    idents: &mut Vec<String>,
) {
    for tree in tokens {
        match tree {
            TokenTree::Group(group) => collect_tokens(group.stream(), literals, idents),
            TokenTree::Ident(ident) => idents.push(ident.to_string()),
            TokenTree::Literal(literal) => {
                let range = literal.span().byte_range();
                match syn::Lit::new(literal) {
                    syn::Lit::Str(s) => literals.push((range, s.value())),
                    // String defaults of `od::OBJECTS` are byte strings.
                    syn::Lit::ByteStr(s) => {
                        literals.push((range, String::from_utf8_lossy(&s.value()).into_owned()))
                    }
                    _ => {}
                }
            }
            TokenTree::Punct(_) => {}
        }
    }
}

/// The distinct `hostile.eds:<line>` locations named in `text`.
fn hostile_locations(text: &str) -> BTreeSet<u32> {
    text.match_indices("hostile.eds:")
        .filter_map(|(at, m)| {
            let digits: String = text[at + m.len()..]
                .chars()
                .take_while(char::is_ascii_digit)
                .collect();
            digits.parse().ok()
        })
        .collect()
}

/// The hostile fixture reads without errors and generates code (compiled by
/// `generated_code_compiles_under_clippy`) in which every hostile text sits
/// inside a string literal and every identifier is ASCII; colliding names are
/// reported with both origins.
#[test]
fn hostile_names_stay_in_string_literals() {
    let path = workspace_root().join(HOSTILE);
    let bytes =
        std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let loaded = eds2rust::eds::read_bytes(HOSTILE, &bytes, &ReadOptions::default());
    assert!(
        !loaded.diagnostics.has_errors(),
        "the hostile fixture must read without errors:\n{}",
        loaded.diagnostics.render()
    );
    let output = expect_generated(HOSTILE, &path);

    let collision = output
        .warnings
        .iter()
        .filter(|d| d.code == "gen::name-collision")
        .any(|d| hostile_locations(&d.to_string()).len() >= 2);
    assert!(
        collision,
        "no gen::name-collision warning names two origins in hostile.eds:\n{}",
        render_warnings(&output.warnings)
    );

    let code = &output.code;
    let tokens: TokenStream = code.parse().expect("the generated code tokenises");
    let (mut literals, mut idents) = (Vec::new(), Vec::new());
    collect_tokens(tokens, &mut literals, &mut idents);
    let line_of = |at: usize| code[..at].matches('\n').count() + 1;
    for marker in MARKERS {
        assert!(
            literals.iter().any(|(_, value)| value.contains(marker)),
            "{marker:?} reaches no string literal: the fixture or the generator changed"
        );
        for (at, _) in code.match_indices(marker) {
            let inside = literals
                .iter()
                .any(|(range, _)| range.start <= at && at + marker.len() <= range.end);
            assert!(
                inside,
                "{marker:?} on generated line {} is outside any string literal:\n{}",
                line_of(at),
                code.lines().nth(line_of(at) - 1).unwrap_or("")
            );
        }
    }
    for ident in &idents {
        assert!(ident.is_ascii(), "identifier `{ident}` is not ASCII");
    }

    let mut snapshots = Vec::new();
    push_snapshots(&mut snapshots, "hostile", HOSTILE, output);
    check_snapshots(&snapshots);
}

/// The hostile YAML table generates code (compiled by
/// `generated_code_compiles_under_clippy`, where rustc's deny-by-default
/// `text_direction_codepoint_in_comment`/`_in_literal` lints would reject a
/// raw bidi control) that holds no control character but line feeds and no
/// bidi control at all: they are `\u{...}` escapes, in doc comments and
/// literals alike; each text that had one gets a `gen::unsafe-text` warning.
#[test]
fn hostile_yaml_text_is_escaped() {
    let path = workspace_root().join(HOSTILE_YAML);
    let output = expect_generated(HOSTILE_YAML, &path);
    for (n, line) in output.code.lines().enumerate() {
        let bad = line.chars().find(|&c| eds2rust::text::is_hazard(c));
        assert!(
            bad.is_none(),
            "generated line {} holds {:?}:\n{line}",
            n + 1,
            bad.unwrap_or_default()
        );
    }
    for escaped in ["\\u{202E}", "\\u{2066}", "\\u{1B}", "\\u{0}"] {
        assert!(
            output.code.contains(escaped),
            "{escaped} is not in the generated code: the fixture or the generator changed"
        );
    }
    let unsafe_text = output
        .warnings
        .iter()
        .filter(|d| d.code == "gen::unsafe-text")
        .count();
    assert!(
        unsafe_text >= 20,
        "expected a gen::unsafe-text warning per hostile text, got {unsafe_text}:\n{}",
        render_warnings(&output.warnings)
    );
    let mut snapshots = Vec::new();
    push_snapshots(&mut snapshots, "hostile_yaml", HOSTILE_YAML, output);
    check_snapshots(&snapshots);
}
