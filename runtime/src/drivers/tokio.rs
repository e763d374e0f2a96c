//! Async drivers over tokio (feature `tokio`): the counterparts of
//! [`crate::blocking`] for an [`AsyncBus`].
//!
//! - [`run`] and [`serve`] run any [`Service`]; [`SdoClient`] reads and
//!   writes the objects of one node.
//! - [`Master`] and its [`Driver`]: the composite [`crate::master::Master`]
//!   with SDO, NMT, PDO configuration and LSS calls, and its events and
//!   PDOs as streams ([`Events`], [`Pdos`]).
//!
//! Time comes from `tokio::time::Instant` (mapped through the [`Clock`]
//! of [`clock`]), so the drivers follow tokio's paused clock in tests.
//! Deadlines are [`Deadline`]s: an [`Instant`] of the cores (`clock.now() +
//! Duration::from_millis(50)`), a `tokio::time::Instant` or
//! [`Deadline::NEVER`].

use core::future::Future;
use core::ops::ControlFlow;
use core::pin::pin;
use std::collections::VecDeque;
use std::string::String;
use std::vec::Vec;

pub use crate::blocking::{Error, RunError};
use crate::blocking::{Object, Transfer, Upload, encode, give_up, transfer_end, visible_string};
use crate::od::{self, Entry};
use crate::sdo::client::{self, ClientConfig, Method};
use crate::sdo::typed::LengthNote;
pub use crate::time::Deadline;
use crate::transport::{AsyncBus, Clock};
use crate::{Instant, Service};

mod master;
mod sdo_stream;
pub use master::{
    DriveHandle, Driver, Events, LssRequestError, MASTER_QUEUE_CAPACITY, Master,
    PDO_QUEUE_CAPACITY, Pdos,
};

/// A clock on tokio's clock whose origin is tokio's now: its
/// [`Clock::now`] follows the paused clock in tests. The clock the tokio
/// drivers make for themselves.
pub fn clock() -> Clock {
    Clock::following_tokio()
}

/// Runs `service` on `bus` (see [`crate::blocking::run`]): sends what it
/// transmits, feeds it received frames and its timeouts, hands its events
/// to `until`, and returns what `until` breaks with, or
/// [`RunError::Deadline`] once `deadline` passes first. Waits with
/// `select!` on the bus and `tokio::time::sleep_until`.
///
/// `deadline` is a point in time: an [`Instant`] of the cores (`clock.now()
/// + Duration::from_millis(50)`), a `tokio::time::Instant` or
/// [`Deadline::NEVER`] (see [`Deadline`]).
pub async fn run<B, S, T>(
    bus: &mut B,
    clock: &Clock,
    service: &mut S,
    deadline: impl Into<Deadline>,
    mut until: impl FnMut(S::Event) -> ControlFlow<T>,
) -> Result<T, RunError>
where
    B: AsyncBus + ?Sized,
    S: Service + ?Sized,
{
    let deadline = deadline.into().on(clock);
    let mut no_hook = |_: &mut S, _| ControlFlow::Continue(());
    let stop = core::future::pending();
    run_loop(
        bus,
        clock,
        service,
        &mut until,
        deadline,
        stop,
        &mut no_hook,
    )
    .await
}

/// Runs `service` on `bus` until `shutdown` completes or `deadline`
/// passes, handing every event to `on_event` (the async [`crate::blocking::serve`]).
///
/// `deadline` is a [`Deadline`]: an [`Instant`] of the cores, a
/// `tokio::time::Instant`, or `None` / [`Deadline::NEVER`] to run until
/// shut down.
pub async fn serve<B, S>(
    bus: &mut B,
    clock: &Clock,
    service: &mut S,
    shutdown: impl Future<Output = ()>,
    deadline: impl Into<Deadline>,
    mut on_event: impl FnMut(S::Event),
) -> std::io::Result<()>
where
    B: AsyncBus + ?Sized,
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
        shutdown,
        &mut no_hook,
    )
    .await
    {
        Ok(()) | Err(RunError::Deadline | RunError::Stopped) => Ok(()),
        Err(RunError::Io(e)) => Err(e),
    }
}

