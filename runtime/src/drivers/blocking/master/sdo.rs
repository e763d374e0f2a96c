//! The SDO calls of the blocking [`Master`]: raw and typed transfers of
//! any node, run while the master keeps running.

use std::string::String;
use std::vec::Vec;

use super::{Error, Master};
use crate::blocking::{
    Object, Transfer, Upload, encode, give_up, master_transfer_end, visible_string,
};
use crate::od::{self, Entry, NodeId};
use crate::sdo::client::Method;
use crate::transport::Bus;

impl<B: Bus> Master<B> {
    fn transfer(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        transfer: Transfer<'_>,
    ) -> Result<Upload, Error> {
        // Events of transfers started on the core stay queued.
        self.pump();
        let now = self.now();
        let object = Object::new(Some(node), index, sub);
        let client = self.core.sdo_or_default(node);
        transfer.start(client, now, object)?;
        let limit = transfer.bound(client.config());
        let result = self.wait(Some(now + limit), &mut |event| {
            master_transfer_end(event, object)
        });
        match result {
            Ok(result) => result,
            Err(e) => {
                let error = give_up(self.core.sdo_or_default(node), e, object, Some(limit));
                // Best effort: the abort frame of a failing bus may not go.
                let _ = self.flush();
                Err(error)
            }
        }
    }

    /// Reads (index, sub) of `node` with [`Method::Auto`]. A node without
    /// an SDO client gets one on its default channel.
    pub fn upload(&mut self, node: NodeId, index: u16, sub: u8) -> Result<Vec<u8>, Error> {
        self.upload_with(node, index, sub, Method::Auto)
    }

    /// Reads (index, sub) of `node` with `method`.
    pub fn upload_with(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        method: Method,
    ) -> Result<Vec<u8>, Error> {
        self.transfer(node, index, sub, Transfer::Upload(method))
            .map(|upload| upload.data)
    }

    /// Writes `data` to (index, sub) of `node` with [`Method::Auto`].
    pub fn download(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Error> {
        self.download_with(node, index, sub, data, Method::Auto)
    }

    /// Writes `data` to (index, sub) of `node` with `method`.
    pub fn download_with(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        data: &[u8],
        method: Method,
    ) -> Result<(), Error> {
        self.transfer(node, index, sub, Transfer::Download(data, method))
            .map(drop)
    }

    /// Reads entry `E` of `node`.
    pub fn read<E>(&mut self, node: NodeId) -> Result<E::Value, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::Scalar,
    {
        self.read_sub::<E>(node, E::SUBINDEX)
    }

    /// Writes `value` to entry `E` of `node`.
    pub fn write<E>(&mut self, node: NodeId, value: E::Value) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::Scalar,
    {
        self.write_sub::<E>(node, E::SUBINDEX, value)
    }

    /// Reads the bytes of a string, DOMAIN or other byte-valued entry.
    pub fn read_bytes<E>(&mut self, node: NodeId) -> Result<Vec<u8>, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::ByteValue,
    {
        self.upload(node, E::INDEX, E::SUBINDEX)
    }

    /// Reads a VISIBLE_STRING entry: the text before the first NUL.
    pub fn read_string<E>(&mut self, node: NodeId) -> Result<String, Error>
    where
        E: Entry<Value = od::bytes::VisibleString>,
        E::Access: od::Read,
    {
        let data = self.upload(node, E::INDEX, E::SUBINDEX)?;
        visible_string(data, Object::new(Some(node), E::INDEX, E::SUBINDEX))
    }

    /// Writes the bytes of a string, DOMAIN or other byte-valued entry.
    pub fn write_bytes<E>(&mut self, node: NodeId, data: &[u8]) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::ByteValue,
    {
        self.download(node, E::INDEX, E::SUBINDEX, data)
    }

    /// Reads element `at` of an ARRAY of `node`: the run-time form of
    /// [`Self::read`] with `A<SUB>`.
    pub fn read_at<A>(&mut self, node: NodeId, at: od::Element<A>) -> Result<A::Value, Error>
    where
        A: od::Array,
        A::Access: od::Read,
        A::Value: od::Scalar,
    {
        self.read_sub::<A>(node, at.subindex())
    }

    /// Writes `value` to element `at` of an ARRAY of `node`.
    pub fn write_at<A>(
        &mut self,
        node: NodeId,
        at: od::Element<A>,
        value: A::Value,
    ) -> Result<(), Error>
    where
        A: od::Array,
        A::Access: od::Write,
        A::Value: od::Scalar,
    {
        self.write_sub::<A>(node, at.subindex(), value)
    }

    /// Reads the bytes of element `at` of a byte-valued ARRAY (DOMAIN,
    /// strings).
    pub fn read_bytes_at<A>(&mut self, node: NodeId, at: od::Element<A>) -> Result<Vec<u8>, Error>
    where
        A: od::Array,
        A::Access: od::Read,
        A::Value: od::ByteValue,
    {
        self.upload(node, A::INDEX, at.subindex())
    }

    /// Writes the bytes of element `at` of a byte-valued ARRAY.
    pub fn write_bytes_at<A>(
        &mut self,
        node: NodeId,
        at: od::Element<A>,
        data: &[u8],
    ) -> Result<(), Error>
    where
        A: od::Array,
        A::Access: od::Write,
        A::Value: od::ByteValue,
    {
        self.download(node, A::INDEX, at.subindex(), data)
    }

    /// Typed read of sub `sub` of `E`'s object (an entry's own, or an
    /// array element's).
    fn read_sub<E>(&mut self, node: NodeId, sub: u8) -> Result<E::Value, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::Scalar,
    {
        let upload = self.transfer(node, E::INDEX, sub, Transfer::Upload(Method::Auto))?;
        let strict = self.core.sdo_or_default(node).config().strict_lengths;
        let object = Object::new(Some(node), E::INDEX, sub);
        upload.value::<E, _>(object, strict, &mut self.notes, |note| (node, note))
    }

    /// Typed write of sub `sub` of `E`'s object.
    fn write_sub<E>(&mut self, node: NodeId, sub: u8, value: E::Value) -> Result<(), Error>
    where
        E: Entry,
        E::Access: od::Write,
        E::Value: od::Scalar,
    {
        let encoded = encode::<E>(value, Object::new(Some(node), E::INDEX, sub))?;
        self.download(node, E::INDEX, sub, encoded.bytes())
    }
}
