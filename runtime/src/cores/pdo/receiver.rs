//! [`PdoReceiver`]: the PDOs the master receives (the devices' TPDOs).

use core::fmt;
use core::time::Duration;

use super::{CobIdError, PdoCobId};
use crate::od::{self, PdoLengthError};
use crate::queue::Ring;
use crate::time::earliest;
use crate::{CanId, Frame, Instant, Service};

/// Number of events a [`PdoReceiver`] keeps; when full, the oldest is
/// dropped and counted ([`PdoReceiver::dropped_events`]). The last data of
/// every PDO stays readable through [`PdoReceiver::latest_data`].
pub const RECEIVER_EVENTS: usize = 16;

/// What a [`PdoReceiver`] saw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum PdoEvent {
    /// A watched PDO arrived with its expected length.
    Received {
        /// The identifier on the bus.
        can_id: CanId,
        /// The data bytes, zero beyond `len`.
        data: [u8; 8],
        /// The number of data bytes.
        len: usize,
        /// When it was received.
        at: Instant,
    },
    /// A watched PDO arrived with another length than its mapping has; its
    /// data was not taken (CiA 301: "PDO not processed due to length
    /// error", EMCY 0x8210, or 0x8220 when it is too long).
    LengthError {
        /// The identifier on the bus.
        can_id: CanId,
        /// The mapped length.
        expected: usize,
        /// The received length.
        actual: usize,
    },
    /// A watched PDO with a reception timeout did not arrive in time after
    /// its last reception. Reported once per silence.
    Timeout {
        /// The identifier on the bus.
        can_id: CanId,
    },
}

impl PdoEvent {
    /// The identifier the event concerns.
    pub const fn can_id(&self) -> CanId {
        match self {
            PdoEvent::Received { can_id, .. }
            | PdoEvent::LengthError { can_id, .. }
            | PdoEvent::Timeout { can_id } => *can_id,
        }
    }

    /// The received data, for [`PdoEvent::Received`].
    pub fn data(&self) -> Option<&[u8]> {
        match self {
            PdoEvent::Received { data, len, .. } => data.get(..*len),
            _ => None,
        }
    }

    /// The CiA 301 emergency error code a device would report for a length
    /// error: 0x8210 (too short) or 0x8220 (too long).
    pub const fn emcy_code(&self) -> Option<u16> {
        match self {
            PdoEvent::LengthError {
                expected, actual, ..
            } => Some(if *actual < *expected { 0x8210 } else { 0x8220 }),
            _ => None,
        }
    }
}

/// Why [`PdoReceiver::watch`] refused a PDO.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum WatchError {
    /// Every slot is taken.
    Full,
    /// The COB-ID entry names no identifier.
    CobId(CobIdError),
    /// The COB-ID entry has bit 31 set: the PDO is disabled.
    Disabled(PdoCobId),
    /// A length above 8 bytes.
    Length(usize),
    /// The generated PDO struct gives no default COB-ID.
    NoDefaultCobId,
    /// The identifier is not watched.
    NotWatched(CanId),
}

impl fmt::Display for WatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WatchError::Full => f.write_str("every PDO receiver slot is taken"),
            WatchError::CobId(e) => e.fmt(f),
            WatchError::Disabled(v) => write!(
                f,
                "COB-ID {v} has bit 31 set: the PDO is disabled and never sent"
            ),
            WatchError::Length(n) => {
                write!(f, "a PDO of {n} bytes; a classic CAN frame holds at most 8")
            }
            WatchError::NoDefaultCobId => {
                f.write_str("the PDO has no default COB-ID; watch it with its COB-ID")
            }
            WatchError::NotWatched(id) => write!(f, "PDO identifier {id} is not watched"),
        }
    }
}

impl core::error::Error for WatchError {}

impl From<CobIdError> for WatchError {
    fn from(e: CobIdError) -> Self {
        WatchError::CobId(e)
    }
}

/// One watched PDO.
#[derive(Debug, Clone, Copy)]
struct Slot {
    can_id: CanId,
    len: u8,
    timeout: Option<Duration>,
    data: [u8; 8],
    /// The last reception with the right length.
    received: Option<Instant>,
    /// When the reception timeout expires (armed by a reception).
    deadline: Option<Instant>,
    timed_out: bool,
}

/// Receives up to `N` PDOs (sans-IO, no heap): each watched identifier
/// (11-bit or 29-bit) has
/// a slot with its expected length, an optional reception timeout and its
/// last data.
///
/// Frames with the expected length are stored and reported as
/// [`PdoEvent::Received`]; other lengths as [`PdoEvent::LengthError`] (the
/// data is dropped). A reception timeout is armed by each reception (as CiA
/// 301 deadline monitoring starts with the first PDO): if the next one does
/// not come within it, [`PdoEvent::Timeout`] is reported once, and again
/// only after a new reception stops. Remote frames and other identifiers are
/// ignored.
#[derive(Debug, Clone)]
pub struct PdoReceiver<const N: usize> {
    slots: [Option<Slot>; N],
    events: Ring<PdoEvent, RECEIVER_EVENTS>,
}

impl<const N: usize> Default for PdoReceiver<N> {
    fn default() -> Self {
        PdoReceiver::new()
    }
}

impl<const N: usize> PdoReceiver<N> {
    /// A receiver watching nothing.
    pub const fn new() -> Self {
        PdoReceiver {
            slots: [None; N],
            events: Ring::new(),
        }
    }

