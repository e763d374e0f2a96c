//! A slave's PDOs as the bus file configures them, and the concise DCF
//! writes that get them there, in dcfgen's order: per PDO, invalidate the
//! COB-ID, write transmission type, inhibit time, event timer and SYNC
//! start value, clear the mapping, write each mapped object, set the
//! count, and write the COB-ID valid again.

use std::path::Path;

use crate::diag::{Diagnostics, Severity};
use crate::ir::DataType;
use crate::ir::pdo::MappedObject;

use super::config::{ConciseEntry, Pdo};
use super::model::{AUTO_COB_ID_END, CobIdSetting, PdoSection, Spot};
use super::view::{DeviceView, PackError, mapped_bits, pack};

/// Bit 31 of a PDO COB-ID: the PDO does not exist (is not valid).
pub(crate) const INVALID: u32 = 0x8000_0000;

/// One slave being configured: its device, the writes so far, the
/// diagnostics.
pub(crate) struct SlaveState<'a> {
    pub view: DeviceView<'a>,
    pub name: &'a str,
    pub bus_file: &'a Path,
    pub concise: Vec<ConciseEntry>,
    /// The entries reported not writable already (one word per entry, not
    /// per write: a mapping's sub 0 is written twice).
    pub not_writable: Vec<(u16, u8)>,
    pub diagnostics: &'a mut Diagnostics,
}

