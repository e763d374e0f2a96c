//! Both masters boot one simulated slave on a quiet virtual bus (no SYNC,
//! no heartbeat): each step of the boot goes out at once, not when the
//! next frame or timer wakes the driver (the SDO timeout would come first
//! and fail the boot with status D).

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use eds2rust::network::{boot_plan, configure, read_bytes};
use eds2rust::read::Options;
use eds2rust_runtime::blocking;
use eds2rust_runtime::boot::{NetworkPlan, NetworkReport, SlaveState};
use eds2rust_runtime::master;
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_sim::boot_bench::{Scenario, bus_file};
use eds2rust_sim::{Device, DeviceConfig, file};

/// One slave of `eds/example.eds` served on `bus` in a thread (its
/// power-on boot-up message already out), and the network's plan.
struct Network {
    plan: NetworkPlan,
    stop: Arc<AtomicBool>,
    device: JoinHandle<std::io::Result<()>>,
}

fn network(bus: &VirtualBus) -> Network {
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
    std::thread::sleep(Duration::from_millis(100));
    Network { plan, stop, device }
}

impl Network {
    fn check(self, report: &NetworkReport, took: Duration) {
        self.stop.store(true, Ordering::Relaxed);
        let served = self.device.join().expect("the device thread");
        served.expect("the virtual bus");
        let errors: Vec<String> = report.errors().map(ToString::to_string).collect();
        // A request left unsent until the next frame or timer ends in the
        // SDO timeout (500 ms) here: the boot fails with status D.
        assert!(report.booted, "after {took:?}: {errors:?}");
        let state = report.slaves.first().map(|s| s.state);
        assert_eq!(state, Some(SlaveState::Operational));
    }
}

#[test]
fn the_blocking_master_boots_a_slave_on_a_quiet_bus() {
    let bus = VirtualBus::new();
    let network = network(&bus);
    let core = master::Master::for_network(&network.plan).expect("the plan's master");
    let mut m = blocking::Master::new(bus.attach(), core);
    m.start().expect("the virtual bus");
    let started = Instant::now();
    let report = m
        .boot_network(
            network.plan.clone(),
            Instant::now() + Duration::from_secs(10),
        )
        .expect("the boot is decided");
    network.check(&report, started.elapsed());
}

#[test]
fn the_tokio_master_boots_a_slave_on_a_quiet_bus() {
    let bus = VirtualBus::new();
    let network = network(&bus);
    let core = master::Master::for_network(&network.plan).expect("the plan's master");
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .expect("a tokio runtime");
    let plan = network.plan.clone();
    let (report, took) = runtime.block_on(async move {
        let (m, driver) = eds2rust_runtime::tokio::Master::new(bus.attach(), core);
        tokio::spawn(driver.run());
        m.start().await.expect("the virtual bus");
        let started = Instant::now();
        let report = tokio::time::timeout(Duration::from_secs(10), m.boot_network(plan))
            .await
            .expect("the boot is decided within 10 s")
            .expect("the driver runs");
        (report, started.elapsed())
    });
    network.check(&report, took);
}
