//! Streamed SDO transfers of the blocking client: a download read from an
//! [`io::Read`] (a file, a slice) and an upload written to an
//! [`io::Write`], neither held whole in memory, with a progress callback.
//! The core keeps a window ([`client::WINDOW`] bytes); see
//! [`client::SdoClient::download_stream`]. The tokio master's streamed
//! transfers run the same [`Pump`] and end the same way.

use core::ops::ControlFlow;
use core::time::Duration;
use std::format;
use std::io::{self, Read, Write};

use super::{
    Error, Master, Object, RunError, SdoClient, Upload, give_up, master_transfer_end, run_loop,
    transfer_end,
};
use crate::master;
use crate::od::{self, Entry, NodeId};
use crate::sdo::AbortCode;
use crate::sdo::client::{self, ClientConfig, Method, Progress};
use crate::transport::Bus;
use crate::{Instant, Service};

/// Bytes read from the source per call.
const CHUNK: usize = 1024;

/// What the hook of a streamed transfer found wrong with its source or sink.
pub(crate) enum Stop {
    Source(io::Error),
    Sink(io::Error),
}

/// The data side of a streamed transfer: feeds the core from `reader`,
/// hands what the core received to `writer`, and reports progress.
pub(crate) struct Pump<'a, R, W, P> {
    reader: Option<&'a mut R>,
    writer: Option<&'a mut W>,
    pub(crate) plan: Plan,
    size: Option<usize>,
    fed: usize,
    done_reading: bool,
    written: usize,
    last: Option<Progress>,
    progress: P,
    stop: Option<Stop>,
}

/// Which streamed transfer a [`Pump`] serves, and how it starts.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Plan {
    /// A download announcing this many bytes (or none).
    Download(Option<u32>, Method),
    /// An upload.
    Upload(Method),
}

impl Plan {
    /// Starts the transfer of `object` on `core` (events left there from
    /// before are dropped); returns its bound (see [`bound`]).
    pub(crate) fn start(
        self,
        core: &mut client::SdoClient,
        now: Instant,
        object: Object,
    ) -> Result<Option<Duration>, Error> {
        while core.poll_event().is_some() {}
        let (started, len) = match self {
            Plan::Download(announced, method) => (
                core.download_stream(now, object.index, object.sub, announced, method),
                announced.map(|s| s as usize),
            ),
            Plan::Upload(method) => (
                core.upload_stream(now, object.index, object.sub, method),
                Some(core.config().max_upload),
            ),
        };
        started.map_err(|client::Busy| object.busy())?;
        Ok(bound(len, core.config()))
    }
}

impl<'a, R: Read, P: FnMut(Progress)> Pump<'a, R, io::Sink, P> {
    /// The pump of a download of what `reader` yields: `size` bytes when
    /// given (announced in the initiate, at most u32::MAX).
    pub(crate) fn download(
        reader: &'a mut R,
        size: Option<u64>,
        method: Method,
        progress: P,
    ) -> Result<Self, Error> {
        let announced = announced(size)?;
        let plan = Plan::Download(announced, method);
        let len = announced.map(|s| s as usize);
        Ok(Pump::new(plan, Some(reader), None, len, progress))
    }
}

impl<'a, W: Write, P: FnMut(Progress)> Pump<'a, io::Empty, W, P> {
    /// The pump of an upload into `writer`.
    pub(crate) fn upload(writer: &'a mut W, method: Method, progress: P) -> Self {
        Pump::new(Plan::Upload(method), None, Some(writer), None, progress)
    }
}

impl<'a, R: Read, W: Write, P: FnMut(Progress)> Pump<'a, R, W, P> {
    fn new(
        plan: Plan,
        reader: Option<&'a mut R>,
        writer: Option<&'a mut W>,
        size: Option<usize>,
        progress: P,
    ) -> Self {
        Pump {
            done_reading: reader.is_none(),
            plan,
            reader,
            writer,
            size,
            fed: 0,
            written: 0,
            last: None,
            progress,
            stop: None,
        }
    }

