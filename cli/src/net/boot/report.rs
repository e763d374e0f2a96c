//! What `eds2rust net boot` prints: one row per slave (comfy-table, ASCII
//! so that a pipe or a log file reads it), a summary line, or the same as
//! one JSON object.

use std::time::Duration;

use comfy_table::{CellAlignment, Table, presets};
use eds2rust_runtime::Instant;
use eds2rust_runtime::boot::{BootStatus, Configuration, NetworkPlan, SlaveState, SlaveStatus};
use serde_json::{Value, json};

/// The column titles.
pub const HEADER: [&str; 8] = [
    "node",
    "name",
    "mandatory",
    "identity",
    "configuration",
    "state",
    "time",
    "boot error",
];

/// One thing that happened while the network ran.
#[derive(Debug, Clone)]
pub(crate) struct Happening {
    /// Seconds since the master started.
    pub seconds: f64,
    pub node: u8,
    /// Its name in the bus file (empty for a node the network lacks).
    pub name: String,
    /// `lost`, `rebooting`, `booted`, `started`, `failed`, `emcy`.
    pub kind: &'static str,
    pub text: String,
}

impl Happening {
    /// `  1.234 s  axis (node 40): lost: E: no heartbeat came from the node`
    pub fn line(&self) -> String {
        let who = if self.name.is_empty() {
            format!("node {}", self.node)
        } else {
            format!("{} (node {})", self.name, self.node)
        };
        let text = format!("{:>9.3} s  {who}: {}", self.seconds, self.text);
        eds2rust::text::terminal_line(&text).into_owned()
    }
}

/// How a boot ended.
#[derive(Debug, Clone)]
pub(crate) struct Outcome {
    /// `Some(true)`: every mandatory slave booted; `Some(false)`: one
    /// failed; `None`: not decided within the timeout.
    pub decided: Option<bool>,
    /// Every slave's report, by node id.
    pub slaves: Vec<SlaveStatus>,
    /// When the master started, and when the boot was decided (or the
    /// timeout passed).
    pub started: Instant,
    pub ended: Instant,
    pub timeout: Duration,
    /// The bus was the network's simulation, in virtual time.
    pub simulated: bool,
    /// With `--run`: how long the network ran after its boot (`ended` is
    /// then the end of that, the slaves' states are those at the end).
    pub ran: Option<Duration>,
}

impl Outcome {
    /// Every mandatory slave is operational (booted, when the network does
    /// not start its slaves).
    pub fn running(&self, plan: &NetworkPlan) -> bool {
        self.decided == Some(true)
            && self
                .slaves
                .iter()
                .filter(|s| s.mandatory)
                .all(|s| up(plan, s))
    }
}

/// Whether `slave` is where the network leaves a booted slave.
fn up(plan: &NetworkPlan, slave: &SlaveStatus) -> bool {
    match slave.state {
        SlaveState::Operational => true,
        SlaveState::Booted => !plan.start_nodes,
        _ => false,
    }
}

/// The identity check: `ok`, `not checked` (the network expects no
/// identity), `wrong` (a status C, D, M, N or O), `-` (not reached).
fn identity(plan: &NetworkPlan, slave: &SlaveStatus) -> &'static str {
    let wrong = slave.error.as_ref().is_some_and(|e| {
        matches!(
            e.status,
            BootStatus::DeviceType
                | BootStatus::VendorId
                | BootStatus::ProductCode
                | BootStatus::RevisionNumber
                | BootStatus::SerialNumber
        )
    });
    if wrong {
        return "wrong";
    }
    if !slave.identity_checked {
        return "-";
    }
    let expected = plan.slave(slave.node).map(|c| &c.plan);
    let none = expected.is_none_or(|p| {
        [
            p.device_type,
            p.vendor_id,
            p.product_code,
            p.revision_number,
            p.serial_number,
        ]
        .iter()
        .all(|&v| v == 0)
    });
    if none { "not checked" } else { "ok" }
}

