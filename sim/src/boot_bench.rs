//! The network boot benchmark (feature `files`): a bus file generated for
//! N copies of one device (node ids 2, 3, ...; the master is node 1), its
//! CiA 302-2 boot plan (`eds2rust::network::boot_plan`), the composite
//! master booting it over [`TimedBus`] against N simulated [`Device`]s,
//! and the boot's time on the bus against the least time its frames need.
//!
//! The frames a boot needs: the NMT commands (reset, start), the boot-up
//! messages, the SDO requests and responses (identity, configuration) and,
//! where the plan waits for it, each slave's first heartbeat after its
//! configuration. Their least time is the sum of their lengths on the wire
//! ([`frame_bits`](eds2rust_runtime::transport::wire::frame_bits): exact
//! stuff bits, intermission included) at the bit rate. Other frames in the
//! boot (later heartbeats, PDOs of started slaves) are counted apart.
//! `cargo bench -p eds2rust-sim --bench boot_network` prints the figures.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Duration;

use eds2rust::network::{boot_plan, configure, read_bytes};
use eds2rust::read::Options;
use eds2rust_runtime::boot::{NetworkEvent, NetworkReport};
use eds2rust_runtime::master::{Master, MasterEvent};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::{CanId, Instant};

use crate::timed_bus::{HostTime, TimedBus, WireFrame};
use crate::{Device, DeviceConfig, file};

/// The master's node id; the slaves take the ids after it.
pub const MASTER_NODE: u8 = 1;

/// What to boot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scenario {
    /// Slaves, at most 126 (node ids 2..=127).
    pub slaves: usize,
    /// Bit rate in bit/s.
    pub bit_rate: u32,
    /// Each slave's heartbeat producer time in ms (0: none; the master
    /// then neither waits for nor supervises heartbeats).
    pub heartbeat_ms: u16,
    /// From power-on (every device sends its boot-up message) to the
    /// start of the boot ([`Scenario::SETTLE`]: the bus is quiet then).
    pub settle: Duration,
}

impl Scenario {
    /// A settle time after which every boot-up message is out.
    pub const SETTLE: Duration = Duration::from_millis(50);

    /// `slaves` at 1 Mbit/s with heartbeats of `heartbeat_ms`, booted
    /// once the bus is quiet.
    pub const fn new(slaves: usize, heartbeat_ms: u16) -> Scenario {
        Scenario {
            slaves,
            bit_rate: 1_000_000,
            heartbeat_ms,
            settle: Scenario::SETTLE,
        }
    }
}

/// How the boot went.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The scenario.
    pub scenario: Scenario,
    /// The master's report.
    pub report: NetworkReport,
    /// From `boot_network` to the end of the last frame the boot needed
    /// (or to the `Booted` event, if later).
    pub boot_time: Duration,
    /// The frames the boot needed, and their least time on the bus.
    pub needed_frames: usize,
    /// See [`Outcome::needed_frames`].
    pub needed_time: Duration,
    /// Other frames on the bus during the boot, and their time.
    pub other_frames: usize,
    /// See [`Outcome::other_frames`].
    pub other_time: Duration,
    /// The longest stretch during the boot with the bus idle, and when it
    /// began (after the boot started).
    pub longest_gap: (Duration, Duration),
    /// When the last SDO frame of the boot ended (after the boot started):
    /// what comes after is the wait for the last slaves' first heartbeats
    /// and the NMT starts.
    pub last_sdo: Duration,
    /// Host time in the master's and the devices' code.
    pub host: HostTime,
}

impl Outcome {
    /// Boot time over the least time of its frames.
    pub fn ratio(&self) -> f64 {
        self.boot_time.as_secs_f64() / self.needed_time.as_secs_f64().max(f64::MIN_POSITIVE)
    }

    /// The master's host time per slave.
    pub fn master_per_node(&self) -> Duration {
        per(self.host.master, self.scenario.slaves)
    }

    /// The simulated devices' host time per slave.
    pub fn devices_per_node(&self) -> Duration {
        per(self.host.devices, self.scenario.slaves)
    }