    /// Watches the PDO with COB-ID entry `can_id` (bit 30 is ignored),
    /// expecting `len` data bytes; `timeout` (`None`: off) reports a PDO
    /// that stops coming for that long. Watching a watched identifier again
    /// replaces its settings and forgets its data.
    pub fn watch(
        &mut self,
        cob_id: PdoCobId,
        len: usize,
        timeout: Option<Duration>,
    ) -> Result<(), WatchError> {
        let can_id = cob_id.checked_can_id()?;
        if !cob_id.is_valid() {
            return Err(WatchError::Disabled(cob_id));
        }
        let len = u8::try_from(len)
            .ok()
            .filter(|&l| l <= 8)
            .ok_or(WatchError::Length(len))?;
        let slot = Slot {
            can_id,
            len,
            timeout,
            data: [0; 8],
            received: None,
            deadline: None,
            timed_out: false,
        };
        let position = self
            .slots
            .iter()
            .position(|s| s.is_some_and(|s| s.can_id == can_id))
            .or_else(|| self.slots.iter().position(Option::is_none));
        match position.and_then(|i| self.slots.get_mut(i)) {
            Some(free) => {
                *free = Some(slot);
                Ok(())
            }
            None => Err(WatchError::Full),
        }
    }

    /// Watches the generated PDO `P` of `node` on its default COB-ID with
    /// its length [`od::Pdo::LEN`], without timeout; returns the identifier.
    pub fn watch_pdo<P: od::Pdo>(&mut self, node: od::NodeId) -> Result<CanId, WatchError> {
        let cob_id = P::default_cob_id(node).ok_or(WatchError::NoDefaultCobId)?;
        self.watch(cob_id, P::LEN, None)?;
        Ok(cob_id.can_id())
    }

    /// Sets the reception timeout of a watched identifier (`None`: off); it
    /// counts from the last reception, if there was one.
    pub fn set_timeout(
        &mut self,
        can_id: CanId,
        timeout: Option<Duration>,
    ) -> Result<(), WatchError> {
        let slot = self
            .slot_mut(can_id)
            .ok_or(WatchError::NotWatched(can_id))?;
        slot.timeout = timeout;
        slot.deadline = match (slot.timeout, slot.received) {
            (Some(t), Some(at)) if !slot.timed_out => Some(at + t),
            _ => None,
        };
        Ok(())
    }

    /// Stops watching `can_id`; `false` when it was not watched.
    pub fn unwatch(&mut self, can_id: CanId) -> bool {
        match self
            .slots
            .iter_mut()
            .find(|s| s.is_some_and(|s| s.can_id == can_id))
        {
            Some(slot) => {
                *slot = None;
                true
            }
            None => false,
        }
    }

    /// Whether `can_id` is watched.
    pub fn is_watched(&self, can_id: CanId) -> bool {
        self.slot(can_id).is_some()
    }

    /// The last data received on `can_id` (`None` before the first
    /// reception or when it is not watched).
    pub fn latest_data(&self, can_id: CanId) -> Option<&[u8]> {
        let slot = self.slot(can_id)?;
        slot.received?;
        slot.data.get(..usize::from(slot.len))
    }

    /// When `can_id` was last received with the right length.
    pub fn last_received(&self, can_id: CanId) -> Option<Instant> {
        self.slot(can_id)?.received
    }

    /// Whether the reception timeout of `can_id` expired and no PDO came since.
    pub fn is_timed_out(&self, can_id: CanId) -> bool {
        self.slot(can_id).is_some_and(|s| s.timed_out)
    }

    /// The last data of `can_id` decoded as the generated struct `P`
    /// (`None` before the first reception or when it is not watched; a
    /// length error when `P` does not have the watched length).
    pub fn latest<P: od::Pdo>(&self, can_id: CanId) -> Option<Result<P, PdoLengthError>> {
        self.latest_data(can_id).map(P::decode)
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }

    fn slot(&self, can_id: CanId) -> Option<&Slot> {
        self.slots.iter().flatten().find(|s| s.can_id == can_id)
    }

    fn slot_mut(&mut self, can_id: CanId) -> Option<&mut Slot> {
        self.slots.iter_mut().flatten().find(|s| s.can_id == can_id)
    }
}

impl<const N: usize> Service for PdoReceiver<N> {
    type Event = PdoEvent;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        if frame.is_remote() {
            return;
        }
        let id = frame.id();
        let Some(slot) = self.slots.iter_mut().flatten().find(|s| s.can_id == id) else {
            return;
        };
        let expected = usize::from(slot.len);
        if frame.len() != expected {
            let event = PdoEvent::LengthError {
                can_id: id,
                expected,
                actual: frame.len(),
            };
            self.events.push(event);
            return;
        }
        slot.data = [0; 8];
        for (d, s) in slot.data.iter_mut().zip(frame.data()) {
            *d = *s;
        }
        slot.received = Some(now);
        slot.deadline = slot.timeout.map(|t| now + t);
        slot.timed_out = false;
        let event = PdoEvent::Received {
            can_id: id,
            data: slot.data,
            len: expected,
            at: now,
        };
        self.events.push(event);
    }

    fn handle_timeout(&mut self, now: Instant) {
        for slot in self.slots.iter_mut().flatten() {
            if slot.deadline.is_some_and(|due| due <= now) {
                slot.deadline = None;
                slot.timed_out = true;
                self.events.push(PdoEvent::Timeout {
                    can_id: slot.can_id,
                });
            }
        }
    }

    fn poll_event(&mut self) -> Option<PdoEvent> {
        self.events.pop()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.slots
            .iter()
            .flatten()
            .fold(None, |acc, slot| earliest(acc, slot.deadline))
    }
}

#[cfg(test)]
mod tests;
