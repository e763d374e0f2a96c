//! A network on the composite master: its cores set up from a
//! [`NetworkPlan`] ([`Master::for_network`]) and the CiA 302-2 boot and
//! supervision ([`NetworkBoot`]) run on them ([`Master::boot_network`]).
//! The boot's SDO transfers, NMT commands and supervision go through the
//! master's own cores; its events come out as [`MasterEvent::Network`].

use alloc::collections::VecDeque;
use core::fmt;
use core::time::Duration;

use super::{Master, MasterEvent, PDO_RX_SLOTS};
use crate::Instant;
use crate::boot::{Action, BootStatus, NetworkBoot, NetworkPlan, Supervision};
use crate::guarding::GuardEvent;
use crate::heartbeat::HeartbeatEvent;
use crate::nmt::NmtState;
use crate::od::standard::{EventTimer, InhibitTime, PdoCobId, TransmissionType};
use crate::pdo::{TransmitterConfig, TransmitterConfigError, WatchError};
use crate::sdo::client::SdoClient;
use crate::sync::{SyncConfigError, SyncProducer};

/// Why a plan's master part could not be set up.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PlanError {
    /// The SYNC period or counter overflow is not valid.
    Sync(SyncConfigError),
    /// A received PDO cannot be watched (node, PDO number, why).
    Receive(u8, u16, WatchError),
    /// A sent PDO cannot be set up (node, PDO number, why).
    Transmit(u8, u16, TransmitterConfigError),
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanError::Sync(e) => write!(f, "the network's SYNC producer: {e}"),
            PlanError::Receive(node, n, e) => {
                write!(f, "node {node} TPDO {n}: the master cannot receive it: {e}")?;
                if *e == WatchError::Full {
                    write!(
                        f,
                        " (the master receives at most {PDO_RX_SLOTS} PDOs; disable \
                         the TPDOs it does not need in the bus file)"
                    )?;
                }
                Ok(())
            }
            PlanError::Transmit(node, n, e) => {
                write!(f, "node {node} RPDO {n}: the master cannot send it: {e}")
            }
        }
    }
}

impl core::error::Error for PlanError {}

/// The network's boot on the master, with the actions that had to wait
/// (an SDO client busy with a caller's transfer, a full NMT queue).
#[derive(Debug)]
pub(super) struct Running {
    pub(super) boot: NetworkBoot,
    retry: VecDeque<Action>,
}

impl Master {
    /// A master for `plan`'s network: its node id and heartbeat, the SYNC
    /// producer, the slaves' TPDOs watched (with their event timers as
    /// reception deadlines) and their valid RPDOs set up to be sent. The
    /// boot is started by [`Master::boot_network`].
    pub fn for_network(plan: &NetworkPlan) -> Result<Master, PlanError> {
        let m = &plan.master;
        let mut master = Master::new(m.node, m.heartbeat);
        if let Some(period) = m.sync_period {
            let overflow = (m.sync_overflow != 0).then_some(m.sync_overflow);
            master.sync = Some(SyncProducer::new(Some(period), overflow).map_err(PlanError::Sync)?);
        }
        for link in plan.receive.iter() {
            let cob_id = PdoCobId(link.cob_id);
            if !cob_id.is_valid() {
                continue;
            }
            let timeout =
                (link.event_timer != 0).then(|| Duration::from_millis(u64::from(link.event_timer)));
            master
                .pdo_rx
                .watch(cob_id, usize::from(link.len), timeout)
                .map_err(|e| PlanError::Receive(link.node.get(), link.number, e))?;
        }
        for link in plan.transmit.iter() {
            let cob_id = PdoCobId(link.cob_id);
            if !cob_id.is_valid() {
                continue;
            }
            let mut config =
                TransmitterConfig::new(cob_id, TransmissionType::from_raw(link.transmission));
            config.inhibit_time = InhibitTime(link.inhibit_time);
            config.event_timer = EventTimer(link.event_timer);
            master
                .add_pdo_tx(config)
                .map_err(|e| PlanError::Transmit(link.node.get(), link.number, e))?;
        }
        Ok(master)
    }