/// The loop behind [`run`] and [`serve`], in the cores' time. `hook` runs
/// first in every round (streamed transfers feed and take data there);
/// breaking from it stops the loop with [`RunError::Stopped`].
pub(crate) async fn run_loop<B, S, T>(
    bus: &mut B,
    clock: &Clock,
    service: &mut S,
    until: &mut impl FnMut(S::Event) -> ControlFlow<T>,
    deadline: Option<Instant>,
    shutdown: impl Future<Output = ()>,
    hook: &mut (dyn FnMut(&mut S, Instant) -> ControlFlow<()> + Send),
) -> Result<T, RunError>
where
    B: AsyncBus + ?Sized,
    S: Service + ?Sized,
{
    let mut shutdown = pin!(shutdown);
    loop {
        if hook(service, clock.now()).is_break() {
            return Err(RunError::Stopped);
        }
        while let Some(frame) = service.poll_transmit() {
            bus.send(&frame).await.map_err(RunError::Io)?;
        }
        while let Some(event) = service.poll_event() {
            if let ControlFlow::Break(value) = until(event) {
                return Ok(value);
            }
        }
        let current = clock.now();
        if deadline.is_some_and(|deadline| current >= deadline) {
            return Err(RunError::Deadline);
        }
        let timer = service.poll_timeout();
        if let Some(at) = timer
            && at <= current
        {
            service.handle_timeout(current);
            continue;
        }
        let sleep = sleep_until(clock, crate::time::earliest(deadline, timer));
        // `recv` is cancel-safe: when the timer or shutdown wins, no frame
        // is lost.
        ::tokio::select! {
            biased;
            () = &mut shutdown => return Err(RunError::Stopped),
            received = bus.recv() => {
                let frame = received.map_err(RunError::Io)?;
                service.handle_frame(clock.now(), &frame);
            }
            () = sleep => {}
        }
    }
}

/// Sleeps until `at` on `clock` (mapped to tokio's clock); forever
/// without one.
pub(crate) async fn sleep_until(clock: &Clock, at: Option<Instant>) {
    match at {
        Some(at) => {
            ::tokio::time::sleep_until(::tokio::time::Instant::from_std(clock.to_std(at))).await
        }
        None => core::future::pending().await,
    }
}

/// An async SDO client for one node: each call runs one whole transfer
/// (see [`crate::blocking::SdoClient`]; the same bounds apply).
#[derive(Debug)]
pub struct SdoClient<B> {
    bus: B,
    clock: Clock,
    core: client::SdoClient,
    notes: VecDeque<LengthNote>,
}

