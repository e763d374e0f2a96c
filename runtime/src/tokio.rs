//! Async drivers over tokio (feature `tokio`): the counterparts of
//! [`crate::blocking`] for an [`AsyncBus`].
//!
//! - [`drive`] and [`serve`] run any [`Service`]; [`SdoClient`] reads and
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

pub use crate::blocking::{DriveError, Error};
use crate::blocking::{Transfer, Upload, encode, give_up, transfer_end, visible_string};
use crate::od::{self, Entry};
use crate::sdo::client::{self, ClientConfig, Method};
use crate::sdo::typed::{self, LengthNote};
pub use crate::time::Deadline;
use crate::transport::{AsyncBus, Clock};
use crate::{Instant, Service};

mod master;
pub use crate::blocking::Cia402Error;
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

/// Runs `service` on `bus` (see [`crate::blocking::drive`]): sends what it
/// transmits, feeds it received frames and its timeouts, hands its events
/// to `until`, and returns what `until` breaks with, or
/// [`DriveError::Deadline`] once `deadline` passes first. Waits with
/// `select!` on the bus and `tokio::time::sleep_until`.
///
/// `deadline` is a point in time: an [`Instant`] of the cores (`clock.now()
/// + Duration::from_millis(50)`), a `tokio::time::Instant` or
/// [`Deadline::NEVER`] (see [`Deadline`]).
pub async fn drive<B, S, T>(
    bus: &mut B,
    clock: &Clock,
    service: &mut S,
    mut until: impl FnMut(S::Event) -> ControlFlow<T>,
    deadline: impl Into<Deadline>,
) -> Result<T, DriveError>
where
    B: AsyncBus + ?Sized,
    S: Service + ?Sized,
{
    let deadline = deadline.into().on(clock);
    run(
        bus,
        clock,
        service,
        &mut until,
        deadline,
        core::future::pending(),
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
    match run(bus, clock, service, &mut until, deadline, shutdown).await {
        Ok(()) | Err(DriveError::Deadline | DriveError::Stopped) => Ok(()),
        Err(DriveError::Io(e)) => Err(e),
    }
}

/// The loop behind [`drive`] and [`serve`], in the cores' time.
async fn run<B, S, T>(
    bus: &mut B,
    clock: &Clock,
    service: &mut S,
    until: &mut impl FnMut(S::Event) -> ControlFlow<T>,
    deadline: Option<Instant>,
    shutdown: impl Future<Output = ()>,
) -> Result<T, DriveError>
where
    B: AsyncBus + ?Sized,
    S: Service + ?Sized,
{
    let mut shutdown = pin!(shutdown);
    loop {
        while let Some(frame) = service.poll_transmit() {
            bus.send(&frame).await.map_err(DriveError::Io)?;
        }
        while let Some(event) = service.poll_event() {
            if let ControlFlow::Break(value) = until(event) {
                return Ok(value);
            }
        }
        let current = clock.now();
        if deadline.is_some_and(|deadline| current >= deadline) {
            return Err(DriveError::Deadline);
        }
        let timer = service.poll_timeout();
        if let Some(at) = timer
            && at <= current
        {
            service.handle_timeout(current);
            continue;
        }
        let wake = crate::time::earliest(deadline, timer)
            .map(|at| ::tokio::time::Instant::from_std(clock.to_std(at)));
        let sleep = async {
            match wake {
                Some(wake) => ::tokio::time::sleep_until(wake).await,
                None => core::future::pending().await,
            }
        };
        // `recv` is cancel-safe: when the timer or shutdown wins, no frame
        // is lost.
        ::tokio::select! {
            biased;
            () = &mut shutdown => return Err(DriveError::Stopped),
            received = bus.recv() => {
                let frame = received.map_err(DriveError::Io)?;
                service.handle_frame(clock.now(), &frame);
            }
            () = sleep => {}
        }
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

    async fn transfer(
        &mut self,
        index: u16,
        sub: u8,
        transfer: Transfer<'_>,
    ) -> Result<Upload, Error> {
        let start = self.clock.now();
        transfer.start(&mut self.core, start, index, sub)?;
        let deadline = start + transfer.bound(self.core.config());
        let until = |event| transfer_end(event, index, sub);
        match drive(&mut self.bus, &self.clock, &mut self.core, until, deadline).await {
            Ok(result) => result,
            Err(e) => {
                let error = give_up(&mut self.core, e);
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
        let sub = E::SUBINDEX;
        let upload = self
            .transfer(E::INDEX, sub, Transfer::Upload(Method::Auto))
            .await?;
        let strict = self.core.config().strict_lengths;
        let (value, note) = typed::decode_upload::<E>(sub, &upload.data, upload.padded, strict)?;
        if let Some(note) = note {
            typed::keep(&mut self.notes, note);
        }
        Ok(value)
    }

    /// Writes `value` to entry `E`.
    pub async fn write<E>(&mut self, value: E::Value) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::Scalar,
    {
        let (buf, len) = encode::<E>(value)?;
        self.download(E::INDEX, E::SUBINDEX, buf.get(..len).unwrap_or(&buf))
            .await
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
        visible_string(self.upload(E::INDEX, E::SUBINDEX).await?)
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
mod tests {
    use core::time::Duration;

    use super::*;
    use crate::transport::virtual_bus::VirtualBus;
    use crate::{CanId, Frame};

    /// A test core: reports frames with id 0x200 and a tick every 10 ms.
    struct Ticker {
        next: Instant,
        events: Vec<Result<Frame, Instant>>,
    }

    impl Service for Ticker {
        type Event = Result<Frame, Instant>;
        fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
            if frame.cob_id() == Some(0x200) {
                self.events.push(Ok(*frame));
            }
        }
        fn handle_timeout(&mut self, now: Instant) {
            self.events.push(Err(now));
            self.next = now + Duration::from_millis(10);
        }
        fn poll_transmit(&mut self) -> Option<Frame> {
            None
        }
        fn poll_event(&mut self) -> Option<Self::Event> {
            (!self.events.is_empty()).then(|| self.events.remove(0))
        }
        fn poll_timeout(&self) -> Option<Instant> {
            Some(self.next)
        }
    }

    fn ticker() -> Ticker {
        Ticker {
            next: Instant::from_millis(10),
            events: Vec::new(),
        }
    }

    #[::tokio::test(start_paused = true)]
    async fn drive_runs_timers_until_the_deadline() {
        let bus = VirtualBus::new();
        let mut port = bus.attach();
        let clock = clock();
        let mut core = ticker();
        let mut ticks = Vec::new();
        let start = ::tokio::time::Instant::now();
        let result = drive(
            &mut port,
            &clock,
            &mut core,
            |event| {
                if let Err(at) = event {
                    ticks.push(at);
                }
                ControlFlow::<()>::Continue(())
            },
            start + Duration::from_millis(55),
        )
        .await;
        assert!(matches!(result, Err(DriveError::Deadline)));
        // Paused time: the ticks come exactly on time.
        let expected: Vec<Instant> = (1..=5).map(|i| Instant::from_millis(10 * i)).collect();
        assert_eq!(ticks, expected);
    }

    #[::tokio::test(start_paused = true)]
    async fn drive_and_serve_take_deadlines_in_the_cores_time() {
        let bus = VirtualBus::new();
        let mut port = bus.attach();
        let clock = clock();
        let mut core = ticker();
        let mut ticks = Vec::new();
        let deadline = clock.now() + Duration::from_millis(55);
        let result = drive(
            &mut port,
            &clock,
            &mut core,
            |event| {
                if let Err(at) = event {
                    ticks.push(at);
                }
                ControlFlow::<()>::Continue(())
            },
            deadline,
        )
        .await;
        assert!(matches!(result, Err(DriveError::Deadline)));
        // Paused time: the deadline is met exactly, after five ticks.
        assert_eq!(clock.now(), deadline);
        assert_eq!(ticks.len(), 5);

        let mut seen = 0;
        let deadline = clock.now() + Duration::from_millis(30);
        serve(
            &mut port,
            &clock,
            &mut core,
            core::future::pending(),
            deadline,
            |_| seen += 1,
        )
        .await
        .unwrap();
        assert_eq!(clock.now(), deadline);
        // Ticks at 60, 70 and 80 ms.
        assert_eq!(seen, 3);
        // No deadline and a shutdown that has come: returns at once.
        serve(
            &mut port,
            &clock,
            &mut core,
            async {},
            Deadline::NEVER,
            |_| {},
        )
        .await
        .unwrap();
        assert_eq!(clock.now(), deadline);
    }

    #[::tokio::test(start_paused = true)]
    async fn drive_breaks_on_a_frame_and_serve_stops_on_shutdown() {
        let bus = VirtualBus::new();
        let mut port = bus.attach();
        let peer = bus.attach();
        let clock = clock();
        let mut core = ticker();
        peer.transmit(&Frame::new(CanId::Standard(0x200), &[1]).unwrap());
        let got = drive(
            &mut port,
            &clock,
            &mut core,
            |event| match event {
                Ok(frame) => ControlFlow::Break(frame),
                Err(_) => ControlFlow::Continue(()),
            },
            ::tokio::time::Instant::now() + Duration::from_secs(1),
        )
        .await
        .unwrap();
        assert_eq!(got.data(), [1]);

        let mut seen = 0;
        let shutdown = ::tokio::time::sleep(Duration::from_millis(35));
        serve(&mut port, &clock, &mut core, shutdown, None, |_| seen += 1)
            .await
            .unwrap();
        // Ticks at 10, 20 and 30 ms.
        assert_eq!(seen, 3);
    }
}
