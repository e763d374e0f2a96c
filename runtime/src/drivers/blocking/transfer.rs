//! One SDO transfer of a driver call: its object (named in its errors),
//! how it starts on the client core, its bound, how its end event reads,
//! and how a transfer the driver gives up on is aborted.

use core::ops::ControlFlow;
use core::time::Duration;
use std::collections::VecDeque;
use std::string::String;
use std::vec::Vec;

use super::{Error, RunError};
use crate::frame::CanId;
use crate::master::MasterEvent;
use crate::od::{self, Entry, NodeId};
use crate::sdo::client::{self, ClientConfig, ClientEvent, Method};
use crate::sdo::typed::{self, LengthNote};
use crate::sdo::{AbortCode, Channel, SdoError};
use crate::{Instant, Service};

/// The object a transfer is about, named in its errors.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Object {
    pub(crate) node: Option<NodeId>,
    pub(crate) index: u16,
    pub(crate) sub: u8,
}

impl Object {
    pub(crate) fn new(node: Option<NodeId>, index: u16, sub: u8) -> Object {
        Object { node, index, sub }
    }

    /// The transfer failed with `error`.
    pub(crate) fn sdo(self, error: SdoError) -> Error {
        let Object { node, index, sub } = self;
        Error::Sdo {
            node,
            index,
            sub,
            error,
        }
    }

    /// The value had the wrong length.
    pub(crate) fn value(self, error: od::ValueError) -> Error {
        let Object { node, index, sub } = self;
        Error::Value {
            node,
            index,
            sub,
            error,
        }
    }

    /// The client core is busy.
    pub(crate) fn busy(self) -> Error {
        Error::SdoBusy { node: self.node }
    }
}

/// The node whose default SDO channel `channel` is (0x600 + node to the
/// server, 0x580 + node back); `None` for any other channel.
pub(crate) fn channel_node(channel: Channel) -> Option<NodeId> {
    let CanId::Standard(request) = channel.request else {
        return None;
    };
    let node = NodeId::new(u8::try_from(request.checked_sub(0x600)?).ok()?)?;
    (Channel::default_for(node) == channel).then_some(node)
}

/// The transfer a driver call runs.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Transfer<'a> {
    Upload(Method),
    Download(&'a [u8], Method),
}

impl Transfer<'_> {
    /// Starts the transfer of `object` on the core.
    pub(crate) fn start(
        self,
        core: &mut client::SdoClient,
        now: Instant,
        object: Object,
    ) -> Result<(), Error> {
        // Events of earlier transfers (there are none unless a call was cut
        // short) would make the core refuse.
        while core.poll_event().is_some() {}
        let (index, sub) = (object.index, object.sub);
        match self {
            Transfer::Upload(method) => core.upload_with(now, index, sub, method),
            Transfer::Download(data, method) => core.download_with(now, index, sub, data, method),
        }
        .map_err(|client::Busy| object.busy())
    }

    /// An upper bound of the transfer's duration when the server answers
    /// every step just in time: one timeout per request/response step
    /// (initiate, one per 7-byte segment, end) plus slack.
    pub(crate) fn bound(self, config: &ClientConfig) -> Duration {
        let len = match self {
            Transfer::Upload(_) => config.max_upload,
            Transfer::Download(data, _) => data.len(),
        };
        let steps = len.div_ceil(7).saturating_add(4);
        let steps = u32::try_from(steps).unwrap_or(u32::MAX);
        config.timeout.saturating_mul(steps)
    }
}

/// The data a transfer ended with (empty for downloads), and whether it
/// is an expedited response's padded 4 bytes
/// ([`ClientEvent::Uploaded`]'s `padded`).
#[derive(Debug)]
pub(crate) struct Upload {
    pub(crate) data: Vec<u8>,
    pub(crate) padded: bool,
}

/// The value the run's closure breaks with once the transfer of `object`
/// ended: the uploaded data (empty for downloads) or the error.
pub(crate) fn transfer_end(
    event: ClientEvent,
    object: Object,
) -> ControlFlow<Result<Upload, Error>> {
    let this = |i: u16, s: u8| (i, s) == (object.index, object.sub);
    match event {
        ClientEvent::Uploaded {
            index,
            sub,
            data,
            padded,
        } if this(index, sub) => ControlFlow::Break(Ok(Upload { data, padded })),
        ClientEvent::Downloaded { index, sub } if this(index, sub) => {
            ControlFlow::Break(Ok(Upload {
                data: Vec::new(),
                padded: false,
            }))
        }
        ClientEvent::Failed { index, sub, error } if this(index, sub) => {
            ControlFlow::Break(Err(object.sdo(error)))
        }
        _ => ControlFlow::Continue(()),
    }
}

