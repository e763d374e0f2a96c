//! `eds2rust net boot --iface` over the kernel's SocketCAN stack: the seed
//! machine (eds/machine/bus.yml) simulated by `eds2rust sim --network` on
//! its own vcan interface, booted by `eds2rust net boot`, and its PDOs
//! decoded by `eds2rust monitor --bus` while `net boot --run` keeps the
//! network running (SYNC, heartbeats).
//!
//! Ignored by default: `tests/vm/run.sh` runs it with `--ignored` in a VM
//! whose kernel has vcan. `CAN_IFACES` names the interfaces (this test
//! takes entry [`NET`]); `EDS2RUST_CLI` the binary (default: the one cargo
//! built). The bus file and the seed devices are written to a scratch
//! directory (the VM has no checkout).
#![cfg(target_os = "linux")]

mod common;
mod vcan;

use common::row;
use vcan::{Running, iface, ok, scratch};

/// The index of this test's interface in `CAN_IFACES`: monitor_vcan's
/// (the VM runs the test binaries one after another).
const NET: usize = 8;

const BUS: &str = include_str!("../../eds/machine/bus.yml");
const DEVICES: [(&str, &str); 3] = [
    ("zimmer_acs.yaml", include_str!("../../eds/zimmer_acs.yaml")),
    (
        "linak_techline.yaml",
        include_str!("../../eds/linak_techline.yaml"),
    ),
    (
        "interroll_ec5000bi.yaml",
        include_str!("../../eds/interroll_ec5000bi.yaml"),
    ),
];

/// The seed machine as in the repository: `DIR/machine/bus.yml` naming
/// `../zimmer_acs.yaml` and the others.
fn machine() -> String {
    let dir = scratch("net-boot-vcan", "eds");
    for (name, text) in DEVICES {
        std::fs::write(dir.join(name), text).unwrap();
    }
    std::fs::create_dir_all(dir.join("machine")).unwrap();
    let bus = dir.join("machine/bus.yml");
    std::fs::write(&bus, BUS).unwrap();
    bus.display().to_string()
}

#[test]
#[ignore = "needs vcan: tests/vm/run.sh"]
fn net_boot_boots_the_simulated_seed_machine_over_vcan() {
    let i = iface(NET);
    let bus = machine();
    let mut sim = Running::spawn(
        &["sim", "--network", &bus, "--iface", &i, "--duration", "60"],
        "sim: ",
    );
    sim.ready();

    // The boot: every slave identified, configured and started.
    let stdout = ok(&["net", "boot", &bus, "--iface", &i]);
    for (node, name) in [("5", "conveyor"), ("32", "actuator"), ("40", "axis")] {
        let cells = row(&stdout, node);
        assert_eq!(cells[1], name, "{stdout}");
        assert_eq!(cells[5], "operational", "{stdout}");
        assert!(cells[4].ends_with("written"), "{stdout}");
        assert_eq!(cells[7], "", "{stdout}");
    }
    assert!(stdout.contains("3 of 3 slaves operational in"), "{stdout}");

    // Booted again and kept running, the network's TPDOs come on SYNC and
    // the monitor names their fields as the bus file maps them.
    let mut running = Running::spawn(
        &[
            "net",
            "boot",
            &bus,
            "--iface",
            &i,
            "--run",
            "--duration",
            "20",
        ],
        "net boot: running",
    );
    running.ready();
    let monitor = ok(&[
        "monitor",
        "--iface",
        &i,
        "--bus",
        &bus,
        "--duration",
        "3",
        "--format",
        "json",
    ]);
    let records: Vec<serde_json::Value> = monitor
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    let tpdo2 = records
        .iter()
        .find(|r| r["node"] == 40 && r["pdo"] == "tpdo2")
        .unwrap_or_else(|| panic!("no TPDO2 of the axis in:\n{monitor}"));
    let names: Vec<&str> = tpdo2["fields"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f["name"].as_str())
        .collect();
    assert_eq!(names, ["Velocity actual value", "Torque actual value"]);
    running.interrupt();
    let ended = running.wait();
    assert_eq!(ended.code, Some(0), "{}{}", ended.stdout, ended.stderr);
    assert!(
        ended.stdout.contains("3 of 3 slaves operational after"),
        "{}",
        ended.stdout
    );
    sim.interrupt();
    let ended = sim.wait();
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
}
