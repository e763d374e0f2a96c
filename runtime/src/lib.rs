//! eds2rust-runtime: the thin CANopen runtime that generated drivers talk through.
//!
//! - [`od`]: the object-dictionary traits and types that generated code
//!   implements (entries as zero-sized types with type-level access rights,
//!   value conversion, PDO structs, node ids). Needs only `core`.
//! - [`frame`], [`time`]: classic CAN frames, CANopen identifiers, and the
//!   caller-supplied monotonic clock of the protocol cores ([`time`] is not
//!   the TIME service; that is [`time_stamp`]).
//! - Protocol cores, sans-IO (fed frames and the current time; they return
//!   frames to send, events and their next deadline through [`Service`]):
//!   [`sdo`] (client and server: expedited, segmented, block), [`nmt`]
//!   (master and slave), [`heartbeat`] (producer and consumer), [`guarding`]
//!   (node guarding, both sides), [`emcy`] (consumer, error tables), [`sync`]
//!   (producer and consumer), [`time_stamp`] (the TIME service: producer,
//!   consumer and the TIME_OF_DAY codec), [`pdo`] (RPDO transmitter, TPDO
//!   receiver, mapping configuration over SDO), [`lss`] (CiA 305 master and
//!   slave), [`cia402`] (drive helper and device state machine).
//! - With `std`: [`transport`] (the virtual bus, candump logs, fault
//!   injection, SocketCAN, `embedded-can`) and the drivers [`blocking`] and,
//!   with `tokio`, `tokio`.
//!
//! Features: `std` (default) and `alloc` (SDO buffers); `tokio`,
//! `socketcan` (Linux) and `embedded-can` for the transports.
#![cfg_attr(not(test), no_std)]
// No `unsafe` anywhere: the SocketCAN and embedded-can adapters use safe
// crate APIs (`socketcan`, `embedded-can`), so nothing needs an exception.
#![forbid(unsafe_code)]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(all(feature = "std", not(test)))]
extern crate std;

#[cfg(feature = "alloc")]
pub mod boot;
pub mod cia402;
pub mod emcy;
mod error_control;
pub mod frame;
pub mod guarding;
pub mod heartbeat;
pub mod lss;
#[cfg(feature = "alloc")]
pub mod master;
pub mod nmt;
pub mod od;
pub mod pdo;
mod queue;
pub mod sdo;
pub mod sync;
pub mod time;
pub mod time_stamp;

#[cfg(feature = "std")]
pub mod blocking;
#[cfg(feature = "tokio")]
pub mod tokio;
#[cfg(feature = "std")]
pub mod transport;

/// `#[derive(Pdo)]`: a custom PDO mapping as a struct of mapped entries
/// (docs/custom-pdos.md).
#[cfg(feature = "derive")]
pub use eds2rust_derive::Pdo;
pub use frame::{CanId, Frame};
pub use time::{Deadline, Instant};
pub use time_stamp::{TimeDifference, TimeOfDay};

/// The interface every sans-IO protocol core offers (the style of
/// quinn-proto): the caller feeds received frames and the current time, then
/// drains frames to send and events, and calls [`Service::handle_timeout`]
/// once the clock reaches [`Service::poll_timeout`].
///
/// Cores ignore frames that are not theirs, so a driver may feed every frame
/// on the bus to every core.
pub trait Service {
    type Event;
    /// A frame was received at `now`.
    fn handle_frame(&mut self, now: Instant, frame: &Frame);
    /// The clock reached (or passed) the deadline of [`Service::poll_timeout`].
    fn handle_timeout(&mut self, now: Instant);
    /// The next frame to send, if any. Call until `None` after every input.
    fn poll_transmit(&mut self) -> Option<Frame>;
    /// The next event, if any. Call until `None` after every input.
    fn poll_event(&mut self) -> Option<Self::Event>;
    /// The earliest instant at which [`Service::handle_timeout`] must be called.
    fn poll_timeout(&self) -> Option<Instant>;
}
