//! `blocking::Master::boot_network` against one simulated slave on a quiet
//! virtual bus (no SYNC, no heartbeat): each step of the boot goes out at
//! once, not when the next frame or timer wakes the driver (the SDO
//! timeout would come first and fail the boot).

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use eds2rust::network::{boot_plan, configure, read_bytes};
use eds2rust::read::Options;
use eds2rust_runtime::blocking::{self, Master};
use eds2rust_runtime::boot::SlaveState;
use eds2rust_runtime::master;
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_sim::boot_bench::{Scenario, bus_file};
use eds2rust_sim::{Device, DeviceConfig, file};

#[test]
fn the_blocking_master_boots_a_slave_on_a_quiet_bus() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../eds");
    let text = bus_file("example.eds", &Scenario::new(1, 0));
    let loaded = read_bytes("one-slave.yml", text.as_bytes(), &dir, &Options::default());
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}",
        loaded.diagnostics.render()
    );
    let bus_model = loaded.bus.expect("a bus");
    let (configured, diagnostics) = configure(&bus_model);
    assert!(!diagnostics.has_errors(), "{}", diagnostics.render());
    let plan = boot_plan(&bus_model, &configured);
    let table = file::load(dir.join("example.eds")).unwrap_or_else(|e| panic!("{e}"));
    let node = plan.slaves.first().expect("one slave").plan.node;

    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let stop = Arc::new(AtomicBool::new(false));
    let device_stop = Arc::clone(&stop);
    let device = std::thread::spawn(move || {
        let clock = Clock::new();
        let mut device = Device::new(table.objects, DeviceConfig::node(node), (), clock.now());
        let deadline = Instant::now() + Duration::from_secs(30);
        blocking::serve(
            &mut port,
            &clock,
            &mut device,
            &device_stop,
            deadline,
            |_| {},
        )
    });
    // The device's power-on boot-up message is out before the boot starts.
    std::thread::sleep(Duration::from_millis(100));
    let core = master::Master::for_network(&plan).expect("the plan's master");
    let mut m = Master::new(bus.attach(), core);
    m.start().expect("the virtual bus");
    let started = Instant::now();
    let report = m
        .boot_network(plan.clone(), Instant::now() + Duration::from_secs(10))
        .expect("the boot is decided");
    let took = started.elapsed();
    stop.store(true, Ordering::Relaxed);
    device
        .join()
        .expect("the device thread")
        .expect("the virtual bus");
    let errors: Vec<String> = report.errors().map(ToString::to_string).collect();
    assert!(report.booted, "{errors:?}");
    assert_eq!(
        report.slaves.first().map(|s| s.state),
        Some(SlaveState::Operational)
    );
    // Some 20 SDO round trips on an idle in-process bus: far below one SDO
    // timeout (500 ms) in all.
    assert!(took < Duration::from_millis(400), "the boot took {took:?}");
}
