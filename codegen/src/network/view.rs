//! A device file's object dictionary as a network configuration sees it:
//! the value of an entry for one node id (ParameterValue, else
//! DefaultValue, `$NODEID` resolved), and a value packed into the bytes of
//! an entry's data type (a concise DCF's data).

use crate::ir::{DataType, Device, Entry, Value, ValueKind};

/// A device at one node id.
pub(crate) struct DeviceView<'a> {
    pub device: &'a Device,
    pub node_id: u8,
}

/// Why a value cannot be packed for an entry.
pub(crate) enum PackError {
    /// The entry has no fixed-size numeric type (a string, a domain).
    NotNumeric(DataType),
    /// The value does not fit the type's range.
    OutOfRange { low: i128, high: i128 },
}

impl DeviceView<'_> {
    pub fn entry(&self, index: u16, sub: u8) -> Option<&Entry> {
        self.device
            .objects
            .get(&index)?
            .entries
            .get(&sub)
            .map(|e| &**e)
    }

    pub fn has_object(&self, index: u16) -> bool {
        self.device.objects.contains_key(&index)
    }

    /// The entry's value as the device starts with it, as an integer.
    pub fn integer(&self, index: u16, sub: u8) -> Option<i128> {
        let entry = self.entry(index, sub)?;
        let literal = entry.parameter_value.as_ref().or(entry.default.as_ref())?;
        match literal.resolve(Some(self.node_id)) {
            Value::Integer(v) => Some(v),
            _ => None,
        }
    }

    /// [`integer`](Self::integer) as a u32 (0 when absent or out of range).
    pub fn u32_or_zero(&self, index: u16, sub: u8) -> u32 {
        self.integer(index, sub)
            .and_then(|v| u32::try_from(v).ok())
            .unwrap_or(0)
    }

    /// The sub-indices of an object but 0, ascending.
    pub fn subs(&self, index: u16) -> Vec<u8> {
        self.device
            .objects
            .get(&index)
            .map(|o| o.entries.keys().copied().filter(|&s| s != 0).collect())
            .unwrap_or_default()
    }
}

/// The bits a PDO maps of a value of `data_type` (BOOLEAN: 1), or `None`
/// for types without a fixed length.
pub(crate) fn mapped_bits(data_type: DataType) -> Option<u8> {
    match data_type.value_kind()? {
        ValueKind::Integer { bits, .. } | ValueKind::Real { bits } => u8::try_from(bits).ok(),
        _ => None,
    }
}

/// `value` as the little-endian bytes of `data_type` (REAL32/REAL64: the
/// integer as a float).
pub(crate) fn pack(data_type: DataType, value: i128) -> Result<Vec<u8>, PackError> {
    match data_type.value_kind() {
        Some(ValueKind::Real { bits: 32 }) => Ok((value as f32).to_le_bytes().to_vec()),
        Some(ValueKind::Real { .. }) => Ok((value as f64).to_le_bytes().to_vec()),
        Some(ValueKind::Integer { bits, .. }) => {
            let (low, high) = data_type.integer_range().unwrap_or((0, 0));
            if value < low || value > high {
                return Err(PackError::OutOfRange { low, high });
            }
            let bytes = bits.div_ceil(8) as usize;
            Ok(value.to_le_bytes()[..bytes].to_vec())
        }
        _ => Err(PackError::NotNumeric(data_type)),
    }
}
