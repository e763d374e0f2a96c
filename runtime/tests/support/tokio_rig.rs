//! The rig of the tokio master tests (`tokio_master.rs`,
//! `tokio_master_events.rs`, `tokio_master_pdo.rs`,
//! `tokio_master_streamed.rs`): the virtual bus under tokio's paused clock,
//! the master and its driver task, a device assembled from the runtime's
//! sans-IO services (SDO server, NMT slave, heartbeat producer, LSS slave,
//! a TPDO transmitter) served on a task, and a monitor port that sees
//! every frame.

use std::time::Duration;

use eds2rust_runtime::lss::{BitRate, BitTiming, Identity, LssSlave};
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::od::{self, AccessRight};
use eds2rust_runtime::pdo::{PdoCobId, PdoTransmitter, TransmissionType, TransmitterConfig};
use eds2rust_runtime::sdo::server::MemoryStore;
use eds2rust_runtime::tokio::{self as driver, Deadline, Events, Master};
use eds2rust_runtime::transport::AsyncBus;
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use eds2rust_runtime::{Frame, Instant, Service};
use tokio::task::JoinHandle;

pub const DEVICE: u8 = 0x20;
pub const IDENTITY: Identity = Identity::new(0x0000_02A5, 0x1234, 7, 0xBEEF);

// What the tests take with `tokio_rig::*`; each uses some of it.
#[allow(unused_imports)]
pub use super::{BasicDevice, assert_sdo_timeout, frame, node};

entry!(ProducerHeartbeatTime, 0x1017, 0, Unsigned16, Rw, u16);
entry!(
    DeviceName,
    0x1008,
    0,
    VisibleString,
    Ro,
    od::bytes::VisibleString
);
entry!(Blob, 0x2100, 0, Domain, Rw, od::bytes::Domain);

// The device's TPDO1: a 16-bit counter at 0x2001:00.
word_pdo!(Counter, Tpdo, 0x1800, 0x180, 0x2001_0010);

/// The device: SDO server, NMT slave, heartbeat every 50 ms, LSS slave,
/// TPDO1 (a counter, sent at every SYNC and counted up after it).
pub struct Device {
    basic: BasicDevice<MemoryStore>,
    lss: LssSlave,
    tpdo: PdoTransmitter,
    counter: u16,
}

impl Device {
    fn new(now: Instant) -> Device {
        let id = node(DEVICE);
        let mut store = MemoryStore::new();
        store.insert_fixed(0x1017, 0, AccessRight::Rw, &50u16.to_le_bytes());
        store.insert(0x1008, 0, AccessRight::Ro, b"eds2rust test device");
        store.insert(0x2100, 0, AccessRight::Rw, &[0xA5; 100]);
        store.insert_fixed(0x1800, 1, AccessRight::Rw, &0x1A0u32.to_le_bytes());
        store.insert_fixed(0x1800, 2, AccessRight::Rw, &[0xFF]);
        store.insert_fixed(0x1800, 5, AccessRight::Rw, &[0; 2]);
        store.insert_fixed(0x1A00, 0, AccessRight::Rw, &[0]);
        store.insert_fixed(0x1A00, 1, AccessRight::Rw, &[0; 4]);
        let mut tpdo = PdoTransmitter::new(TransmitterConfig::new(
            PdoCobId(0x1A0),
            TransmissionType::from_raw(1),
        ))
        .unwrap();
        tpdo.set_data(Instant::ZERO, &0u16.to_le_bytes()).unwrap();
        Device {
            basic: BasicDevice::new(id, store, now),
            lss: LssSlave::new(IDENTITY, Some(id), BitTiming::standard(BitRate::Kbit500)),
            tpdo,
            counter: 0,
        }
    }
}

