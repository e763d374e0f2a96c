//! Blocking drivers: run sans-IO cores over a [`Bus`] on the calling thread.
//!
//! - [`run`] runs any [`Service`] until a closure over its events says
//!   stop, or a deadline passes; [`serve`] runs one until a stop flag is set
//!   (simulators, test peers).
//! - [`SdoClient`] reads and writes objects of one node through
//!   [`crate::sdo::client::SdoClient`]: raw bytes, or typed through the
//!   generated [`od::Entry`] types.
//!
//! Time comes from the [`Clock`] each driver is given: the std clock by
//! default, or a [`crate::transport::ManualClock`] in tests, on which the
//! drivers never sleep (a wait with nothing on the bus moves the clock to
//! its end instead).

use core::fmt;
use core::ops::ControlFlow;
use core::time::Duration;
use std::collections::VecDeque;
use std::io;
use std::string::String;
use std::sync::atomic::{AtomicBool, Ordering};
use std::vec::Vec;

use crate::od::{self, Entry};
use crate::sdo::client::{self, ClientConfig, Method};
use crate::sdo::typed::LengthNote;
pub use crate::time::Deadline;
use crate::transport::{Bus, Clock};
use crate::{Frame, Instant, Service};

mod error;
pub(crate) mod master;
pub(crate) mod stream;
mod transfer;
pub use master::{DRIVE_EVENTS_KEPT, DriveHandle, LssRequestError, MASTER_QUEUE_CAPACITY, Master};

/// How often [`serve`] looks at its stop flag while nothing happens.
pub const STOP_POLL: Duration = Duration::from_millis(10);

/// Longest single wait when neither the core nor the caller set a deadline.
const IDLE_WAIT: Duration = Duration::from_secs(1);

/// Why [`run`] returned without a result.
#[derive(Debug)]
#[non_exhaustive]
pub enum RunError {
    /// The bus failed.
    Io(io::Error),
    /// The deadline passed.
    Deadline,
    /// The stop flag was set.
    Stopped,
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Io(e) => write!(f, "CAN bus error: {e}"),
            RunError::Deadline => f.write_str("the deadline passed"),
            RunError::Stopped => f.write_str("stopped"),
        }
    }
}

impl std::error::Error for RunError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RunError::Io(e) => Some(e),
            _ => None,
        }
    }
}

/// Runs `service` on `bus`: sends what it transmits, feeds it every
/// received frame and its timeouts (times from `clock`), and hands each of
/// its events to `until`. Returns the value `until` breaks with, or
/// [`RunError::Deadline`] once `deadline` passes first. The deadline comes
/// before the closure, as in [`serve`] and [`Master::run_until`].
///
/// `deadline` is a point in time: an [`Instant`] of the cores
/// (`clock.now() + Duration::from_millis(50)`), a `std::time::Instant` or
/// [`Deadline::NEVER`] (see [`Deadline`]).
///
/// Events left in the service when `until` breaks stay there for the next
/// call.
pub fn run<B, S, T>(
    bus: &mut B,
    clock: &Clock,
    service: &mut S,
    deadline: impl Into<Deadline>,
    mut until: impl FnMut(S::Event) -> ControlFlow<T>,
) -> Result<T, RunError>
where
    B: Bus + ?Sized,
    S: Service + ?Sized,
{
    let deadline = deadline.into().on(clock);
    run_loop(
        bus,
        clock,
        service,
        &mut until,
        deadline,
        None,
        &mut |_, _| ControlFlow::Continue(()),
    )
}

