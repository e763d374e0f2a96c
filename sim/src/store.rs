//! The simulated object dictionary: every entry of a generated
//! `od::OBJECTS` table with its current value, enforcing the entry's access
//! right, data type (length) and value limits on writes from the bus.

use std::collections::BTreeMap;

use eds2rust_runtime::od::{
    AccessRight, DataType, DefaultValue, Entry, NodeId, Number, ObjectInfo, Scalar,
};
use eds2rust_runtime::sdo::abort::AbortCode;

/// Largest value accepted by default for an entry without a fixed size
/// (strings, DOMAIN): larger downloads are refused with abort 0x06070012.
/// [`ObjectTable::set_max_variable_size`] changes it (a device that takes
/// program downloads, say).
pub const MAX_VARIABLE_SIZE: usize = 4096;

/// One entry: its description and current value (little-endian bus form).
#[derive(Debug, Clone)]
struct Slot {
    info: ObjectInfo,
    value: Vec<u8>,
}

/// The object dictionary of a simulated device.
///
/// Device-side writes ([`ObjectTable::set`], [`ObjectTable::set_raw`]) check
/// only the length, as firmware writing its own status would; writes from
/// the bus go through [`ObjectTable::check_bus_write`] and
/// [`ObjectTable::check_bus_value`] first, which enforce the access right,
/// the data type's length and the entry's limits with the CiA 301 abort
/// codes.
#[derive(Debug, Clone)]
pub struct ObjectTable {
    slots: BTreeMap<(u16, u8), Slot>,
    /// Largest value of an entry without a fixed size.
    max_variable: usize,
}

/// Why a device-side write did not take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SetError {
    /// The table has no such entry.
    Missing {
        /// Object index.
        index: u16,
        /// Subindex.
        sub: u8,
    },
    /// The value has the wrong length for the entry's data type.
    Length {
        /// Object index.
        index: u16,
        /// Subindex.
        sub: u8,
        /// The data type's length.
        expected: usize,
        /// The value's length.
        actual: usize,
    },
}

impl std::fmt::Display for SetError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            SetError::Missing { index, sub } => {
                write!(f, "object {index:#06X} sub {sub} is not in the table")
            }
            SetError::Length {
                index,
                sub,
                expected,
                actual,
            } => write!(
                f,
                "object {index:#06X} sub {sub} takes {expected} bytes, not {actual}"
            ),
        }
    }
}

impl std::error::Error for SetError {}

impl ObjectTable {
    /// Lets bus writes of entries without a fixed size (strings, DOMAIN)
    /// take up to `bytes` ([`MAX_VARIABLE_SIZE`] by default).
    pub fn set_max_variable_size(&mut self, bytes: usize) {
        self.max_variable = bytes;
    }

    /// The largest value a bus write of a string or DOMAIN may have.
    pub fn max_variable_size(&self) -> usize {
        self.max_variable
    }

    /// A table holding every entry of `objects` at its default value; the
    /// `$NODEID` defaults are resolved for `node` (entries whose default
    /// needs a node id are zero while the node is unconfigured). Entries
    /// without a default start at zero (fixed size) or empty.
    pub fn new(objects: &[ObjectInfo], node: Option<NodeId>) -> ObjectTable {
        let slots = objects
            .iter()
            .map(|info| {
                let value = default_bytes(info, node);
                ((info.index, info.subindex), Slot { info: *info, value })
            })
            .collect();
        ObjectTable {
            slots,
            max_variable: MAX_VARIABLE_SIZE,
        }
    }

    /// Sets every entry in `range` of indices back to its default for
    /// `node` (the communication area 0x1000..=0x1FFF at reset
    /// communication, everything at reset application).
    pub fn reset_to_defaults(
        &mut self,
        range: std::ops::RangeInclusive<u16>,
        node: Option<NodeId>,
    ) {
        for ((index, _), slot) in self.slots.iter_mut() {
            if range.contains(index) {
                slot.value = default_bytes(&slot.info, node);
            }
        }
    }

    /// Copies the values of every entry in `range` of indices from `other`
    /// (the saved values, at reset communication).
    pub fn copy_range_from(&mut self, other: &ObjectTable, range: std::ops::RangeInclusive<u16>) {
        for (key, slot) in self.slots.iter_mut() {
            if range.contains(&key.0)
                && let Some(saved) = other.slots.get(key)
            {
                slot.value.clone_from(&saved.value);
            }
        }
    }

    /// Every entry with its current value, sorted by index and subindex.
    pub fn entries(&self) -> impl Iterator<Item = (&ObjectInfo, &[u8])> {
        self.slots.values().map(|s| (&s.info, s.value.as_slice()))
    }

