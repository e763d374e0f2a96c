//! Boots the network of a bus file with the tokio master (CiA 302-2: every
//! slave reset, checked, configured and started at once), prints one line
//! per slave, then watches the network's events for a while. The boot runs
//! in the same sans-IO core as the blocking master's
//! (`network_blocking.rs`); only the driver differs.
//!
//! ```text
//! cargo run -p eds2rust-sim --example network_tokio -- [BUS] [--iface NAME]
//! ```
//!
//! Without `--iface` the network's own simulation answers on an in-process
//! virtual bus (served by a thread); with it, the real slaves on that
//! SocketCAN interface do. BUS defaults to the seed machine,
//! eds/machine/bus.yml.

use std::error::Error;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use eds2rust::read::Options;
use eds2rust_runtime::boot::{NetworkPlan, NetworkReport};
use eds2rust_runtime::master::{Master, MasterEvent};
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_runtime::transport::{AsyncBus, Clock};
use eds2rust_runtime::{blocking, tokio as canopen};
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

/// Boots the network on `bus` and watches it for `run`.
async fn boot_and_run<B>(
    bus: B,
    clock: Clock,
    plan: NetworkPlan,
    run: Duration,
) -> Res<NetworkReport>
where
    B: AsyncBus + Send + 'static,
{
    let core = Master::for_network(&plan)?;
    let (master, driver) = canopen::Master::with_clock(bus, core, clock);
    let driver = tokio::spawn(driver.run());
    let mut events = master.events();
    master.start().await?;
    let report = master.boot_network(plan).await?;
    for slave in &report.slaves {
        println!(
            "node {:>3} {:<12} {:?}, identity checked: {}, configuration: {:?}",
            slave.node.get(),
            slave.name,
            slave.state,
            slave.identity_checked,
            slave.configuration,
        );
    }
    for error in report.errors() {
        println!("{error}");
    }
    let watch = async {
        while let Some(event) = events.next().await {
            match event {
                MasterEvent::Network(event) => println!("network: {event:?}"),
                MasterEvent::Emcy(emcy) => println!("emergency: {emcy:?}"),
                _ => {}
            }
        }
    };
    let _ = tokio::time::timeout(run, watch).await;
    drop(master);
    driver.await??;
    Ok(report)
}

async fn run(path: &Path, iface: Option<&str>, run_for: Duration) -> Res<NetworkReport> {
    let plan = plan(path)?;
    let clock = Clock::new();
    if let Some(iface) = iface {
        let bus = eds2rust_runtime::transport::socketcan::AsyncSocketCanBus::open(iface)?;
        return boot_and_run(bus, clock, plan, run_for).await;
    }
    let bus = VirtualBus::new();
    let mut simulation = Network::load(path)?.simulation(&[], clock.now())?;
    let mut port = bus.attach();
    let stop = Arc::new(AtomicBool::new(false));
    let (sim_clock, sim_stop) = (clock.clone(), Arc::clone(&stop));
    let server = std::thread::spawn(move || {
        blocking::serve(
            &mut port,
            &sim_clock,
            &mut simulation,
            &sim_stop,
            None,
            |_| {},
        )
    });
    let report = boot_and_run(bus.attach(), clock, plan, run_for).await;
    stop.store(true, Ordering::Relaxed);
    server
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
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()?;
    let report = runtime.block_on(run(&path, iface.as_deref(), Duration::from_secs(2)))?;
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
        checks::assert_docs_show("network_tokio.rs", include_str!("network_tokio.rs"));
    }

    #[test]
    fn the_seed_machine_boots_on_the_virtual_bus() {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .enable_all()
            .build()
            .unwrap();
        let report = runtime
            .block_on(run(
                &checks::seed_machine(),
                None,
                Duration::from_millis(300),
            ))
            .unwrap();
        checks::assert_booted(&report);
    }
}