/// Runs `service` on `bus` (as [`run`] does) until `stop` is set or
/// `deadline` passes, handing every event to `on_event`. `stop` is checked
/// at least every [`STOP_POLL`]. Returns `Ok(())` when stopped or past the
/// deadline, the bus error otherwise.
///
/// `deadline` is a [`Deadline`]: an [`Instant`] of the cores, a
/// `std::time::Instant`, or `None` / [`Deadline::NEVER`] to run until
/// stopped (`Some(std::time::Instant)` is taken too).
pub fn serve<B, S>(
    bus: &mut B,
    clock: &Clock,
    service: &mut S,
    stop: &AtomicBool,
    deadline: impl Into<Deadline>,
    mut on_event: impl FnMut(S::Event),
) -> io::Result<()>
where
    B: Bus + ?Sized,
    S: Service + ?Sized,
{
    let mut until = |event| -> ControlFlow<()> {
        on_event(event);
        ControlFlow::Continue(())
    };
    let deadline = deadline.into().on(clock);
    let mut no_hook = |_: &mut S, _| ControlFlow::Continue(());
    match run_loop(
        bus,
        clock,
        service,
        &mut until,
        deadline,
        Some(stop),
        &mut no_hook,
    ) {
        Ok(()) | Err(RunError::Deadline | RunError::Stopped) => Ok(()),
        Err(RunError::Io(e)) => Err(e),
    }
}

/// The loop behind [`run`] and [`serve`], in the cores' time. `hook`
/// runs first in every round (streamed transfers feed and take data
/// there); breaking from it stops the loop with [`RunError::Stopped`].
pub(crate) fn run_loop<B, S, T>(
    bus: &mut B,
    clock: &Clock,
    service: &mut S,
    until: &mut impl FnMut(S::Event) -> ControlFlow<T>,
    deadline: Option<Instant>,
    stop: Option<&AtomicBool>,
    hook: &mut dyn FnMut(&mut S, Instant) -> ControlFlow<()>,
) -> Result<T, RunError>
where
    B: Bus + ?Sized,
    S: Service + ?Sized,
{
    loop {
        if hook(service, clock.now()).is_break() {
            return Err(RunError::Stopped);
        }
        while let Some(frame) = service.poll_transmit() {
            bus.send(&frame).map_err(RunError::Io)?;
        }
        while let Some(event) = service.poll_event() {
            if let ControlFlow::Break(value) = until(event) {
                return Ok(value);
            }
        }
        if stop.is_some_and(|stop| stop.load(Ordering::Relaxed)) {
            return Err(RunError::Stopped);
        }
        let now = clock.now();
        if deadline.is_some_and(|deadline| now >= deadline) {
            return Err(RunError::Deadline);
        }
        let timer = service.poll_timeout();
        if let Some(at) = timer
            && at <= now
        {
            service.handle_timeout(now);
            continue;
        }
        let mut wake = now + IDLE_WAIT;
        for limit in [deadline, timer].into_iter().flatten() {
            wake = wake.min(limit);
        }
        if stop.is_some() {
            wake = wake.min(now + STOP_POLL);
        }
        if let Some(frame) = recv_until(bus, clock, now, wake).map_err(RunError::Io)? {
            service.handle_frame(clock.now(), &frame);
        }
    }
}

/// Waits on `bus` for the next frame until `wake` (`now` is the time last
/// read from `clock`); `Ok(None)` when none came. On a manual clock it
/// never waits: it takes a frame already there, or else moves the clock to
/// `wake` (see [`crate::transport::ManualClock`]).
pub(crate) fn recv_until<B: Bus + ?Sized>(
    bus: &mut B,
    clock: &Clock,
    now: Instant,
    wake: Instant,
) -> io::Result<Option<Frame>> {
    if !clock.is_manual() {
        return bus.recv(wake - now);
    }
    let frame = bus.recv(Duration::ZERO)?;
    if frame.is_none() {
        clock.skip_to(wake);
        // Lets a peer on another thread run before the next look.
        std::thread::yield_now();
    }
    Ok(frame)
}

pub use error::Error;
pub(crate) use transfer::{
    Object, Transfer, Upload, channel_node, encode, give_up, master_transfer_end, transfer_end,
    visible_string,
};

