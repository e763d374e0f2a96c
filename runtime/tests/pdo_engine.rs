//! The PDO engine end to end: `configure_pdo` against the runtime's SDO
//! server over the virtual bus (a device that enforces the CiA 301 mapping
//! rules, one that refuses an object, one that silently keeps old values),
//! and the transmitter and receiver exchanging PDOs paced by a SYNC
//! producer on a virtual clock.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::Duration;

use eds2rust_runtime::blocking::{self, SdoClient};
use eds2rust_runtime::od::standard::{EventTimer, InhibitTime};
use eds2rust_runtime::od::{self, AccessRight, NodeId, PdoDirection, PdoLengthError};
use eds2rust_runtime::pdo::blocking::{PdoConfigError, configure_pdo};
use eds2rust_runtime::pdo::{
    ConfigCheckError, PdoCobId, PdoConfig, PdoEvent, PdoReceiver, PdoTransmitter, ReadBackMismatch,
    StepKind, TransmissionType, TransmitterConfig,
};
use eds2rust_runtime::sdo::client::ClientConfig;
use eds2rust_runtime::sdo::server::{MemoryStore, ObjectStore, SdoServer, ServerConfig};
use eds2rust_runtime::sdo::{AbortCode, Channel};
use eds2rust_runtime::sync::SyncProducer;
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_runtime::{CanId, Frame, Instant, Service};

const NODE: u8 = 5;

fn node() -> NodeId {
    NodeId::new(NODE).unwrap()
}

/// Statusword (0x6041, UNSIGNED16) and position actual value (0x6064,
/// INTEGER32) as mapping entries.
const STATUSWORD: u32 = 0x6041_0010;
const POSITION: u32 = 0x6064_0020;

/// A device's object dictionary that follows the CiA 301 PDO rules: the
/// mapping changes only while the PDO is invalid (COB-ID bit 31) and its
/// mapping is switched off (sub 0 = 0); sub 0 = n checks the length; the
/// COB-ID's identifier and the inhibit time change only while the PDO is
/// invalid. Two faults can be switched on: refusing one mapping value with
/// 0x06040041, and accepting one without keeping it.
struct Device {
    store: MemoryStore,
    mappable: Vec<u32>,
    refuse: Option<u32>,
    forget: Option<u32>,
}

fn u32_le(data: &[u8]) -> Option<u32> {
    Some(u32::from_le_bytes(data.try_into().ok()?))
}

impl Device {
    /// TPDO1 (0x1800/0x1A00) on 0x185 + bit 30, event-driven, mapping the
    /// statusword only; the objects 0x6041 and 0x6064 are mappable.
    fn new() -> Device {
        let mut store = MemoryStore::new();
        store.insert_fixed(0x1800, 0, AccessRight::Const, &[6]);
        store.insert_fixed(0x1800, 1, AccessRight::Rw, &0x4000_0185u32.to_le_bytes());
        store.insert_fixed(0x1800, 2, AccessRight::Rw, &[0xFE]);
        store.insert_fixed(0x1800, 3, AccessRight::Rw, &[0, 0]);
        store.insert_fixed(0x1800, 5, AccessRight::Rw, &[0, 0]);
        store.insert_fixed(0x1800, 6, AccessRight::Rw, &[0]);
        store.insert_fixed(0x1A00, 0, AccessRight::Rw, &[1]);
        store.insert_fixed(0x1A00, 1, AccessRight::Rw, &STATUSWORD.to_le_bytes());
        for sub in 2..=8 {
            store.insert_fixed(0x1A00, sub, AccessRight::Rw, &[0; 4]);
        }
        store.insert_fixed(0x6041, 0, AccessRight::Ro, &[0x37, 0x02]);
        store.insert_fixed(0x6064, 0, AccessRight::Ro, &[0; 4]);
        Device {
            store,
            mappable: vec![STATUSWORD, POSITION],
            refuse: None,
            forget: None,
        }
    }

    fn cob_id(&self, comm: u16) -> u32 {
        self.store
            .get(comm, 1)
            .and_then(u32_le)
            .unwrap_or(0x8000_0000)
    }

    fn value(&self, index: u16, sub: u8) -> Option<u32> {
        let data = self.store.get(index, sub)?;
        let mut raw = [0u8; 4];
        raw.get_mut(..data.len())?.copy_from_slice(data);
        Some(u32::from_le_bytes(raw))
    }

