//! The blocking composite master over the virtual bus, against a device
//! made of the runtime's SDO server, NMT slave and heartbeat producer
//! (node 0x20) served in a thread, with a monitor port recording every
//! frame and when it was seen.

#[macro_use]
mod support;

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::thread;
use std::time::{Duration, Instant as StdInstant};

use eds2rust_runtime::blocking::{self, Error, Master};
use eds2rust_runtime::emcy::EmcyEvent;
use eds2rust_runtime::heartbeat::HeartbeatEvent;
use eds2rust_runtime::lss::LssState;
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::nmt::{NmtCommand, NmtEvent, NmtState};
use eds2rust_runtime::od::{AccessRight, PdoDirection};
use eds2rust_runtime::pdo::{PdoCobId, PdoConfig, PdoEvent, TransmissionType};
use eds2rust_runtime::sdo::client::Method;
use eds2rust_runtime::sdo::server::{MemoryStore, ObjectStore};
use eds2rust_runtime::sdo::{AbortCode, SdoError};
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use eds2rust_runtime::{CanId, Frame, Instant};
use support::{BasicDevice, node};

const DEVICE: u8 = 0x20;
/// The master's heartbeat period.
const PERIOD: Duration = Duration::from_millis(20);
/// How long the device takes to read its slow object unless released.
const SLOW: Duration = Duration::from_millis(300);

entry!(ProducerHeartbeatTime, 0x1017, 0, Unsigned16, Rw, u16);

entry!(SlowValue, 0x2000, 1, Unsigned32, Ro, u32);

entry!(
    Blob,
    0x2100,
    0,
    Domain,
    Rw,
    eds2rust_runtime::od::bytes::Domain
);

/// A memory store whose object 0x2000:01 takes [`SLOW`] to read, or less
/// when released: it tells `started` when the read begins, then answers
/// when `release` says so or [`SLOW`] has passed.
struct SlowStore {
    store: MemoryStore,
    started: mpsc::Sender<()>,
    release: mpsc::Receiver<()>,
}

impl ObjectStore for SlowStore {
    fn read(&mut self, index: u16, sub: u8, out: &mut Vec<u8>) -> Result<(), AbortCode> {
        if (index, sub) == (0x2000, 1) {
            let _ = self.started.send(());
            let _ = self.release.recv_timeout(SLOW);
        }
        self.store.read(index, sub, out)
    }
    fn check_write(&mut self, index: u16, sub: u8, size: Option<usize>) -> Result<(), AbortCode> {
        self.store.check_write(index, sub, size)
    }
    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode> {
        self.store.write(index, sub, data)
    }
}

/// The bus, the master on it, and the device and monitor threads.
struct Rig {
    bus: VirtualBus,
    master: Master<VirtualPort>,
    frames: Arc<Mutex<Vec<(StdInstant, Frame)>>>,
    /// Told when the device begins reading its slow object.
    slow_read_started: Option<mpsc::Receiver<()>>,
    /// Lets the slow read answer at once.
    release_slow_read: mpsc::Sender<()>,
    stop: Arc<AtomicBool>,
    threads: Vec<thread::JoinHandle<()>>,
}