/// The end of the master's transfer of `object` (of its node) that
/// `event` brings: `Ok` with the uploaded data or the error, or the event
/// given back (`Err`) for the master's queue when it is another one.
pub(crate) fn master_transfer_end(
    event: MasterEvent,
    object: Object,
) -> Result<Result<Upload, Error>, MasterEvent> {
    match event {
        MasterEvent::Sdo(n, e) if Some(n) == object.node => match transfer_end(e.clone(), object) {
            ControlFlow::Break(result) => Ok(result),
            ControlFlow::Continue(()) => Err(MasterEvent::Sdo(n, e)),
        },
        other => Err(other),
    }
}

/// Ends a transfer of `object` the driver gives up on: aborts it on the
/// core (the caller then sends the abort frame) and drops its events.
/// `limit` is the bound on the whole transfer the run's deadline stood
/// for. Returns the error to report.
pub(crate) fn give_up(
    core: &mut client::SdoClient,
    error: RunError,
    object: Object,
    limit: Option<Duration>,
) -> Error {
    let (code, error) = match error {
        RunError::Io(e) => (AbortCode::GeneralError, Error::Io(e)),
        RunError::Deadline => {
            let Object { node, index, sub } = object;
            let error = match limit {
                Some(limit) => Error::TransferTooLong {
                    node,
                    index,
                    sub,
                    limit,
                },
                None => object.sdo(SdoError::Timeout),
            };
            (AbortCode::Timeout, error)
        }
        RunError::Stopped => (
            AbortCode::Timeout,
            object.sdo(SdoError::LocalAbort(AbortCode::Timeout)),
        ),
    };
    if !core.is_idle() {
        core.abort(code);
    }
    while core.poll_event().is_some() {}
    error
}

/// A VISIBLE_STRING value of `object`: the bytes before the first NUL
/// (CiA 301 allows NUL as padding), each a visible character 0x20 to 0x7E.
pub(crate) fn visible_string(mut data: Vec<u8>, object: Object) -> Result<String, Error> {
    if let Some(end) = data.iter().position(|&b| b == 0) {
        data.truncate(end);
    }
    let not_visible = |offset, byte| Error::NotVisible {
        node: object.node,
        index: object.index,
        sub: object.sub,
        offset,
        byte,
    };
    if let Some(offset) = data.iter().position(|b| !(0x20..=0x7E).contains(b)) {
        let byte = data.get(offset).copied().unwrap_or(0);
        return Err(not_visible(offset, byte));
    }
    // Every byte is ASCII, so this never fails.
    String::from_utf8(data).map_err(|e| not_visible(e.utf8_error().valid_up_to(), 0))
}

impl Upload {
    /// The value of entry `E` this upload of `object` carried (see
    /// [`typed::decode_upload`]; `strict` as [`ClientConfig::strict_lengths`]).
    /// A note about a value longer than its type goes to `notes`, made by
    /// `note`.
    pub(crate) fn value<E, T>(
        &self,
        object: Object,
        strict: bool,
        notes: &mut VecDeque<T>,
        note: impl FnOnce(LengthNote) -> T,
    ) -> Result<E::Value, Error>
    where
        E: Entry,
        E::Access: od::Read,
        E::Value: od::Scalar,
    {
        let (value, length) =
            typed::decode_upload::<E>(object.sub, &self.data, self.padded, strict)
                .map_err(|e| object.value(e))?;
        if let Some(length) = length {
            typed::keep(notes, note(length));
        }
        Ok(value)
    }
}

/// The bus form of a typed value (at most 8 bytes).
pub(crate) struct Encoded {
    buf: [u8; 8],
    len: usize,
}

impl Encoded {
    /// The bytes to download.
    pub(crate) fn bytes(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or(&self.buf)
    }
}

/// The bus form of a typed value for `object`.
pub(crate) fn encode<E>(value: E::Value, object: Object) -> Result<Encoded, Error>
where
    E: Entry,
    E::Access: od::Write,
    E::Value: od::Scalar,
{
    let mut buf = [0u8; 8];
    let len = od::encode_value::<E>(value, &mut buf).map_err(|e| object.value(e))?;
    Ok(Encoded { buf, len })
}
