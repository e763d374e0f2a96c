//! `eds2rust sim` without a bus: usage errors (exit 2), a file that does
//! not read (its diagnostics with file and line, exit 1), a file without a
//! node id, and an interface that cannot be opened (named, with why and
//! what to do; exit 1). This machine's kernel has no SocketCAN, so no
//! interface opens here; tests/sim_vcan.rs runs the simulator over vcan in
//! the VM of tests/vm.

mod common;

use common::{assert_usage_errors, example, run, seed, temp_file};

#[test]
fn usage_errors_exit_2() {
    let eds = example();
    assert_usage_errors(&[
        (vec!["sim"], "required arguments were not provided"),
        (vec!["sim", eds.as_str()], "--iface <IFACE>"),
        (
            vec!["sim", eds.as_str(), "-i", "can0", "--node", "0"],
            "0 is not in 1..=127",
        ),
        (
            vec!["sim", eds.as_str(), "-i", "can0", "--node", "128"],
            "128 is not in 1..=127",
        ),
        (
            vec![
                "sim",
                eds.as_str(),
                "-i",
                "can0",
                "-n",
                "5",
                "--duration",
                "soon",
            ],
            "`soon` is not a time in seconds",
        ),
        (
            vec!["sim", eds.as_str(), "-i", "can0", "--speed"],
            "--speed",
        ),
        (
            vec!["sim", eds.as_str(), "-i", "can0", "--time-scale", "0"],
            "`0` is not a positive factor",
        ),
    ]);
}

#[test]
fn help_lists_the_options() {
    let (code, out, _) = run(&["sim", "--help"]);
    assert_eq!(code, 0);
    for text in [
        "Usage: eds2rust sim [OPTIONS] --iface <IFACE> [FILE]",
        "--network <BUS>",
        "--fault <NODE:KIND[=VALUE]>",
        "-i, --iface <IFACE>",
        "-n, --node <N>",
        "--duration <SECONDS>",
        "--overlay <YAML>",
        "--time-scale <F>",
        "-q, --quiet",
        "docs/sim-cli.md",
    ] {
        assert!(out.contains(text), "no {text:?} in:\n{out}");
    }
    let (_, out, _) = run(&["--help"]);
    assert!(out.contains("sim "), "{out}");
}

#[test]
fn an_overlay_that_does_not_read_is_named_with_its_line() {
    let overlay = temp_file(
        "sim-bad-overlay.yaml",
        "format: 1\nmodify:\n  - { index: 0x1017, default: 50 }\n  - { index: 0x7777, name: Nowhere }\n",
    );
    let (code, out, err) = run(&[
        "sim",
        &example(),
        "--overlay",
        &overlay,
        "-i",
        "nosuchcan0",
        "-n",
        "3",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty(), "{out}");
    assert!(err.contains(&format!("{overlay}:4:")), "{err}");
    assert!(err.contains("0x7777"), "{err}");
    assert!(err.contains("not simulated: 1 errors"), "{err}");
    assert!(!err.contains("nosuchcan0"), "{err}");
}

#[test]
fn a_file_that_does_not_read_prints_its_diagnostics_and_exits_1() {
    let bad = temp_file(
        "sim-bad.eds",
        "[DeviceInfo]\nProductName=X\n\n[MandatoryObjects]\nSupportedObjects=1\n1=0x1000\n\n\
         [1000]\nParameterName=Device Type\nObjectType=0x07\nDataType=0xZZ\nAccessType=ro\n\
         DefaultValue=0\nPDOMapping=0\n",
    );
    // The file is read before the interface is opened.
    let (code, out, err) = run(&["sim", &bad, "-i", "nosuchcan0", "-n", "3"]);
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty(), "{out}");
    assert!(
        err.contains(&format!(
            "{bad}:11: error: [1000] DataType: `0xZZ` is not a data type code"
        )),
        "{err}"
    );
    assert!(
        err.contains(&format!("{bad}: not simulated: 1 errors")),
        "{err}"
    );
    assert!(!err.contains("nosuchcan0"), "{err}");

    let (code, _, err) = run(&["sim", "no/such/file.eds", "-i", "can0", "-n", "3"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.starts_with("no/such/file.eds: error: cannot read the file: "),
        "{err}"
    );
}

#[test]
fn a_file_without_a_node_id_asks_for_node() {
    let eds = example();
    let (code, out, err) = run(&["sim", &eds, "-i", "nosuchcan0"]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty(), "{out}");
    assert_eq!(
        err,
        format!(
            "error: {eds} gives no node id (no DCF [DeviceComissioning] NodeID, no YAML \
             network: node_id); pass --node N (1 to 127)\n"
        )
    );
}

#[test]
fn an_interface_that_does_not_exist_is_named_with_what_to_do() {
    // The YAML table gives the node id (network: node_id): no --node.
    let linak = seed("linak_techline");
    let (code, out, err) = run(&["sim", &linak, "--iface", "nosuchcan0"]);
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty(), "{out}");
    assert!(
        err.starts_with(
            "error: nosuchcan0: no such CAN interface; create one with \
             `ip link add dev nosuchcan0 type vcan && ip link set up nosuchcan0`"
        ),
        "{err}"
    );
    // Where the kernel has no SocketCAN (this machine may not), it says so.
    let kernel = "this kernel has no SocketCAN loaded: `modprobe can-raw vcan` first";
    assert_eq!(
        err.contains(kernel),
        !std::path::Path::new("/proc/net/can").exists(),
        "{err}"
    );
    assert!(
        err.contains("(cannot open CAN interface \"nosuchcan0\": "),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn an_interface_that_is_no_can_interface_says_so() {
    // `lo` exists on every Linux machine and is no CAN interface.
    if !std::path::Path::new("/sys/class/net/lo").exists() {
        eprintln!("NOT RUN: no /sys/class/net/lo here");
        return;
    }
    let (code, _, err) = run(&["sim", &seed("linak_techline"), "-i", "lo", "--quiet"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.starts_with("error: lo: not a CAN interface (link type 772)"),
        "{err}"
    );
}