    /// Boots `plan`'s network from `now` (CiA 302-2, every slave at once)
    /// and supervises it from then on; a boot already running is replaced.
    /// Progress comes as [`MasterEvent::Network`] events; do not use the
    /// SDO client of a slave while it boots.
    pub fn boot_network(&mut self, now: Instant, plan: NetworkPlan) {
        self.now = now;
        let mut boot = NetworkBoot::new(plan);
        boot.start(now);
        self.network = Some(Running {
            boot,
            retry: VecDeque::new(),
        });
        self.run_network();
    }

    /// The network's boot and its slaves' reports, once
    /// [`Master::boot_network`] was called.
    pub fn network(&self) -> Option<&NetworkBoot> {
        self.network.as_ref().map(|r| &r.boot)
    }

    /// Carries out the boot's actions on the cores.
    pub(super) fn run_network(&mut self) {
        let Some(mut running) = self.network.take() else {
            return;
        };
        let mut waiting = core::mem::take(&mut running.retry);
        while let Some(action) = waiting.pop_front().or_else(|| running.boot.poll_action()) {
            if !self.carry_out(&action) {
                running.retry.push_back(action);
            }
        }
        self.network = Some(running);
    }

    /// Does `action`; false when it has to wait.
    fn carry_out(&mut self, action: &Action) -> bool {
        let now = self.now;
        match action {
            Action::Nmt(cmd, target) => self.nmt.send(*cmd, *target).is_ok(),
            Action::Read {
                node,
                index,
                sub_index,
            } => self
                .sdo_or_default(*node)
                .upload(now, *index, *sub_index)
                .is_ok(),
            Action::Write { node, write } => self
                .sdo_or_default(*node)
                .download(now, write.index, write.sub_index, &write.data)
                .is_ok(),
            Action::CancelSdo(node) => {
                // The node reset: its transfer is gone without an abort frame.
                if let Some(client) = self.sdo.remove(node) {
                    let config = client.config().clone();
                    self.sdo.insert(*node, SdoClient::new(config));
                }
                true
            }
            Action::Supervise(node, Supervision::Heartbeat(time)) => {
                self.consumer.monitor(*node, Some(*time));
                true
            }
            Action::Supervise(
                node,
                Supervision::Guarding {
                    guard_time,
                    life_time_factor,
                },
            ) => {
                self.guard.guard(now, *node, *guard_time, *life_time_factor);
                true
            }
            Action::Supervise(_, Supervision::None) => true,
            Action::MasterOperational => {
                self.heartbeat.set_state(NmtState::Operational);
                true
            }
        }
    }

    /// Shows a core's event to the boot: `None` when the boot took it as
    /// its own (an SDO transfer it started).
    pub(super) fn network_sees(&mut self, event: MasterEvent) -> Option<MasterEvent> {
        let now = self.now;
        let Some(running) = self.network.as_mut() else {
            return Some(event);
        };
        let event = match event {
            MasterEvent::Sdo(node, e) => {
                if running.boot.sdo_event(now, node, &e) {
                    None
                } else {
                    Some(MasterEvent::Sdo(node, e))
                }
            }
            MasterEvent::Heartbeat(HeartbeatEvent::Timeout { node }) => {
                running.boot.lost(now, node, BootStatus::HeartbeatLost);
                Some(event)
            }
            MasterEvent::Guard(GuardEvent::LifeTimeExpired { node }) => {
                running.boot.lost(now, node, BootStatus::GuardingLost);
                Some(event)
            }
            other => Some(other),
        };
        self.run_network();
        event
    }

    /// The boot's next event.
    pub(super) fn network_event(&mut self) -> Option<MasterEvent> {
        let event = self.network.as_mut()?.boot.poll_event()?;
        Some(MasterEvent::Network(event))
    }
}