impl Rig {
    fn new() -> Rig {
        let bus = VirtualBus::new();
        let stop = Arc::new(AtomicBool::new(false));
        let frames = Arc::new(Mutex::new(Vec::new()));
        let mut threads = Vec::new();

        let monitor = bus.attach();
        let (record, halt) = (frames.clone(), stop.clone());
        threads.push(thread::spawn(move || {
            while !halt.load(Ordering::Relaxed) {
                if let Some(frame) = monitor.recv_timeout(Duration::from_millis(5)) {
                    record.lock().unwrap().push((StdInstant::now(), frame));
                }
            }
        }));

        // The master's port is attached before the device starts, or the
        // device's boot-up can go out before anyone listens.
        let master_port = bus.attach();
        let mut port = bus.attach();
        let halt = stop.clone();
        let (started, slow_read_started) = mpsc::channel();
        let (release_slow_read, release) = mpsc::channel();
        threads.push(thread::spawn(move || {
            let mut store = MemoryStore::new();
            store.insert_fixed(0x1017, 0, AccessRight::Rw, &50u16.to_le_bytes());
            store.insert_fixed(0x2000, 1, AccessRight::Ro, &0xCAFE_F00Du32.to_le_bytes());
            for sub in [1, 2] {
                store.insert_fixed(0x1800, sub, AccessRight::Rw, &[0; 4][..sub_len(sub)]);
            }
            store.insert_fixed(0x1A00, 0, AccessRight::Rw, &[0]);
            store.insert_fixed(0x1A00, 1, AccessRight::Rw, &[0; 4]);
            store.insert(0x2100, 0, AccessRight::Rw, &[]);
            let clock = Clock::new();
            let slow = SlowStore {
                store,
                started,
                release,
            };
            let mut device = BasicDevice::new(node(DEVICE), slow, clock.now());
            blocking::serve(&mut port, &clock, &mut device, &halt, None, |()| {}).unwrap();
        }));

        let mut core = master::Master::new(node(1), Some(PERIOD));
        core.consumer
            .monitor(node(DEVICE), Some(Duration::from_millis(200)));
        let mut master = Master::new(master_port, core);
        master.start().unwrap();
        Rig {
            bus,
            master,
            frames,
            slow_read_started: Some(slow_read_started),
            release_slow_read,
            stop,
            threads,
        }
    }

    /// The frames seen so far with `cob_id`, with when they were seen.
    fn seen(&self, cob_id: u16) -> Vec<(StdInstant, Frame)> {
        let frames = self.frames.lock().unwrap();
        frames
            .iter()
            .filter(|(_, f)| f.standard_id() == Some(cob_id))
            .copied()
            .collect()
    }
}

