//! A composite CANopen master (feature `alloc`): the master-side cores in
//! one [`Service`], so that one driver loop runs them all on one bus.
//!
//! [`Master`] holds an [`NmtMaster`], the master's own
//! [`HeartbeatProducer`], a [`HeartbeatConsumer`], an optional
//! [`SyncProducer`], an [`EmcyConsumer`], a [`TimeConsumer`] and an
//! optional [`TimeProducer`] (the TIME service), an [`LssMaster`], a
//! [`PdoReceiver`] for the devices' TPDOs, any number of
//! [`PdoTransmitter`]s for their RPDOs, and one SDO client core per server
//! node. Every received frame goes to every core; each core's timer runs;
//! frames to send are taken from the cores in turn (one frame per core per
//! round, each core's frames in its own order), so a long SDO block
//! transfer cannot hold back a heartbeat or a SYNC. The master's own SYNC
//! frames are also fed to its PDO transmitters (a bus does not echo them),
//! so synchronous RPDOs follow each SYNC.
//!
//! With `std`, [`crate::blocking::Master`] runs it on a bus and offers
//! blocking SDO, NMT, PDO-configuration and LSS calls during which all the
//! other cores keep running.
//!
//! ```
//! use core::time::Duration;
//! use eds2rust_runtime::master::{Master, MasterEvent};
//! use eds2rust_runtime::od::NodeId;
//! use eds2rust_runtime::sdo::client::ClientConfig;
//! use eds2rust_runtime::sdo::Channel;
//! use eds2rust_runtime::sync::SyncProducer;
//! use eds2rust_runtime::{Instant, Service};
//!
//! let me = NodeId::new(1).unwrap();
//! let drive = NodeId::new(5).unwrap();
//! let mut master = Master::new(me, Some(Duration::from_millis(100)));
//! master.sync = Some(SyncProducer::new(Some(Duration::from_millis(10)), None).unwrap());
//! master.add_sdo_client(drive, ClientConfig::new(Channel::default_for(drive)));
//! master.start(Instant::ZERO);
//!
//! // The boot-up message of node 1 goes out first.
//! assert_eq!(master.poll_transmit().unwrap().to_string(), "701#00");
//! assert!(master.poll_transmit().is_none());
//! // The next deadline is the first SYNC.
//! assert_eq!(master.poll_timeout(), Some(Instant::from_millis(10)));
//!
//! // Start a read on the drive; its request goes out.
//! master.sdo(drive).unwrap().upload(Instant::ZERO, 0x1000, 0).unwrap();
//! assert_eq!(master.poll_transmit().unwrap().to_string(), "605#4000100000000000");
//! ```

use alloc::collections::BTreeMap;
use alloc::vec::Vec;
use core::time::Duration;

use crate::boot::NetworkEvent;
use crate::emcy::{EmcyConsumer, EmcyEvent};
use crate::guarding::{GuardEvent, NodeGuard};
use crate::heartbeat::{HeartbeatConsumer, HeartbeatEvent, HeartbeatProducer};
use crate::lss::{LssEvent, LssMaster};
use crate::nmt::{NmtEvent, NmtMaster};
use crate::od;
use crate::od::NodeId;
use crate::pdo::{
    PdoCobId, PdoError, PdoEvent, PdoReceiver, PdoTransmitter, TransmissionType, TransmitterConfig,
    TransmitterConfigError,
};
use crate::queue::Ring;
use crate::sdo::Channel;
use crate::sdo::client::{ClientConfig, ClientEvent, SdoClient};
use crate::sync::SyncProducer;
use crate::time::earliest;
use crate::time_stamp::{TimeConsumer, TimeEvent, TimeProducer};
use crate::{Frame, Instant, Service};

/// Number of TPDOs the master's [`PdoReceiver`] can watch: 512, as many
/// RPDOs as a CiA 302 manager's object dictionary has room for
/// (0x1400–0x15FF), so that every TPDO of a full network fits.
pub const PDO_RX_SLOTS: usize = 512;

