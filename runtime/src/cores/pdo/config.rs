//! [`PdoConfig`]: configuring a device's PDO over SDO, as a plan of
//! [`Step`]s in the order CiA 301 prescribes.
//!
//! CiA 301 allows the mapping to change only while the PDO is invalid and
//! its mapping is switched off, so the writes are:
//! 1. the COB-ID with bit 31 set (the PDO is invalid);
//! 2. the number of mapped objects (mapping sub 0) = 0;
//! 3. the mapping entries, sub 1 to n;
//! 4. the number of mapped objects = n (the device checks the mapping now);
//! 5. the transmission type (sub 2), inhibit time (sub 3), event timer
//!    (sub 5) and SYNC start value (sub 6), those that are given;
//! 6. the COB-ID as configured (bit 31 clear: the PDO is valid again).
//!
//! Then every written value is read back, the COB-ID last.
//!
//! A [`ConfigSession`] runs the plan without I/O: it says which SDO access
//! comes next and takes the answers; the blocking and the tokio master
//! both run it.

use core::fmt;
use core::iter::FusedIterator;

use super::{CobIdError, PdoCobId, TransmissionType};
use crate::od::standard::{EventTimer, InhibitTime};
use crate::od::{self, PdoDirection};

mod session;
mod step;

pub use session::{ConfigAction, ConfigSession, ReadBackMismatch};
pub(crate) use step::read_value;
pub use step::{Step, StepAction, StepKind};

/// Most mapping entries a PDO mapping object holds (sub 1 to 0x40).
pub const MAX_ENTRIES: usize = 64;

/// The parameters of one PDO to configure on a device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct PdoConfig<'a> {
    /// RPDO (received by the device) or TPDO (sent by it).
    pub direction: PdoDirection,
    /// The communication parameter object: 0x1400 to 0x15FF for RPDOs,
    /// 0x1800 to 0x19FF for TPDOs.
    pub communication_index: u16,
    /// The mapping parameter object: 0x1600 to 0x17FF for RPDOs, 0x1A00 to
    /// 0x1BFF for TPDOs.
    pub mapping_index: u16,
    /// The COB-ID entry to leave the PDO with (bit 31 set keeps it disabled).
    pub cob_id: PdoCobId,
    /// Transmission type (sub 2), if it is to be written.
    pub transmission_type: Option<TransmissionType>,
    /// Inhibit time (sub 3), if it is to be written.
    pub inhibit_time: Option<InhibitTime>,
    /// Event timer (sub 5), if it is to be written.
    pub event_timer: Option<EventTimer>,
    /// SYNC start value (sub 6, TPDOs), if it is to be written.
    pub sync_start: Option<u8>,
    /// The mapping entries (`index << 16 | subindex << 8 | bits`), dummy
    /// entries included.
    pub entries: &'a [u32],
}

