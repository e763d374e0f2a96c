//! PDOs of the nodes with a file: their COB-IDs and mappings as the files
//! define them, changed by the SDO writes a trace makes to 0x1400–0x1BFF,
//! and the decoding of a PDO's data into its mapped fields. The bits of a
//! field are read with the runtime's PDO codec (`pdo::layout`), the one
//! the generated PDO structs and `#[derive(Pdo)]` use.

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use eds2rust::ir::pdo::MappedObject;
use eds2rust::ir::{DataType, PdoDirection, Semantics, ValueKind};
use eds2rust_runtime::CanId;
use eds2rust_runtime::pdo::{PdoCobId, layout};

use crate::dictionary::{Dictionary, comm_index, mapping_index};

/// One mapped entry of a PDO.
#[derive(Debug, Clone)]
pub struct FieldLayout {
    /// The entry's name; `dummy` for a dummy entry, `0xIIII.SS` when the
    /// file lacks the entry.
    pub name: Arc<str>,
    pub index: u16,
    pub subindex: u8,
    /// Bit offset in the data and width in bits.
    pub offset: u32,
    pub width: u32,
    pub data_type: Option<DataType>,
    pub semantics: Arc<Semantics>,
}

/// A PDO as it is configured at a point of the trace.
#[derive(Debug, Clone)]
pub struct PdoLayout {
    pub node: u8,
    pub direction: PdoDirection,
    pub number: u16,
    pub label: Option<Arc<str>>,
    /// Fields in mapping order, dummies left out.
    pub fields: Vec<FieldLayout>,
    /// The mapped bits in all (dummies included).
    pub bits: u32,
}

/// A decoded field: its raw value (sign-extended for signed types; a REAL's
/// bits) and, for REAL32/REAL64 fields, the number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Raw {
    Int(i128),
    Real(f64),
}

/// The configuration of one PDO: its COB-ID entry and mapping entries.
#[derive(Debug, Clone, Default)]
struct PdoParams {
    cob_id: Option<PdoCobId>,
    count: Option<u8>,
    entries: BTreeMap<u8, u32>,
}

/// The PDOs of every node with a file, by COB-ID.
#[derive(Debug, Default)]
pub struct PdoTable {
    params: BTreeMap<(u8, PdoDirection, u16), PdoParams>,
    /// The identifier of a valid COB-ID → the PDO's layout; rebuilt on
    /// change.
    by_cob: HashMap<CanId, Arc<PdoLayout>>,
    dirty: bool,
}

impl PdoTable {
    /// Takes the PDOs a node's file defines.
    pub fn add_node(&mut self, dict: &Dictionary) {
        for (direction, number) in dict.pdo_numbers() {
            let comm = comm_index(direction, number);
            let map = mapping_index(direction, number);
            let mut p = PdoParams {
                cob_id: dict.initial_u32(comm, 1).map(PdoCobId),
                count: dict.initial_u32(map, 0).and_then(|c| u8::try_from(c).ok()),
                entries: BTreeMap::new(),
            };
            for sub in 1..=64u8 {
                if let Some(raw) = dict.initial_u32(map, sub) {
                    p.entries.insert(sub, raw);
                }
            }
            self.params.insert((dict.node, direction, number), p);
        }
        self.dirty = true;
    }

    /// Applies a completed SDO download of `value` to parameter `sub` of
    /// PDO `number` of `node` (`mapping`: of its mapping object).
    pub fn write(&mut self, node: u8, pdo: (PdoDirection, u16, bool), sub: u8, value: u32) -> bool {
        let (direction, number, mapping) = pdo;
        let p = self.params.entry((node, direction, number)).or_default();
        match (mapping, sub) {
            (false, 1) => p.cob_id = Some(PdoCobId(value)),
            (true, 0) => p.count = u8::try_from(value).ok(),
            (true, 1..=64) => {
                p.entries.insert(sub, value);
            }
            _ => return false,
        }
        self.dirty = true;
        true
    }

