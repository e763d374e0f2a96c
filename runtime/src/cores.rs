//! The protocol cores, sans-IO: each is fed received frames and the current
//! time and hands out the frames to send, its events and its next deadline
//! through [`crate::Service`]. No core does I/O or reads a clock; the
//! drivers in `src/drivers/` and any caller of their own run them.
//!
//! The modules are re-exported at the crate root, where their documentation is.

#[cfg(feature = "alloc")]
pub mod boot;
pub mod cia402;
pub mod emcy;
pub(crate) mod error_control;
pub mod guarding;
pub mod heartbeat;
pub mod lss;
#[cfg(feature = "alloc")]
pub mod master;
pub mod nmt;
pub mod pdo;
pub mod sdo;
pub mod sync;
#[cfg(test)]
pub(crate) mod testing;
pub mod time_stamp;