    fn check_mapping_write(&self, index: u16, sub: u8, data: &[u8]) -> Result<bool, AbortCode> {
        let comm = index - 0x200;
        if self.cob_id(comm) & 0x8000_0000 == 0 {
            return Err(AbortCode::CannotTransferDeviceState);
        }
        if sub == 0 {
            let count = *data.first().ok_or(AbortCode::LengthTooLow)?;
            let bits: u32 = (1..=count)
                .map(|s| self.value(index, s).map_or(0, |e| e & 0xFF))
                .sum();
            if count > 8 {
                return Err(AbortCode::ValueTooHigh);
            }
            if bits > 64 {
                return Err(AbortCode::PdoLengthExceeded);
            }
            return Ok(true);
        }
        if self.value(index, 0) != Some(0) {
            return Err(AbortCode::CannotTransferDeviceState);
        }
        let entry = u32_le(data).ok_or(AbortCode::LengthMismatch)?;
        if self.refuse == Some(entry) || !self.mappable.contains(&entry) {
            return Err(AbortCode::CannotMap);
        }
        Ok(self.forget != Some(entry))
    }

    fn check_communication_write(&self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode> {
        let current = self.cob_id(index);
        let valid = current & 0x8000_0000 == 0;
        match sub {
            1 => {
                let new = u32_le(data).ok_or(AbortCode::LengthMismatch)?;
                let new_valid = new & 0x8000_0000 == 0;
                if valid && new_valid && (new & 0x7FF) != (current & 0x7FF) {
                    return Err(AbortCode::InvalidValue);
                }
                Ok(())
            }
            3 if valid => Err(AbortCode::CannotTransferDeviceState),
            _ => Ok(()),
        }
    }
}

impl ObjectStore for Device {
    fn read(&mut self, index: u16, sub: u8, out: &mut Vec<u8>) -> Result<(), AbortCode> {
        self.store.read(index, sub, out)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode> {
        let keep = match index {
            0x1A00..=0x1BFF => self.check_mapping_write(index, sub, data)?,
            0x1800..=0x19FF => {
                self.check_communication_write(index, sub, data)?;
                true
            }
            _ => true,
        };
        if keep {
            self.store.write(index, sub, data)
        } else {
            // Accepted, but the old value stays.
            self.store.check_write(index, sub, Some(data.len()))
        }
    }
}

/// Runs `device` as node 5's SDO server on `bus` until `stop` is set.
fn serve(bus: &VirtualBus, device: Device, stop: Arc<AtomicBool>) -> thread::JoinHandle<Device> {
    let config = ServerConfig::new(Channel::default_for(node()));
    let mut server = SdoServer::new(config, device);
    let mut port = bus.attach();
    thread::spawn(move || {
        blocking::serve(&mut port, &Clock::new(), &mut server, &stop, None, |_| {}).unwrap();
        server.into_store()
    })
}

/// Configures with `config` against `device`; returns the outcome and the
/// device afterwards.
fn configure(device: Device, config: &PdoConfig<'_>) -> (Result<(), PdoConfigError>, Device) {
    let bus = VirtualBus::new();
    let stop = Arc::new(AtomicBool::new(false));
    let server = serve(&bus, device, stop.clone());
    let mut client = SdoClient::new(
        bus.attach(),
        ClientConfig::new(Channel::default_for(node())),
    );
    let result = configure_pdo(&mut client, config);
    stop.store(true, Ordering::Relaxed);
    (result, server.join().unwrap())
}

/// The two-entry TPDO1: statusword then position, event-driven every
/// 500 ms at most every 10 ms.
fn tpdo1(entries: &[u32]) -> PdoConfig<'_> {
    PdoConfig::new(PdoDirection::Tpdo, 1, PdoCobId(0x185), entries)
        .unwrap()
        .with_transmission_type(TransmissionType::from_raw(254))
        .with_inhibit_time(InhibitTime(100))
        .with_event_timer(EventTimer(500))
}

#[test]
fn the_device_enforces_the_cia_301_rules() {
    // Without the configuration order, the strict device refuses.
    let bus = VirtualBus::new();
    let stop = Arc::new(AtomicBool::new(false));
    let server = serve(&bus, Device::new(), stop.clone());
    let mut client = SdoClient::new(
        bus.attach(),
        ClientConfig::new(Channel::default_for(node())),
    );
    let refused = client.download(0x1A00, 1, &POSITION.to_le_bytes());
    assert_eq!(
        refused.unwrap_err().to_string(),
        "SDO transfer of 0x1A00:1 with node 5: the SDO peer aborted the transfer: 0x08000022 \
         (data cannot be transferred or stored to the application because of the present device \
         state)"
    );
    stop.store(true, Ordering::Relaxed);
    server.join().unwrap();
}

#[test]
fn configure_pdo_writes_in_order_and_reads_back() {
    let entries = [STATUSWORD, POSITION];
    let (result, device) = configure(Device::new(), &tpdo1(&entries));
    result.unwrap();
    let store = &device.store;
    assert_eq!(store.get(0x1A00, 0), Some(&[0x02][..]));
    assert_eq!(store.get(0x1A00, 1), Some(&[0x10, 0x00, 0x41, 0x60][..]));
    assert_eq!(store.get(0x1A00, 2), Some(&[0x20, 0x00, 0x64, 0x60][..]));
    assert_eq!(store.get(0x1800, 1), Some(&[0x85, 0x01, 0x00, 0x00][..]));
    assert_eq!(store.get(0x1800, 2), Some(&[0xFE][..]));
    assert_eq!(store.get(0x1800, 3), Some(&[0x64, 0x00][..]));
    assert_eq!(store.get(0x1800, 5), Some(&[0xF4, 0x01][..]));
}

/// TPDO1 of the test device as a generated struct would give it.
#[derive(Debug, PartialEq)]
struct Tpdo1 {
    statusword: u16,
    position: i32,
}

impl od::Pdo for Tpdo1 {
    const DIRECTION: PdoDirection = PdoDirection::Tpdo;
    const NUMBER: u16 = 1;
    const COMMUNICATION_INDEX: u16 = 0x1800;
    const MAPPING_INDEX: u16 = 0x1A00;
    const LEN: usize = 6;
    const MAPPING: &'static [u32] = &[STATUSWORD, POSITION];
    fn default_cob_id(node: NodeId) -> Option<PdoCobId> {
        Some(PdoCobId(0x4000_0180 + u32::from(node.get())))
    }
    fn decode(data: &[u8]) -> Result<Self, PdoLengthError> {
        match *data {
            [a, b, c, d, e, f] => Ok(Tpdo1 {
                statusword: u16::from_le_bytes([a, b]),
                position: i32::from_le_bytes([c, d, e, f]),
            }),
            _ => Err(PdoLengthError {
                expected: 6,
                actual: data.len(),
            }),
        }
    }
    fn encode_into(&self, out: &mut [u8; 8]) -> usize {
        out[..2].copy_from_slice(&self.statusword.to_le_bytes());
        out[2..6].copy_from_slice(&self.position.to_le_bytes());
        6
    }
}

#[test]
fn configure_a_generated_pdo() {
    let config = PdoConfig::from_pdo::<Tpdo1>(node())
        .unwrap()
        .with_transmission_type(TransmissionType::from_raw(1));
    let (result, device) = configure(Device::new(), &config);
    result.unwrap();
    assert_eq!(
        device.store.get(0x1800, 1),
        Some(&[0x85, 0x01, 0x00, 0x40][..])
    );
    assert_eq!(device.store.get(0x1800, 2), Some(&[0x01][..]));
    assert_eq!(device.store.get(0x1A00, 0), Some(&[0x02][..]));
}

#[test]
fn a_refused_entry_is_named_with_the_abort_code() {
    let mut device = Device::new();
    device.refuse = Some(STATUSWORD);
    let entries = [POSITION, STATUSWORD];
    let (result, device) = configure(device, &tpdo1(&entries));
    let error = result.unwrap_err();
    assert_eq!(
        error.to_string(),
        "PDO configuration step 4 of 16 failed: write mapping entry 2 of 0x1A00 = 0x60410010 \
         (object 0x1A00 sub 2): the device refused: 0x06040041 (object cannot be mapped to \
         the PDO); the PDO is left disabled"
    );
    assert_eq!(error.abort_code(), Some(AbortCode::CannotMap));
    assert_eq!(
        error.step().map(|s| s.kind()),
        Some(StepKind::MappingEntry(2))
    );
    assert!(error.pdo_left_disabled());
    // The device holds the disabled PDO with its mapping switched off.
    assert_eq!(
        device.store.get(0x1800, 1),
        Some(&[0x85, 0x01, 0x00, 0x80][..])
    );
    assert_eq!(device.store.get(0x1A00, 0), Some(&[0x00][..]));
}

#[test]
fn a_value_the_device_does_not_keep_fails_the_read_back() {
    let mut device = Device::new();
    device.forget = Some(POSITION);
    let entries = [STATUSWORD, POSITION];
    let (result, _) = configure(device, &tpdo1(&entries));
    let error = result.unwrap_err();
    assert!(matches!(
        error,
        PdoConfigError::Mismatch(ReadBackMismatch { number: 12, .. })
    ));
    assert_eq!(
        error.to_string(),
        "PDO configuration step 12 of 16 failed: read back mapping entry 2 of 0x1A00 (object \
         0x1A00 sub 2): wrote 0x60640020, read 0x00000000; the device did not keep the value"
    );
    assert!(!error.pdo_left_disabled());
}

#[test]
fn an_invalid_configuration_sends_nothing() {
    let entries = [POSITION, POSITION, STATUSWORD];
    let (result, device) = configure(Device::new(), &tpdo1(&entries));
    let error = result.unwrap_err();
    assert!(matches!(
        error,
        PdoConfigError::Invalid(ConfigCheckError::TooLong { bits: 80 })
    ));
    assert_eq!(
        error.to_string(),
        "invalid PDO configuration, nothing was sent: the mapping entries add up to 80 bits; \
         a PDO carries at most 64"
    );
    assert_eq!(
        device.store.get(0x1800, 1),
        Some(&[0x85, 0x01, 0x00, 0x40][..])
    );
}

#[test]
fn a_silent_device_times_out_at_the_first_step() {
    let bus = VirtualBus::new();
    let mut config = ClientConfig::new(Channel::default_for(node()));
    config.timeout = Duration::from_millis(50);
    let mut client = SdoClient::new(bus.attach(), config);
    let error = configure_pdo(&mut client, &tpdo1(&[STATUSWORD])).unwrap_err();
    assert_eq!(
        error.to_string(),
        "PDO configuration step 1 of 14 failed: write COB-ID of 0x1800 = 0x80000185, disabling \
         the PDO (object 0x1800 sub 1): the device did not answer in time"
    );
    assert!(!error.pdo_left_disabled());
    assert_eq!(error.abort_code(), Some(AbortCode::Timeout));
}

/// The master (SYNC producer, RPDO transmitter, TPDO receiver) and a device
/// (RPDO receiver, TPDO transmitter), all on one virtual clock; every frame
/// reaches every other core at the instant it is sent.
struct Network {
    sync: SyncProducer,
    master_tx: PdoTransmitter,
    master_rx: PdoReceiver<2>,
    device_rx: PdoReceiver<1>,
    device_tx: PdoTransmitter,
    /// (time, frame) of everything sent.
    log: Vec<(Instant, Frame)>,
    master_events: Vec<PdoEvent>,
    device_events: Vec<PdoEvent>,
}

impl Network {
    fn deliver(&mut self, now: Instant) {
        loop {
            let mut sent = Vec::new();
            sent.extend(std::iter::from_fn(|| self.sync.poll_transmit()));
            sent.extend(std::iter::from_fn(|| self.master_tx.poll_transmit()));
            sent.extend(std::iter::from_fn(|| self.device_tx.poll_transmit()));
            if sent.is_empty() {
                break;
            }
            for frame in sent {
                self.log.push((now, frame));
                self.master_tx.handle_frame(now, &frame);
                self.master_rx.handle_frame(now, &frame);
                self.device_rx.handle_frame(now, &frame);
                self.device_tx.handle_frame(now, &frame);
            }
        }
        self.master_events
            .extend(std::iter::from_fn(|| self.master_rx.poll_event()));
        self.device_events
            .extend(std::iter::from_fn(|| self.device_rx.poll_event()));
    }

