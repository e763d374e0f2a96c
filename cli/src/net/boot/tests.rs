//! `net boot`'s boot and output on the in-process virtual bus.

use std::path::PathBuf;
use std::time::Duration;

use eds2rust::input::Options;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;

use super::*;

fn machine() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../eds/machine/bus.yml")
}

fn plan(path: &std::path::Path) -> NetworkPlan {
    let network = crate::net::load::read_configured(path, &Options::default(), "booted")
        .expect("the bus file reads");
    eds2rust::network::boot_plan(&network.bus, &network.configured)
}

/// Nobody on the bus: every slave fails with status B once the response
/// time is over; the network does not boot.
#[test]
fn an_empty_bus_fails_every_slave_with_status_b() {
    let mut plan = plan(&machine());
    plan.response_time = Duration::from_millis(50);
    plan.boot_time = None;
    let bus = VirtualBus::new();
    let (_, outcome) =
        boot(bus.attach(), Clock::new(), &plan, Duration::from_secs(5)).expect("the boot runs");
    assert_eq!(
        outcome.decided,
        Some(!plan.slaves.iter().any(|s| s.mandatory))
    );
    assert!(
        outcome
            .slaves
            .iter()
            .all(|s| s.error.as_ref().is_some_and(|e| e.status.letter() == 'B'))
    );
    let text = render_text("bus.yml", &plan, &outcome);
    println!("{text}");
    assert!(text.contains("boot error B"), "{text}");
}
