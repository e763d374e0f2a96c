//! [`Step`]: one SDO access of a PDO configuration, with its description.

use core::fmt;

use crate::pdo::PdoCobId;

/// Whether a step writes a value or reads it back to verify it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StepAction {
    /// An SDO download of [`Step::bytes`].
    Write,
    /// An SDO upload whose value must match [`Step::bytes`]
    /// ([`Step::matches`]).
    ReadBack,
}

/// What a step writes or reads back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StepKind {
    /// The COB-ID with bit 31 set: the PDO is invalid while it changes.
    CobIdDisabled,
    /// Mapping sub 0 = 0: the mapping is switched off.
    MappingCleared,
    /// Mapping entry n (sub n).
    MappingEntry(u8),
    /// Mapping sub 0 = the number of entries: the mapping is switched on.
    MappingCount,
    /// Communication sub 2.
    TransmissionType,
    /// Communication sub 3 (units of 100 µs).
    InhibitTime,
    /// Communication sub 5 (ms).
    EventTimer,
    /// Communication sub 6.
    SyncStart,
    /// The COB-ID as configured (sub 1).
    CobId,
}

/// One SDO access of a PDO configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Step {
    action: StepAction,
    kind: StepKind,
    index: u16,
    sub: u8,
    value: u32,
    data: [u8; 4],
    len: u8,
}

impl Step {
    pub(super) const fn new(
        action: StepAction,
        kind: StepKind,
        index: u16,
        sub: u8,
        value: u32,
        len: u8,
    ) -> Step {
        Step {
            action,
            kind,
            index,
            sub,
            value,
            data: value.to_le_bytes(),
            len: if len > 4 { 4 } else { len },
        }
    }

    pub(super) const fn with(self, action: StepAction) -> Step {
        Step { action, ..self }
    }

    pub(super) const fn with_value(self, value: u32) -> Step {
        Step {
            value,
            data: value.to_le_bytes(),
            ..self
        }
    }

    /// Write or read back.
    pub const fn action(&self) -> StepAction {
        self.action
    }

    /// What the step concerns.
    pub const fn kind(&self) -> StepKind {
        self.kind
    }

    /// Object index.
    pub const fn index(&self) -> u16 {
        self.index
    }

    /// Sub-index.
    pub const fn sub(&self) -> u8 {
        self.sub
    }

    /// The value written, or expected on read-back.
    pub const fn value(&self) -> u32 {
        self.value
    }

    /// The value's little-endian bytes in the size of its data type
    /// (UNSIGNED8, UNSIGNED16 or UNSIGNED32).
    pub fn bytes(&self) -> &[u8] {
        self.data.get(..usize::from(self.len)).unwrap_or(&self.data)
    }

    /// Whether bytes read back hold the expected value: compared as a
    /// little-endian number (a device may answer with more bytes than the
    /// data type has, as long as they are zero); the COB-ID's bit 30 (RTR)
    /// is not compared, since many devices fix it.
    pub fn matches(&self, read: &[u8]) -> bool {
        let Some(read) = read_value(read) else {
            return false;
        };
        let mask = if self.kind == StepKind::CobId {
            !u64::from(PdoCobId(0).with_rtr_allowed(false).to_raw())
        } else {
            u64::MAX
        };
        read & mask == u64::from(self.value) & mask
    }

    /// The name of what the step concerns, e.g. "mapping entry 2 of 0x1A00".
    pub fn name(&self) -> impl fmt::Display + '_ {
        Name(self)
    }

    /// `raw` formatted the way this step's value is (hexadecimal for
    /// COB-IDs and mapping entries, with units for times).
    pub fn format_value(&self, raw: u64) -> impl fmt::Display + '_ {
        FormattedValue { step: self, raw }
    }
}

/// Bytes read back as a little-endian number; `None` for 0 or more than 8.
pub(crate) fn read_value(read: &[u8]) -> Option<u64> {
    if read.is_empty() || read.len() > 8 {
        return None;
    }
    Some(
        read.iter()
            .rev()
            .fold(0u64, |acc, &b| (acc << 8) | u64::from(b)),
    )
}

struct Name<'s>(&'s Step);

impl fmt::Display for Name<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let index = self.0.index;
        match self.0.kind {
            StepKind::CobIdDisabled | StepKind::CobId => write!(f, "COB-ID of {index:#06X}"),
            StepKind::MappingCleared | StepKind::MappingCount => {
                write!(f, "number of mapped objects of {index:#06X}")
            }
            StepKind::MappingEntry(n) => write!(f, "mapping entry {n} of {index:#06X}"),
            StepKind::TransmissionType => write!(f, "transmission type of {index:#06X}"),
            StepKind::InhibitTime => write!(f, "inhibit time of {index:#06X}"),
            StepKind::EventTimer => write!(f, "event timer of {index:#06X}"),
            StepKind::SyncStart => write!(f, "SYNC start value of {index:#06X}"),
        }
    }
}

struct FormattedValue<'s> {
    step: &'s Step,
    raw: u64,
}

impl fmt::Display for FormattedValue<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let raw = self.raw;
        match self.step.kind {
            StepKind::CobIdDisabled | StepKind::CobId | StepKind::MappingEntry(_) => {
                write!(f, "{raw:#010X}")
            }
            StepKind::InhibitTime => write!(f, "{raw} (x 100 µs)"),
            StepKind::EventTimer => write!(f, "{raw} ms"),
            _ => write!(f, "{raw}"),
        }
    }
}

/// "write mapping entry 2 of 0x1A00 = 0x60410010 (object 0x1A00 sub 2)",
/// "read back mapping entry 2 of 0x1A00, expecting 0x60410010 (...)".
impl fmt::Display for Step {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let value = self.format_value(self.value.into());
        match self.action {
            StepAction::Write => {
                write!(f, "write {} = {value}", self.name())?;
                match self.kind {
                    StepKind::CobIdDisabled => f.write_str(", disabling the PDO")?,
                    StepKind::MappingCleared => f.write_str(", switching the mapping off")?,
                    StepKind::CobId if !PdoCobId(self.value).is_valid() => {
                        f.write_str(", leaving the PDO disabled")?
                    }
                    StepKind::CobId => f.write_str(", enabling the PDO")?,
                    _ => {}
                }
            }
            StepAction::ReadBack => write!(f, "read back {}, expecting {value}", self.name())?,
        }
        write!(f, " (object {:#06X} sub {})", self.index, self.sub)
    }
}
