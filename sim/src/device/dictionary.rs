//! The object store behind the simulated device's SDO server: the
//! [`ObjectTable`] plus the model, with the CiA 301 rules for writes to the
//! communication objects (PDO parameters, store and restore signatures).

use std::collections::VecDeque;

use eds2rust_runtime::Instant;
use eds2rust_runtime::nmt::NmtState;
use eds2rust_runtime::od::{AccessRight, NodeId, ObjectInfo};
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_runtime::sdo::server::ObjectStore;

use crate::behaviour::{Behaviour, Context, Effects};
use crate::store::ObjectTable;

/// "save" (0x1010), least significant byte first on the bus.
pub(crate) const SAVE: u32 = 0x6576_6173;
/// "load" (0x1011).
pub(crate) const LOAD: u32 = 0x6461_6F6C;

/// Table, model and what the model asked for, owned by the SDO server.
#[derive(Debug)]
pub(crate) struct Dictionary<B: Behaviour> {
    pub(crate) objects: &'static [ObjectInfo],
    pub(crate) table: ObjectTable,
    pub(crate) behaviour: B,
    pub(crate) effects: Effects<B::Event>,
    pub(crate) now: Instant,
    pub(crate) node: Option<NodeId>,
    pub(crate) nmt: NmtState,
    /// Entries written from the bus, for events and reconfiguration.
    pub(crate) written: VecDeque<(u16, u8)>,
    /// The values saved with the "save" signature (`None`: defaults).
    pub(crate) saved: Option<ObjectTable>,
}

