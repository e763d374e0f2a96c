//! Adapters from `embedded-can` devices to [`Bus`] (feature `embedded-can`).
//!
//! - [`EmbeddedBus`] wraps a blocking device (`embedded_can::blocking::Can`).
//!   That trait has no timeout, so [`Bus::recv`] waits as long as the
//!   device's `receive` does; prefer [`EmbeddedNbBus`] when the device can
//!   poll.
//! - [`EmbeddedNbBus`] wraps a non-blocking device (`embedded_can::nb::Can`)
//!   and polls it, sleeping [`EmbeddedNbBus::poll_interval`] between tries,
//!   until the timeout.
//!
//! Frames the device receives that are no classic CAN frame (a data or
//! remote length above 8, as CAN FD devices may report) are skipped. Device
//! errors become `io::Error`s of kind `Other` carrying [`DeviceError`].

use core::fmt;
use core::time::Duration;
use std::format;
use std::io;
use std::string::String;

use embedded_can::{ExtendedId, Id, StandardId};

use super::Bus;
use crate::{CanId, Frame};

/// Time [`EmbeddedNbBus`] sleeps between two polls unless set otherwise.
pub const DEFAULT_POLL_INTERVAL: Duration = Duration::from_micros(200);

/// Time [`EmbeddedNbBus`] keeps trying to queue a frame for sending unless
/// set otherwise.
pub const DEFAULT_SEND_TIMEOUT: Duration = Duration::from_millis(100);

/// An error a device reported, as carried inside an `io::Error`.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct DeviceError {
    /// The kind the device gave.
    pub kind: embedded_can::ErrorKind,
    /// The device's own error, as `Debug` text.
    pub detail: String,
}

impl fmt::Display for DeviceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "CAN device error: {} ({})", self.kind, self.detail)
    }
}

impl std::error::Error for DeviceError {}

fn device_error<E: embedded_can::Error>(error: E) -> io::Error {
    io::Error::other(DeviceError {
        kind: error.kind(),
        detail: format!("{error:?}"),
    })
}

/// Our identifier as an `embedded-can` one.
pub fn to_embedded_id(id: CanId) -> Id {
    match id {
        CanId::Standard(raw) => match StandardId::new(raw) {
            Some(id) => Id::Standard(id),
            // `CanId` values built by this crate are in range; a raw
            // out-of-range value keeps its low 11 bits.
            None => Id::Standard(StandardId::new(raw & 0x7FF).unwrap_or(StandardId::ZERO)),
        },
        CanId::Extended(raw) => match ExtendedId::new(raw) {
            Some(id) => Id::Extended(id),
            None => Id::Extended(ExtendedId::new(raw & 0x1FFF_FFFF).unwrap_or(ExtendedId::ZERO)),
        },
    }
}

/// An `embedded-can` identifier as ours.
pub fn from_embedded_id(id: Id) -> CanId {
    match id {
        Id::Standard(id) => CanId::Standard(id.as_raw()),
        Id::Extended(id) => CanId::Extended(id.as_raw()),
    }
}

/// Our frame as a device frame; `None` when the device type refuses it.
pub fn to_embedded<F: embedded_can::Frame>(frame: &Frame) -> Option<F> {
    let id = to_embedded_id(frame.id());
    if frame.is_remote() {
        F::new_remote(id, frame.len())
    } else {
        F::new(id, frame.data())
    }
}

/// A device frame as ours; `None` for frames that are no classic CAN frame.
pub fn from_embedded<F: embedded_can::Frame>(frame: &F) -> Option<Frame> {
    let id = from_embedded_id(frame.id());
    if frame.is_remote_frame() {
        Frame::remote(id, u8::try_from(frame.dlc()).ok()?).ok()
    } else {
        Frame::new(id, frame.data()).ok()
    }
}

fn refused(frame: &Frame) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("the CAN device's frame type cannot hold {frame}"),
    )
}

/// A [`Bus`] over a blocking `embedded-can` device.
#[derive(Debug)]
pub struct EmbeddedBus<D> {
    device: D,
}

impl<D> EmbeddedBus<D> {
    /// Wraps `device`.
    pub fn new(device: D) -> EmbeddedBus<D> {
        EmbeddedBus { device }
    }

    /// The device.
    pub fn device(&mut self) -> &mut D {
        &mut self.device
    }

    /// Gives the device back.
    pub fn into_inner(self) -> D {
        self.device
    }
}

