//! The boot and supervision of a whole network, sans-IO: [`NetworkBoot`]
//! runs one [`SlaveBoot`] per slave of a [`NetworkPlan`], all at once,
//! decides when the network is up (CiA 302-2: every mandatory slave
//! booted, start all nodes or each, the master operational), and keeps it
//! running: a slave that sends a boot-up message, or answers again after
//! it was lost, is booted again (identity and configuration included)
//! while the others run on.
//!
//! It does no I/O and knows no master: it sees the error-control frames
//! ([`NetworkBoot::handle_frame`]), the ends of the SDO transfers it asked
//! for ([`NetworkBoot::sdo_event`]) and the supervision losses
//! ([`NetworkBoot::lost`]), and says what to do ([`Action`]).
//! [`crate::master::Master`] runs it on its own cores.

use alloc::collections::VecDeque;
use alloc::vec::Vec;

use super::{BootError, BootEvent, BootStatus, ConfigWrite, NetworkPlan, Request, SlaveBoot};
use super::{
    Configuration, NetworkEvent, NetworkReport, SlaveConfig, SlaveState, SlaveStatus, Supervision,
};
use crate::error_control::parse_error_control;
use crate::nmt::{NmtCommand, NmtState, NmtTarget};
use crate::od::NodeId;
use crate::sdo::client::ClientEvent;
use crate::time::earliest;
use crate::{Frame, Instant};

/// What the master is to do for the network.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Action {
    /// Send this NMT command.
    Nmt(NmtCommand, NmtTarget),
    /// Read by SDO; answer with [`NetworkBoot::sdo_event`].
    Read {
        node: NodeId,
        index: u16,
        sub_index: u8,
    },
    /// Write by SDO; answer with [`NetworkBoot::sdo_event`].
    Write { node: NodeId, write: ConfigWrite },
    /// Drop the SDO transfer in progress with `node` (it reset).
    CancelSdo(NodeId),
    /// Supervise `node` from now on (heartbeat consumer or guarding).
    Supervise(NodeId, Supervision),
    /// The master itself enters Operational.
    MasterOperational,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pending {
    Read(u16, u8),
    Write(u16, u8),
}

#[derive(Debug, Clone)]
struct Slave {
    config: SlaveConfig,
    boot: Option<SlaveBoot>,
    pending: Option<Pending>,
    wait_until: Option<Instant>,
    /// Its first boot is still running (the network's decision waits).
    first: bool,
    supervised: bool,
    status: SlaveStatus,
}

/// The boot and supervision of a network (see the module documentation).
#[derive(Debug, Clone)]
pub struct NetworkBoot {
    plan: NetworkPlan,
    slaves: Vec<Slave>,
    started: Option<Instant>,
    deadline: Option<Instant>,
    /// `Some(ok)` once the network's first boot is decided.
    decided: Option<bool>,
    actions: VecDeque<Action>,
    events: VecDeque<NetworkEvent>,
}

impl NetworkBoot {
    /// The boot of `plan`'s network; nothing happens before
    /// [`NetworkBoot::start`].
    pub fn new(plan: NetworkPlan) -> NetworkBoot {
        let slaves = plan
            .slaves
            .iter()
            .map(|config| Slave {
                status: SlaveStatus {
                    node: config.plan.node,
                    name: config.name.clone(),
                    mandatory: config.mandatory,
                    state: SlaveState::Waiting,
                    identity_checked: false,
                    configuration: None,
                    boot_started: None,
                    boot_ended: None,
                    error: None,
                    boots: 0,
                },
                config: config.clone(),
                boot: None,
                pending: None,
                wait_until: None,
                first: true,
                supervised: false,
            })
            .collect();
        NetworkBoot {
            plan,
            slaves,
            started: None,
            deadline: None,
            decided: None,
            actions: VecDeque::new(),
            events: VecDeque::new(),
        }
    }

    pub fn plan(&self) -> &NetworkPlan {
        &self.plan
    }

    /// Every slave's report, by node id order of the plan.
    pub fn slaves(&self) -> impl Iterator<Item = &SlaveStatus> {
        self.slaves.iter().map(|s| &s.status)
    }

    /// The report of `node`.
    pub fn slave(&self, node: NodeId) -> Option<&SlaveStatus> {
        self.slaves
            .iter()
            .find(|s| s.status.node == node)
            .map(|s| &s.status)
    }

    /// `Some(true)` once every mandatory slave is booted (the network
    /// runs), `Some(false)` once one failed; `None` while the first boot
    /// runs.
    pub fn outcome(&self) -> Option<bool> {
        self.decided
    }

    /// The outcome and every slave's report, once the first boot is
    /// decided.
    pub fn report(&self) -> Option<NetworkReport> {
        Some(NetworkReport {
            booted: self.decided?,
            slaves: self.slaves().cloned().collect(),
        })
    }