    /// The figures, one per line.
    pub fn summary(&self) -> String {
        let s = &self.scenario;
        let mut out = String::new();
        let hb = match s.heartbeat_ms {
            0 => "no heartbeat".to_string(),
            ms => format!("heartbeat {ms} ms"),
        };
        let _ = writeln!(
            out,
            "{} slaves at {} kbit/s, {hb}: booted {} ({} operational)",
            s.slaves,
            s.bit_rate / 1000,
            self.report.booted,
            self.report
                .slaves
                .iter()
                .filter(|x| x.state == eds2rust_runtime::boot::SlaveState::Operational)
                .count()
        );
        let _ = writeln!(
            out,
            "  boot time on the bus   {:>10.3} ms",
            ms(self.boot_time)
        );
        let _ = writeln!(
            out,
            "  least time (frames)    {:>10.3} ms  ({} frames the boot needs, exact stuffing)",
            ms(self.needed_time),
            self.needed_frames
        );
        let _ = writeln!(
            out,
            "  ratio                  {:>10.3}  (goal <= 1.2)",
            self.ratio()
        );
        if s.heartbeat_ms != 0 {
            // The plan waits for each slave's first heartbeat, which a
            // device may send one period after 0x1017 is written: the last
            // slave configured waits up to that long with nothing to send.
            let period = Duration::from_millis(u64::from(s.heartbeat_ms));
            let least = self.needed_time + period;
            let _ = writeln!(
                out,
                "  ratio to least + one heartbeat period {:.3}  ({:.3} ms)",
                self.boot_time.as_secs_f64() / least.as_secs_f64(),
                ms(least)
            );
        }
        let _ = writeln!(
            out,
            "  other frames           {:>10.3} ms  ({} frames: heartbeats, PDOs)",
            ms(self.other_time),
            self.other_frames
        );
        let _ = writeln!(
            out,
            "  longest idle gap       {:>10.3} ms  (at {:.3} ms)",
            ms(self.longest_gap.0),
            ms(self.longest_gap.1)
        );
        let _ = writeln!(
            out,
            "  last SDO frame ended   {:>10.3} ms  (then: first heartbeats, NMT start)",
            ms(self.last_sdo)
        );
        let _ = writeln!(
            out,
            "  host time per node     {:>10.3} µs master, {:.3} µs simulated device",
            self.master_per_node().as_secs_f64() * 1e6,
            self.devices_per_node().as_secs_f64() * 1e6
        );
        out
    }
}