impl<'a> PdoConfig<'a> {
    /// PDO `number` (1 to 512) of `direction` with `cob_id` and `entries`;
    /// `None` for other numbers. No communication parameter besides the
    /// COB-ID is written.
    pub const fn new(
        direction: PdoDirection,
        number: u16,
        cob_id: PdoCobId,
        entries: &'a [u32],
    ) -> Option<PdoConfig<'a>> {
        if number == 0 || number > 512 {
            return None;
        }
        let base = match direction {
            PdoDirection::Rpdo => 0x1400,
            PdoDirection::Tpdo => 0x1800,
        };
        Some(PdoConfig {
            direction,
            communication_index: base + number - 1,
            mapping_index: base + 0x200 + number - 1,
            cob_id,
            transmission_type: None,
            inhibit_time: None,
            event_timer: None,
            sync_start: None,
            entries,
        })
    }

    /// The generated PDO `P` for `node`: its objects, default COB-ID and
    /// mapping; `None` when `P` has no default COB-ID.
    pub fn from_pdo<P: od::Pdo>(node: od::NodeId) -> Option<PdoConfig<'static>> {
        Some(PdoConfig {
            direction: P::DIRECTION,
            communication_index: P::COMMUNICATION_INDEX,
            mapping_index: P::MAPPING_INDEX,
            cob_id: P::default_cob_id(node)?,
            transmission_type: None,
            inhibit_time: None,
            event_timer: None,
            sync_start: None,
            entries: P::MAPPING,
        })
    }

    /// With the transmission type written.
    pub const fn with_transmission_type(mut self, value: TransmissionType) -> Self {
        self.transmission_type = Some(value);
        self
    }

    /// With the inhibit time written.
    pub const fn with_inhibit_time(mut self, value: InhibitTime) -> Self {
        self.inhibit_time = Some(value);
        self
    }

    /// With the event timer written.
    pub const fn with_event_timer(mut self, value: EventTimer) -> Self {
        self.event_timer = Some(value);
        self
    }

    /// With the SYNC start value written.
    pub const fn with_sync_start(mut self, value: u8) -> Self {
        self.sync_start = Some(value);
        self
    }

    /// Checks what CiA 301 rules out before anything is sent: a COB-ID that
    /// names no identifier, object indices outside the direction's range, more
    /// than 64 entries, a mapping longer than 64 bits, an entry of length
    /// 0, a reserved transmission type, a SYNC start value above 240.
    pub fn check(&self) -> Result<(), ConfigCheckError> {
        self.cob_id.checked_can_id()?;
        let (comm, mapping) = match self.direction {
            PdoDirection::Rpdo => (0x1400..=0x15FF, 0x1600..=0x17FF),
            PdoDirection::Tpdo => (0x1800..=0x19FF, 0x1A00..=0x1BFF),
        };
        if !comm.contains(&self.communication_index) {
            return Err(ConfigCheckError::CommunicationIndex {
                direction: self.direction,
                index: self.communication_index,
            });
        }
        if !mapping.contains(&self.mapping_index) {
            return Err(ConfigCheckError::MappingIndex {
                direction: self.direction,
                index: self.mapping_index,
            });
        }
        if self.entries.len() > MAX_ENTRIES {
            return Err(ConfigCheckError::TooManyEntries(self.entries.len()));
        }
        let mut bits = 0u32;
        for (i, &entry) in self.entries.iter().enumerate() {
            if entry & 0xFF == 0 {
                return Err(ConfigCheckError::EmptyEntry {
                    number: i + 1,
                    value: entry,
                });
            }
            bits += entry & 0xFF;
        }
        if bits > 64 {
            return Err(ConfigCheckError::TooLong { bits });
        }
        if let Some(value) = self.transmission_type {
            let allowed = match self.direction {
                PdoDirection::Rpdo => matches!(value.to_raw(), 0..=240 | 254 | 255),
                PdoDirection::Tpdo => matches!(value.to_raw(), 0..=240 | 252..=255),
            };
            if !allowed {
                return Err(ConfigCheckError::TransmissionType {
                    direction: self.direction,
                    value,
                });
            }
        }
        if let Some(value) = self.sync_start
            && value > 240
        {
            return Err(ConfigCheckError::SyncStart(value));
        }
        Ok(())
    }

    /// The SDO writes, then the read-backs (see the module docs). The plan
    /// of a configuration that fails [`PdoConfig::check`] is not meaningful.
    pub fn steps(&self) -> Steps<'_> {
        Steps {
            config: self,
            next: 0,
            end: self.step_count(),
        }
    }

    /// Number of steps: writes and read-backs.
    pub fn step_count(&self) -> usize {
        let n = self.entries.len();
        let params = self.parameters().iter().flatten().count();
        // Writes: disable, clear, n entries, count, parameters, enable.
        // Read-backs: count, n entries, parameters, COB-ID.
        (4 + n + params) + (2 + n + params)
    }

    /// Step `i` of [`PdoConfig::steps`].
    pub fn step(&self, i: usize) -> Option<Step> {
        let n = self.entries.len();
        let params = self.parameters();
        let p = params.iter().flatten().count();
        let writes = 4 + n + p;
        let (action, j) = match i.checked_sub(writes) {
            None => (StepAction::Write, i),
            Some(j) => (StepAction::ReadBack, j),
        };
        let (comm, map) = (self.communication_index, self.mapping_index);
        let count = u8::try_from(n).unwrap_or(u8::MAX);
        let entry = |k: usize| {
            let number = u8::try_from(k).unwrap_or(u8::MAX);
            let value = self.entries.get(k.wrapping_sub(1)).copied().unwrap_or(0);
            Step::new(
                action,
                StepKind::MappingEntry(number),
                map,
                number,
                value,
                4,
            )
        };
        let param = |k: usize| params.iter().flatten().nth(k).map(|s| s.with(action));
        let cob_id = |kind| Step::new(action, kind, comm, 1, self.cob_id.to_raw(), 4);
        let mapping_count = Step::new(action, StepKind::MappingCount, map, 0, count.into(), 1);
        match action {
            StepAction::Write => match j {
                0 => Some(
                    cob_id(StepKind::CobIdDisabled)
                        .with_value(self.cob_id.with_valid(false).to_raw()),
                ),
                1 => Some(Step::new(action, StepKind::MappingCleared, map, 0, 0, 1)),
                j if j < 2 + n => Some(entry(j - 1)),
                j if j == 2 + n => Some(mapping_count),
                j if j < 3 + n + p => param(j - 3 - n),
                _ => Some(cob_id(StepKind::CobId)),
            },
            StepAction::ReadBack => match j {
                0 => Some(mapping_count),
                j if j <= n => Some(entry(j)),
                j if j <= n + p => param(j - 1 - n),
                j if j == n + p + 1 => Some(cob_id(StepKind::CobId)),
                _ => None,
            },
        }
    }

    /// The communication parameters to write, in order.
    fn parameters(&self) -> [Option<Step>; 4] {
        let comm = self.communication_index;
        let write = |kind, sub, value: Option<u32>, size| {
            value.map(|v| Step::new(StepAction::Write, kind, comm, sub, v, size))
        };
        [
            write(
                StepKind::TransmissionType,
                2,
                self.transmission_type.map(|t| u32::from(t.to_raw())),
                1,
            ),
            write(
                StepKind::InhibitTime,
                3,
                self.inhibit_time.map(|t| u32::from(t.to_raw())),
                2,
            ),
            write(
                StepKind::EventTimer,
                5,
                self.event_timer.map(|t| u32::from(t.to_raw())),
                2,
            ),
            write(StepKind::SyncStart, 6, self.sync_start.map(u32::from), 1),
        ]
    }
}

