//! Classic CAN frames and the CANopen identifiers built from node ids
//! (the predefined connection set of CiA 301).

use core::fmt;

use crate::od::NodeId;

/// A CAN identifier, the identifier of a frame on the bus: 11-bit
/// standard (what CANopen uses) or 29-bit extended. A PDO's COB-ID entry,
/// which adds the valid and RTR bits, is [`crate::od::standard::PdoCobId`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum CanId {
    /// An 11-bit identifier (0 to 0x7FF).
    Standard(u16),
    /// A 29-bit identifier (0 to 0x1FFF_FFFF).
    Extended(u32),
}

impl CanId {
    /// A standard identifier; `None` above 0x7FF.
    pub const fn standard(id: u16) -> Option<CanId> {
        if id <= 0x7FF {
            Some(CanId::Standard(id))
        } else {
            None
        }
    }

    /// An extended identifier; `None` above 0x1FFF_FFFF.
    pub const fn extended(id: u32) -> Option<CanId> {
        if id <= 0x1FFF_FFFF {
            Some(CanId::Extended(id))
        } else {
            None
        }
    }

    /// The numeric identifier, standard or extended.
    pub const fn raw(self) -> u32 {
        match self {
            CanId::Standard(id) => id as u32,
            CanId::Extended(id) => id,
        }
    }
}

/// `0x185` (standard, 3 hex digits) or `0x00000185` (extended, 8).
impl fmt::Display for CanId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CanId::Standard(id) => write!(f, "{id:#05X}"),
            CanId::Extended(id) => write!(f, "{id:#010X}"),
        }
    }
}

/// Why a frame could not be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum FrameError {
    /// More than 8 data bytes.
    TooLong(usize),
    /// An identifier out of range for its kind.
    BadId(u32),
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FrameError::TooLong(n) => {
                write!(f, "{n} data bytes; a classic CAN frame holds at most 8")
            }
            FrameError::BadId(id) => write!(f, "CAN identifier {id:#x} is out of range"),
        }
    }
}

impl core::error::Error for FrameError {}

/// A classic CAN data or remote frame (at most 8 data bytes).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Frame {
    id: CanId,
    rtr: bool,
    len: u8,
    data: [u8; 8],
}

impl Frame {
    /// A data frame; fails with more than 8 bytes.
    pub fn new(id: CanId, data: &[u8]) -> Result<Frame, FrameError> {
        if data.len() > 8 {
            return Err(FrameError::TooLong(data.len()));
        }
        let mut buf = [0u8; 8];
        buf[..data.len()].copy_from_slice(data);
        Ok(Frame {
            id,
            rtr: false,
            len: data.len() as u8,
            data: buf,
        })
    }

    /// A remote (RTR) frame asking for `len` bytes (0 to 8).
    pub fn remote(id: CanId, len: u8) -> Result<Frame, FrameError> {
        if len > 8 {
            return Err(FrameError::TooLong(len as usize));
        }
        Ok(Frame {
            id,
            rtr: true,
            len,
            data: [0; 8],
        })
    }

    /// A standard-id data frame from parts the caller knows are valid: the id
    /// is masked to 11 bits and `len` clamped to 8. The protocol cores build
    /// their frames with this.
    pub const fn standard(id: u16, data: [u8; 8], len: u8) -> Frame {
        let len = if len > 8 { 8 } else { len };
        Frame {
            id: CanId::Standard(id & 0x7FF),
            rtr: false,
            len,
            data,
        }
    }

    /// A data frame on `id` from parts the caller knows are valid: the id
    /// is masked to its width (11 or 29 bits) and `len` clamped to 8.
    pub const fn with_id(id: CanId, data: [u8; 8], len: u8) -> Frame {
        let len = if len > 8 { 8 } else { len };
        let id = match id {
            CanId::Standard(id) => CanId::Standard(id & 0x7FF),
            CanId::Extended(id) => CanId::Extended(id & 0x1FFF_FFFF),
        };
        Frame {
            id,
            rtr: false,
            len,
            data,
        }
    }

    pub const fn id(&self) -> CanId {
        self.id
    }