fn per(total: Duration, n: usize) -> Duration {
    total / u32::try_from(n.max(1)).unwrap_or(u32::MAX)
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The bus file of `scenario`: `device` (a file name, beside the bus file)
/// as every slave, RPDO1 (0x6040, 0x607A) and TPDO1 (0x6041, 0x6064)
/// remapped, mandatory.
pub fn bus_file(device: &str, scenario: &Scenario) -> String {
    let mut yaml = format!(
        "master:\n  node_id: {MASTER_NODE}\n  baudrate: {}\n",
        scenario.bit_rate / 1000
    );
    for i in 0..scenario.slaves {
        let node = usize::from(MASTER_NODE) + 1 + i;
        let _ = write!(
            yaml,
            "n{node:03}:\n  dcf: \"{device}\"\n  node_id: {node}\n  mandatory: true\n  \
             heartbeat_producer: {hb}\n  \
             rpdo:\n    1:\n      cob_id: auto\n      transmission: 255\n      mapping:\n        \
             - {{index: 0x6040, sub_index: 0}}\n        - {{index: 0x607A, sub_index: 0}}\n  \
             tpdo:\n    1:\n      cob_id: auto\n      transmission: 255\n      event_timer: 0\n      \
             mapping:\n        - {{index: 0x6041, sub_index: 0}}\n        \
             - {{index: 0x6064, sub_index: 0}}\n",
            hb = scenario.heartbeat_ms
        );
    }
    yaml
}

/// Boots `scenario` with `device` (an EDS/DCF/YAML file with RPDO1, TPDO1
/// and the mapped objects) as every slave. Errors name what failed.
pub fn run(device: &Path, scenario: Scenario) -> Result<Outcome, String> {
    if scenario.slaves == 0 || scenario.slaves > 126 {
        return Err(format!(
            "{} slaves: 1 to 126 fit beside the master",
            scenario.slaves
        ));
    }
    let dir = device.parent().unwrap_or(Path::new(""));
    let name = device
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| format!("{}: no file name", device.display()))?;
    let text = bus_file(name, &scenario);
    let loaded = read_bytes("bench-bus.yml", text.as_bytes(), dir, &Options::default());
    if loaded.diagnostics.has_errors() {
        return Err(loaded.diagnostics.render());
    }
    let bus = loaded.bus.ok_or("the generated bus file was not read")?;
    let (configured, diagnostics) = configure(&bus);
    if diagnostics.has_errors() {
        return Err(diagnostics.render());
    }
    let plan = boot_plan(&bus, &configured);
    let master = Master::for_network(&plan).map_err(|e| e.to_string())?;
    let table = file::load(device).map_err(|e| e.to_string())?;
    let t0 = Instant::ZERO;
    let mut bus = TimedBus::new(scenario.bit_rate, master, t0);
    bus.master.start(t0);
    for slave in plan.slaves.iter() {
        let config = DeviceConfig::node(slave.plan.node);
        bus.add_device(Box::new(Device::new(table.objects, config, (), t0)));
    }
    bus.master_acted();
    // The devices' boot-up messages and the master's first frames go out
    // first; with the default settle time the boot starts on a quiet bus.
    bus.run_until(t0 + scenario.settle, |_| false);
    bus.master_events.clear();
    let start = bus.now();
    let from = bus.trace.len();
    let host_before = bus.host;
    bus.master.boot_network(start, plan.clone());
    bus.master_acted();
    let limit = start + Duration::from_secs(60);
    let booted = bus.run_until(limit, |e| {
        matches!(
            e,
            MasterEvent::Network(NetworkEvent::Booted { .. } | NetworkEvent::BootFailed { .. })
        )
    });
    if !booted {
        return Err("the boot was not decided within 60 s of bus time".to_string());
    }
    let booted_at = bus.now();
    // Let the last NMT start frames go out.
    bus.run_until(booted_at + Duration::from_millis(5), |_| false);
    let report = bus
        .master
        .network()
        .and_then(|n| n.report())
        .ok_or("no report after the boot")?;
    let host = HostTime {
        master: bus.host.master - host_before.master,
        devices: bus.host.devices - host_before.devices,
    };
    let frames = bus.trace.get(from..).unwrap_or_default();
    let needed = needed_frames(frames, scenario.heartbeat_ms != 0);
    let last_needed_end = frames
        .iter()
        .zip(&needed)
        .filter(|(_, n)| **n)
        .map(|(w, _)| w.end)
        .max()
        .unwrap_or(start);
    let end = last_needed_end.max(booted_at);
    let mut outcome = Outcome {
        scenario,
        report,
        boot_time: end - start,
        needed_frames: 0,
        needed_time: Duration::ZERO,
        other_frames: 0,
        other_time: Duration::ZERO,
        longest_gap: (Duration::ZERO, Duration::ZERO),
        last_sdo: Duration::ZERO,
        host,
    };
    let mut idle_from = start;
    for (w, need) in frames.iter().zip(&needed) {
        if w.start >= end {
            break;
        }
        let time = bus.bit_time(u64::from(w.bits));
        if *need {
            outcome.needed_frames += 1;
            outcome.needed_time += time;
        } else {
            outcome.other_frames += 1;
            outcome.other_time += time;
        }
        if let CanId::Standard(0x581..=0x67F) = w.frame.id() {
            outcome.last_sdo = w.end - start;
        }
        let gap = w.start - idle_from;
        if gap > outcome.longest_gap.0 {
            outcome.longest_gap = (gap, idle_from - start);
        }
        idle_from = w.end;
    }
    Ok(outcome)
}

/// Which of `frames` the boot needs (see the module documentation).
fn needed_frames(frames: &[WireFrame], heartbeat: bool) -> Vec<bool> {
    let mut first_heartbeat_seen = [false; 128];
    let mut configured = [false; 128];
    // A slave's configuration ends with its last SDO response.
    let mut last_sdo = [None; 128];
    for (i, w) in frames.iter().enumerate() {
        if let CanId::Standard(id) = w.frame.id()
            && (0x581..=0x5FF).contains(&id)
        {
            last_sdo[usize::from(id - 0x580)] = Some(i);
        }
    }
    frames
        .iter()
        .enumerate()
        .map(|(i, w)| {
            let CanId::Standard(id) = w.frame.id() else {
                return false;
            };
            let node = usize::from(id & 0x7F);
            match id & 0x780 {
                0x000 if id == 0 => true,
                0x580 | 0x600 => u8::try_from(node).ok().and_then(NodeId::new).is_some(),
                0x700 => {
                    let data = w.frame.data();
                    if data == [0] {
                        return true; // boot-up
                    }
                    if let Some(last) = last_sdo.get(node).copied().flatten()
                        && i > last
                        && !configured[node]
                    {
                        configured[node] = true;
                    }
                    if heartbeat && configured[node] && !first_heartbeat_seen[node] {
                        first_heartbeat_seen[node] = true;
                        return true;
                    }
                    false
                }
                _ => false,
            }
        })
        .collect()
}
