//! The LSS frames of CiA 305: every request of the master (COB-ID 0x7E5)
//! and every response of a slave (0x7E4), with their decoders and encoders.
//!
//! Every frame carries exactly 8 data bytes; byte 0 is the command
//! specifier ([`cs`]). Numbers are little-endian; reserved bytes are written
//! as zero and ignored when read. Requests and responses share some command
//! specifiers, so each direction has its own type.

use crate::Frame;
use crate::frame::cob;
use crate::lss::{IdentityField, LssState};

/// Command specifiers (byte 0).
pub mod cs {
    /// Switch state global (no response).
    pub const SWITCH_STATE_GLOBAL: u8 = 0x04;
    /// Switch state selective, vendor id (first of 0x40 to 0x43).
    pub const SWITCH_STATE_SELECTIVE_VENDOR: u8 = 0x40;
    /// Switch state selective, serial number (the last one).
    pub const SWITCH_STATE_SELECTIVE_SERIAL: u8 = 0x43;
    /// Switch state selective response.
    pub const SWITCH_STATE_SELECTIVE_RESPONSE: u8 = 0x44;
    /// Configure node id (request and response).
    pub const CONFIGURE_NODE_ID: u8 = 0x11;
    /// Configure bit timing (request and response).
    pub const CONFIGURE_BIT_TIMING: u8 = 0x13;
    /// Activate bit timing (no response).
    pub const ACTIVATE_BIT_TIMING: u8 = 0x15;
    /// Store configuration (request and response).
    pub const STORE_CONFIGURATION: u8 = 0x17;
    /// Identify remote slave, vendor id (first of 0x46 to 0x4B).
    pub const IDENTIFY_REMOTE_VENDOR: u8 = 0x46;
    /// Identify remote slave, serial number high (the last one).
    pub const IDENTIFY_REMOTE_SERIAL_HIGH: u8 = 0x4B;
    /// Identify non-configured remote slave.
    pub const IDENTIFY_NON_CONFIGURED: u8 = 0x4C;
    /// Identify slave: the answer to identify remote slave and fastscan.
    pub const IDENTIFY_SLAVE: u8 = 0x4F;
    /// Identify non-configured slave: the answer to 0x4C.
    pub const IDENTIFY_NON_CONFIGURED_SLAVE: u8 = 0x50;
    /// Fastscan.
    pub const FASTSCAN: u8 = 0x51;
    /// Inquire identity, vendor id (first of 0x5A to 0x5D; request and
    /// response).
    pub const INQUIRE_VENDOR: u8 = 0x5A;
    /// Inquire node id (request and response).
    pub const INQUIRE_NODE_ID: u8 = 0x5E;
}

/// The fastscan bit check value that resets the scan in every slave and
/// asks the non-configured ones to confirm their presence.
pub const BIT_CHECK_CONFIRM: u8 = 0x80;

indexed_enum! {
    /// One of the six frames of identify remote slave (0x46 to 0x4B).
    pub enum RangeField {
        /// Vendor id (0x46).
        VendorId = 0,
        /// Product code (0x47).
        ProductCode = 1,
        /// Lowest revision number (0x48).
        RevisionLow = 2,
        /// Highest revision number (0x49).
        RevisionHigh = 3,
        /// Lowest serial number (0x4A).
        SerialLow = 4,
        /// Highest serial number (0x4B).
        SerialHigh = 5,
    }
    /// All fields, in the order the master sends them.
    ALL;
}

impl RangeField {
    /// The command specifier of this frame.
    pub const fn command(self) -> u8 {
        cs::IDENTIFY_REMOTE_VENDOR + self as u8
    }

    /// The field whose command specifier is `cs`.
    pub const fn from_command(cs: u8) -> Option<RangeField> {
        RangeField::from_index(cs.wrapping_sub(cs::IDENTIFY_REMOTE_VENDOR))
    }
}

/// The fields of a fastscan request (0x51).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FastscanRequest {
    /// The candidate value of the address part `sub` (bytes 1 to 4).
    pub id_number: u32,
    /// Bits `31..=bit_check` of `id_number` are compared (0 to 31), or
    /// [`BIT_CHECK_CONFIRM`] (byte 5).
    pub bit_check: u8,
    /// The address part being scanned, 0 to 3 ([`IdentityField`] index)
    /// (byte 6).
    pub sub: u8,
    /// The address part a matching slave scans next, 0 to 3 (byte 7).
    pub next: u8,
}

