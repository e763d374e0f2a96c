//! What the runtime's integration tests share: node and frame builders,
//! hand-written object entries and 16-bit PDOs (as generated code would
//! give them), and, with `tokio`, the rig of the tokio master tests
//! ([`tokio_rig`]). Each test file takes it with `#[macro_use] mod support;`.
#![allow(dead_code, unused_macros)]

use std::time::Duration;

use eds2rust_runtime::blocking::Error;
use eds2rust_runtime::heartbeat::HeartbeatProducer;
use eds2rust_runtime::nmt::NmtSlave;
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::server::{ObjectStore, SdoServer, ServerConfig};
use eds2rust_runtime::sdo::{Channel, SdoError};
use eds2rust_runtime::{CanId, Frame, Instant, Service};

pub fn node(id: u8) -> NodeId {
    NodeId::new(id).unwrap()
}

/// A standard data frame.
pub fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

/// Hands `now` to `service` when its timer is due (the devices the tests
/// assemble from several services fire each one's timer so).
pub fn fire_due<S: Service + ?Sized>(service: &mut S, now: Instant) {
    if service.poll_timeout().is_some_and(|at| at <= now) {
        service.handle_timeout(now);
    }
}

/// The core of the devices the master tests serve: an SDO server on
/// `store` (default channel), an NMT slave, booted, and a heartbeat every
/// 50 ms that reports the NMT state, started at `now`.
pub struct BasicDevice<S> {
    pub sdo: SdoServer<S>,
    pub nmt: NmtSlave,
    pub heartbeat: HeartbeatProducer,
}

impl<S: ObjectStore> BasicDevice<S> {
    pub fn new(id: NodeId, store: S, now: Instant) -> BasicDevice<S> {
        let mut device = BasicDevice {
            sdo: SdoServer::new(ServerConfig::new(Channel::default_for(id)), store),
            nmt: NmtSlave::new(id),
            heartbeat: HeartbeatProducer::new(id, Some(Duration::from_millis(50))),
        };
        device.nmt.boot_complete();
        device.heartbeat.set_state(device.nmt.state());
        device.heartbeat.start(now);
        device
    }
}

impl<S: ObjectStore> Service for BasicDevice<S> {
    type Event = ();
    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        self.sdo.handle_frame(now, frame);
        self.nmt.handle_frame(now, frame);
        while self.nmt.poll_event().is_some() {}
        self.heartbeat.set_state(self.nmt.state());
    }
    fn handle_timeout(&mut self, now: Instant) {
        fire_due(&mut self.sdo, now);
        fire_due(&mut self.heartbeat, now);
    }
    fn poll_transmit(&mut self) -> Option<Frame> {
        self.sdo
            .poll_transmit()
            .or_else(|| self.heartbeat.poll_transmit())
    }
    fn poll_event(&mut self) -> Option<()> {
        while self.sdo.poll_event().is_some() {}
        None
    }
    fn poll_timeout(&self) -> Option<Instant> {
        eds2rust_runtime::time::earliest(self.sdo.poll_timeout(), self.heartbeat.poll_timeout())
    }
}

/// `e` is an SDO timeout.
pub fn assert_sdo_timeout(e: &Error) {
    assert!(
        matches!(
            e,
            Error::Sdo {
                error: SdoError::Timeout,
                ..
            }
        ),
        "{e}"
    );
}

/// An object entry as generated code declares it: `entry!(Name, index,
/// sub, DataType variant, access type, value type)`; its NAME is the
/// type's name.
macro_rules! entry {
    ($name:ident, $index:literal, $sub:literal, $ty:ident, $access:ident, $value:ty) => {
        pub struct $name;
        impl ::eds2rust_runtime::od::Entry for $name {
            const INDEX: u16 = $index;
            const SUBINDEX: u8 = $sub;
            const NAME: &'static str = stringify!($name);
            const DATA_TYPE: ::eds2rust_runtime::od::DataType =
                ::eds2rust_runtime::od::DataType::$ty;
            const PDO_MAPPABLE: bool = false;
            type Access = ::eds2rust_runtime::od::access::$access;
            type Value = $value;
        }
    };
}

/// A 16-bit PDO number 1 on the predefined connection set, as generated
/// code declares it: `word_pdo!(Name, Rpdo or Tpdo, communication index,
/// COB-ID base, mapping)`.
macro_rules! word_pdo {
    ($name:ident, $direction:ident, $comm:literal, $base:literal, $mapping:literal) => {
        #[derive(Debug, PartialEq)]
        pub struct $name(pub u16);

        impl ::eds2rust_runtime::od::Pdo for $name {
            const DIRECTION: ::eds2rust_runtime::od::PdoDirection =
                ::eds2rust_runtime::od::PdoDirection::$direction;
            const NUMBER: u16 = 1;
            const COMMUNICATION_INDEX: u16 = $comm;
            const MAPPING_INDEX: u16 = $comm + 0x200;
            const LEN: usize = 2;
            const MAPPING: &'static [u32] = &[$mapping];
            fn default_cob_id(
                node_id: ::eds2rust_runtime::od::NodeId,
            ) -> Option<::eds2rust_runtime::pdo::PdoCobId> {
                Some(::eds2rust_runtime::pdo::PdoCobId(
                    $base + u32::from(node_id.get()),
                ))
            }
            fn decode(data: &[u8]) -> Result<Self, ::eds2rust_runtime::od::PdoLengthError> {
                let bytes = ::eds2rust_runtime::pdo::layout::load::<2>(data)?;
                Ok($name(u16::from_le_bytes(*bytes)))
            }
            fn encode_into(&self, out: &mut [u8; 8]) -> usize {
                out[..2].copy_from_slice(&self.0.to_le_bytes());
                2
            }
        }
    };
}

// After the macros: the rig uses them.
#[cfg(feature = "tokio")]
pub mod tokio_rig;
