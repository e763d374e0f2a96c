//! eds2rust-runtime: the thin CANopen runtime that generated drivers talk through.
//!
//! The source tree shows the sans-IO design: protocol cores that never do I/O,
//! drivers that run them over a bus and a clock, and the buses themselves.
//! Every module keeps its short path (`eds2rust_runtime::heartbeat`, not
//! `…::cores::heartbeat`); the folders are how the source is kept.
//!
//! | folder | modules | needs |
//! |---|---|---|
//! | `src/` (root) | [`od`] object-dictionary traits and types that generated code implements (entries as zero-sized types with type-level access rights, value conversion, PDO structs, node ids); [`frame`] classic CAN frames and CANopen identifiers; [`time`] the caller-supplied monotonic clock of the cores (not the TIME service, that is [`time_stamp`]) | `core` |
//! | `src/cores/` | the protocol cores, fed frames and the current time, giving frames to send, events and their next deadline through [`Service`]: [`sdo`] (client and server: expedited, segmented, block), [`nmt`] (master and slave), [`heartbeat`] (producer and consumer), [`guarding`] (node guarding, both sides), [`emcy`] (consumer, error tables), [`sync`] (producer and consumer), [`time_stamp`] (the TIME service and the TIME_OF_DAY codec), [`pdo`] (RPDO transmitter, TPDO receiver, mapping configuration over SDO), [`lss`] (CiA 305 master and slave), [`cia402`] (drive helper and device state machine); with `alloc`, `master` (all of a master's cores behind one `Service`) and `boot` (the CiA 302-2 boot of a network) | `core` (`alloc` where named) |
//! | `src/drivers/` | `blocking` and, with `tokio`, `tokio`: the cores run over a bus and a clock, one call per request | `std` |
//! | `src/transport/` | `transport`: the [`Bus`](transport::Bus) traits, clocks, the virtual bus, fault injection, SocketCAN (`socketcan`) and `embedded-can` adapters | `std` |
//! | `src/trace/` | `trace`: recorded trace files, the `candump` log and text forms and PEAK-System `.trc`, read and written (the decoder reads through it too) | `std` |
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

mod cores;
#[cfg(feature = "std")]
mod drivers;
pub mod frame;
pub mod od;
mod queue;
pub mod time;
#[cfg(feature = "std")]
pub mod trace;
#[cfg(feature = "std")]
pub mod transport;

use cores::error_control;
#[cfg(feature = "alloc")]
pub use cores::{boot, master};
pub use cores::{cia402, emcy, guarding, heartbeat, lss, nmt, pdo, sdo, sync, time_stamp};
#[cfg(feature = "std")]
pub use drivers::blocking;
#[cfg(feature = "tokio")]
pub use drivers::tokio;

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
///
/// Only [`Service::handle_frame`] must be written; the other methods'
/// defaults are those of a core without that side (no timers, nothing to
/// send, no events), so a core that only listens, or only sends, says just
/// what it does.
pub trait Service {
    type Event;
    /// A frame was received at `now`.
    fn handle_frame(&mut self, now: Instant, frame: &Frame);
    /// The clock reached (or passed) the deadline of [`Service::poll_timeout`].
    /// Default: nothing happens (no timers).
    fn handle_timeout(&mut self, now: Instant) {
        let _ = now;
    }
    /// The next frame to send, if any. Call until `None` after every input.
    /// Default: `None` (the core never sends).
    fn poll_transmit(&mut self) -> Option<Frame> {
        None
    }
    /// The next event, if any. Call until `None` after every input.
    /// Default: `None` (the core reports nothing).
    fn poll_event(&mut self) -> Option<Self::Event> {
        None
    }
    /// The earliest instant at which [`Service::handle_timeout`] must be called.
    /// Default: `None` (no timers).
    fn poll_timeout(&self) -> Option<Instant> {
        None
    }
}
