//! The blocking master's PDO calls on the virtual bus: `send_pdo` sends a
//! typed RPDO, `next_pdo` and `latest_pdo` receive typed TPDOs. The device
//! side is a port the test drives itself.

#[macro_use]
mod support;

use std::time::Duration;

use eds2rust_runtime::blocking::{Error, Master};
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::od::{self, NodeId, PdoDirection, PdoLengthError};
use eds2rust_runtime::pdo::{PdoCobId, PdoError, PdoEvent, TransmissionType, TransmitterConfig};
use eds2rust_runtime::sync::SyncProducer;
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use eds2rust_runtime::{CanId, Frame};
use support::node;

const DEVICE: u8 = 0x20;

word_pdo!(Command, Rpdo, 0x1400, 0x200, 0x2001_0010);
word_pdo!(Status, Tpdo, 0x1800, 0x180, 0x2001_0010);

/// A PDO above the fourth: no default COB-ID.
struct Fifth;

impl od::Pdo for Fifth {
    const DIRECTION: PdoDirection = PdoDirection::Rpdo;
    const NUMBER: u16 = 5;
    const COMMUNICATION_INDEX: u16 = 0x1404;
    const MAPPING_INDEX: u16 = 0x1604;
    const LEN: usize = 0;
    const MAPPING: &'static [u32] = &[];
    fn default_cob_id(_: NodeId) -> Option<PdoCobId> {
        None
    }
    fn decode(_: &[u8]) -> Result<Self, PdoLengthError> {
        Ok(Fifth)
    }
    fn encode_into(&self, _: &mut [u8; 8]) -> usize {
        0
    }
}

/// The master (node 1, no heartbeat) and the device's port.
fn rig(configure: impl FnOnce(&mut master::Master)) -> (Master<VirtualPort>, VirtualPort) {
    let bus = VirtualBus::new();
    let device = bus.attach();
    let mut core = master::Master::new(node(1), None);
    configure(&mut core);
    let mut m = Master::new(bus.attach(), core);
    m.start().unwrap();
    // The boot-up message.
    assert_eq!(device.try_recv().unwrap().to_string(), "701#00");
    (m, device)
}

#[test]
fn send_pdo_sends_the_typed_rpdo_on_its_default_cob_id() {
    let (mut m, device) = rig(|_| {});
    m.send_pdo(node(DEVICE), &Command(0x1234)).unwrap();
    assert_eq!(device.try_recv().unwrap().to_string(), "220#3412");
    // The transmitter added for it is event-driven: every call sends.
    m.send_pdo(node(DEVICE), &Command(0x0001)).unwrap();
    assert_eq!(device.try_recv().unwrap().to_string(), "220#0100");
    assert_eq!(m.core().pdo_tx.len(), 1);
    // Another COB-ID: a 29-bit one.
    let extended = PdoCobId::new(CanId::Extended(0x0123_4567));
    m.send_pdo_on(extended, &Command(0xBEEF)).unwrap();
    assert_eq!(device.try_recv().unwrap().to_string(), "01234567#EFBE");
    assert!(matches!(
        m.send_pdo(node(DEVICE), &Fifth),
        Err(Error::Pdo(PdoError::NoDefaultCobId { number: 5, .. }))
    ));
}

#[test]
fn send_pdo_sets_a_synchronous_transmitter_sent_at_its_sync() {
    let (mut m, device) = rig(|core| {
        core.add_pdo_tx(TransmitterConfig::new(
            Command::default_cob_id_of(node(DEVICE)),
            TransmissionType::SynchronousAcyclic,
        ))
        .unwrap();
        core.sync = Some(SyncProducer::new(Some(Duration::from_millis(5)), None).unwrap());
    });
    m.send_pdo(node(DEVICE), &Command(7)).unwrap();
    assert_eq!(device.try_recv(), None, "a synchronous PDO waits for SYNC");
    // The master runs its cores: the next SYNC, then the PDO, once.
    m.run_for(Duration::from_millis(12)).unwrap();
    let frames: Vec<String> = std::iter::from_fn(|| device.try_recv())
        .map(|f| f.to_string())
        .collect();
    assert_eq!(
        frames.get(..2),
        Some(&["080#".to_string(), "220#0700".to_string()][..]),
        "{frames:?}"
    );
    assert!(frames[2..].iter().all(|f| f == "080#"), "{frames:?}");
    assert_eq!(m.core().pdo_tx.len(), 1);
}

#[test]
fn next_pdo_returns_the_next_typed_tpdo() {
    let (mut m, device) = rig(|_| {});
    // Frames waiting on the master's port are taken in by the call.
    device.transmit(&Frame::new(CanId::Standard(0x1A0), &[0x34, 0x12]).unwrap());
    assert_eq!(
        m.next_pdo::<Status>(node(DEVICE), Duration::from_secs(2))
            .unwrap(),
        Status(0x1234)
    );
    // The event was taken: it is not queued again.
    assert!(
        !m.drain_events()
            .any(|e| matches!(e, MasterEvent::Pdo(PdoEvent::Received { .. })))
    );
    assert_eq!(
        m.latest_pdo::<Status>(node(DEVICE)).unwrap(),
        Some(Status(0x1234))
    );
    // Another length: an error that names the identifier.
    device.transmit(&Frame::new(CanId::Standard(0x1A0), &[1, 2, 3]).unwrap());
    match m.next_pdo::<Status>(node(DEVICE), Duration::from_secs(2)) {
        Err(Error::Pdo(PdoError::Length { can_id, error })) => {
            assert_eq!(can_id, CanId::Standard(0x1A0));
            assert_eq!((error.expected, error.actual), (2, 3));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn next_pdo_times_out_and_latest_pdo_is_none_before_the_first() {
    let (mut m, device) = rig(|_| {});
    assert_eq!(m.latest_pdo::<Status>(node(DEVICE)).unwrap(), None);
    // Another identifier does not count.
    device.transmit(&Frame::new(CanId::Standard(0x1A1), &[1, 2]).unwrap());
    let waited = Duration::from_millis(20);
    match m.next_pdo::<Status>(node(DEVICE), waited) {
        Err(Error::Pdo(PdoError::Timeout { can_id, waited: w })) => {
            assert_eq!((can_id, w), (CanId::Standard(0x1A0), waited));
        }
        other => panic!("{other:?}"),
    }
}

/// The default COB-ID of a PDO struct, read through the trait.
trait DefaultCobId {
    fn default_cob_id_of(node: NodeId) -> PdoCobId;
}

impl<P: od::Pdo> DefaultCobId for P {
    fn default_cob_id_of(node: NodeId) -> PdoCobId {
        P::default_cob_id(node).unwrap()
    }
}
