//! Every real EDS/DCF file of ../shared/eds-corpus reads without an error in
//! lenient mode, and without a panic; one summary line per file.

use eds2rust::eds::{Options, read_file};
use eds2rust::ir::ObjectKind;

#[test]
fn every_corpus_file_reads_without_error() {
    let Some(files) = eds2rust_tests::corpus_files("corpus read test") else {
        return;
    };
    let mut failures = Vec::new();
    let (mut objects, mut entries) = (0, 0);
    for path in &files {
        let loaded = read_file(path, &Options::default());
        let device = loaded
            .device
            .as_ref()
            .expect("a readable file gives a device");
        let n_entries: usize = device.objects.values().map(|o| o.entries.len()).sum();
        objects += device.objects.len();
        entries += n_entries;
        println!(
            "{:<48} {:>4} objects {:>5} entries {:>3} errors {:>4} warnings  {}",
            path.file_name().unwrap().to_string_lossy(),
            device.objects.len(),
            n_entries,
            loaded.diagnostics.error_count(),
            loaded.diagnostics.warning_count(),
            device.identity.product_name.as_deref().unwrap_or("-"),
        );
        if loaded.diagnostics.has_errors() {
            failures.push(format!(
                "{}:\n{}",
                path.display(),
                loaded.diagnostics.render()
            ));
        }
        // Every value-carrying object has at least one entry with its origin in this file.
        for object in device.objects.values() {
            if matches!(object.kind, ObjectKind::Var | ObjectKind::Domain) {
                assert!(
                    object.entries.contains_key(&0),
                    "{}: 0x{:04X} has no sub 0",
                    path.display(),
                    object.index
                );
            }
            for entry in object.entries.values() {
                assert!(entry.origin.line >= 1 && entry.origin.file == path.display().to_string());
            }
        }
    }
    println!(
        "{} files, {objects} objects, {entries} entries",
        files.len()
    );
    assert!(
        failures.is_empty(),
        "files with errors in lenient mode:\n{}",
        failures.join("\n")
    );
    assert_eq!(
        files.len(),
        64,
        "the corpus has 64 files; update this test when it changes"
    );
}

#[test]
fn corpus_identity_is_read() {
    let Some(files) = eds2rust_tests::corpus_files("corpus identity test") else {
        return;
    };
    let maxon = files
        .iter()
        .find(|p| p.ends_with("maxon_epos4-module-50-5.eds"))
        .expect("maxon file in corpus");
    let device = read_file(maxon, &Options::default()).device.unwrap();
    assert_eq!(device.identity.vendor_number, Some(0x000000FB));
    assert!(
        device
            .identity
            .vendor_name
            .as_deref()
            .unwrap_or("")
            .to_lowercase()
            .contains("maxon")
    );
}