impl<D: embedded_can::blocking::Can> Bus for EmbeddedBus<D> {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        let frame = to_embedded::<D::Frame>(frame).ok_or_else(|| refused(frame))?;
        self.device.transmit(&frame).map_err(device_error)
    }

    /// Waits for the device's next classic CAN frame; `timeout` is not
    /// honoured (the blocking trait has none), so this returns only when the
    /// device returns a frame or an error.
    fn recv(&mut self, _timeout: Duration) -> io::Result<Option<Frame>> {
        loop {
            let frame = self.device.receive().map_err(device_error)?;
            if let Some(frame) = from_embedded(&frame) {
                return Ok(Some(frame));
            }
        }
    }
}

/// A [`Bus`] over a non-blocking `embedded-can` device, polled with short
/// sleeps.
#[derive(Debug)]
pub struct EmbeddedNbBus<D> {
    device: D,
    poll_interval: Duration,
    send_timeout: Duration,
}

impl<D> EmbeddedNbBus<D> {
    /// Wraps `device` with the default poll interval and send timeout.
    pub fn new(device: D) -> EmbeddedNbBus<D> {
        EmbeddedNbBus {
            device,
            poll_interval: DEFAULT_POLL_INTERVAL,
            send_timeout: DEFAULT_SEND_TIMEOUT,
        }
    }

    /// Sets the sleep between two polls of the device.
    pub fn with_poll_interval(mut self, interval: Duration) -> EmbeddedNbBus<D> {
        self.poll_interval = interval;
        self
    }

    /// Sets how long [`Bus::send`] waits for room in the transmit queue
    /// before it fails with `TimedOut`.
    pub fn with_send_timeout(mut self, timeout: Duration) -> EmbeddedNbBus<D> {
        self.send_timeout = timeout;
        self
    }

    /// The sleep between two polls.
    pub fn poll_interval(&self) -> Duration {
        self.poll_interval
    }

    /// The device.
    pub fn device(&mut self) -> &mut D {
        &mut self.device
    }

    /// Gives the device back.
    pub fn into_inner(self) -> D {
        self.device
    }

    /// Sleeps one poll interval, or less when `deadline` is nearer; `false`
    /// when the deadline has passed.
    fn pause(&self, deadline: Option<std::time::Instant>) -> bool {
        let now = std::time::Instant::now();
        let nap = match deadline {
            Some(deadline) if deadline <= now => return false,
            Some(deadline) => self.poll_interval.min(deadline - now),
            None => self.poll_interval,
        };
        std::thread::sleep(nap);
        true
    }
}

impl<D: embedded_can::nb::Can> Bus for EmbeddedNbBus<D> {
    /// Queues the frame, waiting up to the send timeout for room. A frame
    /// the device pushes out of its queue to make room (a lower-priority
    /// one) is queued again, so nothing sent is lost.
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        let deadline = std::time::Instant::now().checked_add(self.send_timeout);
        let mut pending = Some(to_embedded::<D::Frame>(frame).ok_or_else(|| refused(frame))?);
        while let Some(next) = pending.take() {
            match self.device.transmit(&next) {
                Ok(displaced) => {
                    let late = deadline.is_some_and(|d| std::time::Instant::now() >= d);
                    if displaced.is_some() && late {
                        return Err(io::Error::new(
                            io::ErrorKind::TimedOut,
                            "the CAN device kept displacing queued frames",
                        ));
                    }
                    pending = displaced;
                }
                Err(nb::Error::WouldBlock) => {
                    if !self.pause(deadline) {
                        return Err(io::Error::new(
                            io::ErrorKind::TimedOut,
                            "the CAN device's transmit queue stayed full",
                        ));
                    }
                    pending = Some(next);
                }
                Err(nb::Error::Other(e)) => return Err(device_error(e)),
            }
        }
        Ok(())
    }

    /// Polls the device until a classic CAN frame comes or `timeout` passes.
    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        let deadline = std::time::Instant::now().checked_add(timeout);
        loop {
            match self.device.receive() {
                Ok(frame) => {
                    if let Some(frame) = from_embedded(&frame) {
                        return Ok(Some(frame));
                    }
                    if deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                        return Ok(None);
                    }
                }
                Err(nb::Error::WouldBlock) => {
                    if !self.pause(deadline) {
                        return Ok(None);
                    }
                }
                Err(nb::Error::Other(e)) => return Err(device_error(e)),
            }
        }
    }
}

#[cfg(test)]
mod tests;