/// A blocking SDO client for one node: each call runs one whole transfer.
///
/// Every call ends: the core bounds each step by
/// [`ClientConfig::timeout`], and the driver also gives up (aborting with
/// 0x05040000) once the whole transfer took longer than one timeout per
/// step it can have.
#[derive(Debug)]
pub struct SdoClient<B> {
    bus: B,
    clock: Clock,
    core: client::SdoClient,
    notes: VecDeque<LengthNote>,
}

impl<B: Bus> SdoClient<B> {
    /// A client on `bus` with `config` (its channel names the node).
    pub fn new(bus: B, config: ClientConfig) -> SdoClient<B> {
        SdoClient::with_clock(bus, config, Clock::new())
    }

    /// A client whose core sees time through `clock`.
    pub fn with_clock(bus: B, config: ClientConfig, clock: Clock) -> SdoClient<B> {
        SdoClient {
            bus,
            clock,
            core: client::SdoClient::new(config),
            notes: VecDeque::new(),
        }
    }

    /// The notes typed reads left since the last call (at most
    /// [`NOTES_KEPT`](crate::sdo::typed::NOTES_KEPT), the newest): values
    /// the server sent longer than their data type, of which the leading
    /// bytes were taken. Empty with [`ClientConfig::strict_lengths`], which
    /// refuses them instead.
    pub fn take_length_notes(&mut self) -> Vec<LengthNote> {
        self.notes.drain(..).collect()
    }

    /// The sans-IO core.
    pub fn core(&self) -> &client::SdoClient {
        &self.core
    }

    /// The bus.
    pub fn bus(&self) -> &B {
        &self.bus
    }

    /// The bus, to send or receive other frames between transfers.
    pub fn bus_mut(&mut self) -> &mut B {
        &mut self.bus
    }

    /// Gives the bus back.
    pub fn into_bus(self) -> B {
        self.bus
    }

    /// The object (index, sub) of this client's node.
    pub(crate) fn object(&self, index: u16, sub: u8) -> Object {
        Object::new(channel_node(self.core.config().channel), index, sub)
    }

    fn transfer(&mut self, index: u16, sub: u8, transfer: Transfer<'_>) -> Result<Upload, Error> {
        let now = self.clock.now();
        let object = self.object(index, sub);
        transfer.start(&mut self.core, now, object)?;
        let limit = transfer.bound(self.core.config());
        let until = |event| transfer_end(event, object);
        match run(
            &mut self.bus,
            &self.clock,
            &mut self.core,
            now + limit,
            until,
        ) {
            Ok(result) => result,
            Err(e) => {
                let error = give_up(&mut self.core, e, object, Some(limit));
                while let Some(frame) = self.core.poll_transmit() {
                    // Best effort: the abort frame of a failing bus may not go.
                    let _ = self.bus.send(&frame);
                }
                Err(error)
            }
        }
    }

