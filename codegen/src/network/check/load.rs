//! The bus load estimate and `net::bus-load`.
//!
//! Counted: SYNC (the master's, every `sync_period`); each configured PDO
//! (a slave's TPDO sent by the slave, a slave's RPDO sent by the master)
//! by its transmission type: 0 (acyclic synchronous) at worst every SYNC,
//! 1..=240 every n-th SYNC, 254/255 (event-driven) every event timer;
//! heartbeats (every producer time); node guarding (a remote request and
//! its answer every guard time). Not counted: RTR-only PDOs (252/253, the
//! master does not request them), event-driven PDOs without an event
//! timer (their rate is the application's), EMCY, TIME, SDO and NMT
//! commands (sporadic). Each frame is counted with its worst-case bit
//! stuffing ([`frame_bits`]).

use std::fmt;

use super::context::{Net, Report};
use crate::network::config::{Configured, Pdo};
use crate::network::model::Bus;

/// The length in bits of a data frame with `data_bytes` bytes, with the
/// worst-case stuff bits: for an 11-bit identifier 47 + 8n bits of which
/// 34 + 8n are stuffed (one stuff bit per 4 after the first), for a 29-bit
/// identifier 67 + 8n of which 54 + 8n are stuffed. Interframe space
/// included.
pub fn frame_bits(data_bytes: u8, extended: bool) -> u32 {
    let n = 8 * u32::from(data_bytes.min(8));
    let (fixed, stuffed) = if extended { (67, 54) } else { (47, 34) };
    fixed + n + (stuffed + n - 1) / 4
}

/// One source of frames.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadItem {
    /// What sends (`SYNC`, `TPDO 1 of drive`, `heartbeat of drive`).
    pub what: String,
    pub frames_per_second: f64,
    /// Bits of one frame, stuffing included.
    pub bits_per_frame: u32,
}

impl LoadItem {
    pub fn bits_per_second(&self) -> f64 {
        self.frames_per_second * f64::from(self.bits_per_frame)
    }
}

/// The estimated load of a bus.
#[derive(Debug, Clone, PartialEq)]
pub struct BusLoad {
    /// The bit rate in bit/s (the master's `baudrate`).
    pub bit_rate: u32,
    /// Every counted source, in the bus's order.
    pub items: Vec<LoadItem>,
    /// Sources whose rate cannot be known here: what, and why.
    pub not_counted: Vec<(String, &'static str)>,
}

impl BusLoad {
    pub fn frames_per_second(&self) -> f64 {
        self.items.iter().map(|i| i.frames_per_second).sum()
    }

    pub fn bits_per_second(&self) -> f64 {
        self.items.iter().map(LoadItem::bits_per_second).sum()
    }

    /// The load in percent of the bit rate.
    pub fn percent(&self) -> f64 {
        if self.bit_rate == 0 {
            return 0.0;
        }
        100.0 * self.bits_per_second() / f64::from(self.bit_rate)
    }

    /// The sources by falling bit rate.
    pub fn heaviest(&self) -> Vec<&LoadItem> {
        let mut items: Vec<&LoadItem> = self.items.iter().collect();
        items.sort_by(|a, b| b.bits_per_second().total_cmp(&a.bits_per_second()));
        items
    }
}

impl fmt::Display for BusLoad {
    /// A summary line, one line per source, then what was not counted.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "bus load at {} kbit/s: {:.1} frames/s, {:.1} kbit/s, {:.1} %",
            self.bit_rate / 1000,
            self.frames_per_second(),
            self.bits_per_second() / 1000.0,
            self.percent()
        )?;
        for item in &self.items {
            writeln!(
                f,
                "  {:<56} {:>9.1} frames/s × {:>3} bits",
                item.what, item.frames_per_second, item.bits_per_frame
            )?;
        }
        let mut reasons: Vec<&str> = self.not_counted.iter().map(|(_, why)| *why).collect();
        reasons.dedup();
        for reason in reasons {
            let whats: Vec<&str> = self
                .not_counted
                .iter()
                .filter(|(_, why)| *why == reason)
                .map(|(what, _)| what.as_str())
                .collect();
            writeln!(f, "  not counted, {reason}: {}", whats.join(", "))?;
        }
        Ok(())
    }
}