    /// One round: returns `Break` (with `self.stop` set) when the source or
    /// the sink failed.
    pub(crate) fn round(&mut self, core: &mut client::SdoClient, now: Instant) -> ControlFlow<()> {
        if let Err(stop) = self.feed(core, now).and_then(|()| self.take(core)) {
            self.stop = Some(stop);
            return ControlFlow::Break(());
        }
        let progress = core.progress();
        if progress.is_some() && progress != self.last {
            self.last = progress;
            if let Some(p) = progress {
                (self.progress)(p);
            }
        }
        ControlFlow::Continue(())
    }

    fn feed(&mut self, core: &mut client::SdoClient, now: Instant) -> Result<(), Stop> {
        let Some(reader) = self.reader.as_deref_mut() else {
            return Ok(());
        };
        let mut chunk = [0u8; CHUNK];
        while !self.done_reading && core.wants_data() > 0 {
            let want = core.wants_data().min(CHUNK);
            let n = read_some(reader, &mut chunk[..want]).map_err(Stop::Source)?;
            if n == 0 {
                self.done_reading = true;
                if let Some(size) = self.size.filter(|&size| self.fed < size) {
                    return Err(Stop::Source(io::Error::new(
                        io::ErrorKind::UnexpectedEof,
                        format!(
                            "the data ended after {} of the {size} bytes announced",
                            self.fed
                        ),
                    )));
                }
                core.end_of_data(now);
                break;
            }
            self.fed += core.feed(now, chunk.get(..n).unwrap_or(&chunk));
            if let Some(size) = self.size.filter(|&size| self.fed == size) {
                self.done_reading = true;
                let mut probe = [0u8; 1];
                if read_some(reader, &mut probe).map_err(Stop::Source)? > 0 {
                    return Err(Stop::Source(io::Error::new(
                        io::ErrorKind::InvalidInput,
                        format!("the data is longer than the {size} bytes announced"),
                    )));
                }
            }
        }
        Ok(())
    }

    fn take(&mut self, core: &mut client::SdoClient) -> Result<(), Stop> {
        let Some(writer) = self.writer.as_deref_mut() else {
            return Ok(());
        };
        let ready = core.received();
        if ready.is_empty() {
            return Ok(());
        }
        writer.write_all(ready).map_err(Stop::Sink)?;
        let n = ready.len();
        self.written += n;
        core.consume(n);
        Ok(())
    }
}

/// `read`, retried when interrupted.
fn read_some(reader: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    loop {
        match reader.read(buf) {
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            other => return other,
        }
    }
}

/// The bound of a streamed transfer of `len` bytes (unknown: none).
pub(crate) fn bound(len: Option<usize>, config: &ClientConfig) -> Option<Duration> {
    let steps = len?.div_ceil(7).saturating_add(4);
    Some(
        config
            .timeout
            .saturating_mul(u32::try_from(steps).unwrap_or(u32::MAX)),
    )
}

/// The length a streamed download of `size` bytes announces (at most
/// u32::MAX: CiA 301's 32-bit size).
pub(crate) fn announced(size: Option<u64>) -> Result<Option<u32>, Error> {
    match size.map(u32::try_from) {
        None => Ok(None),
        Some(Ok(size)) => Ok(Some(size)),
        Some(Err(_)) => Err(Error::Source(io::Error::new(
            io::ErrorKind::InvalidInput,
            "an SDO download announces at most u32::MAX bytes",
        ))),
    }
}

/// The error of a streamed transfer of `object` (bounded by `limit`) the
/// driver loop ended with `error`: the source's or sink's when the pump
/// stopped it (the transfer is then aborted with 0x08000000), else what
/// the loop says. The abort frame is left in `core` for the caller to send.
pub(crate) fn stream_error<R, W, P>(
    core: &mut client::SdoClient,
    pump: &mut Pump<'_, R, W, P>,
    error: RunError,
    object: Object,
    limit: Option<Duration>,
) -> Error {
    let Some(stop) = pump.stop.take() else {
        return give_up(core, error, object, limit);
    };
    if !core.is_idle() {
        core.abort(AbortCode::GeneralError);
    }
    while core.poll_event().is_some() {}
    match stop {
        Stop::Source(e) => Error::Source(e),
        Stop::Sink(e) => Error::Sink(e),
    }
}

