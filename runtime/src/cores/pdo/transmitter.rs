//! [`PdoTransmitter`]: one PDO the master sends (a device's RPDO).

use core::fmt;
use core::time::Duration;

use super::{CobIdError, PdoCobId, TransmissionType};
use crate::frame::FrameError;
use crate::od::standard::{EventTimer, InhibitTime};
use crate::sync::{DEFAULT_COB_ID as SYNC_COB_ID, parse_sync_on};
use crate::time::earliest;
use crate::{CanId, Frame, Instant, Service, od};

/// The communication parameters of a transmitted PDO, as the values of the
/// CiA 301 communication parameter object (0x1400.. on the receiving
/// device).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct TransmitterConfig {
    /// The COB-ID entry: bit 31 set disables the PDO, bit 30 (no RTR) is
    /// ignored.
    pub cob_id: PdoCobId,
    /// Synchronous acyclic (sent at the next SYNC after a change),
    /// synchronous cyclic (sent at every n-th SYNC), or event-driven (sent
    /// when the data is set); the RTR-only and reserved types are refused.
    pub transmission_type: TransmissionType,
    /// Minimum time between two event-driven transmissions (0: none).
    /// Synchronous PDOs are paced by SYNC and ignore it.
    pub inhibit_time: InhibitTime,
    /// Event-driven PDOs only: the data is sent again after this time
    /// without a transmission ([`EventTimer::duration`]; 0 is off).
    pub event_timer: EventTimer,
    /// The COB-ID of the SYNC frames that pace synchronous PDOs (11 bits).
    pub sync_cob_id: u16,
    /// Synchronous cyclic PDOs only: the SYNC counter value of the SYNC
    /// that counts as the first one (0: not used; also ignored for SYNC
    /// frames without a counter). At most 240.
    pub sync_start: u8,
}

impl TransmitterConfig {
    /// `cob_id` with `transmission_type`, no inhibit time, no event timer,
    /// SYNC on 0x080, no SYNC start value.
    pub const fn new(cob_id: PdoCobId, transmission_type: TransmissionType) -> TransmitterConfig {
        TransmitterConfig {
            cob_id,
            transmission_type,
            inhibit_time: InhibitTime(0),
            event_timer: EventTimer(0),
            sync_cob_id: SYNC_COB_ID,
            sync_start: 0,
        }
    }

    /// The configuration of `P` for `node`: its default COB-ID with
    /// `transmission_type`; `None` when `P` has no default COB-ID.
    pub fn from_pdo<P: od::Pdo>(
        node: od::NodeId,
        transmission_type: TransmissionType,
    ) -> Option<Self> {
        P::default_cob_id(node).map(|cob_id| TransmitterConfig::new(cob_id, transmission_type))
    }
}

/// A transmitter configuration this engine cannot run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum TransmitterConfigError {
    /// The COB-ID entry names no identifier.
    CobId(CobIdError),
    /// A transmission type other than 0 to 240, 254 or 255.
    TransmissionType(TransmissionType),
    /// A SYNC start value above 240.
    SyncStart(u8),
    /// A SYNC COB-ID above 0x7FF.
    SyncCobId(u16),
}

impl fmt::Display for TransmitterConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TransmitterConfigError::CobId(e) => e.fmt(f),
            TransmitterConfigError::TransmissionType(t) => write!(
                f,
                "transmission type {} is not supported: use 0 (synchronous acyclic), 1 to 240 \
                 (synchronous cyclic), 254 or 255 (event-driven)",
                t.to_raw()
            ),
            TransmitterConfigError::SyncStart(v) => {
                write!(
                    f,
                    "SYNC start value {v} is invalid; CiA 301 allows 0 to 240"
                )
            }
            TransmitterConfigError::SyncCobId(id) => {
                write!(f, "SYNC COB-ID {id:#x} is not an 11-bit identifier")
            }
        }
    }
}

impl core::error::Error for TransmitterConfigError {}

impl From<CobIdError> for TransmitterConfigError {
    fn from(e: CobIdError) -> Self {
        TransmitterConfigError::CobId(e)
    }
}

/// How transmissions are triggered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Type 0.
    SyncAcyclic,
    /// Types 1 to 240: every n-th SYNC.
    SyncCyclic(u8),
    /// Types 254 and 255.
    Event,
}

