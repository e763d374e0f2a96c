//! The generic simulated device: everything CiA 301 asks of a slave, driven
//! by its object table, with a [`Behaviour`] for the rest.

mod dictionary;
mod pdo;
mod service;

use std::collections::VecDeque;
use std::time::Duration;

use eds2rust_runtime::guarding::GuardResponder;
use eds2rust_runtime::heartbeat::{HeartbeatConsumer, HeartbeatProducer};
use eds2rust_runtime::lss::{BitRate, BitTiming, Identity, LssSlave, LssSlaveEvent};
use eds2rust_runtime::nmt::{NmtCommand, NmtState};
use eds2rust_runtime::od::{NodeId, ObjectInfo};
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::server::{SdoServer, ServerConfig, ServerEvent};
use eds2rust_runtime::{CanId, Frame, Instant, Service};

use crate::behaviour::Behaviour;
use crate::store::{ObjectTable, SetError};
use dictionary::Dictionary;
use pdo::{Rpdo, Tpdo};

/// EMCY code: PDO not processed due to length error (CiA 301).
pub const EMCY_PDO_LENGTH: u16 = 0x8210;
/// EMCY code: PDO length exceeded (CiA 301).
pub const EMCY_PDO_LENGTH_EXCEEDED: u16 = 0x8220;

/// How a simulated device starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeviceConfig {
    /// The node id at power-on; `None`: unconfigured, the device answers
    /// only LSS until a node id is configured and NMT resets communication.
    pub node: Option<NodeId>,
    /// The LSS address when the device is an LSS slave (CiA 305).
    pub lss: Option<Identity>,
    /// The bit rate it reports to LSS.
    pub bit_rate: BitRate,
}

impl DeviceConfig {
    /// A configured device at `node` without LSS.
    pub const fn node(node: NodeId) -> DeviceConfig {
        DeviceConfig {
            node: Some(node),
            lss: None,
            bit_rate: BitRate::Kbit250,
        }
    }
}

/// What a simulated device reports.
#[derive(Debug, Clone, PartialEq)]
pub enum SimEvent<E> {
    /// Its NMT state changed.
    Nmt {
        /// Before.
        from: NmtState,
        /// After.
        to: NmtState,
    },
    /// An entry was written from the bus (SDO or RPDO).
    Written {
        /// Object index.
        index: u16,
        /// Subindex.
        sub: u8,
    },
    /// An SDO transfer ended (done or aborted).
    Sdo(ServerEvent),
    /// A consumed heartbeat was missed.
    HeartbeatLost(NodeId),
    /// A consumed heartbeat came back.
    HeartbeatResumed(NodeId),
    /// The device sent an EMCY with this code.
    Emcy(u16),
    /// LSS set a pending node id (active after reset communication).
    LssNodeId(Option<NodeId>),
    /// LSS store configuration: the pending node id survives power-off.
    LssStored(Option<NodeId>),
    /// The model tried to set an entry its table does not have.
    ModelError(SetError),
    /// An event of the model.
    Model(E),
}

/// A simulated CANopen device (see the crate docs).
#[derive(Debug)]
pub struct Device<B: Behaviour> {
    config: DeviceConfig,
    server: SdoServer<Dictionary<B>>,
    heartbeat: Option<HeartbeatProducer>,
    /// Answers node guarding (CiA 301) once the node has an id.
    guard: Option<GuardResponder>,
    consumer: HeartbeatConsumer,
    lss: Option<LssSlave>,
    /// The node id that survives a power cycle (LSS store).
    stored_node: Option<NodeId>,
    tpdos: Vec<Tpdo>,
    rpdos: Vec<Rpdo>,
    outbox: VecDeque<Frame>,
    events: VecDeque<SimEvent<B::Event>>,
    next_step: Instant,
}

impl<B: Behaviour> Device<B> {
    /// Powers on a device whose dictionary is `objects` (a generated
    /// `od::OBJECTS`) at `now`: it boots (boot-up message) and enters
    /// pre-operational, unless unconfigured.
    pub fn new(
        objects: &'static [ObjectInfo],
        config: DeviceConfig,
        behaviour: B,
        now: Instant,
    ) -> Self {
        let node = config.node;
        let dictionary = Dictionary {
            objects,
            table: ObjectTable::new(objects, node),
            behaviour,
            effects: Default::default(),
            now,
            node,
            nmt: NmtState::BootUp,
            written: VecDeque::new(),
            saved: None,
        };
        let lss = config
            .lss
            .map(|identity| LssSlave::new(identity, node, BitTiming::standard(config.bit_rate)));
        let mut device = Device {
            config,
            server: SdoServer::new(server_config(node), dictionary),
            heartbeat: None,
            guard: None,
            consumer: HeartbeatConsumer::new(),
            lss,
            stored_node: node,
            tpdos: Vec::new(),
            rpdos: Vec::new(),
            outbox: VecDeque::new(),
            events: VecDeque::new(),
            next_step: now,
        };
        device.boot(now);
        device
    }

