//! `net boot`'s boot and output on the in-process virtual bus.

use std::path::PathBuf;
use std::time::Duration;

use eds2rust::input::Options;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;

use super::*;
use crate::served::Served;

fn machine() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../eds/machine/bus.yml")
}

fn plan(path: &std::path::Path) -> NetworkPlan {
    let network = crate::net::load::read_configured(path, &Options::default(), "booted")
        .expect("the bus file reads");
    eds2rust::network::boot_plan(&network.bus, &network.configured)
}

/// The seed machine's plan (each slave's response time `response`, no
/// boot time) booted on an empty virtual bus for at most `timeout`.
fn boot_empty(response: Duration, timeout: Duration) -> (NetworkPlan, Outcome) {
    let mut plan = plan(&machine());
    plan.response_time = response;
    plan.boot_time = None;
    let bus = VirtualBus::new();
    let (_, outcome) = boot(bus.attach(), Clock::new(), &plan, timeout).expect("the boot runs");
    (plan, outcome)
}

/// Nobody on the bus: every slave fails with status B once the response
/// time is over; the network does not boot.
#[test]
fn an_empty_bus_fails_every_slave_with_status_b() {
    let (plan, outcome) = boot_empty(Duration::from_millis(50), Duration::from_secs(5));
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
    assert!(text.contains("boot error B"), "{text}");
}

/// The `--iface` path's boot on the real clock: the seed machine's own
/// simulation served in a thread on one port of a virtual bus (as `eds2rust
/// sim --network` serves it on an interface), the master on another.
#[test]
fn the_seed_machine_boots_on_the_real_clock_against_its_simulation_in_a_thread() {
    let network = crate::net::load::read_configured(&machine(), &Options::default(), "booted")
        .expect("the bus file reads");
    let plan = eds2rust::network::boot_plan(&network.bus, &network.configured);
    let simulated = eds2rust_sim::network::Network::from_bus(&network.bus, &network.configured);
    let bus = VirtualBus::new();
    let clock = Clock::new();
    let served = Served::booted_on(bus.attach(), clock.clone(), |now| {
        simulated.simulation(&[], now).expect("no faults")
    });
    let result = boot(bus.attach(), clock, &plan, default_timeout(&plan));
    served.finish().unwrap();
    let (_, outcome) = result.expect("the boot runs");
    let text = render_text("bus.yml", &plan, &outcome);
    assert!(outcome.running(&plan), "{text}");
    assert!(text.contains("3 of 3 slaves operational in"), "{text}");
    assert!(!text.contains("simulated time"), "{text}");
}

/// A boot not decided within the timeout: every slave still booting (its
/// time so far), the summary names them; not running.
#[test]
fn a_boot_not_decided_in_time_lists_the_slaves_still_booting() {
    let (plan, outcome) = boot_empty(Duration::from_secs(10), Duration::from_millis(30));
    assert_eq!(outcome.decided, None);
    assert!(!outcome.running(&plan));
    let text = render_text("bus.yml", &plan, &outcome);
    assert!(text.contains("| booting "), "{text}");
    assert!(text.contains("> 0.0"), "{text}");
    assert!(
        text.ends_with(
            "bus.yml: the boot was not decided within 0.030 s; not booted: conveyor (node 5) \
             booting, actuator (node 32) booting, axis (node 40) booting\n"
        ),
        "{text}"
    );
}