/// One PDO the master transmits (sans-IO, no heap).
///
/// - Synchronous acyclic (type 0): [`PdoTransmitter::set_data`] marks the
///   data changed; the next SYNC sends it once.
/// - Synchronous cyclic (types 1 to 240): every n-th SYNC sends the current
///   data, counting the first SYNC (or the one whose counter equals the
///   SYNC start value) as the first.
/// - Event-driven (254, 255): [`PdoTransmitter::set_data`] sends at once,
///   unless the inhibit time since the last transmission has not passed:
///   then one frame with the latest data goes out when it ends. With an
///   event timer, the data is sent again whenever that much time passed
///   since the last transmission.
///
/// Nothing is sent before the first [`PdoTransmitter::set_data`], nor while
/// the COB-ID has bit 31 set. SYNC frames are fed through
/// [`Service::handle_frame`], including those of the master's own
/// [`crate::sync::SyncProducer`] (a bus does not echo a port's own frames);
/// other frames are ignored. One frame waits in
/// [`Service::poll_transmit`]: a transmission due before the previous frame
/// was polled replaces it (the newer data wins).
#[derive(Debug, Clone)]
pub struct PdoTransmitter {
    config: TransmitterConfig,
    can_id: CanId,
    mode: Mode,
    data: [u8; 8],
    len: u8,
    has_data: bool,
    /// Type 0: the data changed since the last transmission.
    changed: bool,
    outbox: Option<Frame>,
    /// Event-driven: no transmission before this instant.
    inhibit_until: Option<Instant>,
    /// Event-driven: a transmission waits for the inhibit time to end.
    deferred: bool,
    /// Event-driven: when the event timer sends again.
    event_due: Option<Instant>,
    /// Cyclic: SYNCs until the next transmission; `None` before the first
    /// counted SYNC.
    sync_countdown: Option<u8>,
}

impl PdoTransmitter {
    /// A transmitter with `config`; it refuses COB-IDs that name no
    /// identifier, reserved and RTR-only transmission types (241 to 253)
    /// and SYNC start values above 240.
    pub fn new(config: TransmitterConfig) -> Result<PdoTransmitter, TransmitterConfigError> {
        let can_id = config.cob_id.checked_can_id()?;
        let mode = match config.transmission_type {
            TransmissionType::SynchronousAcyclic => Mode::SyncAcyclic,
            TransmissionType::SynchronousCyclic(n @ 1..=240) => Mode::SyncCyclic(n),
            TransmissionType::EventDrivenManufacturer | TransmissionType::EventDrivenProfile => {
                Mode::Event
            }
            other => return Err(TransmitterConfigError::TransmissionType(other)),
        };
        if config.sync_start > 240 {
            return Err(TransmitterConfigError::SyncStart(config.sync_start));
        }
        if config.sync_cob_id > 0x7FF {
            return Err(TransmitterConfigError::SyncCobId(config.sync_cob_id));
        }
        Ok(PdoTransmitter {
            config,
            can_id,
            mode,
            data: [0; 8],
            len: 0,
            has_data: false,
            changed: false,
            outbox: None,
            inhibit_until: None,
            deferred: false,
            event_due: None,
            sync_countdown: None,
        })
    }

    /// The configuration (with the COB-ID as last set).
    pub const fn config(&self) -> &TransmitterConfig {
        &self.config
    }

    /// The COB-ID entry.
    pub const fn cob_id(&self) -> PdoCobId {
        self.config.cob_id
    }

    /// The identifier the PDO is sent on.
    pub const fn can_id(&self) -> CanId {
        self.can_id
    }

    /// Whether the PDO is enabled (COB-ID bit 31 clear).
    pub const fn is_enabled(&self) -> bool {
        self.config.cob_id.is_valid()
    }

    /// The current data (empty before the first [`PdoTransmitter::set_data`]).
    pub fn data(&self) -> &[u8] {
        self.data.get(..usize::from(self.len)).unwrap_or(&[])
    }

    /// Sets the data at `now` (0 to 8 bytes): an event. Synchronous acyclic
    /// PDOs send it at the next SYNC, event-driven ones now or at the end of
    /// the inhibit time, cyclic ones at their next SYNC. While the PDO is
    /// disabled the data is kept and nothing is scheduled.
    pub fn set_data(&mut self, now: Instant, data: &[u8]) -> Result<(), FrameError> {
        let Some(dest) = self.data.get_mut(..data.len()) else {
            return Err(FrameError::TooLong(data.len()));
        };
        dest.copy_from_slice(data);
        self.len = data.len() as u8;
        self.has_data = true;
        if !self.is_enabled() {
            return Ok(());
        }
        match self.mode {
            Mode::SyncAcyclic => self.changed = true,
            Mode::SyncCyclic(_) => {}
            Mode::Event => {
                if self.inhibited(now) {
                    self.deferred = true;
                } else {
                    self.transmit(now);
                }
            }
        }
        Ok(())
    }