    /// The 11-bit identifier as a number, `None` for extended frames
    /// (CANopen's predefined connection set has only 11-bit identifiers).
    /// The identifier itself, of either length, is [`Frame::id`].
    pub const fn standard_id(&self) -> Option<u16> {
        match self.id {
            CanId::Standard(id) => Some(id),
            CanId::Extended(_) => None,
        }
    }

    pub const fn is_remote(&self) -> bool {
        self.rtr
    }

    /// The data length code (for remote frames: the requested length).
    pub const fn len(&self) -> usize {
        self.len as usize
    }

    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The data bytes (empty for remote frames).
    pub fn data(&self) -> &[u8] {
        if self.rtr {
            &[]
        } else {
            &self.data[..self.len as usize]
        }
    }

    /// All 8 data bytes, zero beyond the length.
    pub const fn data_padded(&self) -> &[u8; 8] {
        &self.data
    }
}

/// Compact candump form: `123#11223344`, `12345678#`, `123#R`.
impl fmt::Display for Frame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.id {
            CanId::Standard(id) => write!(f, "{id:03X}#")?,
            CanId::Extended(id) => write!(f, "{id:08X}#")?,
        }
        if self.rtr {
            f.write_str("R")?;
            if self.len != 0 {
                write!(f, "{}", self.len)?;
            }
            return Ok(());
        }
        for b in self.data() {
            write!(f, "{b:02X}")?;
        }
        Ok(())
    }
}

impl fmt::Debug for Frame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Frame({self})")
    }
}

/// Identifiers of the CiA 301 predefined connection set.
pub mod cob {
    use super::NodeId;

    /// NMT module control (master to all).
    pub const NMT: u16 = 0x000;
    /// SYNC.
    pub const SYNC: u16 = 0x080;
    /// TIME stamp.
    pub const TIME: u16 = 0x100;
    /// LSS master to slaves (CiA 305).
    pub const LSS_MASTER: u16 = 0x7E5;
    /// LSS slaves to master (CiA 305).
    pub const LSS_SLAVE: u16 = 0x7E4;

    pub const fn emcy(node: NodeId) -> u16 {
        0x080 + node.get() as u16
    }
    /// SDO server to client (the device's answer).
    pub const fn sdo_tx(node: NodeId) -> u16 {
        0x580 + node.get() as u16
    }
    /// SDO client to server (the request to the device).
    pub const fn sdo_rx(node: NodeId) -> u16 {
        0x600 + node.get() as u16
    }
    /// NMT error control: heartbeat, boot-up, node guarding.
    pub const fn heartbeat(node: NodeId) -> u16 {
        0x700 + node.get() as u16
    }
    /// Default COB-ID of TPDO `n` (1 to 4).
    pub const fn tpdo(n: u8, node: NodeId) -> u16 {
        0x080 + 0x100 * n as u16 + node.get() as u16
    }
    /// Default COB-ID of RPDO `n` (1 to 4).
    pub const fn rpdo(n: u8, node: NodeId) -> u16 {
        0x100 + 0x100 * n as u16 + node.get() as u16
    }