fn configuration(slave: &SlaveStatus) -> String {
    match slave.configuration {
        Some(Configuration::Current) => "current".into(),
        Some(Configuration::Written(1)) => "1 entry written".into(),
        Some(Configuration::Written(n)) => format!("{n} entries written"),
        Some(Configuration::NotManaged) => "not managed".into(),
        None if slave
            .error
            .as_ref()
            .is_some_and(|e| e.status == BootStatus::ConfigurationFailed) =>
        {
            "failed".into()
        }
        None => "-".into(),
    }
}

fn state(state: SlaveState) -> &'static str {
    match state {
        SlaveState::Waiting => "waiting",
        SlaveState::Booting => "booting",
        SlaveState::Booted => "booted",
        SlaveState::Operational => "operational",
        SlaveState::Failed => "failed",
        SlaveState::Lost => "lost",
    }
}

/// The time its last boot took; for a boot still running, the time so far.
fn taken(outcome: &Outcome, slave: &SlaveStatus) -> Option<(Duration, bool)> {
    let started = slave.boot_started?;
    Some(match slave.boot_ended {
        Some(ended) => (ended - started, true),
        None => (outcome.ended - started, false),
    })
}

fn taken_text(outcome: &Outcome, slave: &SlaveStatus) -> String {
    match taken(outcome, slave) {
        Some((time, true)) => format!("{:.3} s", time.as_secs_f64()),
        Some((time, false)) => format!("> {:.3} s", time.as_secs_f64()),
        None => "-".into(),
    }
}

fn label(slave: &SlaveStatus) -> String {
    format!("{} (node {})", slave.name, slave.node.get())
}

/// The one-line summary.
fn summary(bus: &str, plan: &NetworkPlan, outcome: &Outcome) -> String {
    let seconds = (outcome.ended - outcome.started).as_secs_f64();
    let failed: Vec<&SlaveStatus> = outcome.slaves.iter().filter(|s| !up(plan, s)).collect();
    let mandatory: Vec<&&SlaveStatus> = failed.iter().filter(|s| s.mandatory).collect();
    let list = |slaves: &[&&SlaveStatus]| -> String {
        let items: Vec<String> = slaves
            .iter()
            .map(|s| match &s.error {
                Some(e) => format!("{} {}", label(s), e.status.letter()),
                None => format!("{} {}", label(s), state(s.state)),
            })
            .collect();
        items.join(", ")
    };
    match outcome.decided {
        None => format!(
            "{bus}: the boot was not decided within {:.3} s; not booted: {}",
            outcome.timeout.as_secs_f64(),
            list(&failed.iter().collect::<Vec<_>>())
        ),
        Some(_) if mandatory.len() == 1 && mandatory[0].error.is_some() => {
            let s = mandatory[0];
            let error = s
                .error
                .as_ref()
                .map(ToString::to_string)
                .unwrap_or_default();
            format!("{bus}: the network did not boot: {}: {error}", s.name)
        }
        Some(_) if !mandatory.is_empty() => format!(
            "{bus}: the network did not boot: mandatory slaves not up: {}",
            list(&mandatory)
        ),
        // Booted again since, but the network's first boot failed: the
        // master started nothing.
        Some(false) => {
            format!("{bus}: the network did not boot: a mandatory slave failed its first boot")
        }
        Some(true) => {
            let up = outcome.slaves.len() - failed.len();
            let what = if plan.start_nodes {
                "operational"
            } else {
                "booted"
            };
            let when = match outcome.ran {
                Some(ran) => format!("after {:.3} s of running", ran.as_secs_f64()),
                None => format!("in {seconds:.3} s"),
            };
            let mut line = format!(
                "{bus}: {up} of {} slaves {what} {when}{}",
                outcome.slaves.len(),
                if outcome.simulated {
                    " (simulated time)"
                } else {
                    ""
                }
            );
            if !failed.is_empty() {
                let optional: Vec<&&SlaveStatus> = failed.iter().collect();
                line.push_str(&format!("; optional slaves not up: {}", list(&optional)));
            }
            line
        }
    }
}