impl<B: Behaviour> Dictionary<B> {
    /// Runs `f` on the model with a context onto the table.
    pub(crate) fn with_model<R>(
        &mut self,
        f: impl FnOnce(&mut B, &mut Context<'_, B::Event>) -> R,
    ) -> R {
        let mut ctx = Context {
            now: self.now,
            node: self.node,
            nmt: self.nmt,
            table: &mut self.table,
            effects: &mut self.effects,
        };
        f(&mut self.behaviour, &mut ctx)
    }

    /// A complete write from the bus (SDO download or one RPDO entry):
    /// table checks, CiA 301 rules, the model's check, then the value is
    /// stored and the model told.
    pub(crate) fn bus_write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode> {
        self.table.check_bus_value(index, sub, data)?;
        if self.communication_rules(index, sub, data)? == Keep::No {
            return Ok(());
        }
        self.with_model(|b, ctx| b.check_write(ctx, index, sub, data))?;
        self.table
            .set_raw(index, sub, data)
            .map_err(|_| AbortCode::LengthMismatch)?;
        self.written.push_back((index, sub));
        self.with_model(|b, ctx| b.written(ctx, index, sub));
        Ok(())
    }

    /// The CiA 301 rules for the communication objects the device itself
    /// acts on. `Keep::No` for command entries whose value is not stored.
    fn communication_rules(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<Keep, AbortCode> {
        match index {
            0x1010 if sub >= 1 => {
                if u32_le(data) != Some(SAVE) {
                    return Err(AbortCode::CannotTransfer);
                }
                self.saved = Some(self.table.clone());
                Ok(Keep::No)
            }
            0x1011 if sub >= 1 => {
                if u32_le(data) != Some(LOAD) {
                    return Err(AbortCode::CannotTransfer);
                }
                self.saved = None;
                Ok(Keep::No)
            }
            0x1400..=0x15FF | 0x1800..=0x19FF => {
                self.check_communication(index, sub, data)?;
                Ok(Keep::Yes)
            }
            0x1600..=0x17FF | 0x1A00..=0x1BFF => {
                self.check_mapping(index, sub, data)?;
                Ok(Keep::Yes)
            }
            _ => Ok(Keep::Yes),
        }
    }

    fn cob_id(&self, comm: u16) -> u32 {
        self.table.get_uint(comm, 1).unwrap_or(0x8000_0000) as u32
    }

    /// PDO communication parameters: the COB-ID changes only while the
    /// PDO is disabled (bit 31 set); the inhibit time likewise; transmission
    /// types are 0..=240 and 252..=255 (RPDOs: 0..=240, 254, 255).
    fn check_communication(&self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode> {
        let current = self.cob_id(index);
        let valid = current & 0x8000_0000 == 0;
        match sub {
            1 => {
                let new = u32_le(data).ok_or(AbortCode::LengthMismatch)?;
                let new_valid = new & 0x8000_0000 == 0;
                if valid && new_valid && (new & 0x1FFF_FFFF) != (current & 0x1FFF_FFFF) {
                    return Err(AbortCode::InvalidValue);
                }
                Ok(())
            }
            2 => {
                let t = *data.first().ok_or(AbortCode::LengthTooLow)?;
                let receive = index < 0x1800;
                let ok = match t {
                    0..=240 | 254 | 255 => true,
                    252 | 253 => !receive,
                    _ => false,
                };
                if ok {
                    Ok(())
                } else {
                    Err(AbortCode::InvalidValue)
                }
            }
            3 if valid => Err(AbortCode::CannotTransferDeviceState),
            _ => Ok(()),
        }
    }

    /// PDO mapping parameters: only while the PDO is disabled; entries only
    /// while sub 0 is 0, each naming a mappable entry of matching size (or a
    /// dummy type in an RPDO); sub 0 = n checks the n entries and 64 bits.
    fn check_mapping(&self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode> {
        let comm = index - 0x200;
        if self.cob_id(comm) & 0x8000_0000 == 0 {
            return Err(AbortCode::CannotTransferDeviceState);
        }
        let receive = index < 0x1A00;
        if sub == 0 {
            let count = *data.first().ok_or(AbortCode::LengthTooLow)?;
            let mut bits = 0u32;
            for s in 1..=count {
                let entry = self
                    .table
                    .get_uint(index, s)
                    .ok_or(AbortCode::ValueTooHigh)? as u32;
                self.check_entry(entry, receive)?;
                bits += entry & 0xFF;
            }
            if bits > 64 {
                return Err(AbortCode::PdoLengthExceeded);
            }
            return Ok(());
        }
        if self.table.get_uint(index, 0) != Some(0) {
            return Err(AbortCode::CannotTransferDeviceState);
        }
        let entry = u32_le(data).ok_or(AbortCode::LengthMismatch)?;
        if entry != 0 {
            self.check_entry(entry, receive)?;
        }
        Ok(())
    }

    /// One mapping entry `index << 16 | sub << 8 | bits`.
    fn check_entry(&self, entry: u32, receive: bool) -> Result<(), AbortCode> {
        let index = (entry >> 16) as u16;
        let sub = (entry >> 8) as u8;
        let bits = (entry & 0xFF) as usize;
        if receive && (1..=7).contains(&index) && bits > 0 && bits.is_multiple_of(8) && bits <= 64 {
            return Ok(()); // dummy entry (CiA 301 static data types)
        }
        let info = self.table.info(index, sub).ok_or(AbortCode::CannotMap)?;
        let readable = info.access != AccessRight::Wo;
        let writable = !matches!(info.access, AccessRight::Ro | AccessRight::Const);
        let direction = if receive { writable } else { readable };
        if !info.pdo_mappable || !direction || info.data_type.size().map(|s| s * 8) != Some(bits) {
            return Err(AbortCode::CannotMap);
        }
        Ok(())
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Keep {
    Yes,
    No,
}

pub(crate) fn u32_le(data: &[u8]) -> Option<u32> {
    Some(u32::from_le_bytes(data.try_into().ok()?))
}

impl<B: Behaviour> ObjectStore for Dictionary<B> {
    fn read(&mut self, index: u16, sub: u8, out: &mut Vec<u8>) -> Result<(), AbortCode> {
        out.extend_from_slice(self.table.check_bus_read(index, sub)?);
        Ok(())
    }

    fn check_write(&mut self, index: u16, sub: u8, size: Option<usize>) -> Result<(), AbortCode> {
        self.table.check_bus_write(index, sub, size)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode> {
        self.bus_write(index, sub, data)
    }
}
