//! The SDO calls of the tokio [`Master`]: raw and typed transfers, and the
//! PDO configuration over them.

use core::time::Duration;
use std::vec::Vec;

use ::tokio::sync::oneshot;

use super::{Error, Master, SdoWaiter, Shared};
use crate::Instant;
use crate::blocking::{Object, RunError, Transfer, Upload, encode, give_up, visible_string};
use crate::od::{self, Entry, NodeId};
use crate::sdo::client::{self, Method};

/// Ends the transfer of a call that did not see its end (dropped, or past
/// its bound `limit`): aborts it on the core and wakes the driver to send
/// the abort. `None` when the transfer had already ended (its result is in
/// the call's channel).
fn abandon(
    shared: &Shared,
    object: Object,
    id: u64,
    why: RunError,
    limit: Option<Duration>,
) -> Option<Error> {
    let node = object.node?;
    let mut state = shared.lock();
    if state.sdo.get(&node).is_none_or(|w| w.id != id) {
        return None;
    }
    state.sdo.remove(&node);
    let error = give_up(state.core.sdo_or_default(node), why, object, limit);
    drop(state);
    shared.wake.notify_one();
    Some(error)
}

/// The round of a transfer that is not streamed (never called).
type NoRound = fn(&mut client::SdoClient, Instant) -> Result<(), Error>;

/// Abandons the transfer when the call's future is dropped before its end.
struct Guard<'a> {
    shared: &'a Shared,
    object: Object,
    id: u64,
    armed: bool,
}

impl Drop for Guard<'_> {
    fn drop(&mut self) {
        if self.armed {
            abandon(self.shared, self.object, self.id, RunError::Stopped, None);
        }
    }
}

impl Master {
    async fn transfer(
        &self,
        node: NodeId,
        index: u16,
        sub: u8,
        transfer: Transfer<'_>,
    ) -> Result<Upload, Error> {
        let object = Object::new(Some(node), index, sub);
        let start = |client: &mut client::SdoClient, now| {
            transfer.start(client, now, object)?;
            Ok(Some(transfer.bound(client.config())))
        };
        self.run_transfer(node, index, sub, start, None::<NoRound>)
            .await
    }

    /// Runs one transfer with `node` to its end: waits for the node's turn,
    /// `start`s it on the core (which gives the bound of the whole
    /// transfer, `None`: unbounded), and waits for its end event, giving up
    /// (aborting) past the bound or when dropped. A streamed transfer runs
    /// `round` on the node's client once at the start and after every
    /// frame the driver receives; an error of `round` ends the transfer
    /// with it (`round` has queued the abort).
    pub(super) async fn run_transfer<R>(
        &self,
        node: NodeId,
        index: u16,
        sub: u8,
        start: impl FnOnce(&mut client::SdoClient, Instant) -> Result<Option<Duration>, Error>,
        mut round: Option<R>,
    ) -> Result<Upload, Error>
    where
        R: FnMut(&mut client::SdoClient, Instant) -> Result<(), Error>,
    {
        let turn = {
            let mut state = self.shared.lock();
            state.running()?;
            state.turns.entry(node).or_default().clone()
        };
        let _turn = turn.lock_owned().await;
        let object = Object::new(Some(node), index, sub);
        let (mut reply, bound, deadline, id) = {
            let mut state = self.shared.lock();
            state.running()?;
            let now = self.shared.now();
            let client = state.core.sdo_or_default(node);
            let bound = start(client, now)?;
            let (tx, rx) = oneshot::channel();
            let id = state.next_id();
            let waiter = SdoWaiter {
                id,
                object,
                reply: tx,
            };
            state.sdo.insert(node, waiter);
            (rx, bound, bound.map(|b| now + b), id)
        };
        let mut guard = Guard {
            shared: &self.shared,
            object,
            id,
            armed: true,
        };
        let wake =
            deadline.map(|at| ::tokio::time::Instant::from_std(self.shared.clock.to_std(at)));
        let result = loop {
            // Armed before the round looks at the core, so that a frame
            // received after it wakes this call.
            let received = self.shared.received.notified();
            let mut received = core::pin::pin!(received);
            if let Some(round) = round.as_mut() {
                received.as_mut().enable();
                let mut state = self.shared.lock();
                if state.sdo.get(&node).is_some_and(|w| w.id == id) {
                    let now = self.shared.now();
                    if let Err(error) = round(state.core.sdo_or_default(node), now) {
                        state.sdo.remove(&node);
                        drop(state);
                        guard.armed = false;
                        self.shared.wake.notify_one();
                        return Err(error);
                    }
                }
            }
            self.shared.wake.notify_one();
            let until = async {
                match wake {
                    Some(wake) => ::tokio::time::sleep_until(wake).await,
                    None => core::future::pending().await,
                }
            };
            let streamed = round.is_some();
            ::tokio::select! {
                result = &mut reply => break Some(result),
                () = until => break None,
                () = received, if streamed => {}
            }
        };
        guard.armed = false;
        let result = match result {
            Some(result) => result.ok(),
            None => match abandon(&self.shared, object, id, RunError::Deadline, bound) {
                Some(error) => return Err(error),
                None => reply.try_recv().ok(),
            },
        };
        // A dropped sender: the driver stopped.
        result.unwrap_or_else(|| Err(self.shared.lock().stopped_error()))
    }