/// Number of [`MasterEvent::Sync`] events kept (when enabled); when full the
/// oldest is dropped.
pub const SYNC_EVENTS: usize = 8;

/// Cores with a fixed place in the transmit rotation: NMT, heartbeat
/// producer, heartbeat consumer, SYNC, EMCY, LSS, PDO receiver, TIME
/// producer, node guarding.
const FIXED_CORES: usize = 9;

mod network;

pub use network::PlanError;

/// What one of the master's cores reported.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum MasterEvent {
    /// The NMT master saw a boot-up or a state change of a node.
    Nmt(NmtEvent),
    /// The heartbeat consumer saw a state, a timeout or a resumption.
    Heartbeat(HeartbeatEvent),
    /// The master's SYNC producer sent a SYNC (with its counter, if it has
    /// one). Only reported after [`Master::set_sync_events`]`(true)`.
    Sync(Option<u8>),
    /// The EMCY consumer received an emergency message.
    Emcy(EmcyEvent),
    /// The TIME consumer received a TIME frame (decoded, or malformed with
    /// the frame and the reason).
    Time(TimeEvent),
    /// The LSS request in progress ended.
    Lss(LssEvent),
    /// The PDO receiver got a TPDO, a length error or a timeout.
    Pdo(PdoEvent),
    /// The SDO transfer with this node ended.
    Sdo(NodeId, ClientEvent),
    /// Node guarding saw a state, a toggle error, a loss or a return.
    Guard(GuardEvent),
    /// The network's boot or supervision ([`Master::boot_network`]).
    Network(NetworkEvent),
}

/// The composite master: public cores plus one SDO client per server node.
///
/// Configure the cores through their fields (for example
/// `master.consumer.monitor(node, Some(time))`,
/// `master.pdo_rx.watch(..)`, `master.sync = Some(..)`), then call
/// [`Master::start`] and run it as any [`Service`].
#[derive(Debug)]
pub struct Master {
    /// Sends NMT commands and tracks the states nodes report.
    pub nmt: NmtMaster,
    /// The master's own heartbeat (node id and period given to
    /// [`Master::new`]); it reports Pre-operational until
    /// [`HeartbeatProducer::set_state`] says otherwise.
    pub heartbeat: HeartbeatProducer,
    /// Watches the heartbeats of the nodes given to
    /// [`HeartbeatConsumer::monitor`].
    pub consumer: HeartbeatConsumer,
    /// The SYNC producer, if the master produces SYNC.
    pub sync: Option<SyncProducer>,
    /// Receives the emergency messages of all nodes.
    pub emcy: EmcyConsumer,
    /// Decodes the TIME frames on 0x100 (reconfigure with
    /// [`TimeConsumer::with_id`]); `None` ignores TIME frames.
    pub time_rx: Option<TimeConsumer>,
    /// The TIME producer, if the master produces TIME (started by
    /// [`Master::start`]; give it the wall-clock time with
    /// [`TimeProducer::set_time`]).
    pub time_tx: Option<TimeProducer>,
    /// Runs LSS requests (CiA 305).
    pub lss: LssMaster,
    /// Guards the nodes given to [`NodeGuard::guard`].
    pub guard: NodeGuard,
    /// Receives the devices' TPDOs.
    pub pdo_rx: PdoReceiver<PDO_RX_SLOTS>,
    /// The RPDOs the master sends.
    pub pdo_tx: Vec<PdoTransmitter>,
    sdo: BTreeMap<NodeId, SdoClient>,
    /// Where the transmit rotation continues.
    next_core: usize,
    /// The time of the last input.
    now: Instant,
    sync_events: bool,
    sync_sent: Ring<Option<u8>, SYNC_EVENTS>,
    network: Option<network::Running>,
}