impl FastscanRequest {
    /// The confirm request that starts a scan: id 0, bit check 0x80.
    pub const CONFIRM: FastscanRequest = FastscanRequest {
        id_number: 0,
        bit_check: BIT_CHECK_CONFIRM,
        sub: 0,
        next: 0,
    };

    /// Whether the fields are in range: bit check 0 to 31 or 0x80, sub and
    /// next 0 to 3.
    pub const fn is_valid(&self) -> bool {
        (self.bit_check <= 31 || self.bit_check == BIT_CHECK_CONFIRM)
            && self.sub <= 3
            && self.next <= 3
    }
}

/// A request of the LSS master (COB-ID 0x7E5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Request {
    /// 0x04: all slaves enter `state` (byte 1: 0 waiting, 1 configuration).
    SwitchStateGlobal(LssState),
    /// 0x40 to 0x43: one part of the address of the slave to select
    /// (bytes 1 to 4); the slave with all four enters configuration.
    SwitchStateSelective(IdentityField, u32),
    /// 0x11: set the pending node id (byte 1; 1 to 127, or 0xFF).
    ConfigureNodeId(u8),
    /// 0x13: set the pending bit timing (byte 1: table selector, byte 2:
    /// table index).
    ConfigureBitTiming {
        /// Table selector.
        table: u8,
        /// Index in the table.
        index: u8,
    },
    /// 0x15: switch to the pending bit timing after the delay, in ms
    /// (bytes 1 to 2).
    ActivateBitTiming {
        /// The switch delay, in milliseconds.
        delay_ms: u16,
    },
    /// 0x17: store the pending node id and bit timing.
    StoreConfiguration,
    /// 0x5A to 0x5D: ask for one part of the address.
    InquireIdentity(IdentityField),
    /// 0x5E: ask for the active node id.
    InquireNodeId,
    /// 0x46 to 0x4B: one bound of an identify remote slave range (bytes 1
    /// to 4).
    IdentifyRemote(RangeField, u32),
    /// 0x4C: non-configured slaves, answer.
    IdentifyNonConfigured,
    /// 0x51: one fastscan step (bytes 1 to 4 id number, 5 bit check, 6 LSS
    /// sub, 7 LSS next).
    Fastscan(FastscanRequest),
}

/// Bytes 1 to 4 of `data` as a little-endian number.
const fn le32(b1: u8, b2: u8, b3: u8, b4: u8) -> u32 {
    u32::from_le_bytes([b1, b2, b3, b4])
}

/// `[cs, value (LE), 0, 0, 0]`.
const fn with_u32(cs: u8, value: u32) -> [u8; 8] {
    let [a, b, c, d] = value.to_le_bytes();
    [cs, a, b, c, d, 0, 0, 0]
}

/// Whether `frame` is a data frame on `cob_id` with exactly 8 bytes.
fn lss_data(frame: &Frame, cob_id: u16) -> Option<&[u8]> {
    (frame.standard_id() == Some(cob_id) && !frame.is_remote() && frame.len() == 8)
        .then(|| frame.data())
}

