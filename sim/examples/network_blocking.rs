//! Boots the network of a bus file with the blocking master (CiA 302-2:
//! every slave reset, checked, configured and started at once), prints one
//! line per slave, then keeps the network running for a while and prints
//! what its slaves do (losses, re-boots, emergencies).
//!
//! ```text
//! cargo run -p eds2rust-sim --example network_blocking -- [BUS] [--iface NAME]
//! ```
//!
//! Without `--iface` the network's own simulation (every slave from its
//! device file) answers on an in-process virtual bus; with it, the real
//! slaves on that SocketCAN interface do. BUS defaults to the seed machine,
//! eds/machine/bus.yml.

use std::error::Error;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

use eds2rust::read::Options;
use eds2rust_runtime::blocking;
use eds2rust_runtime::boot::{NetworkPlan, NetworkReport};
use eds2rust_runtime::master::{Master, MasterEvent};
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_sim::network::Network;

type Res<T> = Result<T, Box<dyn Error>>;

/// The bus file read, configured and made into the plan the master boots
/// by; every problem names the file, line and key.
fn plan(path: &Path) -> Res<NetworkPlan> {
    let loaded = eds2rust::network::read_file(path, &Options::default());
    let bus = match loaded.bus {
        Some(bus) if !loaded.diagnostics.has_errors() => bus,
        _ => return Err(loaded.diagnostics.render().into()),
    };
    let (configured, diagnostics) = eds2rust::network::configure(&bus);
    if diagnostics.has_errors() {
        return Err(diagnostics.render().into());
    }
    Ok(eds2rust::network::boot_plan(&bus, &configured))
}

/// Boots the network on `bus` and runs it for `run`.
fn boot_and_run<B: Bus>(
    bus: B,
    clock: Clock,
    plan: NetworkPlan,
    run: Duration,
) -> Res<NetworkReport> {
    let core = Master::for_network(&plan)?;
    let mut master = blocking::Master::with_clock(bus, core, clock);
    master.start()?;
    let report = master.boot_network(plan, master.now() + Duration::from_secs(10))?;
    for slave in &report.slaves {
        let took = slave.boot_ended.zip(slave.boot_started).map(|(e, s)| e - s);
        println!(
            "node {:>3} {:<12} {:?}, identity checked: {}, configuration: {:?}, in {:?}",
            slave.node.get(),
            slave.name,
            slave.state,
            slave.identity_checked,
            slave.configuration,
            took.unwrap_or_default(),
        );
    }
    for error in report.errors() {
        println!("{error}");
    }
    let end = master.now() + run;
    while let Some(event) = master.wait_event(end)? {
        match event {
            MasterEvent::Network(event) => println!("network: {event:?}"),
            MasterEvent::Emcy(emcy) => println!("emergency: {emcy:?}"),
            _ => {}
        }
    }
    Ok(report)
}

/// The network's own simulation served on `bus` in a thread until `stop`.
fn simulate(
    path: &Path,
    bus: &VirtualBus,
    clock: &Clock,
    stop: &Arc<AtomicBool>,
) -> Res<JoinHandle<std::io::Result<()>>> {
    let mut simulation = Network::load(path)?.simulation(&[], clock.now())?;
    let mut port = bus.attach();
    let (clock, stop) = (clock.clone(), Arc::clone(stop));
    Ok(std::thread::spawn(move || {
        blocking::serve(&mut port, &clock, &mut simulation, &stop, None, |_| {})
    }))
}

fn run(path: &Path, iface: Option<&str>, run_for: Duration) -> Res<NetworkReport> {
    let plan = plan(path)?;
    let clock = Clock::new();
    if let Some(iface) = iface {
        let bus = eds2rust_runtime::transport::socketcan::SocketCanBus::open(iface)?;
        return boot_and_run(bus, clock, plan, run_for);
    }
    let bus = VirtualBus::new();
    let stop = Arc::new(AtomicBool::new(false));
    let simulation = simulate(path, &bus, &clock, &stop)?;
    let report = boot_and_run(bus.attach(), clock, plan, run_for);
    stop.store(true, Ordering::Relaxed);
    simulation
        .join()
        .map_err(|_| "the simulation thread panicked")??;
    report
}

fn main() -> Res<()> {
    let mut args = std::env::args().skip(1);
    let (mut path, mut iface) = (PathBuf::from("eds/machine/bus.yml"), None);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--iface" => iface = Some(args.next().ok_or("--iface needs an interface name")?),
            _ => path = PathBuf::from(arg),
        }
    }
    let report = run(&path, iface.as_deref(), Duration::from_secs(2))?;
    if !report.booted {
        return Err("a mandatory slave did not boot".into());
    }
    println!("{}: every mandatory slave booted", path.display());
    Ok(())
}

#[cfg(test)]
#[path = "network/checks.rs"]
mod checks;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn docs_network_md_shows_this_program() {
        checks::assert_docs_show("network_blocking.rs", include_str!("network_blocking.rs"));
    }

    #[test]
    fn the_seed_machine_boots_on_the_virtual_bus() {
        let report = run(&checks::seed_machine(), None, Duration::from_millis(300)).unwrap();
        checks::assert_booted(&report);
    }
}
