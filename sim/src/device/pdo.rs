//! The simulated device's PDOs, read from the communication (0x1400..,
//! 0x1800..) and mapping (0x1600.., 0x1A00..) parameters in its table.
//! TPDOs are sent by the runtime's [`PdoTransmitter`] (transmission types
//! 0, 1–240, 254, 255 with inhibit time and event timer); RPDOs are
//! unpacked into the mapped entries.

use eds2rust_runtime::CanId;
use eds2rust_runtime::od::standard::{EventTimer, InhibitTime};
use eds2rust_runtime::pdo::{PdoCobId, PdoTransmitter, TransmissionType, TransmitterConfig};

use crate::store::ObjectTable;

/// One mapped entry: where it lives and its width in bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Mapped {
    pub(crate) index: u16,
    pub(crate) sub: u8,
    pub(crate) bits: u32,
}

impl Mapped {
    fn from_entry(entry: u32) -> Mapped {
        Mapped {
            index: (entry >> 16) as u16,
            sub: (entry >> 8) as u8,
            bits: entry & 0xFF,
        }
    }

    /// Dummy entries of an RPDO (indices 1..=7) only take space.
    fn is_dummy(&self) -> bool {
        (1..=7).contains(&self.index)
    }
}

/// A TPDO in operation.
#[derive(Debug)]
pub(crate) struct Tpdo {
    pub(crate) number: u16,
    pub(crate) tx: PdoTransmitter,
    pub(crate) mapping: Vec<Mapped>,
}

/// An RPDO the device listens to.
#[derive(Debug)]
pub(crate) struct Rpdo {
    pub(crate) can_id: CanId,
    pub(crate) synchronous: bool,
    pub(crate) mapping: Vec<Mapped>,
    /// Data of a synchronous RPDO, applied at the next SYNC.
    pub(crate) pending: Option<Vec<u8>>,
}

impl Rpdo {
    /// Bytes the mapping covers.
    pub(crate) fn len(&self) -> usize {
        (self.mapping.iter().map(|m| m.bits).sum::<u32>() as usize).div_ceil(8)
    }
}

/// The mapping of the parameter at `map_index`, from its sub 0 count.
fn mapping(table: &ObjectTable, map_index: u16) -> Vec<Mapped> {
    let count = table.get_uint(map_index, 0).unwrap_or(0) as u8;
    (1..=count)
        .filter_map(|sub| table.get_uint(map_index, sub))
        .map(|entry| Mapped::from_entry(entry as u32))
        .collect()
}

/// Every valid TPDO of the table (0x1800 + n - 1 with its mapping 0x1A00 +
/// n - 1). TPDOs with a transmission type the transmitter does not run
/// (252/253, remote only) are left out.
pub(crate) fn tpdos(table: &ObjectTable, sync_cob_id: u16) -> Vec<Tpdo> {
    valid_pdos(table, 0x1800)
        .filter_map(|(n, cob_id)| {
            let comm = 0x1800 + n;
            let transmission = table.get_uint(comm, 2).unwrap_or(255) as u8;
            let mut config =
                TransmitterConfig::new(cob_id, TransmissionType::from_raw(transmission));
            config.inhibit_time = InhibitTime(table.get_uint(comm, 3).unwrap_or(0) as u16);
            config.event_timer = EventTimer(table.get_uint(comm, 5).unwrap_or(0) as u16);
            config.sync_start = table.get_uint(comm, 6).unwrap_or(0) as u8;
            config.sync_cob_id = sync_cob_id;
            let tx = PdoTransmitter::new(config).ok()?;
            Some(Tpdo {
                number: n + 1,
                tx,
                mapping: mapping(table, 0x1A00 + n),
            })
        })
        .collect()
}

/// The PDOs whose communication parameter record is at `base + n` (n
/// from 0, at most 512) with a valid COB-ID (sub 1): (n, COB-ID).
fn valid_pdos(table: &ObjectTable, base: u16) -> impl Iterator<Item = (u16, PdoCobId)> + '_ {
    (0..512u16)
        .filter(move |n| table.has_index(base + n))
        .filter_map(move |n| {
            let cob_id = PdoCobId(table.get_uint(base + n, 1)? as u32);
            cob_id.is_valid().then_some((n, cob_id))
        })
}