impl Request {
    /// Decodes the 8 data bytes of a request; `None` for any other length,
    /// an unknown command specifier, a mode other than 0 or 1, and fastscan
    /// fields out of range ([`FastscanRequest::is_valid`]).
    pub fn parse(data: &[u8]) -> Option<Request> {
        let [code, b1, b2, b3, b4, b5, b6, b7] = *data else {
            return None;
        };
        let value = le32(b1, b2, b3, b4);
        let request = match code {
            cs::SWITCH_STATE_GLOBAL => Request::SwitchStateGlobal(LssState::from_byte(b1)?),
            0x40..=0x43 => Request::SwitchStateSelective(
                IdentityField::from_index(code - cs::SWITCH_STATE_SELECTIVE_VENDOR)?,
                value,
            ),
            cs::CONFIGURE_NODE_ID => Request::ConfigureNodeId(b1),
            cs::CONFIGURE_BIT_TIMING => Request::ConfigureBitTiming {
                table: b1,
                index: b2,
            },
            cs::ACTIVATE_BIT_TIMING => Request::ActivateBitTiming {
                delay_ms: u16::from_le_bytes([b1, b2]),
            },
            cs::STORE_CONFIGURATION => Request::StoreConfiguration,
            0x5A..=0x5D => {
                Request::InquireIdentity(IdentityField::from_index(code - cs::INQUIRE_VENDOR)?)
            }
            cs::INQUIRE_NODE_ID => Request::InquireNodeId,
            0x46..=0x4B => Request::IdentifyRemote(RangeField::from_command(code)?, value),
            cs::IDENTIFY_NON_CONFIGURED => Request::IdentifyNonConfigured,
            cs::FASTSCAN => {
                let scan = FastscanRequest {
                    id_number: value,
                    bit_check: b5,
                    sub: b6,
                    next: b7,
                };
                if !scan.is_valid() {
                    return None;
                }
                Request::Fastscan(scan)
            }
            _ => return None,
        };
        Some(request)
    }

    /// Decodes a frame: a data frame on COB-ID 0x7E5 with 8 bytes that
    /// [`Request::parse`] accepts.
    pub fn from_frame(frame: &Frame) -> Option<Request> {
        Request::parse(lss_data(frame, cob::LSS_MASTER)?)
    }

    /// The 8 data bytes.
    pub const fn encode(&self) -> [u8; 8] {
        match *self {
            Request::SwitchStateGlobal(state) => {
                [cs::SWITCH_STATE_GLOBAL, state.to_byte(), 0, 0, 0, 0, 0, 0]
            }
            Request::SwitchStateSelective(field, value) => {
                with_u32(cs::SWITCH_STATE_SELECTIVE_VENDOR + field.index(), value)
            }
            Request::ConfigureNodeId(id) => [cs::CONFIGURE_NODE_ID, id, 0, 0, 0, 0, 0, 0],
            Request::ConfigureBitTiming { table, index } => {
                [cs::CONFIGURE_BIT_TIMING, table, index, 0, 0, 0, 0, 0]
            }
            Request::ActivateBitTiming { delay_ms } => {
                let [lo, hi] = delay_ms.to_le_bytes();
                [cs::ACTIVATE_BIT_TIMING, lo, hi, 0, 0, 0, 0, 0]
            }
            Request::StoreConfiguration => [cs::STORE_CONFIGURATION, 0, 0, 0, 0, 0, 0, 0],
            Request::InquireIdentity(field) => {
                [cs::INQUIRE_VENDOR + field.index(), 0, 0, 0, 0, 0, 0, 0]
            }
            Request::InquireNodeId => [cs::INQUIRE_NODE_ID, 0, 0, 0, 0, 0, 0, 0],
            Request::IdentifyRemote(field, value) => with_u32(field.command(), value),
            Request::IdentifyNonConfigured => [cs::IDENTIFY_NON_CONFIGURED, 0, 0, 0, 0, 0, 0, 0],
            Request::Fastscan(scan) => {
                let [a, b, c, d] = scan.id_number.to_le_bytes();
                [
                    cs::FASTSCAN,
                    a,
                    b,
                    c,
                    d,
                    scan.bit_check,
                    scan.sub,
                    scan.next,
                ]
            }
        }
    }

    /// The frame: COB-ID 0x7E5, the 8 bytes of [`Request::encode`].
    pub const fn to_frame(&self) -> Frame {
        Frame::standard(cob::LSS_MASTER, self.encode(), 8)
    }
}