impl Master {
    /// A master with node id `node` and heartbeat producer time
    /// `heartbeat_period` (`None`: no heartbeats, only the boot-up message).
    /// No SYNC, no SDO clients, no PDOs; nothing runs before
    /// [`Master::start`].
    pub fn new(node: NodeId, heartbeat_period: Option<Duration>) -> Master {
        Master {
            nmt: NmtMaster::new(),
            heartbeat: HeartbeatProducer::new(node, heartbeat_period),
            consumer: HeartbeatConsumer::new(),
            sync: None,
            emcy: EmcyConsumer::new(),
            time_rx: Some(TimeConsumer::new()),
            time_tx: None,
            lss: LssMaster::new(),
            guard: NodeGuard::new(),
            pdo_rx: PdoReceiver::new(),
            pdo_tx: Vec::new(),
            sdo: BTreeMap::new(),
            next_core: 0,
            now: Instant::ZERO,
            sync_events: false,
            sync_sent: Ring::new(),
            network: None,
        }
    }

    /// The master's node id.
    pub const fn node(&self) -> NodeId {
        self.heartbeat.node()
    }

    /// Starts the heartbeat producer (boot-up message now, heartbeats every
    /// period), the SYNC producer and the TIME producer, if any.
    pub fn start(&mut self, now: Instant) {
        self.now = now;
        self.heartbeat.start(now);
        if let Some(sync) = &mut self.sync {
            sync.start(now);
        }
        if let Some(time) = &mut self.time_tx {
            time.start(now);
        }
    }

    /// Whether [`MasterEvent::Sync`] is reported for every SYNC sent (off by
    /// default: at short periods these events crowd out the others).
    pub fn set_sync_events(&mut self, on: bool) {
        self.sync_events = on;
        if !on {
            while self.sync_sent.pop().is_some() {}
        }
    }

    /// Adds an SDO client for `node` with `config` (replacing any client
    /// the node had, with its transfer) and returns it.
    pub fn add_sdo_client(&mut self, node: NodeId, config: ClientConfig) -> &mut SdoClient {
        self.sdo.remove(&node);
        self.sdo
            .entry(node)
            .or_insert_with(|| SdoClient::new(config))
    }

    /// The SDO client of `node`, if one was added.
    pub fn sdo(&mut self, node: NodeId) -> Option<&mut SdoClient> {
        self.sdo.get_mut(&node)
    }

    /// The SDO client of `node`; one on the node's default channel (0x600 +
    /// node, 0x580 + node) with default settings is added if it had none.
    pub fn sdo_or_default(&mut self, node: NodeId) -> &mut SdoClient {
        self.sdo
            .entry(node)
            .or_insert_with(|| SdoClient::new(ClientConfig::new(Channel::default_for(node))))
    }

    /// Removes the SDO client of `node` (a transfer in progress is dropped
    /// without an abort frame).
    pub fn remove_sdo_client(&mut self, node: NodeId) -> Option<SdoClient> {
        self.sdo.remove(&node)
    }