    /// Reads (index, sub) with [`Method::Auto`].
    pub fn upload(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, Error> {
        self.upload_with(index, sub, Method::Auto)
    }

    /// Reads (index, sub) with `method`.
    pub fn upload_with(&mut self, index: u16, sub: u8, method: Method) -> Result<Vec<u8>, Error> {
        self.transfer(index, sub, Transfer::Upload(method))
            .map(|upload| upload.data)
    }

    /// Writes `data` to (index, sub) with [`Method::Auto`].
    pub fn download(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), Error> {
        self.download_with(index, sub, data, Method::Auto)
    }

    /// Writes `data` to (index, sub) with `method`. Above 4 bytes (or
    /// segmented or block for any size) the data is sent from `data` as
    /// the transfer goes, without a copy ([`SdoClient::download_from`]).
    pub fn download_with(
        &mut self,
        index: u16,
        sub: u8,
        data: &[u8],
        method: Method,
    ) -> Result<(), Error> {
        let expedited =
            (1..=4).contains(&data.len()) && matches!(method, Method::Auto | Method::Standard);
        if expedited {
            return self
                .transfer(index, sub, Transfer::Download(data, method))
                .map(drop);
        }
        let mut source = data;
        let size = Some(data.len() as u64);
        self.download_from(index, sub, &mut source, size, method, |_| {})
    }

    /// Reads the value of entry `E`.
    pub fn read<E>(&mut self) -> Result<E::Value, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::Scalar,
    {
        self.read_sub::<E>(E::SUBINDEX)
    }

    /// Writes `value` to entry `E`.
    pub fn write<E>(&mut self, value: E::Value) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::Scalar,
    {
        self.write_sub::<E>(E::SUBINDEX, value)
    }

    /// Reads the bytes of a string, DOMAIN or other byte-valued entry.
    pub fn read_bytes<E>(&mut self) -> Result<Vec<u8>, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::ByteValue,
    {
        self.upload(E::INDEX, E::SUBINDEX)
    }

    /// Reads a VISIBLE_STRING entry: the text before the first NUL; a byte
    /// outside 0x20 to 0x7E gives [`Error::NotVisible`] (use
    /// [`SdoClient::read_bytes`] for the raw bytes).
    pub fn read_string<E>(&mut self) -> Result<String, Error>
    where
        E: Entry<Value = od::bytes::VisibleString>,
        E::Access: od::Read,
    {
        let data = self.upload(E::INDEX, E::SUBINDEX)?;
        visible_string(data, self.object(E::INDEX, E::SUBINDEX))
    }

    /// Writes the bytes of a string, DOMAIN or other byte-valued entry.
    pub fn write_bytes<E>(&mut self, data: &[u8]) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::ByteValue,
    {
        self.download(E::INDEX, E::SUBINDEX, data)
    }

    /// Reads element `at` of an ARRAY: the run-time form of
    /// [`Self::read`] with `A<SUB>`.
    pub fn read_at<A>(&mut self, at: od::Element<A>) -> Result<A::Value, Error>
    where
        A: od::Array,
        A::Access: od::Read,
        A::Value: od::Scalar,
    {
        self.read_sub::<A>(at.subindex())
    }

    /// Writes `value` to element `at` of an ARRAY.
    pub fn write_at<A>(&mut self, at: od::Element<A>, value: A::Value) -> Result<(), Error>
    where
        A: od::Array,
        A::Access: od::Write,
        A::Value: od::Scalar,
    {
        self.write_sub::<A>(at.subindex(), value)
    }

    /// Reads the bytes of element `at` of a byte-valued ARRAY (DOMAIN,
    /// strings).
    pub fn read_bytes_at<A>(&mut self, at: od::Element<A>) -> Result<Vec<u8>, Error>
    where
        A: od::Array,
        A::Access: od::Read,
        A::Value: od::ByteValue,
    {
        self.upload(A::INDEX, at.subindex())
    }

    /// Writes the bytes of element `at` of a byte-valued ARRAY.
    pub fn write_bytes_at<A>(&mut self, at: od::Element<A>, data: &[u8]) -> Result<(), Error>
    where
        A: od::Array,
        A::Access: od::Write,
        A::Value: od::ByteValue,
    {
        self.download(A::INDEX, at.subindex(), data)
    }

    /// Typed read of sub `sub` of `E`'s object (an entry's own, or an
    /// array element's).
    fn read_sub<E>(&mut self, sub: u8) -> Result<E::Value, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::Scalar,
    {
        let upload = self.transfer(E::INDEX, sub, Transfer::Upload(Method::Auto))?;
        let strict = self.core.config().strict_lengths;
        let object = self.object(E::INDEX, sub);
        upload.value::<E, _>(object, strict, &mut self.notes, |note| note)
    }

    /// Typed write of sub `sub` of `E`'s object.
    fn write_sub<E>(&mut self, sub: u8, value: E::Value) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::Scalar,
    {
        let encoded = encode::<E>(value, self.object(E::INDEX, sub))?;
        self.download(E::INDEX, sub, encoded.bytes())
    }
}

#[cfg(test)]
mod tests;
