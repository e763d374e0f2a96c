//! Streamed SDO transfers of the tokio [`Master`]: a download read from an
//! [`io::Read`](std::io::Read) and an upload written to an
//! [`io::Write`](std::io::Write), neither held whole in memory, with a progress callback. The data side is the
//! blocking master's pump (`blocking::stream`), run on the calling task
//! after every frame the driver receives; the transfer itself is the
//! master's ordinary one (turns, bound, abort when dropped).
//!
//! The reader and writer are `std::io` ones (a file, a slice, a `Vec`):
//! each call reads or writes at most the core's window ([`WINDOW`] bytes)
//! between two frames. A source that blocks for long (a pipe, a network
//! stream) blocks the calling task meanwhile; read it into memory first,
//! or run the call on a `spawn_blocking`-friendly task.
//!
//! [`WINDOW`]: crate::sdo::client::WINDOW

use core::ops::ControlFlow;

use std::io::{Read, Write};

use super::{Error, Master};
use crate::blocking::stream::{Pump, stream_error};
use crate::blocking::{Object, RunError};
use crate::od::{self, Entry, NodeId};
use crate::sdo::client::{self, Method, Progress};

impl Master {
    /// Writes the value `reader` yields to (index, sub) of `node` without
    /// holding it (see [`crate::blocking::SdoClient::download_from`]: `size`,
    /// `method` and the errors are the same). A reader that fails, ends
    /// early or yields more than `size` aborts the transfer (0x08000000)
    /// and gives [`Error::Source`]. Dropping the future aborts the
    /// transfer (0x05040000) like any other.
    #[allow(clippy::too_many_arguments)]
    pub async fn download_from<R, P>(
        &self,
        node: NodeId,
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
        self.run_stream(node, (index, sub), pump).await.map(drop)
    }

    /// Reads (index, sub) of `node` into `writer` as the data arrives;
    /// returns the number of bytes (see
    /// [`crate::blocking::SdoClient::upload_into`]: a transfer that fails at the
    /// end may have written data the caller must discard).
    pub async fn upload_into<W, P>(
        &self,
        node: NodeId,
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
        let pump = Pump::upload(writer, method, progress);
        self.run_stream(node, (index, sub), pump).await
    }

    /// [`Master::download_from`] into the byte-valued entry `E` (a DOMAIN
    /// such as program data 0x1F50, or a string): compiles only for a
    /// writable one.
    pub async fn write_from<E, R, P>(
        &self,
        node: NodeId,
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
        self.download_from(node, E::INDEX, E::SUBINDEX, reader, size, method, progress)
            .await
    }

    /// [`Master::upload_into`] from the byte-valued entry `E`: compiles
    /// only for a readable one.
    pub async fn read_into<E, W, P>(
        &self,
        node: NodeId,
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
        self.upload_into(node, E::INDEX, E::SUBINDEX, writer, method, progress)
            .await
    }

    /// Runs the streamed transfer of `pump` on (index, sub) of `node`
    /// (started on the node's client, which gives the bound), the pump
    /// after every frame; returns the bytes fed or written.
    async fn run_stream<R, W, P>(
        &self,
        node: NodeId,
        (index, sub): (u16, u8),
        mut pump: Pump<'_, R, W, P>,
    ) -> Result<usize, Error>
    where
        R: Read,
        W: Write,
        P: FnMut(Progress),
    {
        let object = Object::new(Some(node), index, sub);
        let plan = pump.plan;
        let start = move |client: &mut client::SdoClient, now| plan.start(client, now, object);
        let round = |client: &mut client::SdoClient, now| match pump.round(client, now) {
            ControlFlow::Continue(()) => Ok(()),
            // The source or sink failed: its error, the abort queued.
            ControlFlow::Break(()) => Err(stream_error(
                client,
                &mut pump,
                RunError::Stopped,
                object,
                None,
            )),
        };
        let upload = self
            .run_transfer(node, index, sub, start, Some(round))
            .await?;
        pump.finish(&upload.data)
    }
}
