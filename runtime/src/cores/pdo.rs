//! PDO: process data objects (CiA 301), master side.
//!
//! The master transmits the devices' RPDOs and receives their TPDOs:
//! - [`PdoTransmitter`]: one PDO the master sends, with the CiA 301
//!   transmission types (synchronous acyclic and cyclic, paced by SYNC
//!   frames; event-driven with inhibit time and event timer).
//! - [`PdoReceiver`]: a fixed number of PDOs the master listens to; it keeps
//!   the last data of each, reports length errors and reception timeouts,
//!   and decodes generated [`crate::od::Pdo`] structs.
//! - [`PdoConfig`]: the SDO writes that configure a PDO's mapping and
//!   communication parameters in the order CiA 301 prescribes, with the
//!   read-backs that verify them, as a plan of [`Step`]s that a
//!   [`ConfigSession`] runs without I/O; with `std`,
//!   [`blocking::configure_pdo`] runs it over a blocking SDO client, and
//!   both masters run it for a node.
//!
//! The cores need only `core` and allocate nothing.
//!
//! A PDO's COB-ID entry (sub 1 of the communication parameter) is a
//! [`PdoCobId`]; the identifier its frames carry on the bus is a
//! [`CanId`](crate::CanId), 11-bit or 29-bit.

mod config;
#[doc(hidden)]
pub mod derive;
mod error;
pub mod layout;
mod receiver;
#[cfg(test)]
mod test_pdos;
mod transmitter;

#[cfg(feature = "std")]
pub mod blocking;

pub use crate::od::standard::{CobIdError, PdoCobId, TransmissionType};
pub use config::{
    ConfigAction, ConfigCheckError, ConfigSession, MAX_ENTRIES, PdoConfig, ReadBackMismatch, Step,
    StepAction, StepKind, Steps,
};
pub use error::PdoError;
pub use receiver::{PdoEvent, PdoReceiver, RECEIVER_EVENTS, WatchError};
pub use transmitter::{PdoTransmitter, TransmitterConfig, TransmitterConfigError};

/// The default COB-ID of `P` for `node`, or the error that says it has none.
#[cfg(feature = "std")]
pub(crate) fn default_cob_id<P: crate::od::Pdo>(
    node: crate::od::NodeId,
) -> Result<PdoCobId, PdoError> {
    P::default_cob_id(node).ok_or(PdoError::NoDefaultCobId {
        node,
        direction: P::DIRECTION,
        number: P::NUMBER,
    })
}