    /// The PDO that frames with CAN identifier `id` are (`extended`: a
    /// 29-bit identifier).
    pub fn lookup(
        &mut self,
        dicts: &BTreeMap<u8, Dictionary>,
        id: u32,
        extended: bool,
    ) -> Option<Arc<PdoLayout>> {
        if self.dirty {
            self.rebuild(dicts);
        }
        let key = if extended {
            CanId::extended(id)?
        } else {
            CanId::standard(u16::try_from(id).ok()?)?
        };
        self.by_cob.get(&key).cloned()
    }

    fn rebuild(&mut self, dicts: &BTreeMap<u8, Dictionary>) {
        self.by_cob.clear();
        for (&(node, direction, number), p) in &self.params {
            let Some(cob) = p.cob_id else { continue };
            // Bit 31 set: the PDO is not valid (no frames are expected).
            if !cob.is_valid() {
                continue;
            }
            let key = cob.can_id();
            let Some(dict) = dicts.get(&node) else {
                continue;
            };
            // Two valid PDOs on one COB-ID (a file's mistake): the frames
            // are decoded as the lower-numbered one.
            if self.by_cob.contains_key(&key) {
                continue;
            }
            let layout = build_layout(dict, direction, number, p);
            self.by_cob.insert(key, Arc::new(layout));
        }
        self.dirty = false;
    }
}

fn build_layout(
    dict: &Dictionary,
    direction: PdoDirection,
    number: u16,
    p: &PdoParams,
) -> PdoLayout {
    let count = p.count.unwrap_or(p.entries.len() as u8);
    let mut fields = Vec::new();
    let mut offset = 0;
    for sub in 1..=count.min(64) {
        let Some(&raw) = p.entries.get(&sub) else {
            break;
        };
        let target = MappedObject::from_raw(raw);
        let width = u32::from(target.bits);
        if width == 0 {
            continue;
        }
        if !target.is_dummy() {
            let entry = dict.entry(target.index, target.subindex);
            let name = match &entry {
                Some(e) => e.name.clone(),
                None => format!("0x{:04X}.{}", target.index, target.subindex).into(),
            };
            fields.push(FieldLayout {
                name,
                index: target.index,
                subindex: target.subindex,
                offset,
                width,
                data_type: entry.as_ref().map(|e| e.data_type),
                semantics: entry.map(|e| e.semantics).unwrap_or_default(),
            });
        }
        offset += width;
    }
    PdoLayout {
        node: dict.node,
        direction,
        number,
        label: dict.pdo_label(direction, number),
        fields,
        bits: offset,
    }
}

impl PdoLayout {
    /// The data bytes the mapping needs.
    pub fn len(&self) -> usize {
        layout::len(self.bits)
    }

    pub fn is_empty(&self) -> bool {
        self.bits == 0
    }
}

/// The raw value of `field` in the data as one word (`layout::word_of`).
pub fn read_field(field: &FieldLayout, word: u64) -> Raw {
    let kind = field.data_type.and_then(DataType::value_kind);
    let signed = matches!(kind, Some(ValueKind::Integer { signed: true, .. }));
    let bits = layout::field(word, field.offset, field.width, signed);
    match (kind, field.width) {
        (Some(ValueKind::Real { bits: 32 }), 32) => {
            Raw::Real(f64::from(f32::from_bits(bits as u32)))
        }
        (Some(ValueKind::Real { bits: 64 }), 64) => Raw::Real(f64::from_bits(bits)),
        // A BOOLEAN mapped into more than one bit: any other value than 0
        // is true, as python-canopen reads it.
        (Some(ValueKind::Integer { bits: 1, .. }), _) => Raw::Int(i128::from(bits != 0)),
        _ if signed => Raw::Int(i128::from(bits as i64)),
        _ => Raw::Int(i128::from(bits)),
    }
}