impl Service for Device {
    type Event = ();
    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        self.basic.handle_frame(now, frame);
        self.lss.handle_frame(now, frame);
        while self.lss.poll_event().is_some() {}
        self.tpdo.handle_frame(now, frame);
        if frame.standard_id() == Some(0x080) {
            // The value of the next SYNC.
            self.counter = self.counter.wrapping_add(1);
            let _ = self.tpdo.set_data(now, &self.counter.to_le_bytes());
        }
    }
    fn handle_timeout(&mut self, now: Instant) {
        self.basic.handle_timeout(now);
    }
    fn poll_transmit(&mut self) -> Option<Frame> {
        self.basic
            .poll_transmit()
            .or_else(|| self.lss.poll_transmit())
            .or_else(|| self.tpdo.poll_transmit())
    }
    fn poll_event(&mut self) -> Option<()> {
        self.basic.poll_event()
    }
    fn poll_timeout(&self) -> Option<Instant> {
        self.basic.poll_timeout()
    }
}

/// Serves the device on `port` until the task is aborted.
pub fn spawn_device(mut port: VirtualPort) -> JoinHandle<()> {
    tokio::spawn(async move {
        let clock = driver::clock();
        let mut device = Device::new(clock.now());
        let pending = std::future::pending();
        let _ = driver::serve(
            &mut port,
            &clock,
            &mut device,
            pending,
            Deadline::NEVER,
            |()| {},
        )
        .await;
    })
}

/// The bus, the master, its driver task, the device task and a monitor.
pub struct Rig {
    pub bus: VirtualBus,
    pub master: Master,
    pub events: Events,
    pub driver: JoinHandle<std::io::Result<()>>,
    pub device: JoinHandle<()>,
    pub monitor: VirtualPort,
}

impl Rig {
    pub async fn new(configure: impl FnOnce(&mut master::Master)) -> Rig {
        let bus = VirtualBus::new();
        let monitor = bus.attach();
        let device = spawn_device(bus.attach());
        let mut core = master::Master::new(node(1), Some(Duration::from_millis(100)));
        configure(&mut core);
        let (master, driver) = Master::new(bus.attach(), core);
        let events = master.events();
        let driver = tokio::spawn(driver.run());
        master.start().await.unwrap();
        Rig {
            bus,
            master,
            events,
            driver,
            device,
            monitor,
        }
    }

    /// The frames the monitor saw since the last call.
    pub fn seen(&self) -> Vec<Frame> {
        std::iter::from_fn(|| self.monitor.try_recv()).collect()
    }

    /// The frames with `cob_id` the monitor saw since the last call (of
    /// this or [`Rig::seen`]), as text.
    pub fn seen_on(&self, cob_id: u16) -> Vec<String> {
        self.seen()
            .iter()
            .filter(|f| f.standard_id() == Some(cob_id))
            .map(Frame::to_string)
            .collect()
    }

    /// Waits (in virtual time) for the first event `pick` takes.
    pub async fn wait_for<T>(&mut self, mut pick: impl FnMut(&MasterEvent) -> Option<T>) -> T {
        let within = Duration::from_secs(10);
        tokio::time::timeout(within, async {
            loop {
                let event = self.events.next().await.expect("the driver stopped");
                if let Some(value) = pick(&event) {
                    return value;
                }
            }
        })
        .await
        .expect("no such event within 10 s")
    }
}

/// Plays node 0x31 on `peer`: answers the upload of 0x1008:00 with a
/// segmented initiate of 20 bytes and takes the first segment request.
pub async fn start_segmented_upload(peer: &mut VirtualPort) {
    let request = recv_from(peer, 0x631).await.unwrap();
    assert_eq!(request.to_string(), "631#4008100000000000");
    let response = frame(0x5B1, &[0x41, 0x08, 0x10, 0x00, 20, 0, 0, 0]);
    AsyncBus::send(peer, &response).await.unwrap();
    let segment = recv_from(peer, 0x631).await.unwrap();
    assert_eq!(segment.to_string(), "631#6000000000000000");
}

/// The next frame `port` receives with `cob_id`.
pub async fn recv_from(port: &mut VirtualPort, cob_id: u16) -> std::io::Result<Frame> {
    loop {
        let frame = AsyncBus::recv(port).await?;
        if frame.standard_id() == Some(cob_id) {
            return Ok(frame);
        }
    }
}
