//! `eds2rust sim --network BUS` without a bus: usage errors (exit 2), a
//! bad --fault (named, with the kinds or the slaves), a bus file that does
//! not read (file, line and key; exit 1), and the interface opened only
//! once the network and its faults are good. src/sim/tests.rs runs the
//! network simulation on the virtual bus against a master.

mod common;

use common::{assert_usage_errors, run, temp_file};

fn bus() -> String {
    format!(
        "{}/../tests/networks/boot/matrix.yml",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn usage_errors_exit_2() {
    let bus = bus();
    let eds = common::example();
    assert_usage_errors(&[
        (vec!["sim", "--network", bus.as_str()], "--iface <IFACE>"),
        (
            vec!["sim", eds.as_str(), "--network", bus.as_str(), "-i", "can0"],
            "cannot be used with",
        ),
        (
            vec!["sim", "--network", bus.as_str(), "-i", "can0", "-n", "3"],
            "cannot be used with",
        ),
        (
            vec!["sim", eds.as_str(), "-i", "can0", "--fault", "2:missing"],
            "--network <BUS>",
        ),
    ]);
}

#[test]
fn a_bad_fault_is_named_with_what_is_allowed() {
    let bus = bus();
    for (fault, says) in [
        (
            "2",
            "--fault `2`: not NODE:KIND[=VALUE]; the kinds: missing, device-type=V",
        ),
        (
            "9:missing",
            "--fault `9:missing`: no slave has node id 9; the slaves of",
        ),
        (
            "nobody:missing",
            "`nobody` is neither a node id nor a slave's name",
        ),
        (
            "left:melting",
            "--fault `left:melting`: unknown kind `melting`; the kinds:",
        ),
        (
            "left:vendor-id",
            "`vendor-id` needs a value (`vendor-id=...`)",
        ),
        (
            "left:vendor-id=lots",
            "`lots` is not Vendor-ID (a 32-bit number",
        ),
        ("left:late-boot=soon", "`soon` is not a duration"),
        ("left:sdo-abort=0x6060", "`0x6060` is not INDEX:SUB[:CODE]"),
        ("left:missing=1", "`missing` takes no value"),
    ] {
        let (code, out, err) = run(&[
            "sim",
            "--network",
            &bus,
            "-i",
            "nosuchcan0",
            "--fault",
            fault,
        ]);
        assert_eq!(code, 2, "{fault}: {err}");
        assert!(out.is_empty(), "{fault}: {out}");
        assert!(err.contains(says), "{fault}: no {says:?} in {err}");
        // The slaves are listed by id and name where the node is wrong.
        if says.contains("slave") {
            assert!(err.contains("2 (left), 3 (right)"), "{err}");
        }
        assert!(!err.contains("nosuchcan0"), "the bus is not opened: {err}");
    }
}

#[test]
fn a_fault_that_does_not_fit_the_network_says_what_to_do() {
    // config-current needs the slave's configuration to carry 0x1020.
    let device = format!(
        "{}/../tests/networks/boot/drive.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let file = temp_file(
        "sim-network-no-date.yml",
        format!("master:\n  node_id: 1\n\nonly:\n  dcf: {device}\n  node_id: 4\n"),
    );
    let (code, _, err) = run(&[
        "sim",
        "--network",
        &file,
        "-i",
        "nosuchcan0",
        "--fault",
        "only:config-current",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("carries no date and time; add `sdo:` writes of 0x1020 sub 1"),
        "{err}"
    );
    assert!(!err.contains("nosuchcan0"), "{err}");
}

#[test]
fn a_bus_file_that_does_not_read_names_file_line_and_key() {
    let file = temp_file(
        "sim-network-bad.yml",
        "master:\n  node_id: 1\n\nleft:\n  dcf: no-such-device.eds\n  node_id: 2\n",
    );
    let (code, out, err) = run(&["sim", "--network", &file, "-i", "nosuchcan0"]);
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty(), "{out}");
    assert!(err.contains(&format!("{file}:5")), "{err}");
    assert!(err.contains("dcf"), "{err}");
    assert!(err.contains(&format!("{file}: not simulated:")), "{err}");
    assert!(!err.contains("nosuchcan0"), "{err}");
}

#[test]
fn a_good_network_opens_the_interface() {
    let (code, out, err) = run(&[
        "sim",
        "--network",
        &bus(),
        "-i",
        "nosuchcan0",
        "--fault",
        "right:missing",
        "--fault",
        "2:product-code=4",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty(), "{out}");
    assert!(
        err.starts_with("error: nosuchcan0: no such CAN interface"),
        "{err}"
    );
}
