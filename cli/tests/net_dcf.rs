//! `eds2rust net dcf`: what it writes, and that it writes nothing on an
//! error (the comparison with dcfgen is tests/tests/network_dcfgen.rs).

mod common;

use common::{example, run, temp_file, tempdir};

fn bus(dir: &std::path::Path, slave: &str) -> String {
    let path = dir.join("bus.yml");
    let text = format!(
        "master:\n  node_id: 1\n  sync_period: 10000\n{slave}:\n  dcf: \"{}\"\n  node_id: 3\n  heartbeat_producer: 500\n",
        example()
    );
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn writes_master_dcf_and_the_concise_dcfs() {
    let dir = tempdir().join("net_dcf_good");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let bus = bus(&dir, "axis");
    let out = dir.join("out");
    let (code, _, stderr) = run(&["net", "dcf", "-r", &bus, "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("wrote axis.bin, master.dcf"), "{stderr}");
    let dcf = std::fs::read_to_string(out.join("master.dcf")).unwrap();
    assert!(
        dcf.contains("[1F81Value]\nNrOfEntries=1\n3=0x00000305\n"),
        "{dcf}"
    );
    assert!(
        dcf.contains("[1016Value]\nNrOfEntries=1\n1=0x000305DC\n"),
        "{dcf}"
    );
    let bin = std::fs::read(out.join("axis.bin")).unwrap();
    let writes = eds2rust::network::dcf::concise::decode(&bin).unwrap();
    assert!(
        writes
            .iter()
            .any(|w| w.index == 0x1017 && w.data == [0xF4, 0x01]),
        "{writes:?}"
    );
}

#[test]
fn writes_nothing_on_an_error() {
    let dir = tempdir().join("net_dcf_bad");
    let _ = std::fs::remove_dir_all(&dir);
    let path = temp_file(
        "net_dcf_bad/bus.yml",
        "master:\n  node_id: 1\naxis:\n  dcf: missing.eds\n  node_id: 3\n",
    );
    let out = dir.join("out");
    let (code, _, stderr) = run(&["net", "dcf", &path, "-o", out.to_str().unwrap()]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("not written: 1 errors"), "{stderr}");
    assert!(!out.exists());

    // A slave whose file would land outside the directory.
    let bus = bus(&dir, "\"cell/axis\"");
    let (code, _, stderr) = run(&["net", "dcf", &bus, "-o", out.to_str().unwrap()]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("not a plain file name"), "{stderr}");
    assert!(!out.exists());

    let (code, _, _) = run(&["net", "dcf", "--deny", "no::such-rule", &bus, "-o", "x"]);
    assert_eq!(code, 2);
}