/// What CiA 301 rules out in a [`PdoConfig`] (see [`PdoConfig::check`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ConfigCheckError {
    /// The COB-ID entry names no identifier.
    CobId(CobIdError),
    /// The communication parameter index is outside the direction's range.
    CommunicationIndex {
        /// The configured direction.
        direction: PdoDirection,
        /// The configured index.
        index: u16,
    },
    /// The mapping parameter index is outside the direction's range.
    MappingIndex {
        /// The configured direction.
        direction: PdoDirection,
        /// The configured index.
        index: u16,
    },
    /// More than 64 mapping entries.
    TooManyEntries(usize),
    /// The entries map more than 64 bits.
    TooLong {
        /// The mapped bits.
        bits: u32,
    },
    /// A mapping entry of length 0.
    EmptyEntry {
        /// 1-based entry number (its sub-index).
        number: usize,
        /// The entry.
        value: u32,
    },
    /// A transmission type CiA 301 reserves for the direction.
    TransmissionType {
        /// The configured direction.
        direction: PdoDirection,
        /// The configured transmission type.
        value: TransmissionType,
    },
    /// A SYNC start value above 240.
    SyncStart(u8),
}

impl fmt::Display for ConfigCheckError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ConfigCheckError::CobId(e) => e.fmt(f),
            ConfigCheckError::CommunicationIndex { direction, index } => write!(
                f,
                "communication parameter {index:#06X} is not one of an {} ({})",
                ranges(direction).0,
                ranges(direction).1
            ),
            ConfigCheckError::MappingIndex { direction, index } => write!(
                f,
                "mapping parameter {index:#06X} is not one of an {} ({})",
                ranges(direction).0,
                ranges(direction).2
            ),
            ConfigCheckError::TooManyEntries(n) => {
                write!(f, "{n} mapping entries; a PDO maps at most 64")
            }
            ConfigCheckError::TooLong { bits } => write!(
                f,
                "the mapping entries add up to {bits} bits; a PDO carries at most 64"
            ),
            ConfigCheckError::EmptyEntry { number, value } => write!(
                f,
                "mapping entry {number} ({value:#010X}) has length 0; the low byte gives the bits"
            ),
            ConfigCheckError::TransmissionType { direction, value } => write!(
                f,
                "transmission type {} is reserved for an {} by CiA 301",
                value.to_raw(),
                ranges(direction).0
            ),
            ConfigCheckError::SyncStart(v) => {
                write!(
                    f,
                    "SYNC start value {v} is invalid; CiA 301 allows 0 to 240"
                )
            }
        }
    }
}

impl core::error::Error for ConfigCheckError {}

/// The direction's name and its communication and mapping index ranges.
const fn ranges(direction: PdoDirection) -> (&'static str, &'static str, &'static str) {
    match direction {
        PdoDirection::Rpdo => ("RPDO", "0x1400 to 0x15FF", "0x1600 to 0x17FF"),
        PdoDirection::Tpdo => ("TPDO", "0x1800 to 0x19FF", "0x1A00 to 0x1BFF"),
    }
}

impl From<CobIdError> for ConfigCheckError {
    fn from(e: CobIdError) -> Self {
        ConfigCheckError::CobId(e)
    }
}

/// The steps of a [`PdoConfig`], in order ([`PdoConfig::steps`]).
#[derive(Debug, Clone)]
pub struct Steps<'c> {
    config: &'c PdoConfig<'c>,
    next: usize,
    end: usize,
}

impl Iterator for Steps<'_> {
    type Item = Step;

    fn next(&mut self) -> Option<Step> {
        if self.next >= self.end {
            return None;
        }
        let step = self.config.step(self.next);
        self.next += 1;
        step
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.end.saturating_sub(self.next);
        (left, Some(left))
    }
}

impl ExactSizeIterator for Steps<'_> {}

impl FusedIterator for Steps<'_> {}

#[cfg(test)]
mod tests;