/// The summary line alone.
pub(crate) fn render_summary(bus: &str, plan: &NetworkPlan, outcome: &Outcome) -> String {
    let text = format!("{}\n", summary(bus, plan, outcome));
    eds2rust::text::terminal(&text).into_owned()
}

/// The table and the summary line.
pub(crate) fn render_text(bus: &str, plan: &NetworkPlan, outcome: &Outcome) -> String {
    let mut table = Table::new();
    table.load_style(presets::ASCII_FULL_CONDENSED);
    table.set_header(HEADER);
    for slave in &outcome.slaves {
        table.add_row([
            slave.node.get().to_string(),
            slave.name.to_string(),
            if slave.mandatory { "yes" } else { "no" }.to_string(),
            identity(plan, slave).to_string(),
            configuration(slave),
            state(slave.state).to_string(),
            taken_text(outcome, slave),
            slave
                .error
                .as_ref()
                .map(ToString::to_string)
                .unwrap_or_default(),
        ]);
    }
    for column in [0, 6] {
        if let Some(c) = table.column_mut(column) {
            c.set_cell_alignment(CellAlignment::Right);
        }
    }
    // Names come from the bus file: terminal-safe.
    let text = format!("{table}\n{}\n", summary(bus, plan, outcome));
    eds2rust::text::terminal(&text).into_owned()
}

/// Seconds to the microsecond the times are kept in (no binary tails).
fn secs(seconds: f64) -> f64 {
    (seconds * 1e6).round() / 1e6
}

/// The outcome as one JSON object (and a newline), with what happened
/// while the network ran (`--run`).
pub(crate) fn render_json(
    bus: &str,
    plan: &NetworkPlan,
    outcome: &Outcome,
    happenings: &[Happening],
) -> String {
    let slaves: Vec<Value> = outcome
        .slaves
        .iter()
        .map(|s| {
            let (seconds, done) =
                taken(outcome, s).map_or((None, false), |(t, d)| (Some(secs(t.as_secs_f64())), d));
            json!({
                "node": s.node.get(),
                "name": s.name,
                "mandatory": s.mandatory,
                "identity": identity(plan, s),
                "configuration": configuration(s),
                "entries_written": match s.configuration {
                    Some(Configuration::Written(n)) => Some(n),
                    _ => None,
                },
                "state": state(s.state),
                "seconds": seconds,
                "boot_ended": done,
                "boots": s.boots,
                "error": s.error.as_ref().map(|e| json!({
                    "status": e.status.letter().to_string(),
                    "meaning": e.status.meaning(),
                    "object": e.object.map(|(i, sub)| format!("0x{i:04X} sub {sub}")),
                    "expected": e.expected,
                    "found": e.found,
                    "abort": e.abort.map(|a| a.to_string()),
                    "text": e.to_string(),
                })),
            })
        })
        .collect();
    let value = json!({
        "bus": bus,
        "running": outcome.running(plan),
        "decided": outcome.decided,
        "seconds": secs((outcome.ended - outcome.started).as_secs_f64()),
        "simulated": outcome.simulated,
        "summary": summary(bus, plan, outcome),
        "slaves": slaves,
    });
    let mut value = value;
    if let Some(ran) = outcome.ran {
        value["ran_seconds"] = json!(secs(ran.as_secs_f64()));
        value["events"] = happenings
            .iter()
            .map(|h| {
                json!({
                    "seconds": secs(h.seconds),
                    "node": h.node,
                    "name": h.name,
                    "event": h.kind,
                    "text": h.text,
                })
            })
            .collect();
    }
    let mut text = serde_json::to_string_pretty(&value).unwrap_or_default();
    text.push('\n');
    text
}