/// Every valid RPDO of the table (0x1400 + n - 1, mapping 0x1600 + n - 1).
pub(crate) fn rpdos(table: &ObjectTable) -> Vec<Rpdo> {
    valid_pdos(table, 0x1400)
        .filter_map(|(n, cob_id)| {
            let transmission = table.get_uint(0x1400 + n, 2).unwrap_or(255);
            Some(Rpdo {
                can_id: cob_id.checked_can_id().ok()?,
                synchronous: transmission <= 240,
                mapping: mapping(table, 0x1600 + n),
                pending: None,
            })
        })
        .collect()
}

/// The TPDO data: the mapped values packed least significant bit first.
/// `None` if the mapping is longer than 64 bits or names a missing entry.
pub(crate) fn pack(table: &ObjectTable, mapping: &[Mapped]) -> Option<Vec<u8>> {
    let mut raw: u128 = 0;
    let mut offset = 0u32;
    for m in mapping {
        // A dummy entry in a TPDO (some EDS files have them) sends zeros.
        let value = if m.is_dummy() {
            0
        } else {
            table.get_uint(m.index, m.sub)?
        };
        let mask = if m.bits >= 64 {
            u64::MAX
        } else {
            (1u64 << m.bits) - 1
        };
        raw |= u128::from(value & mask) << offset;
        offset += m.bits;
        if offset > 64 {
            return None;
        }
    }
    let len = (offset as usize).div_ceil(8);
    Some(raw.to_le_bytes()[..len].to_vec())
}

/// The entries of an RPDO's data: (index, sub, bytes in bus form), dummies
/// left out. The data must cover the mapping.
pub(crate) fn unpack(data: &[u8], mapping: &[Mapped]) -> Vec<(u16, u8, Vec<u8>)> {
    let mut buf = [0u8; 16];
    let n = data.len().min(8);
    buf[..n].copy_from_slice(&data[..n]);
    let raw = u128::from_le_bytes(buf);
    let mut offset = 0u32;
    let mut out = Vec::new();
    for m in mapping {
        if m.bits == 0 || m.bits > 64 || offset + m.bits > 64 {
            break;
        }
        let mask = if m.bits >= 64 {
            u64::MAX
        } else {
            (1u64 << m.bits) - 1
        };
        let value = (raw >> offset) as u64 & mask;
        offset += m.bits;
        if !m.is_dummy() {
            let bytes = (m.bits as usize).div_ceil(8);
            out.push((m.index, m.sub, value.to_le_bytes()[..bytes].to_vec()));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unpack_and_pack_follow_the_mapping_bit_order() {
        // LINAK RPDO1: position u16, current u8, speed u8, soft start u8,
        // soft stop u8, two reserved u8 (manual p. 30).
        let mapping: Vec<Mapped> = [
            0x2000_0110u32,
            0x2000_0208,
            0x2000_0308,
            0x2000_0408,
            0x2000_0508,
            0x2000_0608,
            0x2000_0708,
        ]
        .into_iter()
        .map(Mapped::from_entry)
        .collect();
        let entries = unpack(&[0x03, 0xFB, 0xFB, 0xFB, 0xFB, 0xFB, 0x00, 0x00], &mapping);
        assert_eq!(entries[0], (0x2000, 1, vec![0x03, 0xFB]));
        assert_eq!(entries[1], (0x2000, 2, vec![0xFB]));
        assert_eq!(entries.len(), 7);
        // A dummy INTEGER8 (0x0002) takes a byte and is not written.
        let with_dummy: Vec<Mapped> = [0x0002_0008u32, 0x2000_0208]
            .into_iter()
            .map(Mapped::from_entry)
            .collect();
        assert_eq!(
            unpack(&[0x11, 0x22], &with_dummy),
            vec![(0x2000, 2, vec![0x22])]
        );
    }
}