    /// Sets the data from a generated PDO struct (see
    /// [`PdoTransmitter::set_data`]).
    pub fn set<P: od::Pdo>(&mut self, now: Instant, pdo: &P) -> Result<(), FrameError> {
        let mut buf = [0u8; 8];
        let len = pdo.encode_into(&mut buf);
        match buf.get(..len) {
            Some(data) => self.set_data(now, data),
            None => Err(FrameError::TooLong(len)),
        }
    }

    /// Changes the COB-ID entry at `now`. Setting bit 31 disables the PDO
    /// (anything scheduled is dropped); clearing it enables the PDO again:
    /// the SYNC count restarts, and an event-driven PDO with data starts its
    /// event timer.
    pub fn set_cob_id(&mut self, now: Instant, cob_id: PdoCobId) -> Result<(), CobIdError> {
        let can_id = cob_id.checked_can_id()?;
        let was_enabled = self.is_enabled();
        self.can_id = can_id;
        self.config.cob_id = cob_id;
        if !cob_id.is_valid() {
            self.outbox = None;
            self.changed = false;
            self.deferred = false;
            self.inhibit_until = None;
            self.event_due = None;
            self.sync_countdown = None;
        } else if !was_enabled {
            self.sync_countdown = None;
            if self.mode == Mode::Event && self.has_data {
                self.event_due = self.event_timer().map(|t| now + t);
            }
        } else if let Some(frame) = self.outbox {
            // The waiting frame goes out on the new identifier.
            self.outbox = Some(Frame::with_id(
                can_id,
                *frame.data_padded(),
                frame.len() as u8,
            ));
        }
        Ok(())
    }

    fn event_timer(&self) -> Option<Duration> {
        self.config.event_timer.duration()
    }

    fn inhibited(&self, now: Instant) -> bool {
        self.inhibit_until.is_some_and(|end| now < end)
    }

    /// Queues a frame with the current data.
    fn queue_frame(&mut self) {
        if self.has_data {
            let mut data = [0u8; 8];
            for (d, s) in data.iter_mut().zip(self.data()) {
                *d = *s;
            }
            self.outbox = Some(Frame::with_id(self.can_id, data, self.len));
        }
    }

    /// An event-driven transmission at `now`: restarts the inhibit time and
    /// the event timer.
    fn transmit(&mut self, now: Instant) {
        self.queue_frame();
        self.deferred = false;
        let inhibit = self.config.inhibit_time.duration();
        self.inhibit_until = (!inhibit.is_zero()).then(|| now + inhibit);
        self.event_due = self.event_timer().map(|t| now + t);
    }

    fn on_sync(&mut self, counter: Option<u8>) {
        match self.mode {
            Mode::SyncAcyclic => {
                if self.changed {
                    self.changed = false;
                    self.queue_frame();
                }
            }
            Mode::SyncCyclic(every) => {
                let remaining = match self.sync_countdown {
                    Some(remaining) => remaining,
                    None => {
                        let start = self.config.sync_start;
                        if start != 0 && counter.is_some_and(|c| c != start) {
                            return;
                        }
                        every
                    }
                };
                if remaining <= 1 {
                    self.sync_countdown = Some(every);
                    self.queue_frame();
                } else {
                    self.sync_countdown = Some(remaining - 1);
                }
            }
            Mode::Event => {}
        }
    }
}

impl Service for PdoTransmitter {
    type Event = core::convert::Infallible;

    /// SYNC frames on the configured SYNC COB-ID (without data or with a
    /// counter byte) trigger synchronous transmissions.
    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        if !self.is_enabled() {
            return;
        }
        if let Some(counter) = parse_sync_on(self.config.sync_cob_id, frame) {
            self.on_sync(counter);
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        if !self.is_enabled() || self.mode != Mode::Event {
            return;
        }
        let timer_due = self.event_due.is_some_and(|due| due <= now);
        if !(self.deferred || timer_due) {
            return;
        }
        if self.inhibited(now) {
            // The event timer fired within the inhibit time: send at its end.
            self.deferred = true;
            self.event_due = None;
        } else {
            self.transmit(now);
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        self.outbox.take()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        if !self.is_enabled() || self.mode != Mode::Event {
            return None;
        }
        let inhibit_end = if self.deferred {
            self.inhibit_until
        } else {
            None
        };
        earliest(inhibit_end, self.event_due)
    }
}

#[cfg(test)]
mod tests;