impl<B: AsyncBus> SdoClient<B> {
    /// A client on `bus` with `config`; its clock starts at tokio's now.
    pub fn new(bus: B, config: ClientConfig) -> SdoClient<B> {
        SdoClient::with_clock(bus, config, clock())
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

    /// The notes typed reads left since the last call (see
    /// [`crate::blocking::SdoClient::take_length_notes`]).
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
    fn object(&self, index: u16, sub: u8) -> Object {
        Object::new(
            crate::blocking::channel_node(self.core.config().channel),
            index,
            sub,
        )
    }

    async fn transfer(
        &mut self,
        index: u16,
        sub: u8,
        transfer: Transfer<'_>,
    ) -> Result<Upload, Error> {
        let start = self.clock.now();
        let object = self.object(index, sub);
        transfer.start(&mut self.core, start, object)?;
        let limit = transfer.bound(self.core.config());
        let until = |event| transfer_end(event, object);
        let result = run(
            &mut self.bus,
            &self.clock,
            &mut self.core,
            start + limit,
            until,
        )
        .await;
        match result {
            Ok(result) => result,
            Err(e) => {
                let error = give_up(&mut self.core, e, object, Some(limit));
                while let Some(frame) = self.core.poll_transmit() {
                    // Best effort: the abort frame of a failing bus may not go.
                    let _ = self.bus.send(&frame).await;
                }
                Err(error)
            }
        }
    }

    /// Reads (index, sub) with [`Method::Auto`].
    pub async fn upload(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, Error> {
        self.upload_with(index, sub, Method::Auto).await
    }

    /// Reads (index, sub) with `method`.
    pub async fn upload_with(
        &mut self,
        index: u16,
        sub: u8,
        method: Method,
    ) -> Result<Vec<u8>, Error> {
        self.transfer(index, sub, Transfer::Upload(method))
            .await
            .map(|upload| upload.data)
    }

    /// Writes `data` to (index, sub) with [`Method::Auto`].
    pub async fn download(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), Error> {
        self.download_with(index, sub, data, Method::Auto).await
    }

    /// Writes `data` to (index, sub) with `method`.
    pub async fn download_with(
        &mut self,
        index: u16,
        sub: u8,
        data: &[u8],
        method: Method,
    ) -> Result<(), Error> {
        self.transfer(index, sub, Transfer::Download(data, method))
            .await
            .map(drop)
    }

    /// Reads the value of entry `E`.
    pub async fn read<E>(&mut self) -> Result<E::Value, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::Scalar,
    {
        self.read_sub::<E>(E::SUBINDEX).await
    }

    /// Writes `value` to entry `E`.
    pub async fn write<E>(&mut self, value: E::Value) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::Scalar,
    {
        self.write_sub::<E>(E::SUBINDEX, value).await
    }

    /// Reads element `at` of an ARRAY: the run-time form of
    /// [`Self::read`] with `A<SUB>`.
    pub async fn read_at<A>(&mut self, at: od::Element<A>) -> Result<A::Value, Error>
    where
        A: od::Array,
        A::Access: od::Read,
        A::Value: od::Scalar,
    {
        self.read_sub::<A>(at.subindex()).await
    }

    /// Writes `value` to element `at` of an ARRAY.
    pub async fn write_at<A>(&mut self, at: od::Element<A>, value: A::Value) -> Result<(), Error>
    where
        A: od::Array,
        A::Access: od::Write,
        A::Value: od::Scalar,
    {
        self.write_sub::<A>(at.subindex(), value).await
    }

    /// Reads the bytes of element `at` of a byte-valued ARRAY (DOMAIN,
    /// strings).
    pub async fn read_bytes_at<A>(&mut self, at: od::Element<A>) -> Result<Vec<u8>, Error>
    where
        A: od::Array,
        A::Access: od::Read,
        A::Value: od::ByteValue,
    {
        self.upload(A::INDEX, at.subindex()).await
    }

    /// Writes the bytes of element `at` of a byte-valued ARRAY.
    pub async fn write_bytes_at<A>(&mut self, at: od::Element<A>, data: &[u8]) -> Result<(), Error>
    where
        A: od::Array,
        A::Access: od::Write,
        A::Value: od::ByteValue,
    {
        self.download(A::INDEX, at.subindex(), data).await
    }

    /// Typed read of sub `sub` of `E`'s object (an entry's own, or an
    /// array element's).
    async fn read_sub<E>(&mut self, sub: u8) -> Result<E::Value, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::Scalar,
    {
        let upload = self
            .transfer(E::INDEX, sub, Transfer::Upload(Method::Auto))
            .await?;
        let strict = self.core.config().strict_lengths;
        let object = self.object(E::INDEX, sub);
        upload.value::<E, _>(object, strict, &mut self.notes, |note| note)
    }

    /// Typed write of sub `sub` of `E`'s object.
    async fn write_sub<E>(&mut self, sub: u8, value: E::Value) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::Scalar,
    {
        let encoded = encode::<E>(value, self.object(E::INDEX, sub))?;
        self.download(E::INDEX, sub, encoded.bytes()).await
    }

    /// Reads the bytes of a string, DOMAIN or other byte-valued entry.
    pub async fn read_bytes<E>(&mut self) -> Result<Vec<u8>, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::ByteValue,
    {
        self.upload(E::INDEX, E::SUBINDEX).await
    }

    /// Reads a VISIBLE_STRING entry (see
    /// [`crate::blocking::SdoClient::read_string`]).
    pub async fn read_string<E>(&mut self) -> Result<String, Error>
    where
        E: Entry<Value = od::bytes::VisibleString>,
        E::Access: od::Read,
    {
        let data = self.upload(E::INDEX, E::SUBINDEX).await?;
        visible_string(data, self.object(E::INDEX, E::SUBINDEX))
    }

    /// Writes the bytes of a string, DOMAIN or other byte-valued entry.
    pub async fn write_bytes<E>(&mut self, data: &[u8]) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::ByteValue,
    {
        self.download(E::INDEX, E::SUBINDEX, data).await
    }
}

#[cfg(test)]
mod tests;