    /// The nodes that have an SDO client, in ascending order.
    pub fn sdo_nodes(&self) -> impl Iterator<Item = NodeId> + '_ {
        self.sdo.keys().copied()
    }

    /// Adds an RPDO transmitter with `config`; returns its position in
    /// [`Master::pdo_tx`].
    pub fn add_pdo_tx(
        &mut self,
        config: TransmitterConfig,
    ) -> Result<usize, TransmitterConfigError> {
        self.pdo_tx.push(PdoTransmitter::new(config)?);
        Ok(self.pdo_tx.len() - 1)
    }

    /// Sets the data of the RPDO the master sends on `cob_id`'s identifier
    /// from `pdo` at `now` ([`PdoTransmitter::set`]): an event-driven PDO
    /// goes out at once (or when its inhibit time ends), a synchronous one
    /// at its SYNC. When no transmitter sends on that identifier, an
    /// event-driven one (transmission type 255) is added for it.
    pub fn set_pdo<P: od::Pdo>(
        &mut self,
        now: Instant,
        cob_id: PdoCobId,
        pdo: &P,
    ) -> Result<(), PdoError> {
        let can_id = cob_id
            .checked_can_id()
            .map_err(TransmitterConfigError::from)?;
        let i = match self.pdo_tx.iter().position(|tx| tx.can_id() == can_id) {
            Some(i) => i,
            None => self.add_pdo_tx(TransmitterConfig::new(
                cob_id,
                TransmissionType::EventDrivenProfile,
            ))?,
        };
        match self.pdo_tx.get_mut(i) {
            Some(tx) => Ok(tx.set(now, pdo)?),
            None => Ok(()),
        }
    }

    /// Watches the PDO `P` on `cob_id` with its length [`od::Pdo::LEN`]
    /// and no reception timeout, unless that identifier is watched already
    /// (its settings stay); returns the identifier.
    pub fn watch_pdo<P: od::Pdo>(&mut self, cob_id: PdoCobId) -> Result<crate::CanId, PdoError> {
        let can_id = cob_id
            .checked_can_id()
            .map_err(crate::pdo::WatchError::from)?;
        if !self.pdo_rx.is_watched(can_id) {
            self.pdo_rx.watch(cob_id, P::LEN, None)?;
        }
        Ok(can_id)
    }

    /// Events of SYNC sends dropped because they were not polled in time.
    pub fn dropped_sync_events(&self) -> u32 {
        self.sync_sent.dropped()
    }

    /// Number of cores in the transmit rotation.
    fn core_count(&self) -> usize {
        FIXED_CORES + self.pdo_tx.len() + self.sdo.len()
    }

    /// The next frame of core `i` of the rotation.
    fn transmit_from(&mut self, i: usize) -> Option<Frame> {
        match i {
            0 => self.nmt.poll_transmit(),
            1 => self.heartbeat.poll_transmit(),
            2 => self.consumer.poll_transmit(),
            3 => {
                let frame = self.sync.as_mut()?.poll_transmit()?;
                self.sync_sent_frame(&frame);
                Some(frame)
            }
            4 => self.emcy.poll_transmit(),
            5 => self.lss.poll_transmit(),
            6 => self.pdo_rx.poll_transmit(),
            7 => self.time_tx.as_mut()?.poll_transmit(),
            8 => self.guard.poll_transmit(),
            i => {
                let i = i - FIXED_CORES;
                match self.pdo_tx.get_mut(i) {
                    Some(tx) => tx.poll_transmit(),
                    None => self
                        .sdo
                        .values_mut()
                        .nth(i - self.pdo_tx.len())
                        .and_then(Service::poll_transmit),
                }
            }
        }
    }

    /// The master's own SYNC goes out: the PDO transmitters see it as if
    /// received, and it is reported when asked for.
    fn sync_sent_frame(&mut self, frame: &Frame) {
        for tx in &mut self.pdo_tx {
            tx.handle_frame(self.now, frame);
        }
        if self.sync_events {
            let counter = frame.data().first().copied();
            self.sync_sent.push(counter);
        }
    }
}

/// Calls `handle_timeout` on `core` when its deadline is at or before `now`.
fn timeout_if_due<S: Service + ?Sized>(core: &mut S, now: Instant) {
    if core.poll_timeout().is_some_and(|due| due <= now) {
        core.handle_timeout(now);
    }
}

impl Service for Master {
    type Event = MasterEvent;