impl<R, W: Write, P: FnMut(Progress)> Pump<'_, R, W, P> {
    /// The end of the pump's transfer of `object` (bounded by `limit`)
    /// that the driver loop ended with `result`: the bytes fed or written
    /// ([`Pump::finish`]), or the error; an abort is then left in `core`
    /// for the caller to send ([`stream_error`]).
    pub(crate) fn end(
        &mut self,
        core: &mut client::SdoClient,
        result: Result<Result<Upload, Error>, RunError>,
        object: Object,
        limit: Option<Duration>,
    ) -> Result<usize, Error> {
        match result {
            Ok(Ok(upload)) => self.finish(&upload.data),
            Ok(Err(e)) => Err(e),
            Err(e) => Err(stream_error(core, self, e, object, limit)),
        }
    }

    /// Ends a transfer that went through: an upload's writer gets the rest
    /// its end event carried and is flushed; the last progress report
    /// says all was done. Returns the bytes fed (download) or written
    /// (upload) in all.
    pub(crate) fn finish(&mut self, rest: &[u8]) -> Result<usize, Error> {
        if let Plan::Download(..) = self.plan {
            if let Some(p) = self.last
                && p.done != self.fed
            {
                (self.progress)(Progress {
                    done: self.fed,
                    total: p.total,
                });
            }
            return Ok(self.fed);
        }
        if let Some(writer) = self.writer.as_deref_mut() {
            writer
                .write_all(rest)
                .and_then(|()| writer.flush())
                .map_err(Error::Sink)?;
        }
        let written = self.written + rest.len();
        if let Some(p) = self.last {
            (self.progress)(Progress {
                done: written,
                total: p.total,
            });
        }
        Ok(written)
    }
}

impl<B: Bus> SdoClient<B> {
    /// Writes the value `reader` yields to (index, sub) without holding it:
    /// the client reads it as the transfer goes ([`client::WINDOW`] bytes
    /// at most in memory). With `size` the initiate announces it and the
    /// reader must yield exactly that many bytes; without, it does not
    /// (segmented or block download without size indication, CiA 301).
    /// `method`: [`Method::Block`] for a block download (or
    /// [`Method::Auto`] above `block_download_above`), anything else a
    /// segmented one. `progress` hears of every step.
    ///
    /// A reader that fails, ends early or yields more than `size` aborts
    /// the transfer (0x08000000) and gives [`Error::Source`].
    pub fn download_from(
        &mut self,
        index: u16,
        sub: u8,
        reader: &mut impl Read,
        size: Option<u64>,
        method: Method,
        progress: impl FnMut(Progress),
    ) -> Result<(), Error> {
        let pump = Pump::download(reader, size, method, progress)?;
        self.run_stream(index, sub, pump).map(drop)
    }

    /// Reads (index, sub) into `writer` as the data arrives, holding only
    /// what was not written yet; returns the number of bytes. A block
    /// upload's last segment is written once the end frame says how much of
    /// it is data, and its CRC covers everything written: a transfer that
    /// fails at the end (CRC, length) may have written data the caller must
    /// discard. `max_upload` bounds the value.
    pub fn upload_into(
        &mut self,
        index: u16,
        sub: u8,
        writer: &mut impl Write,
        method: Method,
        progress: impl FnMut(Progress),
    ) -> Result<usize, Error> {
        self.run_stream(index, sub, Pump::upload(writer, method, progress))
    }

    /// [`SdoClient::download_from`] into the byte-valued entry `E` (a
    /// DOMAIN such as program data 0x1F50, or a string): compiles only for
    /// a writable one.
    pub fn write_from<E>(
        &mut self,
        reader: &mut impl Read,
        size: Option<u64>,
        method: Method,
        progress: impl FnMut(Progress),
    ) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::ByteValue,
    {
        self.download_from(E::INDEX, E::SUBINDEX, reader, size, method, progress)
    }

    /// [`SdoClient::upload_into`] from the byte-valued entry `E`: compiles
    /// only for a readable one.
    pub fn read_into<E>(
        &mut self,
        writer: &mut impl Write,
        method: Method,
        progress: impl FnMut(Progress),
    ) -> Result<usize, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::ByteValue,
    {
        self.upload_into(E::INDEX, E::SUBINDEX, writer, method, progress)
    }