    /// The description of (index, sub).
    pub fn info(&self, index: u16, sub: u8) -> Option<&ObjectInfo> {
        self.slots.get(&(index, sub)).map(|s| &s.info)
    }

    /// Whether the table has any entry of `index`.
    pub fn has_index(&self, index: u16) -> bool {
        self.slots
            .range((index, 0)..=(index, u8::MAX))
            .next()
            .is_some()
    }

    /// The current value of (index, sub) in its bus form.
    pub fn get(&self, index: u16, sub: u8) -> Option<&[u8]> {
        self.slots.get(&(index, sub)).map(|s| s.value.as_slice())
    }

    /// The current value of a fixed-size entry as an unsigned integer
    /// (little-endian, up to 8 bytes).
    pub fn get_uint(&self, index: u16, sub: u8) -> Option<u64> {
        let value = self.get(index, sub)?;
        (value.len() <= 8).then(|| raw_le(value))
    }

    /// The current value of a numeric entry as a signed integer, whatever
    /// its type: integers sign-extended per the type (UNSIGNED64 above
    /// `i64::MAX` saturates), reals rounded. `None` when the table lacks
    /// the entry or it is not a number. For code that works on any table
    /// (the generic [`Cia402`](crate::cia402::Cia402)).
    pub fn get_int(&self, index: u16, sub: u8) -> Option<i64> {
        let slot = self.slots.get(&(index, sub))?;
        match number(slot.info.data_type, &slot.value)? {
            Number::Int(v) => Some(v.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64),
            Number::Real(v) if v.is_finite() => Some(v.round() as i64),
            Number::Real(_) => None,
        }
    }

    /// Stores `value` into a numeric entry of any type, saturated to the
    /// type's range (reals converted); returns whether the value changed.
    /// [`SetError::Missing`] when the table lacks the entry, and
    /// [`SetError::Length`] (expected 0) for an entry that is not a number.
    pub fn set_int(&mut self, index: u16, sub: u8, value: i64) -> Result<bool, SetError> {
        let info = *self
            .info(index, sub)
            .ok_or(SetError::Missing { index, sub })?;
        let data_type = info.data_type;
        let not_a_number = SetError::Length {
            index,
            sub,
            expected: 0,
            actual: 8,
        };
        let size = data_type.size().ok_or(not_a_number)?;
        let raw: u64 = match data_type {
            DataType::Real32 => u64::from((value as f32).to_bits()),
            DataType::Real64 => (value as f64).to_bits(),
            DataType::Boolean => u64::from(value != 0),
            DataType::TimeOfDay | DataType::TimeDifference => return Err(not_a_number),
            t if t.is_signed() => {
                let bits = 8 * size as u32;
                let (min, max) = (-(1i64 << (bits - 1).min(63)), i64::MAX >> (64 - bits));
                value.clamp(min, max) as u64
            }
            _ => {
                let bits = 8 * size as u32;
                let max = u64::MAX >> (64 - bits);
                (value.max(0) as u64).min(max)
            }
        };
        let bytes = raw.to_le_bytes();
        self.set_raw(index, sub, &bytes[..size.min(8)])
    }

    /// The typed value of a generated entry, whatever its access right (the
    /// device reads its own objects).
    pub fn value<E>(&self) -> Option<E::Value>
    where
        E: Entry,
        E::Value: Scalar,
    {
        let bytes = self.get(E::INDEX, E::SUBINDEX)?;
        if Some(bytes.len()) != E::DATA_TYPE.size() {
            return None;
        }
        let mut raw = raw_le(bytes);
        if E::DATA_TYPE.is_signed() && bytes.len() < 8 {
            let shift = 64 - 8 * bytes.len() as u32;
            raw = (((raw << shift) as i64) >> shift) as u64;
        }
        Some(E::Value::from_raw(raw))
    }

    /// Stores the typed value of a generated entry, whatever its access
    /// right; returns whether the value changed.
    pub fn set<E>(&mut self, value: E::Value) -> Result<bool, SetError>
    where
        E: Entry,
        E::Value: Scalar,
    {
        let size = E::DATA_TYPE.size().unwrap_or(0);
        let bytes = value.to_raw().to_le_bytes();
        self.set_raw(E::INDEX, E::SUBINDEX, &bytes[..size.min(8)])
    }