    /// The node id in use (`None`: unconfigured).
    pub fn node(&self) -> Option<NodeId> {
        self.server.store().node
    }

    /// The NMT state.
    pub fn nmt_state(&self) -> NmtState {
        self.server.store().nmt
    }

    /// The object table.
    pub fn table(&self) -> &ObjectTable {
        &self.server.store().table
    }

    /// Lets SDO downloads of strings and DOMAINs take up to `bytes` (4096
    /// by default; a device that takes program downloads needs more). The
    /// SDO server's own bound grows with it.
    pub fn set_max_variable_size(&mut self, bytes: usize) {
        self.server.store_mut().table.set_max_variable_size(bytes);
        if self.server.config().max_download < bytes {
            self.server.set_max_download(bytes);
        }
    }

    /// The model.
    pub fn behaviour(&self) -> &B {
        &self.server.store().behaviour
    }

    /// Runs `f` on the model with a context at `now`, as the device does
    /// (for tests and examples that act on the device locally: a fault, a
    /// button); what it asks for is sent on the next poll.
    pub fn with_model<R>(
        &mut self,
        now: Instant,
        f: impl FnOnce(&mut B, &mut crate::Context<'_, B::Event>) -> R,
    ) -> R {
        self.server.store_mut().now = now;
        let r = self.server.store_mut().with_model(f);
        self.after_input(now);
        r
    }

    /// Saves what the table holds now, as a write of "save" to 0x1010
    /// does: it survives resets and power cycles.
    pub fn save(&mut self) {
        let d = self.server.store_mut();
        d.saved = Some(d.table.clone());
    }

    /// Switches the device off and on again at `now`: values not saved
    /// (0x1010) return to their defaults, the LSS-stored node id is used.
    pub fn power_cycle(&mut self, now: Instant) {
        let node = self.stored_node;
        if let Some(lss) = self.lss.as_mut() {
            *lss = LssSlave::new(
                lss.identity(),
                node,
                BitTiming::standard(self.config.bit_rate),
            );
        }
        let d = self.server.store_mut();
        d.node = node;
        d.table = match &d.saved {
            Some(saved) => saved.clone(),
            None => ObjectTable::new(d.objects, node),
        };
        d.with_model(|b, ctx| b.reset_application(ctx));
        self.restart(now);
    }

    /// Boot-up: NMT state pre-operational, boot-up message, heartbeat from
    /// 0x1017, consumer from 0x1016.
    fn boot(&mut self, now: Instant) {
        let d = self.server.store_mut();
        d.now = now;
        let Some(node) = d.node else {
            self.heartbeat = None;
            self.guard = None;
            self.server.set_extra_channels(Vec::new());
            return;
        };
        let ms = d.table.get_uint(0x1017, 0).unwrap_or(0);
        // A new responder: the toggle starts at 0 after a boot.
        self.guard = Some(GuardResponder::new(node));
        let mut producer = HeartbeatProducer::new(node, producer_time(ms));
        producer.start(now);
        self.heartbeat = Some(producer);
        self.configure_consumer();
        self.configure_extra_sdo();
        self.set_nmt(now, NmtState::PreOperational);
    }

    /// Restarts communication after a reset at `now`: the SDO server moves
    /// to the (possibly new) node id, PDOs and the consumer start afresh.
    fn restart(&mut self, now: Instant) {
        self.tpdos.clear();
        self.rpdos.clear();
        self.consumer = HeartbeatConsumer::new();
        self.set_nmt(now, NmtState::BootUp);
        let node = self.node();
        self.server.set_channel(server_config(node).channel);
        self.boot(now);
    }

    /// The additional server SDO channels of the table (0x1201 to 0x127F:
    /// sub 1 client to server, sub 2 server to client; 11- or 29-bit, those
    /// with bit 31 set are not in use). The server serves them besides its
    /// default channel, one transfer at a time.
    fn configure_extra_sdo(&mut self) {
        let table = &self.server.store().table;
        let channels: Vec<Channel> = (0x1201..=0x127F)
            .filter_map(|index| {
                let request = table.get_uint(index, 1)?;
                let response = table.get_uint(index, 2)?;
                Channel::from_cob_ids(request as u32, response as u32).ok()
            })
            .collect();
        self.server.set_extra_channels(channels);
    }

    fn configure_consumer(&mut self) {
        let table = &self.server.store().table;
        let count = table.get_uint(0x1016, 0).unwrap_or(0) as u8;
        let entries: Vec<u32> = (1..=count)
            .filter_map(|sub| table.get_uint(0x1016, sub))
            .map(|v| v as u32)
            .collect();
        self.consumer = HeartbeatConsumer::new();
        self.consumer.configure(&entries);
    }

    fn set_nmt(&mut self, now: Instant, to: NmtState) {
        let d = self.server.store_mut();
        let from = d.nmt;
        if from == to {
            return;
        }
        d.nmt = to;
        if let Some(hb) = self.heartbeat.as_mut() {
            hb.set_state(to);
        }
        if let Some(guard) = self.guard.as_mut() {
            guard.set_state(to);
        }
        if to == NmtState::Operational {
            self.load_pdos();
        } else {
            self.tpdos.clear();
            self.rpdos.clear();
        }
        self.events.push_back(SimEvent::Nmt { from, to });
        self.server
            .store_mut()
            .with_model(|b, ctx| b.nmt_changed(ctx, from, to));
        self.after_input(now);
    }

    fn sync_cob_id(&self) -> u16 {
        (self.table().get_uint(0x1005, 0).unwrap_or(0x80) & 0x7FF) as u16
    }

    fn load_pdos(&mut self) {
        let sync = self.sync_cob_id();
        self.tpdos = pdo::tpdos(self.table(), sync);
        self.rpdos = pdo::rpdos(self.table());
    }

    fn emcy_cob_id(&self) -> Option<u16> {
        let node = self.node()?;
        match self.table().get_uint(0x1014, 0) {
            Some(v) if v & 0x8000_0000 != 0 => None,
            Some(v) => Some((v & 0x7FF) as u16),
            None => Some(0x80 + u16::from(node.get())),
        }
    }

    /// At a reset: the node id LSS configured becomes the one in use.
    fn take_pending_node_id(&mut self) -> Option<NodeId> {
        if let Some(lss) = self.lss.as_mut() {
            lss.apply_pending();
        }
        let node = self
            .lss
            .as_ref()
            .map_or(self.node(), LssSlave::active_node_id);
        self.server.store_mut().node = node;
        node
    }

    /// NMT commands, also while unconfigured (where only the resets matter).
    fn handle_nmt(&mut self, now: Instant, cmd: NmtCommand) {
        match cmd {
            NmtCommand::ResetNode => {
                let node = self.take_pending_node_id();
                let d = self.server.store_mut();
                d.table = match &d.saved {
                    Some(saved) => saved.clone(),
                    None => ObjectTable::new(d.objects, node),
                };
                d.with_model(|b, ctx| b.reset_application(ctx));
                self.restart(now);
            }
            NmtCommand::ResetCommunication => {
                let node = self.take_pending_node_id();
                let d = self.server.store_mut();
                match &d.saved {
                    Some(saved) => {
                        let saved = saved.clone();
                        d.table.copy_range_from(&saved, 0x1000..=0x1FFF);
                    }
                    None => d.table.reset_to_defaults(0x1000..=0x1FFF, node),
                }
                self.restart(now);
            }
            _ if self.node().is_none() || self.nmt_state() == NmtState::BootUp => {}
            NmtCommand::Start => self.set_nmt(now, NmtState::Operational),
            NmtCommand::Stop => self.set_nmt(now, NmtState::Stopped),
            NmtCommand::EnterPreOperational => self.set_nmt(now, NmtState::PreOperational),
        }
    }

    /// After every input: take what was written and what the model asked
    /// for, refresh the TPDO data.
    fn after_input(&mut self, now: Instant) {
        let written: Vec<(u16, u8)> = self.server.store_mut().written.drain(..).collect();
        let mut pdo_changed = false;
        for (index, sub) in written {
            self.events.push_back(SimEvent::Written { index, sub });
            match index {
                0x1017 => {
                    let ms = self.table().get_uint(0x1017, 0).unwrap_or(0);
                    if let Some(hb) = self.heartbeat.as_mut() {
                        hb.set_period(now, producer_time(ms));
                    }
                }
                0x1016 => self.configure_consumer(),
                0x1201..=0x127F => self.configure_extra_sdo(),
                0x1400..=0x1BFF => pdo_changed = true,
                _ => {}
            }
        }
        if pdo_changed && self.nmt_state() == NmtState::Operational {
            self.load_pdos();
        }
        let effects = &mut self.server.store_mut().effects;
        let emcy: Vec<[u8; 8]> = effects.emcy.drain(..).collect();
        let errors: Vec<SetError> = effects.errors.drain(..).collect();
        let model: Vec<B::Event> = effects.events.drain(..).collect();
        let requests: Vec<u16> = effects.tpdo_requests.drain(..).collect();
        let emcy_id = self.emcy_cob_id();
        for data in emcy {
            self.events
                .push_back(SimEvent::Emcy(u16::from_le_bytes([data[0], data[1]])));
            if let Some(id) = emcy_id
                && self.nmt_state() != NmtState::Stopped
                && let Ok(frame) = Frame::new(CanId::Standard(id), &data)
            {
                self.outbox.push_back(frame);
            }
        }
        self.events
            .extend(errors.into_iter().map(SimEvent::ModelError));
        self.events.extend(model.into_iter().map(SimEvent::Model));
        self.refresh_tpdos(now, &requests);
    }

    /// Packs each TPDO from the table; a changed value is an event for the
    /// transmitter; requested TPDOs are sent now.
    fn refresh_tpdos(&mut self, now: Instant, requests: &[u16]) {
        let table = &self.server.store().table;
        for tpdo in &mut self.tpdos {
            let Some(data) = pdo::pack(table, &tpdo.mapping) else {
                continue;
            };
            if tpdo.tx.data() != data.as_slice() {
                let _ = tpdo.tx.set_data(now, &data);
            }
            if requests.contains(&tpdo.number)
                && tpdo.tx.is_enabled()
                && let Ok(frame) = Frame::new(tpdo.tx.can_id(), &data)
            {
                self.outbox.push_back(frame);
            }
        }
    }

    fn receive_pdo(&mut self, now: Instant, frame: &Frame) -> bool {
        let id = frame.id();
        let Some(i) = self.rpdos.iter().position(|r| r.can_id == id) else {
            return false;
        };
        if frame.is_remote() {
            return true;
        }
        let need = self.rpdos[i].len();
        let data = frame.data();
        if data.len() < need {
            self.device_emcy(now, EMCY_PDO_LENGTH);
            return true;
        }
        if data.len() > need {
            self.device_emcy(now, EMCY_PDO_LENGTH_EXCEEDED);
        }
        if self.rpdos[i].synchronous {
            self.rpdos[i].pending = Some(data.to_vec());
        } else {
            self.apply_rpdo(i, data.to_vec());
        }
        true
    }

    fn apply_rpdo(&mut self, i: usize, data: Vec<u8>) {
        let entries = pdo::unpack(&data, &self.rpdos[i].mapping);
        let d = self.server.store_mut();
        for (index, sub, value) in entries {
            // A refused entry is dropped; CiA 301 has no answer for RPDOs.
            let _ = d.bus_write(index, sub, &value);
        }
    }

    fn device_emcy(&mut self, now: Instant, code: u16) {
        let d = self.server.store_mut();
        d.now = now;
        d.with_model(|_, ctx| ctx.emcy(code, [0; 5]));
    }

    fn handle_sync(&mut self, now: Instant, frame: &Frame) {
        for i in 0..self.rpdos.len() {
            if let Some(data) = self.rpdos[i].pending.take() {
                self.apply_rpdo(i, data);
            }
        }
        self.server.store_mut().with_model(|b, ctx| b.sync(ctx));
        self.after_input(now);
        for tpdo in &mut self.tpdos {
            tpdo.tx.handle_frame(now, frame);
        }
    }

    fn handle_lss(&mut self, now: Instant, frame: &Frame) {
        let Some(lss) = self.lss.as_mut() else {
            return;
        };
        lss.handle_frame(now, frame);
        while let Some(f) = lss.poll_transmit() {
            self.outbox.push_back(f);
        }
        let mut reset = false;
        while let Some(event) = lss.poll_event() {
            match event {
                LssSlaveEvent::NodeIdChanged { pending } => {
                    self.events.push_back(SimEvent::LssNodeId(pending));
                }
                LssSlaveEvent::StoreRequested => {
                    self.stored_node = lss.pending_node_id();
                    self.events.push_back(SimEvent::LssStored(self.stored_node));
                }
                LssSlaveEvent::ResetCommunication => reset = true,
                _ => {}
            }
        }
        // CiA 305: an unconfigured device that got a node id resets its
        // communication when switched back to waiting.
        if reset {
            self.handle_nmt(now, NmtCommand::ResetCommunication);
        }
    }

    fn run_step(&mut self, now: Instant) {
        let period = self.behaviour().period().max(Duration::from_millis(1));
        self.server.store_mut().with_model(|b, ctx| b.step(ctx));
        self.next_step = now + period;
        if self.next_step <= now {
            self.next_step = now + Duration::from_millis(1);
        }
        self.after_input(now);
    }
}

/// The server of `node`; an unconfigured device listens on the (unused)
/// channel of node 0 and answers nothing.
fn server_config(node: Option<NodeId>) -> ServerConfig {
    let channel = match node {
        Some(node) => Channel::default_for(node),
        None => Channel::standard(0x600, 0x580),
    };
    ServerConfig::new(channel)
}

/// The heartbeat period of object 0x1017's value in ms (0: none).
fn producer_time(ms: u64) -> Option<Duration> {
    (ms != 0).then(|| Duration::from_millis(ms))
}