impl SlaveState<'_> {
    pub fn report(&mut self, spot: &Spot, severity: Severity, code: &'static str, message: String) {
        let message = format!("{}: {message}", self.name);
        self.diagnostics
            .push(spot.diagnostic(self.bus_file, severity, code, message));
    }

    /// Appends a write of `value` to `index`/`sub`, packed by the entry's
    /// data type; an entry that does not exist or a value that does not
    /// fit is an error and nothing is written.
    pub fn write(&mut self, index: u16, sub: u8, value: i128, spot: &Spot) -> bool {
        match self.packed(index, sub, value, spot) {
            Some(data) => {
                self.concise.push(ConciseEntry {
                    index,
                    sub_index: sub,
                    data,
                    spot: Some(spot.clone()),
                });
                true
            }
            None => false,
        }
    }

    /// [`write`](Self::write) at the front of the list (the master's
    /// heartbeat consumer entry comes first).
    pub fn write_first(&mut self, index: u16, sub: u8, value: i128, spot: &Spot) {
        if let Some(data) = self.packed(index, sub, value, spot) {
            let entry = ConciseEntry {
                index,
                sub_index: sub,
                data,
                spot: Some(spot.clone()),
            };
            self.concise.insert(0, entry);
        }
    }

    fn packed(&mut self, index: u16, sub: u8, value: i128, spot: &Spot) -> Option<Vec<u8>> {
        let Some(entry) = self.view.entry(index, sub) else {
            let what = if self.view.has_object(index) {
                format!("sub-object 0x{index:04X}/{sub} does not exist in the device file")
            } else {
                format!("object 0x{index:04X} does not exist in the device file")
            };
            self.report(spot, Severity::Error, "net::unknown-object", what);
            return None;
        };
        let (data_type, writable) = (entry.data_type, entry.access.is_writable());
        if !writable && !self.not_writable.contains(&(index, sub)) {
            self.not_writable.push((index, sub));
            let message = format!(
                "0x{index:04X}/{sub} is not writable; the write will be refused by the device"
            );
            self.report(spot, Severity::Warning, "net::not-writable", message);
        }
        match pack(data_type, value) {
            Ok(data) => Some(data),
            Err(PackError::NotNumeric(t)) => {
                let message = format!(
                    "0x{index:04X}/{sub} is a {}; a bus file can write numbers only",
                    t.name()
                );
                self.report(spot, Severity::Error, "net::value-range", message);
                None
            }
            Err(PackError::OutOfRange { low, high }) => {
                let message = format!(
                    "{value} does not fit 0x{index:04X}/{sub}, a {} ({low}..={high})",
                    data_type.name()
                );
                self.report(spot, Severity::Error, "net::value-range", message);
                None
            }
        }
    }

    /// The PDO the device file defines at communication index `comm`.
    pub fn device_pdo(&self, comm: u16, number: u16) -> Pdo {
        let v = &self.view;
        let tpdo = is_tpdo(comm);
        let n = v.integer(comm, 0).unwrap_or(0);
        let sub = |s: u8| {
            if n >= i128::from(s) {
                v.integer(comm, s)
            } else {
                None
            }
        };
        let cob_id = sub(1)
            .and_then(|c| u32::try_from(c).ok())
            .unwrap_or(INVALID);
        let transmission = sub(2).and_then(|t| u8::try_from(t).ok()).unwrap_or(0);
        let mut pdo = Pdo::new(number, cob_id, transmission, Vec::new());
        if tpdo {
            pdo.inhibit_time = sub(3).and_then(|t| u16::try_from(t).ok()).unwrap_or(0);
            pdo.sync_start = sub(6).and_then(|t| u8::try_from(t).ok()).unwrap_or(0);
        }
        pdo.event_timer = sub(5).and_then(|t| u16::try_from(t).ok()).unwrap_or(0);
        let map = comm + 0x200;
        let count = v.integer(map, 0).unwrap_or(0).clamp(0, 64) as u8;
        for i in 1..=count {
            let raw = v
                .integer(map, i)
                .and_then(|r| u32::try_from(r).ok())
                .unwrap_or(0);
            if raw == 0 {
                continue;
            }
            let mut mapped = MappedObject::from_raw(raw);
            if let Some(bits) = self.bits_of(mapped.index, mapped.subindex) {
                mapped.bits = bits;
            }
            pdo.mapping.push(mapped);
        }
        pdo
    }

    /// The mapped length of an entry (or of a dummy's data type).
    fn bits_of(&self, index: u16, sub: u8) -> Option<u8> {
        match self.view.entry(index, sub) {
            Some(entry) => mapped_bits(entry.data_type),
            None if (1..=7).contains(&index) => mapped_bits(DataType::from_code(index)),
            None => None,
        }
    }

    /// Applies one `rpdo`/`tpdo` section to `pdo`, appending the writes.
    /// `next_auto` is the next free COB-ID for `cob_id: auto` beyond the
    /// pre-defined ones. True when the section disables a PDO whose COB-ID
    /// was valid (dcfgen keeps such a PDO in master.dcf).
    pub fn apply(
        &mut self,
        pdo: &mut Pdo,
        comm: u16,
        section: &PdoSection,
        next_auto: &mut u32,
    ) -> bool {
        let tpdo = is_tpdo(comm);
        let before = pdo.cob_id;
        pdo.spot = Some(section.spot.clone());
        if let Some(setting) = &section.cob_id {
            match setting.value {
                CobIdSetting::Value(value) => pdo.cob_id = value,
                CobIdSetting::Auto => {
                    let i = u32::from(comm & 0x01FF);
                    let node = u32::from(self.view.node_id);
                    if i < 4 {
                        pdo.cob_id = (i + 1) * 0x100 + if tpdo { 0x80 } else { 0x100 } + node;
                    } else if *next_auto >= AUTO_COB_ID_END {
                        let message = format!(
                            "no 11-bit COB-ID left for `cob_id: auto` (they run from 0x680 to 0x{:X}); give this PDO a number",
                            AUTO_COB_ID_END - 1
                        );
                        self.report(&setting.spot, Severity::Error, "net::auto-cob-id", message);
                    } else {
                        pdo.cob_id = *next_auto;
                        *next_auto += 1;
                    }
                }
            }
        }
        let cob_spot = section
            .cob_id
            .as_ref()
            .map_or(&section.spot, |c| &c.spot)
            .clone();
        if before != pdo.cob_id | INVALID {
            self.write(comm, 1, i128::from(pdo.cob_id | INVALID), &cob_spot);
        }
        if pdo.cob_id & INVALID == 0 {
            if let Some(t) = &section.transmission
                && t.value != pdo.transmission
            {
                pdo.transmission = t.value;
                self.write(comm, 2, i128::from(t.value), &t.spot);
            }
            if let Some(t) = &section.inhibit_time
                && t.value != pdo.inhibit_time
            {
                pdo.inhibit_time = t.value;
                if tpdo {
                    self.write(comm, 3, i128::from(t.value), &t.spot);
                }
            }
            if tpdo {
                if let Some(t) = &section.event_timer
                    && t.value != pdo.event_timer
                {
                    pdo.event_timer = t.value;
                    self.write(comm, 5, i128::from(t.value), &t.spot);
                }
                if let Some(t) = &section.sync_start
                    && t.value != pdo.sync_start
                {
                    pdo.sync_start = t.value;
                    self.write(comm, 6, i128::from(t.value), &t.spot);
                }
                // The master's mirror (an RPDO) watches the deadline.
                if let Some(t) = &section.event_deadline {
                    pdo.master_event_timer = t.value;
                }
            } else {
                // The master's mirror (a TPDO) sends on these.
                if let Some(t) = &section.event_timer {
                    pdo.master_event_timer = t.value;
                }
                if let Some(t) = &section.sync_start {
                    pdo.master_sync_start = t.value;
                }
            }
            if !tpdo
                && let Some(t) = &section.event_deadline
                && t.value != pdo.event_timer
            {
                // Sub 5 of an RPDO is its event deadline (dcfgen 2.4.2
                // writes the event timer here, or fails without one).
                pdo.event_timer = t.value;
                self.write(comm, 5, i128::from(t.value), &t.spot);
            }
            if let Some(items) = &section.mapping {
                self.map(pdo, comm + 0x200, items, &section.spot);
            }
            if section.enabled.value {
                self.write(comm, 1, i128::from(pdo.cob_id), &cob_spot);
            } else {
                // Written invalid above and left so: the PDO does not run.
                pdo.cob_id |= INVALID;
                return true;
            }
        }
        false
    }

    fn map(&mut self, pdo: &mut Pdo, map: u16, items: &[super::model::MappingItem], spot: &Spot) {
        if !pdo.mapping.is_empty() || !items.is_empty() {
            pdo.mapping.clear();
            self.write(map, 0, 0, spot);
        }
        for item in items {
            let Some(bits) = self.mappable(item.index, item.sub_index, &item.spot) else {
                continue;
            };
            let mapped = MappedObject {
                index: item.index,
                subindex: item.sub_index,
                bits,
            };
            let n = pdo.mapping.len() as u8 + 1;
            if self.write(map, n, i128::from(mapped.raw()), &item.spot) {
                pdo.mapping.push(mapped);
            }
        }
        if !pdo.mapping.is_empty() {
            self.write(map, 0, pdo.mapping.len() as i128, spot);
        }
    }

    /// The bits a mapping item maps, or an error when the object does not
    /// exist or has no fixed length.
    fn mappable(&mut self, index: u16, sub: u8, spot: &Spot) -> Option<u8> {
        let exists = self.view.entry(index, sub).is_some() || (1..=7).contains(&index);
        if !exists {
            let message =
                format!("maps 0x{index:04X}/{sub}, which does not exist in the device file");
            self.report(spot, Severity::Error, "net::unknown-object", message);
            return None;
        }
        let bits = self.bits_of(index, sub);
        if bits.is_none() {
            let message =
                format!("maps 0x{index:04X}/{sub}, which has no fixed length (a string or domain)");
            self.report(spot, Severity::Error, "net::unknown-object", message);
        }
        bits
    }
}

/// Is `comm` a TPDO communication parameter (0x1800–0x19FF)?
pub(crate) fn is_tpdo(comm: u16) -> bool {
    comm & 0xFE00 == 0x1800
}
