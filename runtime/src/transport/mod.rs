//! Transports: where frames come from and go to (std only).
//!
//! - [`Bus`]: a blocking CAN interface; `AsyncBus` (feature `tokio`) its
//!   async counterpart.
//! - [`Clock`]: maps the std clock, tokio's clock or a [`ManualClock`]
//!   (tests) to the [`crate::Instant`] of the protocol cores.
//! - [`virtual_bus`]: an in-process CAN bus for simulators and tests, with an
//!   optional bit-time model ([`wire`] counts the bits of a frame).
//! - [`fault`]: fault injection between a core and a bus.
//! - `embedded` (feature `embedded-can`): adapters for `embedded-can` devices.
//! - `socketcan` (feature `socketcan`, Linux): SocketCAN sockets.

use core::time::Duration;
use std::io;

use crate::Frame;

pub mod clock;
#[cfg(feature = "embedded-can")]
pub mod embedded;
pub mod fault;
#[cfg(all(feature = "socketcan", target_os = "linux"))]
pub mod socketcan;
pub mod virtual_bus;
pub mod wire;

pub use clock::{Clock, ManualClock};

/// A blocking CAN interface: SocketCAN, an `embedded-can` device, a port of
/// the virtual bus, or a test peer.
pub trait Bus {
    /// Sends one frame.
    fn send(&mut self, frame: &Frame) -> io::Result<()>;
    /// Waits up to `timeout` for the next frame; `Ok(None)` when none came.
    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>>;
}

impl<B: Bus + ?Sized> Bus for &mut B {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        (**self).send(frame)
    }
    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        (**self).recv(timeout)
    }
}

/// An asynchronous CAN interface (feature `tokio`): a port of the virtual
/// bus, or a SocketCAN socket registered with tokio.
///
/// [`AsyncBus::recv`] must be cancel-safe: when its future is dropped before
/// it completed (for example because another branch of a `select!` won), no
/// frame is lost; the next call returns the frame the dropped one would have.
#[cfg(feature = "tokio")]
pub trait AsyncBus {
    /// Sends one frame.
    fn send(&mut self, frame: &Frame) -> impl Future<Output = io::Result<()>> + Send;
    /// Waits for the next frame. Cancel-safe (see the trait documentation).
    fn recv(&mut self) -> impl Future<Output = io::Result<Frame>> + Send;
}

#[cfg(feature = "tokio")]
impl<B: AsyncBus + ?Sized> AsyncBus for &mut B {
    fn send(&mut self, frame: &Frame) -> impl Future<Output = io::Result<()>> + Send {
        (**self).send(frame)
    }
    fn recv(&mut self) -> impl Future<Output = io::Result<Frame>> + Send {
        (**self).recv()
    }
}
