//! Streamed SDO transfers of the tokio [`SdoClient`]: a download read from
//! an [`io::Read`](std::io::Read) and an upload written to an
//! [`io::Write`](std::io::Write), neither held whole in memory, with a
//! progress callback. The data side is the blocking driver's pump
//! (`blocking::stream`), run in every round of the loop; see [`crate::tokio::Master::download_from`] for what a source
//! that blocks means on a task.

use std::io::{Read, Write};

use super::{Error, SdoClient, run_loop};
use crate::Service;
use crate::blocking::stream::Pump;
use crate::blocking::transfer_end;
use crate::od::{self, Entry};
use crate::sdo::client::{self, Method, Progress};
use crate::transport::AsyncBus;

impl<B: AsyncBus> SdoClient<B> {
    /// Writes the value `reader` yields to (index, sub) without holding it
    /// (see [`crate::blocking::SdoClient::download_from`]: `size`, `method`
    /// and the errors are the same).
    pub async fn download_from<R, P>(
        &mut self,
        index: u16,
        sub: u8,
        reader: &mut R,
        size: Option<u64>,
        method: Method,
        progress: P,
    ) -> Result<(), Error>
    where
        R: Read + Send,
        P: FnMut(Progress) + Send,
    {
        let pump = Pump::download(reader, size, method, progress)?;
        self.run_stream(index, sub, pump).await.map(drop)
    }

    /// Reads (index, sub) into `writer` as the data arrives; returns the
    /// number of bytes (see [`crate::blocking::SdoClient::upload_into`]).
    pub async fn upload_into<W, P>(
        &mut self,
        index: u16,
        sub: u8,
        writer: &mut W,
        method: Method,
        progress: P,
    ) -> Result<usize, Error>
    where
        W: Write + Send,
        P: FnMut(Progress) + Send,
    {
        self.run_stream(index, sub, Pump::upload(writer, method, progress))
            .await
    }

    /// [`SdoClient::download_from`] into the byte-valued entry `E`:
    /// compiles only for a writable one.
    pub async fn write_from<E, R, P>(
        &mut self,
        reader: &mut R,
        size: Option<u64>,
        method: Method,
        progress: P,
    ) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::ByteValue,
        R: Read + Send,
        P: FnMut(Progress) + Send,
    {
        self.download_from(E::INDEX, E::SUBINDEX, reader, size, method, progress)
            .await
    }

    /// [`SdoClient::upload_into`] from the byte-valued entry `E`: compiles
    /// only for a readable one.
    pub async fn read_into<E, W, P>(
        &mut self,
        writer: &mut W,
        method: Method,
        progress: P,
    ) -> Result<usize, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::ByteValue,
        W: Write + Send,
        P: FnMut(Progress) + Send,
    {
        self.upload_into(E::INDEX, E::SUBINDEX, writer, method, progress)
            .await
    }

    /// Runs the streamed transfer of `pump` on (index, sub) to its end;
    /// returns the bytes fed or written (see the blocking driver's).
    async fn run_stream<R, W, P>(
        &mut self,
        index: u16,
        sub: u8,
        mut pump: Pump<'_, R, W, P>,
    ) -> Result<usize, Error>
    where
        R: Read + Send,
        W: Write + Send,
        P: FnMut(Progress) + Send,
    {
        let start = self.clock.now();
        let object = self.object(index, sub);
        let limit = pump.plan.start(&mut self.core, start, object)?;
        let deadline = limit.map(|b| start + b);
        let mut until = |event| transfer_end(event, object);
        let mut hook = |core: &mut client::SdoClient, now| pump.round(core, now);
        let stop = core::future::pending();
        let result = run_loop(
            &mut self.bus,
            &self.clock,
            &mut self.core,
            &mut until,
            deadline,
            stop,
            &mut hook,
        )
        .await;
        let end = pump.end(&mut self.core, result, object, limit);
        if end.is_err() {
            while let Some(frame) = self.core.poll_transmit() {
                // Best effort: the abort frame of a failing bus may not go.
                let _ = self.bus.send(&frame).await;
            }
        }
        end
    }
}