    /// Reads (index, sub) of `node` with [`Method::Auto`]. A node without
    /// an SDO client gets one on its default channel.
    pub async fn upload(&self, node: NodeId, index: u16, sub: u8) -> Result<Vec<u8>, Error> {
        self.upload_with(node, index, sub, Method::Auto).await
    }

    /// Reads (index, sub) of `node` with `method`.
    pub async fn upload_with(
        &self,
        node: NodeId,
        index: u16,
        sub: u8,
        method: Method,
    ) -> Result<Vec<u8>, Error> {
        self.transfer(node, index, sub, Transfer::Upload(method))
            .await
            .map(|upload| upload.data)
    }

    /// Writes `data` to (index, sub) of `node` with [`Method::Auto`].
    pub async fn download(
        &self,
        node: NodeId,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Error> {
        self.download_with(node, index, sub, data, Method::Auto)
            .await
    }

    /// Writes `data` to (index, sub) of `node` with `method`.
    pub async fn download_with(
        &self,
        node: NodeId,
        index: u16,
        sub: u8,
        data: &[u8],
        method: Method,
    ) -> Result<(), Error> {
        self.transfer(node, index, sub, Transfer::Download(data, method))
            .await
            .map(drop)
    }

    /// Reads entry `E` of `node`:
    ///
    /// ```no_run
    /// use eds2rust_runtime::od::{access, DataType, Entry, NodeId};
    /// struct HeartbeatTime;
    /// impl Entry for HeartbeatTime {
    ///     const INDEX: u16 = 0x1017;
    ///     const SUBINDEX: u8 = 0;
    ///     const NAME: &'static str = "Producer heartbeat time";
    ///     const DATA_TYPE: DataType = DataType::Unsigned16;
    ///     const PDO_MAPPABLE: bool = false;
    ///     type Access = access::Rw;
    ///     type Value = u16;
    /// }
    /// async fn f(m: &eds2rust_runtime::tokio::Master, node: NodeId) {
    ///     let ms: u16 = m.read::<HeartbeatTime>(node).await.unwrap();
    ///     m.write::<HeartbeatTime>(node, ms * 2).await.unwrap();
    /// }
    /// ```
    ///
    /// Reading a write-only entry does not compile:
    ///
    /// ```compile_fail
    /// use eds2rust_runtime::od::{access, DataType, Entry, NodeId};
    /// struct Command;
    /// impl Entry for Command {
    ///     const INDEX: u16 = 0x2000;
    ///     const SUBINDEX: u8 = 0;
    ///     const NAME: &'static str = "Command";
    ///     const DATA_TYPE: DataType = DataType::Unsigned8;
    ///     const PDO_MAPPABLE: bool = false;
    ///     type Access = access::Wo;
    ///     type Value = u8;
    /// }
    /// async fn f(m: &eds2rust_runtime::tokio::Master, node: NodeId) {
    ///     let _ = m.read::<Command>(node).await;
    /// }
    /// ```
    pub async fn read<E>(&self, node: NodeId) -> Result<E::Value, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::Scalar,
    {
        self.read_sub::<E>(node, E::SUBINDEX).await
    }

    /// Writes `value` to entry `E` of `node`. Writing a read-only entry
    /// does not compile:
    ///
    /// ```compile_fail
    /// use eds2rust_runtime::od::{access, DataType, Entry, NodeId};
    /// struct DeviceType;
    /// impl Entry for DeviceType {
    ///     const INDEX: u16 = 0x1000;
    ///     const SUBINDEX: u8 = 0;
    ///     const NAME: &'static str = "Device type";
    ///     const DATA_TYPE: DataType = DataType::Unsigned32;
    ///     const PDO_MAPPABLE: bool = false;
    ///     type Access = access::Ro;
    ///     type Value = u32;
    /// }
    /// async fn f(m: &eds2rust_runtime::tokio::Master, node: NodeId) {
    ///     let _ = m.write::<DeviceType>(node, 1).await;
    /// }
    /// ```
    pub async fn write<E>(&self, node: NodeId, value: E::Value) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::Scalar,
    {
        self.write_sub::<E>(node, E::SUBINDEX, value).await
    }

    /// Reads the bytes of a string, DOMAIN or other byte-valued entry.
    pub async fn read_bytes<E>(&self, node: NodeId) -> Result<Vec<u8>, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::ByteValue,
    {
        self.upload(node, E::INDEX, E::SUBINDEX).await
    }

    /// Reads a VISIBLE_STRING entry: the text before the first NUL.
    pub async fn read_string<E>(&self, node: NodeId) -> Result<std::string::String, Error>
    where
        E: Entry<Value = od::bytes::VisibleString>,
        E::Access: od::Read,
    {
        let data = self.upload(node, E::INDEX, E::SUBINDEX).await?;
        visible_string(data, Object::new(Some(node), E::INDEX, E::SUBINDEX))
    }

    /// Writes the bytes of a string, DOMAIN or other byte-valued entry.
    pub async fn write_bytes<E>(&self, node: NodeId, data: &[u8]) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::ByteValue,
    {
        self.download(node, E::INDEX, E::SUBINDEX, data).await
    }

    /// Reads element `at` of an ARRAY of `node`: the run-time form of
    /// [`Self::read`] with `A<SUB>`.
    pub async fn read_at<A>(&self, node: NodeId, at: od::Element<A>) -> Result<A::Value, Error>
    where
        A: od::Array,
        A::Access: od::Read,
        A::Value: od::Scalar,
    {
        self.read_sub::<A>(node, at.subindex()).await
    }

    /// Writes `value` to element `at` of an ARRAY of `node`.
    pub async fn write_at<A>(
        &self,
        node: NodeId,
        at: od::Element<A>,
        value: A::Value,
    ) -> Result<(), Error>
    where
        A: od::Array,
        A::Access: od::Write,
        A::Value: od::Scalar,
    {
        self.write_sub::<A>(node, at.subindex(), value).await
    }

    /// Reads the bytes of element `at` of a byte-valued ARRAY (DOMAIN,
    /// strings).
    pub async fn read_bytes_at<A>(&self, node: NodeId, at: od::Element<A>) -> Result<Vec<u8>, Error>
    where
        A: od::Array,
        A::Access: od::Read,
        A::Value: od::ByteValue,
    {
        self.upload(node, A::INDEX, at.subindex()).await
    }

    /// Writes the bytes of element `at` of a byte-valued ARRAY.
    pub async fn write_bytes_at<A>(
        &self,
        node: NodeId,
        at: od::Element<A>,
        data: &[u8],
    ) -> Result<(), Error>
    where
        A: od::Array,
        A::Access: od::Write,
        A::Value: od::ByteValue,
    {
        self.download(node, A::INDEX, at.subindex(), data).await
    }

    /// Typed read of sub `sub` of `E`'s object.
    async fn read_sub<E>(&self, node: NodeId, sub: u8) -> Result<E::Value, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::Scalar,
    {
        let upload = self
            .transfer(node, E::INDEX, sub, Transfer::Upload(Method::Auto))
            .await?;
        let mut state = self.shared.lock();
        let strict = state.core.sdo_or_default(node).config().strict_lengths;
        let object = Object::new(Some(node), E::INDEX, sub);
        upload.value::<E, _>(object, strict, &mut state.notes, |note| (node, note))
    }

    /// Typed write of sub `sub` of `E`'s object.
    async fn write_sub<E>(&self, node: NodeId, sub: u8, value: E::Value) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::Scalar,
    {
        let encoded = encode::<E>(value, Object::new(Some(node), E::INDEX, sub))?;
        self.download(node, E::INDEX, sub, encoded.bytes()).await
    }
}
