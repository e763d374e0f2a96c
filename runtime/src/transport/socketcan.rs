//! Linux SocketCAN (feature `socketcan`): [`SocketCanBus`] (blocking) and,
//! with the feature `tokio`, [`AsyncSocketCanBus`].
//!
//! The sockets are raw CAN sockets for classic frames. Error frames are
//! skipped (the sockets do not ask for them, and one that comes anyway is
//! not a frame on the bus), and so are CAN FD frames (a classic socket does
//! not receive them).

use core::time::Duration;
use std::format;
use std::io;
use std::string::{String, ToString};
use std::vec::Vec;

use ::socketcan::{
    CanFilter, CanFrame, EmbeddedFrame, ExtendedId, Id, Socket, SocketOptions, StandardId,
};

use super::Bus;
use crate::{CanId, Frame};

/// The flag of extended identifiers in Linux `can_id` words; filters set it
/// in their mask so that they match standard frames only.
const CAN_EFF_FLAG: u32 = 0x8000_0000;

/// Longest pause [`SocketCanBus::send`] makes in all while the kernel's
/// transmit queue is full.
const SEND_PATIENCE: Duration = Duration::from_millis(100);

fn open_error(interface: &str, error: io::Error) -> io::Error {
    io::Error::new(
        error.kind(),
        format!("cannot open CAN interface {interface:?}: {error}"),
    )
}

fn to_socketcan(frame: &Frame) -> io::Result<CanFrame> {
    let id = match frame.id() {
        CanId::Standard(raw) => StandardId::new(raw).map(Id::Standard),
        CanId::Extended(raw) => ExtendedId::new(raw).map(Id::Extended),
    };
    let converted = id.and_then(|id| {
        if frame.is_remote() {
            CanFrame::new_remote(id, frame.len())
        } else {
            CanFrame::new(id, frame.data())
        }
    });
    converted.ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{frame} is not a valid CAN frame"),
        )
    })
}

/// Our frame, or `None` for error frames.
fn from_socketcan(frame: &CanFrame) -> Option<Frame> {
    let id = match frame.id() {
        Id::Standard(id) => CanId::Standard(id.as_raw()),
        Id::Extended(id) => CanId::Extended(id.as_raw()),
    };
    match frame {
        CanFrame::Data(data) => Frame::new(id, data.data()).ok(),
        CanFrame::Remote(remote) => Frame::remote(id, u8::try_from(remote.dlc()).ok()?).ok(),
        CanFrame::Error(_) => None,
    }
}

/// Kernel filters from (COB-ID, mask) pairs: a standard frame passes when
/// `frame_id & mask == cob_id & mask` for one of the pairs; extended frames
/// never pass.
fn filters(pairs: &[(u16, u16)]) -> Vec<CanFilter> {
    pairs
        .iter()
        .map(|&(id, mask)| CanFilter::new(u32::from(id & 0x7FF), u32::from(mask) | CAN_EFF_FLAG))
        .collect()
}

/// Kernel filters that pass exactly the frames on `ids`: standard ones on
/// their 11-bit identifier, extended ones on their 29-bit identifier.
fn id_filters(ids: &[CanId]) -> Vec<CanFilter> {
    ids.iter()
        .map(|id| match *id {
            CanId::Standard(id) => CanFilter::new(u32::from(id & 0x7FF), 0x7FF | CAN_EFF_FLAG),
            CanId::Extended(id) => CanFilter::new(
                (id & 0x1FFF_FFFF) | CAN_EFF_FLAG,
                0x1FFF_FFFF | CAN_EFF_FLAG,
            ),
        })
        .collect()
}

fn set_id_filters(socket: &impl SocketOptions, ids: &[CanId]) -> io::Result<()> {
    if ids.is_empty() {
        socket.set_filter_drop_all()
    } else {
        socket.set_filters(&id_filters(ids))
    }
}

/// A blocking SocketCAN socket.
#[derive(Debug)]
pub struct SocketCanBus {
    socket: ::socketcan::CanSocket,
    interface: String,
}

impl SocketCanBus {
    /// Opens a raw CAN socket on `interface` (`can0`, `vcan0`, ...). The
    /// error names the interface.
    pub fn open(interface: &str) -> io::Result<SocketCanBus> {
        let socket =
            ::socketcan::CanSocket::open(interface).map_err(|e| open_error(interface, e))?;
        Ok(SocketCanBus {
            socket,
            interface: interface.to_string(),
        })
    }

    /// Receives only standard frames whose identifier matches one of the
    /// (COB-ID, mask) pairs (`id & mask == cob_id & mask`); an empty list
    /// receives nothing.
    pub fn set_filters(self, pairs: &[(u16, u16)]) -> io::Result<SocketCanBus> {
        set_filters(&self.socket, pairs)?;
        Ok(self)
    }

    /// Receives only the frames on `ids`, 11- or 29-bit (an SDO channel's
    /// response identifier, say); an empty list receives nothing.
    pub fn set_id_filters(self, ids: &[CanId]) -> io::Result<SocketCanBus> {
        set_id_filters(&self.socket, ids)?;
        Ok(self)
    }

    /// The interface name it was opened on.
    pub fn interface(&self) -> &str {
        &self.interface
    }

    /// The socket, for settings this type does not offer.
    pub fn socket(&self) -> &::socketcan::CanSocket {
        &self.socket
    }
}

fn set_filters(socket: &impl SocketOptions, pairs: &[(u16, u16)]) -> io::Result<()> {
    if pairs.is_empty() {
        socket.set_filter_drop_all()
    } else {
        socket.set_filters(&filters(pairs))
    }
}

