//! Object tables read at run time (`eds2rust_sim::file`, feature `files`)
//! from the real files of ../shared/eds-corpus (read there, not copied):
//! every file becomes a device that boots and answers SDO uploads of
//! 0x1000 and 0x1018 sub 1 with the values the file gives (DCF parameter
//! value, else default, `$NODEID` resolved), read independently through
//! the IR.

use std::path::{Path, PathBuf};

use eds2rust::input::{Options, read_device};
use eds2rust::ir::Value;
use eds2rust_runtime::Instant;
use eds2rust_runtime::master::Master;
use eds2rust_runtime::od::NodeId;
use eds2rust_sim::bench::Bench;
use eds2rust_sim::file::{self, LoadError};
use eds2rust_sim::{Device, DeviceConfig};

fn corpus() -> Option<Vec<PathBuf>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/eds-corpus/files");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        println!("skipped: {} is missing", dir.display());
        return None;
    };
    let mut files: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
    files.sort();
    Some(files)
}

/// The value the file gives (index, sub), as the device should answer it.
fn file_value(path: &Path, index: u16, sub: u8, node: u8) -> Option<Vec<u8>> {
    let device = read_device(path, &Options::lenient()).device?;
    let entry = device.objects.get(&index)?.entries.get(&sub)?;
    let literal = entry.parameter_value.as_ref().or(entry.default.as_ref())?;
    match literal.resolve(Some(node)) {
        Value::Integer(v) => {
            let size = match sub {
                0 if index == 0x1018 => 1,
                _ => 4,
            };
            Some(v.to_le_bytes()[..size].to_vec())
        }
        _ => None,
    }
}

#[test]
fn every_corpus_file_boots_and_answers_its_identity() {
    let Some(files) = corpus() else {
        return;
    };
    assert!(files.len() > 20, "{files:?}");
    let mut failures = Vec::new();
    for path in &files {
        let table = match file::load(path) {
            Ok(table) => table,
            Err(e) => {
                failures.push(format!("{e}"));
                continue;
            }
        };
        let node = table.node.or(NodeId::new(5)).expect("node id");
        let device = Device::new(table.objects, DeviceConfig::node(node), (), Instant::ZERO);
        let master = Master::new(NodeId::new(1).expect("master"), None);
        let mut bench = Bench::new(master, device, Instant::ZERO);
        let boot = format!("{:03X}#00", 0x700 + u16::from(node.get()));
        assert!(
            bench.trace_lines().contains(&boot),
            "{}: no boot-up {boot}: {:?}",
            path.display(),
            bench.trace_lines()
        );
        for (index, sub) in [(0x1000, 0), (0x1018, 1)] {
            let expected = file_value(path, index, sub, node.get());
            let answer = bench.upload(node, index, sub);
            match (table.entry(index, sub), expected) {
                (Some(_), Some(expected)) => assert_eq!(
                    answer.as_deref().ok(),
                    Some(expected.as_slice()),
                    "{}: {index:#06X} sub {sub}",
                    path.display()
                ),
                (Some(_), None) => assert!(answer.is_ok(), "{}: {index:#06X}", path.display()),
                (None, _) => assert!(answer.is_err(), "{}: {index:#06X}", path.display()),
            }
        }
        // One classifier, the generator's (eds2rust::profiles::is_cia402):
        // a CiA 418 battery's 0x6040/0x6041 arrays are no drive.
        let name = path.file_name().unwrap().to_string_lossy();
        if name == "stm32_cia418-reference.eds" {
            assert!(!table.cia402, "{name}");
        }
        if name == "cia402_sample.eds" || name.starts_with("elmo_gold") {
            assert!(table.cia402, "{name}");
        }
    }
    assert!(
        failures.is_empty(),
        "files that did not load:\n{}",
        failures.join("\n")
    );
}

#[test]
fn a_dcf_parameter_value_and_node_id_win_over_the_defaults() {
    let Some(files) = corpus() else {
        return;
    };
    let Some(dcf) = files
        .iter()
        .find(|p| p.ends_with("maxon_epos4-50-15_ec90flat_node1.dcf"))
    else {
        println!("skipped: the maxon DCF is not in the corpus");
        return;
    };
    let table = file::load(dcf).expect("loads");
    assert!(table.cia402);
    assert_eq!(table.device_type.map(|t| t & 0xFFFF), Some(402));
    assert_eq!(table.node.map(NodeId::get), Some(1));
}

#[test]
fn errors_name_the_file_and_the_line() {
    let dir = std::env::temp_dir().join(format!("eds2rust-sim-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    // An object without a DataType is an error of the EDS reader.
    let path = dir.join("broken.eds");
    std::fs::write(
        &path,
        "[FileInfo]\nFileName=broken.eds\n[MandatoryObjects]\nSupportedObjects=1\n1=0x1000\n\n[1000]\nParameterName=Device type\nObjectType=0x7\nAccessType=ro\nDefaultValue=0\n",
    )
    .expect("write");
    let error: LoadError = file::load(&path).expect_err("refused");
    let text = error.to_string();
    assert!(text.contains("broken.eds:"), "{text}");
    // `…/broken.eds:LINE: error: …`
    assert!(
        error.errors.iter().all(|e| e
            .split_once("broken.eds:")
            .is_some_and(|(_, rest)| rest.starts_with(|c: char| c.is_ascii_digit()))),
        "{error:?}"
    );
    let missing = file::load(dir.join("absent.eds")).expect_err("absent");
    assert!(missing.to_string().contains("absent.eds"), "{missing}");
    let _ = std::fs::remove_dir_all(&dir);
}