    /// Stores `data` as the value of (index, sub), checking only that the
    /// entry exists and that a fixed-size type gets its length; returns
    /// whether the value changed.
    pub fn set_raw(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<bool, SetError> {
        let slot = self
            .slots
            .get_mut(&(index, sub))
            .ok_or(SetError::Missing { index, sub })?;
        if let Some(expected) = slot.info.data_type.size()
            && expected != data.len()
        {
            return Err(SetError::Length {
                index,
                sub,
                expected,
                actual: data.len(),
            });
        }
        if slot.value == data {
            return Ok(false);
        }
        slot.value.clear();
        slot.value.extend_from_slice(data);
        Ok(true)
    }

    /// Checks a read from the bus: the entry exists and is readable.
    pub fn check_bus_read(&self, index: u16, sub: u8) -> Result<&[u8], AbortCode> {
        let slot = self.slot(index, sub)?;
        if slot.info.access == AccessRight::Wo {
            return Err(AbortCode::ReadWriteOnly);
        }
        Ok(&slot.value)
    }

    /// Checks the start of a write from the bus: the entry exists, is
    /// writable, and an announced `size` fits its type.
    pub fn check_bus_write(
        &self,
        index: u16,
        sub: u8,
        size: Option<usize>,
    ) -> Result<(), AbortCode> {
        let slot = self.slot(index, sub)?;
        if matches!(slot.info.access, AccessRight::Ro | AccessRight::Const) {
            return Err(AbortCode::WriteReadOnly);
        }
        match size {
            Some(size) => check_length(slot.info.data_type, size, self.max_variable),
            None => Ok(()),
        }
    }

    /// Checks a complete value written from the bus: access, length, the
    /// BOOLEAN values 0 and 1, and the entry's low and high limits.
    pub fn check_bus_value(&self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode> {
        self.check_bus_write(index, sub, Some(data.len()))?;
        let info = &self.slot(index, sub)?.info;
        let Some(value) = number(info.data_type, data) else {
            return Ok(());
        };
        if info.data_type == DataType::Boolean && !matches!(value, Number::Int(0 | 1)) {
            return Err(AbortCode::InvalidValue);
        }
        if info.low_limit.is_some_and(|low| less(value, low)) {
            return Err(AbortCode::ValueTooLow);
        }
        if info.high_limit.is_some_and(|high| less(high, value)) {
            return Err(AbortCode::ValueTooHigh);
        }
        Ok(())
    }

    fn slot(&self, index: u16, sub: u8) -> Result<&Slot, AbortCode> {
        match self.slots.get(&(index, sub)) {
            Some(slot) => Ok(slot),
            None if self.has_index(index) => Err(AbortCode::SubindexDoesNotExist),
            None => Err(AbortCode::ObjectDoesNotExist),
        }
    }
}

/// The default value of `info` for `node` in its bus form.
fn default_bytes(info: &ObjectInfo, node: Option<NodeId>) -> Vec<u8> {
    let mut buf = [0u8; 8];
    if let Some(len) = info.encode_default(node, &mut buf) {
        return buf[..len].to_vec();
    }
    match (info.default, info.data_type.size()) {
        (Some(DefaultValue::Bytes(bytes)), _) => bytes.to_vec(),
        (_, Some(size)) => vec![0; size],
        (_, None) => Vec::new(),
    }
}

/// A download of `size` bytes into an entry of `data_type`: fixed sizes must
/// match; variable sizes must stay within `max_variable`.
fn check_length(data_type: DataType, size: usize, max_variable: usize) -> Result<(), AbortCode> {
    match data_type.size() {
        Some(expected) if size > expected => Err(AbortCode::LengthTooHigh),
        Some(expected) if size < expected => Err(AbortCode::LengthTooLow),
        None if size > max_variable => Err(AbortCode::LengthTooHigh),
        _ => Ok(()),
    }
}

fn raw_le(bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .take(8)
        .enumerate()
        .fold(0, |acc, (i, b)| acc | u64::from(*b) << (8 * i))
}

/// The numeric value of `data` for comparison with limits; `None` for
/// types without an order (strings, DOMAIN, unknown).
fn number(data_type: DataType, data: &[u8]) -> Option<Number> {
    let size = data_type.size()?;
    if data.len() != size || size > 8 {
        return None;
    }
    let raw = raw_le(data);
    Some(match data_type {
        DataType::Real32 => Number::Real(f64::from(f32::from_bits(raw as u32))),
        DataType::Real64 => Number::Real(f64::from_bits(raw)),
        DataType::Other(_) | DataType::VisibleString | DataType::OctetString => return None,
        DataType::UnicodeString | DataType::Domain => return None,
        t if t.is_signed() => {
            let shift = 64 - 8 * size as u32;
            Number::Int(i128::from(((raw << shift) as i64) >> shift))
        }
        _ => Number::Int(i128::from(raw)),
    })
}

/// `a < b` across integer and real numbers.
fn less(a: Number, b: Number) -> bool {
    match (a, b) {
        (Number::Int(a), Number::Int(b)) => a < b,
        (a, b) => as_f64(a) < as_f64(b),
    }
}

fn as_f64(n: Number) -> f64 {
    match n {
        Number::Int(v) => v as f64,
        Number::Real(v) => v,
    }
}