    /// Feeds `frame` to every core (each ignores frames not its own).
    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        self.now = now;
        self.nmt.handle_frame(now, frame);
        self.consumer.handle_frame(now, frame);
        self.emcy.handle_frame(now, frame);
        if let Some(time) = &mut self.time_rx {
            time.handle_frame(now, frame);
        }
        self.lss.handle_frame(now, frame);
        self.pdo_rx.handle_frame(now, frame);
        for tx in &mut self.pdo_tx {
            tx.handle_frame(now, frame);
        }
        for client in self.sdo.values_mut() {
            client.handle_frame(now, frame);
        }
        self.guard.handle_frame(now, frame);
        if let Some(running) = &mut self.network {
            running.boot.handle_frame(now, frame);
            self.run_network();
        }
    }

    /// Runs the timer of every core whose deadline passed.
    fn handle_timeout(&mut self, now: Instant) {
        self.now = now;
        timeout_if_due(&mut self.nmt, now);
        timeout_if_due(&mut self.heartbeat, now);
        timeout_if_due(&mut self.consumer, now);
        if let Some(sync) = &mut self.sync {
            timeout_if_due(sync, now);
        }
        timeout_if_due(&mut self.emcy, now);
        timeout_if_due(&mut self.lss, now);
        timeout_if_due(&mut self.pdo_rx, now);
        if let Some(time) = &mut self.time_tx {
            timeout_if_due(time, now);
        }
        for tx in &mut self.pdo_tx {
            timeout_if_due(tx, now);
        }
        for client in self.sdo.values_mut() {
            timeout_if_due(client, now);
        }
        timeout_if_due(&mut self.guard, now);
        if let Some(running) = &mut self.network
            && running.boot.poll_timeout().is_some_and(|due| due <= now)
        {
            running.boot.handle_timeout(now);
            self.run_network();
        }
    }

    /// Takes one frame from the next core that has one, in rotation: NMT,
    /// heartbeat, SYNC, LSS, TIME, the PDO transmitters, then the SDO
    /// clients by node id.
    fn poll_transmit(&mut self) -> Option<Frame> {
        let count = self.core_count();
        for k in 0..count {
            let i = (self.next_core + k) % count;
            if let Some(frame) = self.transmit_from(i) {
                self.next_core = (i + 1) % count;
                return Some(frame);
            }
        }
        None
    }

    /// Events in a fixed order: the network's, then the cores': NMT,
    /// heartbeat consumer, SYNC, EMCY, TIME, LSS, PDO receiver, node
    /// guarding, SDO clients by node id. The network's boot sees each
    /// core's event first and keeps the ends of its own SDO transfers.
    fn poll_event(&mut self) -> Option<MasterEvent> {
        loop {
            if let Some(event) = self.network_event() {
                return Some(event);
            }
            let event = self.core_event()?;
            if let Some(event) = self.network_sees(event) {
                return Some(event);
            }
        }
    }

    /// The earliest deadline of all cores.
    fn poll_timeout(&self) -> Option<Instant> {
        let mut at = earliest(self.nmt.poll_timeout(), self.heartbeat.poll_timeout());
        at = earliest(at, self.consumer.poll_timeout());
        at = earliest(at, self.sync.as_ref().and_then(Service::poll_timeout));
        at = earliest(at, self.emcy.poll_timeout());
        at = earliest(at, self.lss.poll_timeout());
        at = earliest(at, self.pdo_rx.poll_timeout());
        at = earliest(at, self.time_tx.as_ref().and_then(Service::poll_timeout));
        at = earliest(at, self.guard.poll_timeout());
        at = earliest(
            at,
            self.network.as_ref().and_then(|r| r.boot.poll_timeout()),
        );
        for tx in &self.pdo_tx {
            at = earliest(at, tx.poll_timeout());
        }
        for client in self.sdo.values() {
            at = earliest(at, client.poll_timeout());
        }
        at
    }
}

impl Master {
    /// The next event of the cores, in their fixed order.
    fn core_event(&mut self) -> Option<MasterEvent> {
        if let Some(e) = self.nmt.poll_event() {
            return Some(MasterEvent::Nmt(e));
        }
        if let Some(e) = self.consumer.poll_event() {
            return Some(MasterEvent::Heartbeat(e));
        }
        if let Some(counter) = self.sync_sent.pop() {
            return Some(MasterEvent::Sync(counter));
        }
        if let Some(e) = self.emcy.poll_event() {
            return Some(MasterEvent::Emcy(e));
        }
        if let Some(e) = self.time_rx.as_mut().and_then(Service::poll_event) {
            return Some(MasterEvent::Time(e));
        }
        if let Some(e) = self.lss.poll_event() {
            return Some(MasterEvent::Lss(e));
        }
        if let Some(e) = self.pdo_rx.poll_event() {
            return Some(MasterEvent::Pdo(e));
        }
        if let Some(e) = self.guard.poll_event() {
            return Some(MasterEvent::Guard(e));
        }
        self.sdo
            .iter_mut()
            .find_map(|(node, client)| client.poll_event().map(|e| MasterEvent::Sdo(*node, e)))
    }
}

#[cfg(test)]
mod tests;
