//! PDO mapping entries (CiA 301: `index << 16 | subindex << 8 | bit length`)
//! and the checks every reader runs on a device's default mappings.

use std::fmt;

use super::{DataType, Device, Value, ValueKind};

/// One decoded mapping entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MappedObject {
    pub index: u16,
    pub subindex: u8,
    pub bits: u8,
}

impl MappedObject {
    pub fn from_raw(raw: u32) -> MappedObject {
        MappedObject {
            index: (raw >> 16) as u16,
            subindex: (raw >> 8) as u8,
            bits: raw as u8,
        }
    }

    pub fn raw(self) -> u32 {
        u32::from(self.index) << 16 | u32::from(self.subindex) << 8 | u32::from(self.bits)
    }

    /// A dummy entry maps a basic data type (0x0001–0x0007) as a gap.
    pub fn is_dummy(self) -> bool {
        (1..=7).contains(&self.index)
    }
}

/// The bit lengths a PDO may map an entry of `data_type` with, or `None`
/// for types without a fixed length.
pub fn mappable_bits(data_type: DataType) -> Option<&'static [u8]> {
    match data_type.value_kind()? {
        ValueKind::Integer { bits: 1, .. } => Some(&[1, 8]),
        ValueKind::Integer { bits, .. } | ValueKind::Real { bits } => Some(match bits {
            8 => &[8],
            16 => &[16],
            24 => &[24],
            32 => &[32],
            40 => &[40],
            48 => &[48],
            56 => &[56],
            _ => &[64],
        }),
        _ => None,
    }
}

/// Is `index` a PDO mapping parameter object (0x1600–0x17FF, 0x1A00–0x1BFF)?
pub fn is_mapping_object(index: u16) -> bool {
    (0x1600..=0x17FF).contains(&index) || (0x1A00..=0x1BFF).contains(&index)
}

/// What is wrong with one default mapping entry, or with a whole mapping.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MappingProblem {
    DummyNotEnabled {
        data_type: DataType,
    },
    MissingObject {
        target: MappedObject,
    },
    MissingSub {
        target: MappedObject,
    },
    NotMappable {
        target: MappedObject,
        name: String,
    },
    WrongLength {
        target: MappedObject,
        data_type: DataType,
        bits: u8,
    },
    TooLong {
        total: u32,
    },
}

impl fmt::Display for MappingProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MappingProblem::DummyNotEnabled { data_type } => write!(
                f,
                "dummy {} is not enabled in [DummyUsage]",
                data_type.name()
            ),
            MappingProblem::MissingObject { target: t } => write!(
                f,
                "maps object 0x{:04X} sub {}, which does not exist",
                t.index, t.subindex
            ),
            MappingProblem::MissingSub { target: t } => write!(
                f,
                "maps object 0x{:04X} sub {}; 0x{:04X} has no sub-index {}",
                t.index, t.subindex, t.index, t.subindex
            ),
            MappingProblem::NotMappable { target: t, name } => write!(
                f,
                "maps 0x{:04X} sub {} (`{name}`), which is not PDO-mappable",
                t.index, t.subindex
            ),
            MappingProblem::WrongLength {
                target: t,
                data_type,
                bits,
            } => write!(
                f,
                "maps 0x{:04X} sub {} with {} bits, but its type {} has {bits} bits",
                t.index,
                t.subindex,
                t.bits,
                data_type.name()
            ),
            MappingProblem::TooLong { total } => {
                write!(
                    f,
                    "the mapping totals {total} bits; a PDO carries at most 64"
                )
            }
        }
    }
}

impl MappingProblem {
    /// How to fix the problem in a YAML overlay, when a fix is known: the
    /// `modify:` of mapping entry `sub` of mapping object `mapping_index`
    /// (or of the mapped object) that makes it consistent.
    pub fn fix(&self, mapping_index: u16, sub: u8) -> Option<String> {
        match self {
            MappingProblem::WrongLength { target, bits, .. } => {
                let fixed = MappedObject {
                    bits: *bits,
                    ..*target
                };
                Some(format!(
                    "to map it with its type's length, write in a YAML overlay: \
                     `modify: [{{ index: 0x{mapping_index:04X}, sub: {sub}, default: 0x{:08X} }}]`",
                    fixed.raw()
                ))
            }
            MappingProblem::NotMappable { target, .. } => Some(format!(
                "if the device does map it, say so in a YAML overlay: \
                 `modify: [{{ index: 0x{:04X}, sub: {}, pdo: true }}]`",
                target.index, target.subindex
            )),
            _ => None,
        }
    }
}

/// The raw default (or DCF value) of a mapping entry, when it is a plain number.
pub fn raw_mapping(entry: &super::Entry) -> Option<u32> {
    let literal = entry.parameter_value.as_ref().or(entry.default.as_ref())?;
    match (&literal.value, literal.plus_node_id) {
        (Value::Integer(raw), false) => u32::try_from(*raw).ok(),
        _ => None,
    }
}

/// Checks one mapping entry against the device: every problem it has.
pub fn check_entry(device: &Device, raw: u32) -> Vec<MappingProblem> {
    let mut problems = Vec::new();
    if raw == 0 {
        return problems;
    }
    let target = MappedObject::from_raw(raw);
    if target.is_dummy() {
        let data_type = DataType::from_code(target.index);
        if !device.dummy_usage.is_empty() && !device.dummy_usage.contains(&data_type) {
            problems.push(MappingProblem::DummyNotEnabled { data_type });
        }
        return problems;
    }
    let Some(object) = device.objects.get(&target.index) else {
        problems.push(MappingProblem::MissingObject { target });
        return problems;
    };
    let Some(mapped) = object.entries.get(&target.subindex) else {
        problems.push(MappingProblem::MissingSub { target });
        return problems;
    };
    if !mapped.pdo_mappable {
        problems.push(MappingProblem::NotMappable {
            target,
            name: mapped.name.clone(),
        });
    }
    if let Some(bits) = mappable_bits(mapped.data_type)
        && !bits.contains(&target.bits)
    {
        problems.push(MappingProblem::WrongLength {
            target,
            data_type: mapped.data_type,
            bits: bits[bits.len() - 1],
        });
    }
    problems
}

/// The total bit length of a mapping object's active entries (subs 1 to the
/// default of sub 0, or every sub when sub 0 has no default).
pub fn total_bits(device: &Device, mapping_index: u16) -> u32 {
    let Some(object) = device.objects.get(&mapping_index) else {
        return 0;
    };
    let count = object
        .entries
        .get(&0)
        .map(Box::as_ref)
        .and_then(raw_mapping)
        .map_or(u32::MAX, |n| n);
    object
        .entries
        .values()
        .map(Box::as_ref)
        .filter(|e| e.subindex >= 1 && u32::from(e.subindex) <= count)
        .filter_map(raw_mapping)
        .map(|raw| u32::from(MappedObject::from_raw(raw).bits))
        .sum()
}