/// Estimates the load of `bus` as `configured`.
pub fn bus_load(bus: &Bus, configured: &Configured) -> BusLoad {
    let master = &bus.master;
    let mut load = BusLoad {
        bit_rate: master.baudrate.saturating_mul(1000),
        items: Vec::new(),
        not_counted: Vec::new(),
    };
    let sync = (master.sync_period > 0).then(|| 1e6 / f64::from(master.sync_period));
    if let Some(rate) = sync {
        load.items.push(LoadItem {
            what: format!("SYNC (every {} µs)", master.sync_period),
            frames_per_second: rate,
            bits_per_frame: frame_bits(u8::from(master.sync_overflow > 0), false),
        });
    }
    if master.heartbeat_producer > 0 {
        load.items
            .push(heartbeat("the master", master.heartbeat_producer));
    }
    for node in &configured.nodes {
        for pdo in &node.tpdos {
            let what = format!("TPDO {} of {}", pdo.number, node.name);
            pdo_load(&mut load, what, pdo, sync);
        }
        for pdo in &node.rpdos {
            let what = format!("RPDO {} of {} (the master sends it)", pdo.number, node.name);
            pdo_load(&mut load, what, pdo, sync);
        }
        if node.heartbeat_producer > 0 {
            load.items
                .push(heartbeat(&node.name, node.heartbeat_producer));
        }
        if node.guard_time > 0 && node.life_time_factor > 0 {
            let rate = 1000.0 / f64::from(node.guard_time);
            load.items.push(LoadItem {
                what: format!("node guarding of {} (request)", node.name),
                frames_per_second: rate,
                bits_per_frame: frame_bits(0, false),
            });
            load.items.push(LoadItem {
                what: format!("node guarding of {} (answer)", node.name),
                frames_per_second: rate,
                bits_per_frame: frame_bits(1, false),
            });
        }
    }
    load
}

fn heartbeat(who: &str, producer_ms: u16) -> LoadItem {
    LoadItem {
        what: format!("heartbeat of {who} (every {producer_ms} ms)"),
        frames_per_second: 1000.0 / f64::from(producer_ms),
        bits_per_frame: frame_bits(1, false),
    }
}

fn pdo_load(load: &mut BusLoad, what: String, pdo: &Pdo, sync: Option<f64>) {
    let bits: u32 = pdo.mapping.iter().map(|m| u32::from(m.bits)).sum();
    let bytes = u8::try_from(bits.div_ceil(8)).unwrap_or(8);
    let extended = super::ids::can_id(pdo.cob_id).1;
    let t = pdo.transmission;
    let rate = match t {
        0..=240 => match sync {
            // Type 0 is sent on a SYNC after a change: at worst every SYNC.
            Some(rate) => rate / f64::from(t.max(1)),
            None => {
                load.not_counted
                    .push((what, "synchronous, but no SYNC is sent"));
                return;
            }
        },
        252 | 253 => {
            load.not_counted.push((what, "sent on remote request only"));
            return;
        }
        _ if pdo.event_timer > 0 => 1000.0 / f64::from(pdo.event_timer),
        _ => {
            load.not_counted.push((
                what,
                "event-driven without an event timer (sent when the application says)",
            ));
            return;
        }
    };
    let what = match t {
        0 => format!("{what} (acyclic synchronous, at worst every SYNC)"),
        1 => format!("{what} (every SYNC)"),
        2..=240 => format!("{what} (every {t}th SYNC)"),
        _ => format!("{what} (every {} ms)", pdo.event_timer),
    };
    load.items.push(LoadItem {
        what,
        frames_per_second: rate,
        bits_per_frame: frame_bits(bytes, extended),
    });
}

/// `net::bus-load`: the estimate above the limit.
pub(super) fn check(net: &Net, limits: &super::context::CheckLimits, report: &mut Report<'_>) {
    let load = bus_load(net.bus, net.configured);
    let percent = load.percent();
    if percent <= limits.max_bus_load_percent {
        return;
    }
    let spot = if net.bus.master.sync_period > 0 {
        net.master_spot("sync_period")
    } else {
        net.master_spot("baudrate")
    };
    let mut notes: Vec<String> = load
        .heaviest()
        .into_iter()
        .take(3)
        .map(|i| {
            format!(
                "{}: {:.1} % ({:.1} frames/s)",
                i.what,
                100.0 * i.bits_per_second() / f64::from(load.bit_rate.max(1)),
                i.frames_per_second
            )
        })
        .collect();
    notes.push(
        "lengthen `sync_period`, send PDOs every n-th SYNC (`transmission: n`), lengthen \
         event timers, or raise `baudrate`; the limit is `--max-bus-load`"
            .into(),
    );
    report.warning(
        "net::bus-load",
        &spot,
        format!(
            "the estimated bus load is {percent:.1} % of {} kbit/s ({:.1} frames/s), above \
             the limit of {} %{}",
            load.bit_rate / 1000,
            load.frames_per_second(),
            limits.max_bus_load_percent,
            if percent > 100.0 {
                ": more than the bus can carry, frames are late or lost"
            } else {
                ""
            }
        ),
        notes,
    );
}
