//! Entries as plain data: the generated `od::OBJECTS` table.

use super::{AccessRight, DataType, NodeId};

/// A number from an object description (default or limit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Number {
    /// Integers, BOOLEAN and the TIME types (as their raw integer).
    Int(i128),
    /// REAL32 and REAL64.
    Real(f64),
}

/// The default value of an entry, as the source gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DefaultValue {
    Number(Number),
    /// `$NODEID + value`: the node id is added for a given node.
    NodeRelative(i128),
    /// Strings and domains: their bytes.
    Bytes(&'static [u8]),
}

/// The description of one entry as plain data, for code that works on the
/// whole dictionary at run time (device simulators, configuration tools).
/// Generated code lists every entry in `od::OBJECTS`, sorted by index and
/// subindex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectInfo {
    pub index: u16,
    pub subindex: u8,
    /// The entry's name in the source.
    pub name: &'static str,
    pub data_type: DataType,
    pub access: AccessRight,
    pub pdo_mappable: bool,
    pub default: Option<DefaultValue>,
    pub low_limit: Option<Number>,
    pub high_limit: Option<Number>,
}

impl ObjectInfo {
    /// An entry without default or limits; generated tables add them with
    /// [`ObjectInfo::with_default`] and [`ObjectInfo::with_limits`], one
    /// line per entry.
    pub const fn new(
        index: u16,
        subindex: u8,
        name: &'static str,
        data_type: DataType,
        access: AccessRight,
        pdo_mappable: bool,
    ) -> ObjectInfo {
        ObjectInfo {
            index,
            subindex,
            name,
            data_type,
            access,
            pdo_mappable,
            default: None,
            low_limit: None,
            high_limit: None,
        }
    }

    /// The same entry with a default.
    pub const fn with_default(mut self, default: DefaultValue) -> ObjectInfo {
        self.default = Some(default);
        self
    }

    /// The same entry with limits (either may be `None`).
    pub const fn with_limits(mut self, low: Option<Number>, high: Option<Number>) -> ObjectInfo {
        self.low_limit = low;
        self.high_limit = high;
        self
    }

    /// The little-endian bus form of a numeric default for `node` (needed
    /// for `$NODEID` defaults) into `out`; returns its length. `None` for
    /// byte defaults, entries without a fixed size, a node-relative default
    /// without a node, or a value that does not fit the type.
    pub fn encode_default(&self, node: Option<NodeId>, out: &mut [u8; 8]) -> Option<usize> {
        let size = self.data_type.size()?;
        let raw: u64 = match self.default? {
            DefaultValue::Number(Number::Int(v)) => int_bits(v, self.data_type, size)?,
            DefaultValue::NodeRelative(v) => {
                int_bits(v + i128::from(node?.get()), self.data_type, size)?
            }
            DefaultValue::Number(Number::Real(f)) => match self.data_type {
                DataType::Real32 => u64::from((f as f32).to_bits()),
                DataType::Real64 => f.to_bits(),
                _ => return None,
            },
            DefaultValue::Bytes(_) => return None,
        };
        let bytes = raw.to_le_bytes();
        out[..size].copy_from_slice(&bytes[..size]);
        Some(size)
    }
}

/// The two's-complement bits of `v` in `size` bytes, when it fits the type.
fn int_bits(v: i128, data_type: DataType, size: usize) -> Option<u64> {
    let bits = 8 * size as u32;
    let (min, max) = if data_type.is_signed() {
        (-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1)
    } else {
        (0, (1i128 << bits) - 1)
    };
    if v < min || v > max {
        return None;
    }
    Some(v as u64 & (u64::MAX >> (64 - bits)))
}