/// A response of an LSS slave (COB-ID 0x7E4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Response {
    /// 0x44: the addressed slave entered the configuration state.
    SwitchStateSelective,
    /// 0x11: result of configure node id (byte 1 error code, byte 2
    /// implementation-specific error when the code is 0xFF).
    ConfigureNodeId {
        /// Error code: 0 success, 1 node id out of range, 0xFF see `spec`.
        error: u8,
        /// Implementation-specific error.
        spec: u8,
    },
    /// 0x13: result of configure bit timing (bytes 1 and 2 as above).
    ConfigureBitTiming {
        /// Error code: 0 success, 1 bit timing not supported, 0xFF see
        /// `spec`.
        error: u8,
        /// Implementation-specific error.
        spec: u8,
    },
    /// 0x17: result of store configuration (bytes 1 and 2 as above).
    StoreConfiguration {
        /// Error code: 0 success, 1 not supported, 2 storage media access
        /// error, 0xFF see `spec`.
        error: u8,
        /// Implementation-specific error.
        spec: u8,
    },
    /// 0x5A to 0x5D: one part of the slave's address (bytes 1 to 4).
    InquireIdentity(IdentityField, u32),
    /// 0x5E: the slave's active node id (byte 1; 0xFF: none).
    InquireNodeId(u8),
    /// 0x4F: the slave is within an identify remote slave range, or
    /// matches a fastscan step.
    IdentifySlave,
    /// 0x50: the slave has no node id.
    IdentifyNonConfiguredSlave,
}

impl Response {
    /// Decodes the 8 data bytes of a response; `None` for any other length
    /// and unknown command specifiers.
    pub fn parse(data: &[u8]) -> Option<Response> {
        let [code, b1, b2, b3, b4, _, _, _] = *data else {
            return None;
        };
        let response = match code {
            cs::SWITCH_STATE_SELECTIVE_RESPONSE => Response::SwitchStateSelective,
            cs::CONFIGURE_NODE_ID => Response::ConfigureNodeId {
                error: b1,
                spec: b2,
            },
            cs::CONFIGURE_BIT_TIMING => Response::ConfigureBitTiming {
                error: b1,
                spec: b2,
            },
            cs::STORE_CONFIGURATION => Response::StoreConfiguration {
                error: b1,
                spec: b2,
            },
            0x5A..=0x5D => Response::InquireIdentity(
                IdentityField::from_index(code - cs::INQUIRE_VENDOR)?,
                le32(b1, b2, b3, b4),
            ),
            cs::INQUIRE_NODE_ID => Response::InquireNodeId(b1),
            cs::IDENTIFY_SLAVE => Response::IdentifySlave,
            cs::IDENTIFY_NON_CONFIGURED_SLAVE => Response::IdentifyNonConfiguredSlave,
            _ => return None,
        };
        Some(response)
    }

    /// Decodes a frame: a data frame on COB-ID 0x7E4 with 8 bytes that
    /// [`Response::parse`] accepts.
    pub fn from_frame(frame: &Frame) -> Option<Response> {
        Response::parse(lss_data(frame, cob::LSS_SLAVE)?)
    }

    /// The 8 data bytes.
    pub const fn encode(&self) -> [u8; 8] {
        match *self {
            Response::SwitchStateSelective => {
                [cs::SWITCH_STATE_SELECTIVE_RESPONSE, 0, 0, 0, 0, 0, 0, 0]
            }
            Response::ConfigureNodeId { error, spec } => {
                [cs::CONFIGURE_NODE_ID, error, spec, 0, 0, 0, 0, 0]
            }
            Response::ConfigureBitTiming { error, spec } => {
                [cs::CONFIGURE_BIT_TIMING, error, spec, 0, 0, 0, 0, 0]
            }
            Response::StoreConfiguration { error, spec } => {
                [cs::STORE_CONFIGURATION, error, spec, 0, 0, 0, 0, 0]
            }
            Response::InquireIdentity(field, value) => {
                with_u32(cs::INQUIRE_VENDOR + field.index(), value)
            }
            Response::InquireNodeId(id) => [cs::INQUIRE_NODE_ID, id, 0, 0, 0, 0, 0, 0],
            Response::IdentifySlave => [cs::IDENTIFY_SLAVE, 0, 0, 0, 0, 0, 0, 0],
            Response::IdentifyNonConfiguredSlave => {
                [cs::IDENTIFY_NON_CONFIGURED_SLAVE, 0, 0, 0, 0, 0, 0, 0]
            }
        }
    }

    /// The frame: COB-ID 0x7E4, the 8 bytes of [`Response::encode`].
    pub const fn to_frame(&self) -> Frame {
        Frame::standard(cob::LSS_SLAVE, self.encode(), 8)
    }
}

#[cfg(test)]
mod tests;
