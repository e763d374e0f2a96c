//! The typed network generated from a bus file (`Builder::network`,
//! `build::generate_network`): the seed machine (eds/machine/bus.yml) is
//! snapshotted (its top file whole, each node's `pdo` module: the node's
//! object dictionary is the seed's own, snapshotted in
//! tests/tests/generated_code.rs); a mapping of an object the device lacks
//! is an error naming the bus file, line and object; the builder writes
//! the files and reads every input once.
//!
//! The bus file is given relative to this crate's directory (where cargo
//! runs the test), so the origins in the generated docs do not depend on
//! where the checkout is.

use std::path::{Path, PathBuf};

use eds2rust::Builder;
use eds2rust::build::generate_network;
use eds2rust::diag::Severity;
use eds2rust::r#gen::rust::Options;

const MACHINE: &str = "../eds/machine/bus.yml";

/// A fresh, empty directory for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("network-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The `pdo` module of a node's generated file.
fn pdo_module(code: &str) -> &str {
    code.find("\n/// The PDOs the network configures")
        .map_or("(no pdo module)", |at| &code[at + 1..])
}

#[test]
fn the_seed_machine_generates() {
    let generated = generate_network(
        "machine",
        Path::new(MACHINE),
        &Options::default(),
        &Default::default(),
    );
    let (files, warnings) = match generated.result {
        Ok(ok) => ok,
        Err(diagnostics) => panic!("{}", diagnostics.render()),
    };
    let names: Vec<String> = files.iter().map(|(p, _)| p.display().to_string()).collect();
    assert_eq!(
        names,
        [
            "machine.rs",
            "machine/axis.rs",
            "machine/actuator.rs",
            "machine/conveyor.rs"
        ]
    );
    // Every input is a file to rerun on: the bus file and the three tables.
    let read: Vec<String> = generated
        .files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for file in [
        "bus.yml",
        "zimmer_acs.yaml",
        "linak_techline.yaml",
        "interroll_ec5000bi.yaml",
    ] {
        assert!(read.iter().any(|r| r == file), "{file} in {read:?}");
    }
    insta::assert_snapshot!("machine_top", &files[0].1);
    let mut pdos = String::new();
    for (path, code) in &files[1..] {
        pdos.push_str(&format!("// ---- {}\n", path.display()));
        pdos.push_str(pdo_module(code));
    }
    insta::assert_snapshot!("machine_pdos", pdos);
    let mut lines: Vec<String> = warnings
        .iter()
        .map(|d| format!("{} {}: {}", d.code, d.file, d.message))
        .collect();
    lines.sort();
    insta::assert_snapshot!("machine_warnings", lines.join("\n"));
    // Generation is deterministic.
    let again = generate_network(
        "machine",
        Path::new(MACHINE),
        &Options::default(),
        &Default::default(),
    );
    assert_eq!(again.result.unwrap().0, files);
}

#[test]
fn a_mapping_of_a_missing_object_names_the_bus_file_line_and_object() {
    let dir = scratch("missing");
    let eds = Path::new(env!("CARGO_MANIFEST_DIR")).join("../eds");
    let bus = dir.join("bus.yml");
    std::fs::write(
        &bus,
        format!(
            "master:\n  node_id: 1\naxis:\n  dcf: \"{}\"\n  node_id: 40\n  tpdo:\n    1:\n      \
             mapping:\n        - {{index: 0x6041, sub_index: 0}}\n        - {{index: 0x6099, sub_index: 0}}\n",
            eds.join("zimmer_acs.yaml").display()
        ),
    )
    .unwrap();
    let generated = generate_network("m", &bus, &Options::default(), &Default::default());
    let diagnostics = generated.result.expect_err("a build error");
    let error = diagnostics
        .iter()
        .find(|d| d.severity == Severity::Error)
        .expect("an error");
    assert_eq!(
        error.file,
        bus.display().to_string(),
        "{}",
        diagnostics.render()
    );
    assert_eq!(error.location.line, Some(10), "{}", diagnostics.render());
    assert!(error.message.contains("0x6099"), "{}", diagnostics.render());
    let rendered = diagnostics
        .render()
        .replace(&dir.display().to_string(), "<dir>")
        .replace(env!("CARGO_MANIFEST_DIR"), "<codegen>");
    insta::assert_snapshot!("missing_object", rendered);
    // Through the builder, the same error and nothing written.
    let out = dir.join("out");
    let err = Builder::new()
        .network("m", &bus)
        .out_dir(&out)
        .cargo_output(false)
        .build()
        .expect_err("a build error");
    assert!(err.to_string().contains("0x6099"), "{err}");
    assert!(!out.join("m.rs").exists());
}

#[test]
fn the_builder_writes_the_network_and_reruns_on_every_input() {
    let out = scratch("builder");
    let report = Builder::new()
        .network("machine", MACHINE)
        .out_dir(&out)
        .cargo_output(false)
        .build()
        .unwrap_or_else(|e| panic!("{e}"));
    for file in [
        "machine.rs",
        "machine/axis.rs",
        "machine/actuator.rs",
        "machine/conveyor.rs",
    ] {
        assert!(out.join(file).is_file(), "{file}");
    }
    let top = std::fs::read_to_string(out.join("machine.rs")).unwrap();
    assert!(top.contains("include!(\"machine/axis.rs\")"), "{top}");
    let reruns: Vec<String> = report
        .cargo_lines()
        .into_iter()
        .filter(|l| l.starts_with("cargo:rerun-if-changed="))
        .collect();
    assert_eq!(reruns.len(), 4, "{reruns:?}");
    // A network's name is checked like a device's, and shares their space.
    let err = Builder::new()
        .device("machine", "../eds/zimmer_acs.yaml")
        .network("machine", MACHINE)
        .out_dir(&out)
        .cargo_output(false)
        .build()
        .expect_err("a name given twice");
    assert!(err.to_string().contains("given twice"), "{err}");
    let err = Builder::new()
        .network("My-Machine", MACHINE)
        .out_dir(&out)
        .cargo_output(false)
        .build()
        .expect_err("not an identifier");
    assert!(err.to_string().contains("network name"), "{err}");
}

/// A node's object dictionary is the device's as `Builder::device` makes it
/// (identity, `od`, `errors`): only `pdo` differs.
#[test]
fn a_node_is_its_device_but_for_the_pdos() {
    let generated = generate_network(
        "machine",
        Path::new(MACHINE),
        &Options::default(),
        &Default::default(),
    );
    let (files, _) = generated.result.expect("the machine generates");
    for (node, table) in [
        ("axis", "zimmer_acs.yaml"),
        ("actuator", "linak_techline.yaml"),
        ("conveyor", "interroll_ec5000bi.yaml"),
    ] {
        let path = format!("../eds/machine/../{table}");
        let device = eds2rust::build::generate(Path::new(&path), &[], &Options::default())
            .unwrap_or_else(|d| panic!("{}", d.render()));
        let (_, code) = files
            .iter()
            .find(|(p, _)| p.ends_with(format!("{node}.rs")))
            .expect("the node's file");
        let before = |text: &str| -> usize {
            text.find("\n/// The PDOs the network configures")
                .or_else(|| text.find("\n/// Default PDOs"))
                .unwrap_or(text.len())
        };
        let (node_od, device_od) = (&code[..before(code)], &device[..before(&device)]);
        assert!(
            node_od == device_od,
            "{node}: the object dictionary differs"
        );
        assert!(
            code.contains("\n/// The PDOs the network configures"),
            "{node}"
        );
    }
}