/// A kernel transmit queue that is full right now.
fn queue_full(error: &io::Error) -> bool {
    error.kind() == io::ErrorKind::WouldBlock || error.raw_os_error() == Some(105) // ENOBUFS
}

impl Bus for SocketCanBus {
    /// Writes the frame; while the kernel's transmit queue is full, retries
    /// for up to 100 ms.
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        let frame = to_socketcan(frame)?;
        let mut waited = Duration::ZERO;
        loop {
            match self.socket.write_frame(&frame) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) if queue_full(&e) && waited < SEND_PATIENCE => {
                    std::thread::sleep(Duration::from_millis(1));
                    waited += Duration::from_millis(1);
                }
                other => return other,
            }
        }
    }

    /// Waits up to `timeout` (rounded up to whole milliseconds) for the next
    /// classic frame; error frames are skipped.
    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        let deadline = std::time::Instant::now().checked_add(timeout);
        loop {
            let left = match deadline {
                Some(deadline) => deadline.saturating_duration_since(std::time::Instant::now()),
                None => timeout,
            };
            let left = left.as_nanos().div_ceil(1_000_000);
            let left = Duration::from_millis(u64::try_from(left).unwrap_or(u64::MAX));
            match self.socket.read_frame_timeout(left) {
                Ok(frame) => {
                    if let Some(frame) = from_socketcan(&frame) {
                        return Ok(Some(frame));
                    }
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock
                    ) =>
                {
                    return Ok(None);
                }
                Err(e) => return Err(e),
            }
            if deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                return Ok(None);
            }
        }
    }
}

/// A SocketCAN socket registered with tokio (features `socketcan` and
/// `tokio`).
#[cfg(feature = "tokio")]
#[derive(Debug)]
pub struct AsyncSocketCanBus {
    socket: ::socketcan::tokio::CanSocket,
    interface: String,
}

#[cfg(feature = "tokio")]
impl AsyncSocketCanBus {
    /// Opens a raw CAN socket on `interface`; must be called inside a tokio
    /// runtime. The error names the interface.
    pub fn open(interface: &str) -> io::Result<AsyncSocketCanBus> {
        let socket =
            ::socketcan::tokio::CanSocket::open(interface).map_err(|e| open_error(interface, e))?;
        Ok(AsyncSocketCanBus {
            socket,
            interface: interface.to_string(),
        })
    }

    /// Same as [`SocketCanBus::set_filters`].
    pub fn set_filters(self, pairs: &[(u16, u16)]) -> io::Result<AsyncSocketCanBus> {
        set_filters(&self.socket, pairs)?;
        Ok(self)
    }

    /// Receives only the frames on `ids` (see
    /// [`SocketCanBus::set_id_filters`]).
    pub fn set_id_filters(self, ids: &[CanId]) -> io::Result<AsyncSocketCanBus> {
        set_id_filters(&self.socket, ids)?;
        Ok(self)
    }

    /// The interface name it was opened on.
    pub fn interface(&self) -> &str {
        &self.interface
    }

    /// The socket, for settings this type does not offer.
    pub fn socket(&self) -> &::socketcan::tokio::CanSocket {
        &self.socket
    }
}

/// `recv` is cancel-safe: a frame is read from the socket only in the poll
/// that returns it.
#[cfg(feature = "tokio")]
impl super::AsyncBus for AsyncSocketCanBus {
    fn send(&mut self, frame: &Frame) -> impl Future<Output = io::Result<()>> + Send {
        let frame = to_socketcan(frame);
        async move { self.socket.write_frame(frame?).await }
    }

    /// Waits for the next classic frame; error frames are skipped.
    async fn recv(&mut self) -> io::Result<Frame> {
        loop {
            let frame = self.socket.read_frame().await?;
            if let Some(frame) = from_socketcan(&frame) {
                return Ok(frame);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_interface_is_named() {
        let error = SocketCanBus::open("nosuchcan7").unwrap_err();
        assert!(error.to_string().contains("\"nosuchcan7\""), "{error}");
    }

    #[test]
    fn frames_convert_both_ways() {
        for frame in [
            Frame::new(CanId::Standard(0x701), &[0x05]).unwrap(),
            Frame::remote(CanId::Standard(0x701), 1).unwrap(),
            Frame::new(CanId::Extended(0x1ABC_DEF0), &[1, 2, 3, 4, 5, 6, 7, 8]).unwrap(),
        ] {
            let converted = to_socketcan(&frame).unwrap();
            assert_eq!(from_socketcan(&converted), Some(frame));
        }
    }

    #[test]
    fn id_filters_match_each_kind_exactly() {
        assert_eq!(
            id_filters(&[CanId::Standard(0x585), CanId::Extended(0x1ABC_0585)]),
            [
                CanFilter::new(0x585, 0x8000_07FF),
                CanFilter::new(0x9ABC_0585, 0x9FFF_FFFF)
            ]
        );
    }

    #[test]
    fn filters_match_standard_frames_only() {
        assert_eq!(
            filters(&[(0x581, 0x7FF), (0x0FFF, 0x780)]),
            [
                CanFilter::new(0x581, 0x8000_07FF),
                CanFilter::new(0x7FF, 0x8000_0780)
            ]
        );
    }

    #[cfg(feature = "tokio")]
    #[::tokio::test]
    async fn async_missing_interface_is_named() {
        let error = AsyncSocketCanBus::open("nosuchcan8").unwrap_err();
        assert!(error.to_string().contains("\"nosuchcan8\""), "{error}");
    }
}