    /// What a standard identifier is in the predefined connection set of
    /// CiA 301 (and CiA 305 for LSS), by its function code (bits 7 to 10)
    /// and node id (bits 0 to 6).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    pub enum Function {
        /// 0x000: NMT module control.
        Nmt,
        /// 0x080: SYNC.
        Sync,
        /// 0x081 to 0x0FF: EMCY of a node.
        Emcy(NodeId),
        /// 0x100: TIME stamp.
        Time,
        /// TPDO 1 to 4 of a node (0x181 to 0x4FF, every second block).
        Tpdo(u8, NodeId),
        /// RPDO 1 to 4 of a node (0x201 to 0x57F, every second block).
        Rpdo(u8, NodeId),
        /// 0x581 to 0x5FF: SDO server to client (the node's answer).
        SdoTx(NodeId),
        /// 0x601 to 0x67F: SDO client to server (the request to the node).
        SdoRx(NodeId),
        /// 0x701 to 0x77F: NMT error control (heartbeat, boot-up, node guarding).
        ErrorControl(NodeId),
        /// 0x7E5: LSS master to slaves.
        LssMaster,
        /// 0x7E4: LSS slaves to master.
        LssSlave,
        /// Anything else: no predefined meaning (node id 0 in a per-node
        /// block, the restricted ranges, and the free identifiers).
        Other,
    }

    /// The predefined meaning of standard identifier `id`.
    pub const fn classify(id: u16) -> Function {
        match id {
            NMT => return Function::Nmt,
            SYNC => return Function::Sync,
            TIME => return Function::Time,
            LSS_MASTER => return Function::LssMaster,
            LSS_SLAVE => return Function::LssSlave,
            _ => {}
        }
        let Some(node) = NodeId::new((id & 0x7F) as u8) else {
            return Function::Other;
        };
        match id >> 7 {
            0x1 => Function::Emcy(node),
            code @ (0x3 | 0x5 | 0x7 | 0x9) => Function::Tpdo((code as u8 - 1) / 2, node),
            code @ (0x4 | 0x6 | 0x8 | 0xA) => Function::Rpdo((code as u8 - 2) / 2, node),
            0xB => Function::SdoTx(node),
            0xC => Function::SdoRx(node),
            0xE => Function::ErrorControl(node),
            _ => Function::Other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn functions_of_the_predefined_connection_set() {
        use cob::{Function as F, classify};
        let n = |id| NodeId::new(id).unwrap();
        let cases = [
            (0x000, F::Nmt),
            (0x080, F::Sync),
            (0x081, F::Emcy(n(1))),
            (0x0FF, F::Emcy(n(127))),
            (0x100, F::Time),
            (0x101, F::Other),
            (0x180, F::Other),
            (0x1A0, F::Tpdo(1, n(32))),
            (0x220, F::Rpdo(1, n(32))),
            (0x2A0, F::Tpdo(2, n(32))),
            (0x4FF, F::Tpdo(4, n(127))),
            (0x57F, F::Rpdo(4, n(127))),
            (0x5A0, F::SdoTx(n(32))),
            (0x620, F::SdoRx(n(32))),
            (0x680, F::Other),
            (0x6E0, F::Other),
            (0x720, F::ErrorControl(n(32))),
            (0x7E4, F::LssSlave),
            (0x7E5, F::LssMaster),
            (0x7FF, F::Other),
        ];
        for (id, function) in cases {
            assert_eq!(classify(id), function, "{id:#05X}");
        }
        for node in 1..=127u8 {
            let id = n(node);
            for k in 1..=4 {
                assert_eq!(classify(cob::tpdo(k, id)), F::Tpdo(k, id));
                assert_eq!(classify(cob::rpdo(k, id)), F::Rpdo(k, id));
            }
            assert_eq!(classify(cob::emcy(id)), F::Emcy(id));
            assert_eq!(classify(cob::sdo_tx(id)), F::SdoTx(id));
            assert_eq!(classify(cob::sdo_rx(id)), F::SdoRx(id));
            assert_eq!(classify(cob::heartbeat(id)), F::ErrorControl(id));
        }
    }

    #[test]
    fn display_is_candump_compact() {
        let f = Frame::new(
            CanId::Standard(0x220),
            &[3, 0xFB, 0xFB, 0xFB, 0xFB, 0xFB, 0, 0],
        )
        .unwrap();
        assert_eq!(f.to_string(), "220#03FBFBFBFBFB0000");
        assert_eq!(
            Frame::new(CanId::Standard(0x720), &[0])
                .unwrap()
                .to_string(),
            "720#00"
        );
        assert_eq!(
            Frame::remote(CanId::Standard(0x720), 1)
                .unwrap()
                .to_string(),
            "720#R1"
        );
        assert_eq!(
            Frame::new(CanId::Extended(0x1234), &[])
                .unwrap()
                .to_string(),
            "00001234#"
        );
    }

    #[test]
    fn predefined_connection_set() {
        let n = NodeId::new(32).unwrap();
        assert_eq!(cob::tpdo(1, n), 0x1A0);
        assert_eq!(cob::rpdo(1, n), 0x220);
        assert_eq!(cob::tpdo(4, n), 0x4A0);
        assert_eq!(cob::rpdo(4, n), 0x520);
        assert_eq!((cob::sdo_rx(n), cob::sdo_tx(n)), (0x620, 0x5A0));
        assert_eq!(cob::heartbeat(n), 0x720);
    }

    #[test]
    fn too_long_is_an_error() {
        assert_eq!(
            Frame::new(CanId::Standard(1), &[0; 9]),
            Err(FrameError::TooLong(9))
        );
    }
}
