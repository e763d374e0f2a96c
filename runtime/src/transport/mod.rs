//! Transports: where frames come from and go to (std only).

use core::time::Duration;
use std::io;

use crate::Frame;

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
