//! The drivers: the protocol cores run over a bus ([`crate::transport`]) and a
//! clock, one call per request. `blocking` needs `std`; `tokio` the feature of
//! that name. Both are thin: the protocol rules live in the cores, and what
//! the two drivers share lives in the cores' helpers, not here twice.
//!
//! The modules are re-exported at the crate root, where their documentation is.

pub mod blocking;
#[cfg(feature = "tokio")]
pub mod tokio;