impl Drop for Rig {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// Sub 1 (COB-ID) of 0x1800 has 4 bytes, sub 2 (transmission type) one.
fn sub_len(sub: u8) -> usize {
    if sub == 2 { 1 } else { 4 }
}

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

#[test]
fn heartbeat_keeps_its_period_during_a_slow_sdo_read() {
    let mut rig = Rig::new();
    let start = StdInstant::now();
    assert_eq!(
        rig.master.read::<SlowValue>(node(DEVICE)).unwrap(),
        0xCAFE_F00D
    );
    let end = StdInstant::now();
    assert!(end - start >= SLOW);

    let beats: Vec<_> = rig.seen(0x701);
    // Boot-up first, then heartbeats reporting Pre-operational (0x7F).
    assert_eq!(beats[0].1, frame(0x701, &[0x00]));
    let during: Vec<_> = beats
        .iter()
        .filter(|(at, _)| *at > start && *at <= end)
        .collect();
    assert!(
        during.len() >= 12,
        "{} heartbeats in {:?}",
        during.len(),
        end - start
    );
    for pair in during.windows(2) {
        assert_eq!(pair[1].1, frame(0x701, &[0x7F]));
        let gap = pair[1].0 - pair[0].0;
        assert!(gap <= PERIOD + Duration::from_millis(15), "gap {gap:?}");
    }

    // Typed write and read back of 0x1017 (expedited, 2 bytes).
    rig.master
        .write::<ProducerHeartbeatTime>(node(DEVICE), 250)
        .unwrap();
    assert_eq!(
        rig.master
            .read::<ProducerHeartbeatTime>(node(DEVICE))
            .unwrap(),
        250
    );
    // A missing object: the device's abort 0x06020000 comes back.
    let e = rig.master.upload(node(DEVICE), 0x2001, 0).unwrap_err();
    assert!(matches!(
        e,
        Error::Sdo {
            error: SdoError::RemoteAbort(AbortCode::ObjectDoesNotExist),
            ..
        }
    ));
}

#[test]
fn nmt_command_bytes_and_the_state_the_node_reports() {
    let mut rig = Rig::new();
    rig.master.nmt(NmtCommand::Start, node(DEVICE)).unwrap();
    let deadline = StdInstant::now() + Duration::from_secs(1);
    let to = rig
        .master
        .run_until(deadline, |event| match event {
            MasterEvent::Nmt(NmtEvent::StateChanged { node: n, to, .. })
                if n.get() == DEVICE && *to == NmtState::Operational =>
            {
                ControlFlow::Break(*to)
            }
            _ => ControlFlow::Continue(()),
        })
        .unwrap();
    assert_eq!(to, NmtState::Operational);
    // CiA 301 NMT start remote node: command 0x01, node 0x20.
    let nmt = rig.seen(0x000);
    assert_eq!(nmt.len(), 1);
    assert_eq!(nmt[0].1.to_string(), "000#0120");
    assert_eq!(
        rig.master.core().nmt.state(node(DEVICE)),
        Some(NmtState::Operational)
    );
    // The monitor records on its own thread: the heartbeat the master has
    // just seen may reach its log a moment later.
    let deadline = StdInstant::now() + Duration::from_secs(1);
    while !rig.seen(0x720).iter().any(|(_, f)| f.data() == [0x05]) {
        assert!(
            StdInstant::now() < deadline,
            "no operational heartbeat 0x720#05 on the bus"
        );
        thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_pdo_received_during_an_sdo_transfer_is_kept_and_queued() {
    let mut rig = Rig::new();
    rig.master
        .core_mut()
        .pdo_rx
        .watch(PdoCobId(0x1A0), 2, None)
        .unwrap();
    // Another node sends its TPDO1 (0x1A0) while the slow read runs; the
    // device answers the read only after that.
    let sender = rig.bus.attach();
    let started = rig.slow_read_started.take().unwrap();
    let release = rig.release_slow_read.clone();
    let pdo = thread::spawn(move || {
        started.recv().unwrap();
        sender.transmit(&frame(0x1A0, &[0x11, 0x22]));
        sender.transmit(&frame(0x721, &[0x00]));
        // EMCY 0x8110 (CAN overrun), error register 0x11.
        sender.transmit(&frame(0x0A1, &[0x10, 0x81, 0x11, 0, 0, 0, 0, 0]));
        release.send(()).unwrap();
    });
    assert_eq!(
        rig.master.read::<SlowValue>(node(DEVICE)).unwrap(),
        0xCAFE_F00D
    );
    pdo.join().unwrap();
    assert_eq!(
        rig.master.core().pdo_rx.latest_data(CanId::Standard(0x1A0)),
        Some(&[0x11, 0x22][..])
    );
    // Queued events are offered first, even with a deadline already past;
    // the one taken leaves the queue.
    let queued = rig.master.queued_events();
    let data = rig
        .master
        .run_until(StdInstant::now(), |e| match e {
            MasterEvent::Pdo(PdoEvent::Received {
                can_id: CanId::Standard(0x1A0),
                data,
                ..
            }) => ControlFlow::Break(*data),
            _ => ControlFlow::Continue(()),
        })
        .unwrap();
    assert_eq!(data[..2], [0x11, 0x22]);
    assert_eq!(rig.master.queued_events(), queued - 1);
    let events: Vec<_> = rig.master.drain_events().collect();
    // The boot-up and the EMCY of node 0x21 came during the read too;
    // neither event was lost.
    assert!(
        events.contains(&MasterEvent::Nmt(NmtEvent::BootUp(node(0x21)))),
        "{events:?}"
    );
    assert!(
        events
            .iter()
            .any(|e| matches!(e, MasterEvent::Emcy(EmcyEvent::Emergency { node: n, .. }) if n.get() == 0x21)),
        "{events:?}"
    );
    assert_eq!(rig.master.dropped_events(), 0);
    assert_eq!(rig.master.next_event(), None);
}

#[test]
fn queue_capacity_bounds_the_events_and_counts_the_dropped() {
    let mut rig = Rig::new();
    // Wait for the device's boot-up so that it does not mix in (a bound
    // only: on a loaded machine the device thread may start late).
    let deadline = StdInstant::now() + Duration::from_secs(10);
    rig.master
        .run_until(deadline, |e| match e {
            MasterEvent::Heartbeat(HeartbeatEvent::State {
                state: NmtState::BootUp,
                ..
            }) => ControlFlow::Break(()),
            _ => ControlFlow::Continue(()),
        })
        .unwrap();
    rig.master.drain_events().for_each(drop);
    rig.master.set_queue_capacity(2);
    let sender = rig.bus.attach();
    rig.master
        .core_mut()
        .pdo_rx
        .watch(PdoCobId(0x1A0), 1, None)
        .unwrap();
    for b in 1..=5 {
        sender.transmit(&frame(0x1A0, &[b]));
    }
    rig.master.run_for(Duration::from_millis(30)).unwrap();
    assert_eq!(rig.master.queued_events(), 2);
    let got: Vec<_> = rig.master.drain_events().collect();
    // The newest events stay; the three oldest were dropped and counted.
    let pdo = |b| {
        MasterEvent::Pdo(PdoEvent::Received {
            can_id: CanId::Standard(0x1A0),
            data: [b, 0, 0, 0, 0, 0, 0, 0],
            len: 1,
            at: Instant::ZERO,
        })
    };
    let got: Vec<_> = got
        .into_iter()
        .map(|e| match e {
            MasterEvent::Pdo(PdoEvent::Received {
                can_id, data, len, ..
            }) => MasterEvent::Pdo(PdoEvent::Received {
                can_id,
                data,
                len,
                at: Instant::ZERO,
            }),
            other => other,
        })
        .collect();
    assert_eq!(got, [pdo(4), pdo(5)]);
    assert_eq!(rig.master.dropped_events(), 3);
}

#[test]
fn lss_switch_global_frame() {
    let mut rig = Rig::new();
    rig.master
        .lss_switch_global(LssState::Configuration)
        .unwrap();
    rig.master.run_for(Duration::from_millis(20)).unwrap();
    // CiA 305: switch state global (cs 0x04), mode 1 = configuration.
    let lss = rig.seen(0x7E5);
    assert_eq!(lss.len(), 1);
    assert_eq!(lss[0].1.to_string(), "7E5#0401000000000000");
    // No LSS slave on this bus: a confirmed request times out.
    let e = rig.master.lss_store().unwrap_err();
    assert!(
        matches!(
            e,
            blocking::Error::Lss(blocking::LssRequestError::NoResponse)
        ),
        "{e}"
    );
}

#[test]
fn configure_pdo_runs_the_steps_through_the_master() {
    let mut rig = Rig::new();
    // TPDO1 of the device: on 0x1A0, synchronous every SYNC, mapping
    // 0x2000:01 (32 bits).
    let config = PdoConfig::new(PdoDirection::Tpdo, 1, PdoCobId(0x1A0), &[0x2000_0120])
        .unwrap()
        .with_transmission_type(TransmissionType::from_raw(1));
    rig.master.configure_pdo(node(DEVICE), &config).unwrap();
    // A mapping index outside the TPDO range: refused before anything is sent.
    let mut bad = config;
    bad.mapping_index = 0x1600;
    let e = rig.master.configure_pdo(node(DEVICE), &bad).unwrap_err();
    assert!(
        e.to_string().starts_with("invalid PDO configuration"),
        "{e}"
    );
}

#[test]
fn streamed_entries_go_through_the_master() {
    let mut rig = Rig::new();
    let data: Vec<u8> = (0..700u32).map(|i| (i * 13 % 251) as u8).collect();
    let mut done = 0;
    rig.master
        .write_from::<Blob>(
            node(DEVICE),
            &mut data.as_slice(),
            Some(700),
            Method::Block,
            |p| done = p.done,
        )
        .unwrap();
    assert_eq!(done, 700);
    let mut back = Vec::new();
    let n = rig
        .master
        .read_into::<Blob>(node(DEVICE), &mut back, Method::Segmented, |_| {})
        .unwrap();
    assert_eq!((n, back), (700, data));
}