    /// Runs the timers up to `until` (1 ms resolution, all timers here are
    /// whole milliseconds).
    fn run_until(&mut self, from: u64, until: u64) {
        for ms in from..=until {
            let now = Instant::from_millis(ms);
            let due = |t: Option<Instant>| t.is_some_and(|t| t <= now);
            if due(self.sync.poll_timeout()) {
                self.sync.handle_timeout(now);
            }
            if due(self.master_tx.poll_timeout()) {
                self.master_tx.handle_timeout(now);
            }
            if due(self.device_tx.poll_timeout()) {
                self.device_tx.handle_timeout(now);
            }
            if due(self.master_rx.poll_timeout()) {
                self.master_rx.handle_timeout(now);
            }
            if due(self.device_rx.poll_timeout()) {
                self.device_rx.handle_timeout(now);
            }
            self.deliver(now);
        }
    }

    fn sent_on(&self, id: u16) -> Vec<(u64, Vec<u8>)> {
        self.log
            .iter()
            .filter(|(_, f)| f.standard_id() == Some(id))
            .map(|(t, f)| (t.as_micros() / 1000, f.data().to_vec()))
            .collect()
    }
}

#[test]
fn master_and_device_exchange_pdos_paced_by_sync() {
    let node = node();
    // RPDO1 of the device: synchronous cyclic, every 2nd SYNC.
    let mut master_tx = PdoTransmitter::new(TransmitterConfig::new(
        PdoCobId(0x205),
        TransmissionType::from_raw(2),
    ))
    .unwrap();
    // TPDO1 of the device: event-driven, inhibit 5 ms, event timer 40 ms.
    let mut device_config =
        TransmitterConfig::from_pdo::<Tpdo1>(node, TransmissionType::EventDrivenManufacturer)
            .unwrap();
    device_config.inhibit_time = InhibitTime(50);
    device_config.event_timer = EventTimer(40);
    let device_tx = PdoTransmitter::new(device_config).unwrap();
    let mut master_rx = PdoReceiver::new();
    let tpdo = master_rx.watch_pdo::<Tpdo1>(node).unwrap();
    master_rx
        .set_timeout(tpdo, Some(Duration::from_millis(100)))
        .unwrap();
    let mut device_rx = PdoReceiver::new();
    device_rx.watch(PdoCobId(0x205), 2, None).unwrap();
    let mut sync = SyncProducer::new(Some(Duration::from_millis(10)), None).unwrap();
    sync.start(Instant::ZERO);
    master_tx.set_data(Instant::ZERO, &[0x0F, 0x00]).unwrap();
    let mut net = Network {
        sync,
        master_tx,
        master_rx,
        device_rx,
        device_tx,
        log: Vec::new(),
        master_events: Vec::new(),
        device_events: Vec::new(),
    };

    net.run_until(0, 45);
    // SYNC at 10, 20, 30, 40: the RPDO goes with the 2nd and 4th.
    assert_eq!(
        net.sent_on(0x205),
        [(20, vec![0x0F, 0x00]), (40, vec![0x0F, 0x00])]
    );
    assert_eq!(net.device_events.len(), 2);
    assert_eq!(
        net.device_rx.latest_data(CanId::Standard(0x205)),
        Some(&[0x0F, 0x00][..])
    );

    // The device reports three changes within 1 ms: one frame now, one
    // with the latest value when the 5 ms inhibit time ends.
    let t = Instant::from_millis(46);
    for position in [100, 200, 300] {
        let pdo = Tpdo1 {
            statusword: 0x0237,
            position,
        };
        net.device_tx.set(t, &pdo).unwrap();
    }
    net.deliver(t);
    net.run_until(46, 120);
    let tpdo_frames = net.sent_on(0x185);
    assert_eq!(
        tpdo_frames[..3],
        [
            (46, vec![0x37, 0x02, 100, 0, 0, 0]),
            (51, vec![0x37, 0x02, 0x2C, 0x01, 0, 0]),
            // The event timer resends 40 ms after the last frame.
            (91, vec![0x37, 0x02, 0x2C, 0x01, 0, 0]),
        ]
    );
    assert_eq!(
        net.master_rx.latest::<Tpdo1>(tpdo),
        Some(Ok(Tpdo1 {
            statusword: 0x0237,
            position: 300
        }))
    );

    // The device goes silent (PDO disabled): the master reports the
    // timeout once, 100 ms after the last TPDO.
    net.device_tx
        .set_cob_id(Instant::from_millis(121), PdoCobId(0xC000_0185))
        .unwrap();
    let last = net.sent_on(0x185).last().unwrap().0;
    net.run_until(121, 400);
    let timeouts: Vec<&PdoEvent> = net
        .master_events
        .iter()
        .filter(|e| matches!(e, PdoEvent::Timeout { .. }))
        .collect();
    assert_eq!(
        timeouts,
        [&PdoEvent::Timeout {
            can_id: CanId::Standard(0x185)
        }]
    );
    assert!(net.master_rx.is_timed_out(tpdo));
    assert_eq!(last, 91);
    let received_at: Vec<u64> = net
        .master_events
        .iter()
        .filter_map(|e| match e {
            PdoEvent::Received { at, .. } => Some(at.as_micros() / 1000),
            _ => None,
        })
        .collect();
    assert_eq!(received_at, [46, 51, 91]);
    // The timeout fired at 191 ms: nothing after that was sent on 0x185.
    assert!(net.sent_on(0x185).iter().all(|(t, _)| *t <= 191));
}