    /// Runs the streamed transfer of `pump` on (index, sub) to its end;
    /// returns the bytes fed or written ([`Pump::finish`]).
    fn run_stream<R: Read, W: Write, P: FnMut(Progress)>(
        &mut self,
        index: u16,
        sub: u8,
        mut pump: Pump<'_, R, W, P>,
    ) -> Result<usize, Error> {
        let now = self.clock.now();
        let object = self.object(index, sub);
        let bound = pump.plan.start(&mut self.core, now, object)?;
        let deadline = bound.map(|b| now + b);
        let mut until = |event| transfer_end(event, object);
        let mut hook = |core: &mut client::SdoClient, now| pump.round(core, now);
        let result = run_loop(
            &mut self.bus,
            &self.clock,
            &mut self.core,
            &mut until,
            deadline,
            None,
            &mut hook,
        );
        let end = pump.end(&mut self.core, result, object, bound);
        if end.is_err() {
            while let Some(frame) = self.core.poll_transmit() {
                // Best effort: the abort frame of a failing bus may not go.
                let _ = self.bus.send(&frame);
            }
        }
        end
    }
}

impl<B: Bus> Master<B> {
    /// [`SdoClient::download_from`] to `node` while the master keeps
    /// running (heartbeat, PDOs, events queue up). A node without an SDO
    /// client gets one on its default channel.
    #[allow(clippy::too_many_arguments)]
    pub fn download_from(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        reader: &mut impl Read,
        size: Option<u64>,
        method: Method,
        progress: impl FnMut(Progress),
    ) -> Result<(), Error> {
        let pump = Pump::download(reader, size, method, progress)?;
        self.run_stream(node, index, sub, pump).map(drop)
    }

    /// [`SdoClient::upload_into`] from `node` while the master keeps
    /// running.
    pub fn upload_into(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        writer: &mut impl Write,
        method: Method,
        progress: impl FnMut(Progress),
    ) -> Result<usize, Error> {
        let pump = Pump::upload(writer, method, progress);
        self.run_stream(node, index, sub, pump)
    }

    /// [`Master::download_from`] into the byte-valued entry `E` of `node`
    /// (a DOMAIN such as program data 0x1F50, or a string): compiles only
    /// for a writable one.
    pub fn write_from<E>(
        &mut self,
        node: NodeId,
        reader: &mut impl Read,
        size: Option<u64>,
        method: Method,
        progress: impl FnMut(Progress),
    ) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::ByteValue,
    {
        self.download_from(node, E::INDEX, E::SUBINDEX, reader, size, method, progress)
    }

    /// [`Master::upload_into`] from the byte-valued entry `E` of `node`:
    /// compiles only for a readable one.
    pub fn read_into<E>(
        &mut self,
        node: NodeId,
        writer: &mut impl Write,
        method: Method,
        progress: impl FnMut(Progress),
    ) -> Result<usize, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::ByteValue,
    {
        self.upload_into(node, E::INDEX, E::SUBINDEX, writer, method, progress)
    }

    /// Runs the streamed transfer of `pump` on (index, sub) of `node` to
    /// its end; returns the bytes fed or written ([`Pump::finish`]).
    fn run_stream<R: Read, W: Write, P: FnMut(Progress)>(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        mut pump: Pump<'_, R, W, P>,
    ) -> Result<usize, Error> {
        let now = self.now();
        let object = Object::new(Some(node), index, sub);
        let client = self.core_mut().sdo_or_default(node);
        let bound = pump.plan.start(client, now, object)?;
        let deadline = bound.map(|b| now + b);
        let mut until = |event| master_transfer_end(event, object);
        let mut hook = |core: &mut master::Master, now| pump.round(core.sdo_or_default(node), now);
        let result = self.wait_with(deadline, &mut until, &mut hook);
        let end = pump.end(self.core_mut().sdo_or_default(node), result, object, bound);
        if end.is_err() {
            // Best effort: the abort frame of a failing bus may not go.
            let _ = self.flush();
        }
        end
    }
}
