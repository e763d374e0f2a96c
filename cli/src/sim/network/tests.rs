//! `eds2rust sim --network` on the in-process virtual bus: the runtime's
//! blocking master boots the simulated network (a fault on the optional
//! slave), and the event lines name each node.

use std::path::PathBuf;
use std::time::Duration;

use eds2rust_runtime::blocking::Master;
use eds2rust_runtime::boot::SlaveState;
use eds2rust_runtime::master;
use eds2rust_sim::network::Network;

use super::{faults, simulate};
use crate::sim::SimArgs;
use crate::sim::tests::Running;

fn args(faults: &[&str]) -> SimArgs {
    SimArgs {
        file: None,
        overlays: Vec::new(),
        network: Some(bus_file()),
        faults: faults.iter().map(|f| f.to_string()).collect(),
        iface: "virtual".into(),
        node: None,
        duration: None,
        time_scale: 1.0,
        quiet: false,
    }
}

fn bus_file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/networks/boot/matrix.yml")
}

#[test]
fn a_master_boots_the_simulated_network_and_the_lines_name_the_nodes() {
    let args = args(&["right:missing", "2:sdo-abort=0x2000:0"]);
    let network = Network::load(bus_file()).unwrap();
    let faults = faults(&args, &network).unwrap();
    let sim_network = network.clone();
    let running = Running::spawn(move |port, stop, out, err| {
        simulate(&args, &sim_network, &faults, port, stop, out, err)
    });
    let core = master::Master::for_network(network.plan()).unwrap();
    let mut m = Master::new(running.bus.attach(), core);
    m.start().unwrap();
    let report = m
        .boot_network(
            network.plan().clone(),
            std::time::Instant::now() + Duration::from_secs(10),
        )
        .unwrap();
    let (code, out, err) = running.stop();
    assert!(report.booted, "{report:#?}\n{out}\n{err}");
    let states: Vec<SlaveState> = report.slaves.iter().map(|s| s.state).collect();
    assert_eq!(states, [SlaveState::Operational, SlaveState::Failed]);
    assert_eq!(code, "ExitCode(unix_exit_status(0))", "{err}");
    for line in [
        "sim: ",
        "matrix.yml: 2 slaves on virtual; until Ctrl-C",
        "sim:   node 2 left: ",
        "drive.yaml (a CiA 402 drive); fault: refuses writes to 0x2000 sub 0",
        "sim:   node 3 right: ",
        "; fault: missing (never on the bus)",
    ] {
        assert!(err.contains(line), "no {line:?} in:\n{err}");
    }
    for line in [
        "node 2 left: power on",
        "node 2 left: NMT: boot-up -> pre-operational",
        "node 2 left: SDO write 0x6060 Modes of operation := ",
        "node 2 left: SDO write 0x1017 Producer heartbeat time := 50",
        "node 2 left: NMT: pre-operational -> operational",
    ] {
        assert!(out.contains(line), "no {line:?} in:\n{out}");
    }
    assert!(!out.contains("node 3"), "{out}");
}