    /// Starts the boot of every slave at `now` (again, if it ran).
    pub fn start(&mut self, now: Instant) {
        self.started = Some(now);
        self.deadline = self.plan.boot_time.map(|t| now + t);
        self.decided = None;
        if self.plan.reset_all_nodes {
            self.actions
                .push_back(Action::Nmt(NmtCommand::ResetCommunication, NmtTarget::All));
        }
        for i in 0..self.slaves.len() {
            self.slaves[i].first = true;
            let reset = if self.plan.reset_all_nodes {
                None
            } else {
                self.slaves[i].config.plan.reset
            };
            self.boot_slave(now, i, reset, false);
        }
        self.decide(now);
    }

    /// An error-control frame (boot-up, heartbeat, guarding reply) from a
    /// slave moves its boot on, or starts it again.
    pub fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        if self.started.is_none() {
            return;
        }
        let Some((node, byte)) = parse_error_control(frame) else {
            return;
        };
        let Some(i) = self.index(node) else {
            return;
        };
        let Some(state) = NmtState::from_byte(byte & 0x7F) else {
            return;
        };
        let slave = &self.slaves[i];
        let booting = slave.status.state == SlaveState::Booting;
        let awaiting_boot_up = booting
            && slave.pending.is_none()
            && slave.boot.as_ref().is_some_and(SlaveBoot::awaits_boot_up);
        let awaiting_heartbeat =
            booting && slave.boot.as_ref().is_some_and(SlaveBoot::awaits_heartbeat);
        let without_reset = slave.config.plan.reset.is_none() && !self.plan.reset_all_nodes;
        let lost = slave.status.state == SlaveState::Lost;
        // A boot-up while the read of 0x1000 that follows a boot-up is in
        // flight: the boot it starts would send that read again (two
        // boot-ups in a row: one already on its way when the boot started,
        // then the one of the reset the master asked for). Replacing the
        // transfer would take the node's answer to the first read as the
        // answer to the second and fail on the next.
        let reading_device_type = booting && slave.pending == Some(Pending::Read(0x1000, 0));
        if state == NmtState::BootUp && reading_device_type {
            return;
        }
        if state == NmtState::BootUp {
            if !awaiting_boot_up {
                // It reset by itself: everything it was told is gone.
                if self.slaves[i].pending.take().is_some() {
                    self.actions.push_back(Action::CancelSdo(node));
                }
                if !booting || !self.slaves[i].first {
                    self.events.push_back(NetworkEvent::Rebooting(node));
                }
                self.boot_slave(now, i, None, true);
            }
            self.booted_up(now, i, state);
        } else if awaiting_boot_up && without_reset {
            // Waiting without a reset: a node already running answers with
            // its heartbeat.
            self.booted_up(now, i, state);
        } else if awaiting_heartbeat {
            self.slaves[i].wait_until = None;
            let steps = self.slaves[i].boot.as_mut().map(SlaveBoot::heartbeat);
            self.steps(now, i, steps.unwrap_or_default());
        } else if lost {
            self.events.push_back(NetworkEvent::Rebooting(node));
            let reset = self.slaves[i].config.plan.reset;
            self.boot_slave(now, i, reset, true);
        }
        self.drive(now);
    }

    /// The end of an SDO transfer with `node`; true when it was the boot's
    /// own (the master then does not report it).
    pub fn sdo_event(&mut self, now: Instant, node: NodeId, event: &ClientEvent) -> bool {
        let Some(i) = self.index(node) else {
            return false;
        };
        let slave = &mut self.slaves[i];
        let (index, sub) = match event {
            ClientEvent::Uploaded { index, sub, .. }
            | ClientEvent::Downloaded { index, sub }
            | ClientEvent::Failed { index, sub, .. } => (*index, *sub),
        };
        let Some(pending) = slave.pending else {
            return false;
        };
        let (Pending::Read(pi, ps) | Pending::Write(pi, ps)) = pending;
        if (pi, ps) != (index, sub) {
            return false;
        }
        slave.pending = None;
        let Some(boot) = slave.boot.as_mut() else {
            return true;
        };
        let result = match (pending, event) {
            (Pending::Read(..), ClientEvent::Uploaded { data, .. }) => boot.read_done(Ok(data)),
            (Pending::Read(..), ClientEvent::Failed { error, .. }) => {
                boot.read_done(Err(error.code()))
            }
            (Pending::Write(..), ClientEvent::Downloaded { .. }) => boot.write_done(Ok(())),
            (Pending::Write(..), ClientEvent::Failed { error, .. }) => {
                boot.write_done(Err(error.code()))
            }
            _ => return true,
        };
        match result {
            Ok(steps) => self.steps(now, i, steps),
            Err(error) => self.failed(now, i, error),
        }
        self.drive(now);
        true
    }

    /// Supervision lost `node` (`status` E for heartbeat, F for guarding).
    pub fn lost(&mut self, now: Instant, node: NodeId, status: BootStatus) {
        let Some(i) = self.index(node) else {
            return;
        };
        let slave = &mut self.slaves[i];
        if matches!(
            slave.status.state,
            SlaveState::Booted | SlaveState::Operational
        ) {
            slave.status.state = SlaveState::Lost;
            slave.status.boot_ended = Some(now);
            self.events.push_back(NetworkEvent::Lost { node, status });
        }
    }

    /// Runs the waits whose time is up.
    pub fn handle_timeout(&mut self, now: Instant) {
        for i in 0..self.slaves.len() {
            let slave = &mut self.slaves[i];
            if slave.wait_until.is_some_and(|at| at <= now) {
                slave.wait_until = None;
                if let Some(Err(error)) = slave.boot.as_mut().map(SlaveBoot::timed_out) {
                    self.failed(now, i, error);
                }
            }
        }
        self.drive(now);
    }

    /// The earliest wait that ends.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.slaves
            .iter()
            .fold(None, |at, s| earliest(at, s.wait_until))
    }

    pub fn poll_action(&mut self) -> Option<Action> {
        self.actions.pop_front()
    }

    pub fn poll_event(&mut self) -> Option<NetworkEvent> {
        self.events.pop_front()
    }

    fn index(&self, node: NodeId) -> Option<usize> {
        self.slaves.iter().position(|s| s.status.node == node)
    }

    /// Starts a boot of slave `i` (with `reset`, or waiting for its
    /// boot-up message); `again`: not the network's first boot of it.
    fn boot_slave(&mut self, now: Instant, i: usize, reset: Option<NmtCommand>, again: bool) {
        let start = self.plan.start_nodes && (!self.plan.start_all_nodes || self.decided.is_some());
        let start = start && self.decided != Some(false);
        let slave = &mut self.slaves[i];
        slave.status.state = SlaveState::Booting;
        slave.status.boots += 1;
        slave.status.boot_started = Some(now);
        slave.status.boot_ended = None;
        slave.status.error = None;
        slave.status.identity_checked = false;
        slave.status.configuration = None;
        slave.pending = None;
        slave.wait_until = None;
        if again {
            slave.first = slave.first && self.decided.is_none();
        }
        if !slave.config.boot {
            // Not managed: only started and supervised.
            slave.boot = None;
            slave.status.configuration = Some(Configuration::NotManaged);
            self.booted(now, i, start);
            return;
        }
        let mut plan = slave.config.plan.clone();
        plan.reset = reset;
        plan.start = start;
        slave.boot = Some(SlaveBoot::new(plan));
        self.drive(now);
    }

    fn booted_up(&mut self, now: Instant, i: usize, state: NmtState) {
        let slave = &mut self.slaves[i];
        slave.wait_until = None;
        let steps = slave
            .boot
            .as_mut()
            .map(|b| b.boot_up(state))
            .unwrap_or_default();
        self.steps(now, i, steps);
    }

    /// Hands out the requests of every running boot.
    fn drive(&mut self, now: Instant) {
        for i in 0..self.slaves.len() {
            while let Some(request) = self.slaves[i]
                .boot
                .as_mut()
                .and_then(SlaveBoot::poll_request)
            {
                let slave = &mut self.slaves[i];
                let node = slave.status.node;
                match request {
                    Request::Nmt(NmtCommand::Start) => {
                        self.actions
                            .push_back(Action::Nmt(NmtCommand::Start, NmtTarget::Node(node)));
                        slave.status.state = SlaveState::Operational;
                        self.events.push_back(NetworkEvent::Started(node));
                    }
                    Request::Nmt(cmd) => {
                        self.actions
                            .push_back(Action::Nmt(cmd, NmtTarget::Node(node)));
                    }
                    Request::AwaitBootUp => {
                        slave.wait_until =
                            Some(wait_end(&self.plan, self.deadline, slave.first, now));
                    }
                    Request::AwaitHeartbeat => {
                        let time = match slave.config.supervision {
                            Supervision::Heartbeat(time) => time,
                            _ => self.plan.response_time,
                        };
                        self.actions
                            .push_back(Action::Supervise(node, slave.config.supervision));
                        slave.supervised = true;
                        // As every wait of a first boot, it ends with the
                        // boot time (docs/network.md); else it lasts the
                        // consumer time or the response time.
                        slave.wait_until = Some(match self.deadline {
                            Some(deadline) if slave.first => deadline.max(now),
                            _ => now + time.max(self.plan.response_time),
                        });
                    }
                    Request::Read { index, sub_index } => {
                        slave.pending = Some(Pending::Read(index, sub_index));
                        self.actions.push_back(Action::Read {
                            node,
                            index,
                            sub_index,
                        });
                    }
                    Request::Write(write) => {
                        slave.pending = Some(Pending::Write(write.index, write.sub_index));
                        self.actions.push_back(Action::Write { node, write });
                    }
                }
            }
        }
    }

    fn steps(&mut self, now: Instant, i: usize, steps: Vec<BootEvent>) {
        let node = self.slaves[i].status.node;
        for step in steps {
            let status = &mut self.slaves[i].status;
            match step {
                BootEvent::IdentityChecked => status.identity_checked = true,
                BootEvent::ConfigurationCurrent => {
                    status.configuration = Some(Configuration::Current)
                }
                BootEvent::Configured { entries } => {
                    status.configuration = Some(Configuration::Written(entries))
                }
                _ => {}
            }
            let done = step == BootEvent::Booted;
            self.events.push_back(NetworkEvent::Step { node, step });
            if done {
                let start = self.slaves[i].boot.as_ref().is_some_and(|b| b.plan().start);
                self.booted(now, i, start);
            }
        }
        self.drive(now);
    }

    /// Slave `i` is booted; `start`: its boot starts it.
    fn booted(&mut self, now: Instant, i: usize, start: bool) {
        let slave = &mut self.slaves[i];
        slave.status.state = SlaveState::Booted;
        slave.status.boot_ended = Some(now);
        let node = slave.status.node;
        if !slave.supervised && slave.config.supervision != Supervision::None {
            slave.supervised = true;
            self.actions
                .push_back(Action::Supervise(node, slave.config.supervision));
        }
        if start && slave.boot.is_none() {
            self.actions
                .push_back(Action::Nmt(NmtCommand::Start, NmtTarget::Node(node)));
            slave.status.state = SlaveState::Operational;
            self.events.push_back(NetworkEvent::Started(node));
        }
        if slave.first {
            slave.first = false;
            self.decide(now);
        }
    }

    fn failed(&mut self, now: Instant, i: usize, error: BootError) {
        let slave = &mut self.slaves[i];
        slave.status.state = SlaveState::Failed;
        slave.status.boot_ended = Some(now);
        slave.status.error = Some(error.clone());
        slave.pending = None;
        slave.wait_until = None;
        self.events.push_back(NetworkEvent::Failed(error));
        if slave.first {
            slave.first = false;
            self.decide(now);
        }
    }

    /// Once every slave's first boot is over: start the network, or not.
    fn decide(&mut self, _now: Instant) {
        if self.decided.is_some() || self.slaves.iter().any(|s| s.first) {
            return;
        }
        let failed: Vec<&Slave> = self
            .slaves
            .iter()
            .filter(|s| s.status.state == SlaveState::Failed)
            .collect();
        let mandatory: Vec<BootError> = failed
            .iter()
            .filter(|s| s.config.mandatory)
            .filter_map(|s| s.status.error.clone())
            .collect();
        let optional: Vec<NodeId> = failed
            .iter()
            .filter(|s| !s.config.mandatory)
            .map(|s| s.status.node)
            .collect();
        if !mandatory.is_empty() {
            self.decided = Some(false);
            if self.plan.stop_all_nodes {
                self.actions
                    .push_back(Action::Nmt(NmtCommand::Stop, NmtTarget::All));
            }
            self.events
                .push_back(NetworkEvent::BootFailed { failed: mandatory });
            return;
        }
        self.decided = Some(true);
        if self.plan.start_nodes && self.plan.start_all_nodes {
            let waiting: Vec<usize> = (0..self.slaves.len())
                .filter(|&i| self.slaves[i].status.state == SlaveState::Booted)
                .collect();
            // One broadcast when no slave failed (a failed one must not be
            // started); else each booted slave on its own.
            if optional.is_empty() {
                self.actions
                    .push_back(Action::Nmt(NmtCommand::Start, NmtTarget::All));
            }
            for i in waiting {
                let node = self.slaves[i].status.node;
                if !optional.is_empty() {
                    self.actions
                        .push_back(Action::Nmt(NmtCommand::Start, NmtTarget::Node(node)));
                }
                self.slaves[i].status.state = SlaveState::Operational;
                self.events.push_back(NetworkEvent::Started(node));
            }
        }
        if self.plan.start_master {
            self.actions.push_back(Action::MasterOperational);
        }
        self.events
            .push_back(NetworkEvent::Booted { failed: optional });
    }
}

/// When a wait for a slave ends: at the boot time's end while the first
/// boot runs (if a boot time is given), else after the response time.
fn wait_end(plan: &NetworkPlan, deadline: Option<Instant>, first: bool, now: Instant) -> Instant {
    match deadline {
        Some(deadline) if first => deadline.max(now),
        _ => now + plan.response_time,
    }
}

#[cfg(test)]
mod tests;
