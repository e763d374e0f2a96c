//! A device that takes program downloads (CiA 302-3): program data 0x1F50
//! (DOMAIN), program control 0x1F51 and, when the table has it, program
//! software identification 0x1F56, for any object table that has them (a
//! vendor's bootloader EDS, say). Sub-index N of each is program N.
//!
//! What the model does, where CiA 302-3 leaves it to the device:
//! - 0x1F51 written: 0 stops the program, 1 starts it, 2 resets it (stop and
//!   start), 3 clears it (its data becomes empty). Read back: 0 stopped,
//!   1 started. Any other value is refused with 0x06090030 (invalid value
//!   for parameter); starting a program without data, with 0x08000022 (present
//!   device state).
//! - 0x1F50 is written only while the program is stopped (0x08000022
//!   otherwise). A complete download sets 0x1F56 of the program to the
//!   data's CRC-32 (ISO-HDLC, the zlib one), which stands in for the
//!   software identification a real image carries, and is reported as
//!   [`ProgramEvent::Received`].

use eds2rust_runtime::sdo::abort::AbortCode;

use crate::behaviour::{Behaviour, Context};

/// Program data (DOMAIN).
pub const PROGRAM_DATA: u16 = 0x1F50;
/// Program control (UNSIGNED8).
pub const PROGRAM_CONTROL: u16 = 0x1F51;
/// Program software identification (UNSIGNED32).
pub const PROGRAM_ID: u16 = 0x1F56;

/// The values written to 0x1F51 (0 and 1 are also what it reads).
pub mod control {
    /// Stop the program (read: stopped).
    pub const STOP: u8 = 0;
    /// Start the program (read: started).
    pub const START: u8 = 1;
    /// Reset the program: stop and start it.
    pub const RESET: u8 = 2;
    /// Clear the program's data.
    pub const CLEAR: u8 = 3;
}

/// What the program model reports.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ProgramEvent {
    /// A program was downloaded.
    Received {
        /// The program number (the sub-index).
        program: u8,
        /// Its length in bytes.
        len: usize,
        /// Its CRC-32, also in 0x1F56.
        crc32: u32,
    },
    /// A program was started (also by a reset).
    Started {
        /// The program number.
        program: u8,
    },
    /// A program was stopped.
    Stopped {
        /// The program number.
        program: u8,
    },
    /// A program was cleared.
    Cleared {
        /// The program number.
        program: u8,
    },
}

/// The CiA 302-3 program model; see the module documentation.
#[derive(Debug, Clone, Default)]
pub struct ProgramControl;

const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

fn started(ctx: &Context<'_, ProgramEvent>, program: u8) -> bool {
    ctx.table()
        .get(PROGRAM_CONTROL, program)
        .and_then(|v| v.first().copied())
        == Some(control::START)
}

/// Stores the status of `program` in 0x1F51 (the device's own write).
fn set_status(ctx: &mut Context<'_, ProgramEvent>, program: u8, status: u8) {
    // The entry exists: it was just written from the bus.
    let _ = ctx.table_mut().set_raw(PROGRAM_CONTROL, program, &[status]);
}

impl Behaviour for ProgramControl {
    type Event = ProgramEvent;

    fn check_write(
        &mut self,
        ctx: &mut Context<'_, ProgramEvent>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), AbortCode> {
        match (index, sub, data) {
            (PROGRAM_DATA, 1.., _) if started(ctx, sub) => {
                Err(AbortCode::CannotTransferDeviceState)
            }
            (PROGRAM_CONTROL, 1.., [command]) => match *command {
                control::STOP | control::CLEAR => Ok(()),
                control::START | control::RESET => {
                    let has_data = ctx
                        .table()
                        .get(PROGRAM_DATA, sub)
                        .is_some_and(|d| !d.is_empty());
                    if has_data {
                        Ok(())
                    } else {
                        Err(AbortCode::CannotTransferDeviceState)
                    }
                }
                _ => Err(AbortCode::InvalidValue),
            },
            _ => Ok(()),
        }
    }

    fn written(&mut self, ctx: &mut Context<'_, ProgramEvent>, index: u16, sub: u8) {
        match index {
            PROGRAM_DATA if sub >= 1 => {
                let data = ctx.table().get(PROGRAM_DATA, sub).unwrap_or(&[]);
                let (len, crc32) = (data.len(), CRC32.checksum(data));
                let _ = ctx
                    .table_mut()
                    .set_raw(PROGRAM_ID, sub, &crc32.to_le_bytes());
                ctx.emit(ProgramEvent::Received {
                    program: sub,
                    len,
                    crc32,
                });
            }
            PROGRAM_CONTROL if sub >= 1 => {
                let command = ctx
                    .table()
                    .get(PROGRAM_CONTROL, sub)
                    .and_then(|v| v.first().copied());
                match command {
                    Some(control::START | control::RESET) => {
                        set_status(ctx, sub, control::START);
                        ctx.emit(ProgramEvent::Started { program: sub });
                    }
                    Some(control::CLEAR) => {
                        let _ = ctx.table_mut().set_raw(PROGRAM_DATA, sub, &[]);
                        set_status(ctx, sub, control::STOP);
                        ctx.emit(ProgramEvent::Cleared { program: sub });
                    }
                    _ => {
                        set_status(ctx, sub, control::STOP);
                        ctx.emit(ProgramEvent::Stopped { program: sub });
                    }
                }
            }
            _ => {}
        }
    }
}
