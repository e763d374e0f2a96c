//! The protocol cores, sans-IO: each is fed received frames and the current
//! time and hands out the frames to send, its events and its next deadline
//! through [`crate::Service`]. No core does I/O or reads a clock; the
//! drivers in `src/drivers/` and any caller of their own run them.
//!
//! The modules are re-exported at the crate root, where their documentation is.

/// `Default` for the cores whose default is their `new()` (a `const fn`,
/// which `Default::default` cannot be): the one place that says so.
macro_rules! default_is_new {
    ($core:ty) => {
        impl Default for $core {
            fn default() -> Self {
                <$core>::new()
            }
        }
    };
}

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
