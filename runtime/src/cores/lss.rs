//! Layer setting services (CiA 305): set a device's node id and bit timing
//! over the bus, identified by its LSS address (the identity object 0x1018:
//! vendor id, product code, revision number, serial number).
//!
//! Frames: the master sends on COB-ID 0x7E5, slaves answer on 0x7E4; every
//! frame has 8 data bytes, byte 0 being the command specifier (see
//! [`proto`]). A slave is in the waiting or the configuration state
//! ([`LssState`]); configuration services need the configuration state, which
//! the master reaches for all slaves at once ([`LssMaster::switch_global`]),
//! for one slave by address ([`LssMaster::switch_selective`]) or for one
//! unknown non-configured slave by the fastscan search ([`LssMaster::fastscan`]).
//!
//! - [`LssMaster`]: one request at a time, a response timeout, and the
//!   fastscan procedure as a sub-state machine.
//! - [`LssSlave`]: answers every service, for devices and simulators. A node
//!   id set by LSS is pending until the next NMT reset communication.
//!
//! Both are sans-IO [`Service`](crate::Service)s and use only `core`.

use core::fmt;

use crate::od::NodeId;

mod fastscan;
mod master;
pub mod proto;
mod slave;

pub use fastscan::KnownIdentity;
pub use master::{ConfigureService, DEFAULT_TIMEOUT, LssError, LssEvent, LssMaster};
pub use slave::{LssSlave, LssSlaveEvent};

/// The node id byte meaning "no node id" (an unconfigured LSS slave).
pub const UNCONFIGURED: u8 = 0xFF;

/// The node id byte of `node`, [`UNCONFIGURED`] for `None`.
pub const fn node_id_byte(node: Option<NodeId>) -> u8 {
    match node {
        Some(node) => node.get(),
        None => UNCONFIGURED,
    }
}

/// The node id a configure-node-id request gives the slave: a node id, or,
/// spelled out, none ([`UNCONFIGURED`]). An invalid id never turns into
/// "unconfigured": [`NodeId`] holds only 1 to 127.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LssNodeId {
    /// Node id 1 to 127.
    Node(NodeId),
    /// No node id: the slave becomes unconfigured (0xFF).
    Unconfigured,
}

impl LssNodeId {
    /// The node id byte of the request.
    pub const fn to_byte(self) -> u8 {
        match self {
            LssNodeId::Node(node) => node.get(),
            LssNodeId::Unconfigured => UNCONFIGURED,
        }
    }
}

impl From<NodeId> for LssNodeId {
    fn from(node: NodeId) -> LssNodeId {
        LssNodeId::Node(node)
    }
}

/// Error code of a configuration response: success.
pub const ERROR_NONE: u8 = 0;
/// Error code of configure node id: the node id is out of range. Of
/// configure bit timing: the bit timing is not supported. Of store
/// configuration: storing is not supported.
pub const ERROR_NOT_SUPPORTED: u8 = 1;
/// Error code of store configuration: the storage media could not be
/// accessed.
pub const ERROR_STORAGE_ACCESS: u8 = 2;
/// Error code of every configuration response: implementation specific, the
/// reason is in the spec error byte.
pub const ERROR_IMPLEMENTATION_SPECIFIC: u8 = 0xFF;

byte_enum! {
    /// The state of an LSS slave, also the mode byte of switch state global.
    pub enum LssState {
        /// Waiting: only switch services, identification and fastscan apply.
        Waiting = 0 => "waiting",
        /// Configuration: node id, bit timing, store and inquiry services apply.
        Configuration = 1 => "configuration",
    }
}

indexed_enum! {
    /// One of the four parts of an LSS address; its index (0 to 3) is the
    /// `LSSSub` of fastscan and the sub-index of object 0x1018 minus one.
    pub enum IdentityField {
        /// Vendor id (0x1018:01).
        VendorId = 0,
        /// Product code (0x1018:02).
        ProductCode = 1,
        /// Revision number (0x1018:03).
        Revision = 2,
        /// Serial number (0x1018:04).
        Serial = 3,
    }
    /// All fields, in LSS address order.
    ALL;
}

/// An LSS address: the four entries of the identity object 0x1018.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Identity {
    /// Vendor id (0x1018:01).
    pub vendor_id: u32,
    /// Product code (0x1018:02).
    pub product_code: u32,
    /// Revision number (0x1018:03).
    pub revision: u32,
    /// Serial number (0x1018:04).
    pub serial: u32,
}

impl Identity {
    /// An identity from its four parts.
    pub const fn new(vendor_id: u32, product_code: u32, revision: u32, serial: u32) -> Identity {
        Identity {
            vendor_id,
            product_code,
            revision,
            serial,
        }
    }

    /// The value of `field`.
    pub const fn get(&self, field: IdentityField) -> u32 {
        match field {
            IdentityField::VendorId => self.vendor_id,
            IdentityField::ProductCode => self.product_code,
            IdentityField::Revision => self.revision,
            IdentityField::Serial => self.serial,
        }
    }

    /// Sets the value of `field`.
    pub fn set(&mut self, field: IdentityField, value: u32) {
        match field {
            IdentityField::VendorId => self.vendor_id = value,
            IdentityField::ProductCode => self.product_code = value,
            IdentityField::Revision => self.revision = value,
            IdentityField::Serial => self.serial = value,
        }
    }
}

impl fmt::Display for Identity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "vendor {:#010x}, product {:#010x}, revision {:#010x}, serial {:#010x}",
            self.vendor_id, self.product_code, self.revision, self.serial
        )
    }
}

/// The address range of identify remote slave: a vendor id and product code,
/// and inclusive ranges of revision and serial numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct IdentityRange {
    /// The vendor id to match.
    pub vendor_id: u32,
    /// The product code to match.
    pub product_code: u32,
    /// Lowest revision number (inclusive).
    pub revision_low: u32,
    /// Highest revision number (inclusive).
    pub revision_high: u32,
    /// Lowest serial number (inclusive).
    pub serial_low: u32,
    /// Highest serial number (inclusive).
    pub serial_high: u32,
}

impl IdentityRange {
    /// Every revision and serial number of one vendor's product.
    pub const fn product(vendor_id: u32, product_code: u32) -> IdentityRange {
        IdentityRange {
            vendor_id,
            product_code,
            revision_low: 0,
            revision_high: u32::MAX,
            serial_low: 0,
            serial_high: u32::MAX,
        }
    }

    /// Whether `identity` lies within the range.
    pub const fn contains(&self, identity: &Identity) -> bool {
        identity.vendor_id == self.vendor_id
            && identity.product_code == self.product_code
            && self.revision_low <= identity.revision
            && identity.revision <= self.revision_high
            && self.serial_low <= identity.serial
            && identity.serial <= self.serial_high
    }
}

/// A bit timing as configure bit timing names it: a table selector (0 is
/// the CiA 301 table, [`BitRate`]) and an index in that table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BitTiming {
    /// Table selector; 0 is the CiA 301 standard table, 1 to 127 are
    /// reserved, 128 to 255 are manufacturer specific.
    pub table: u8,
    /// Index in the table.
    pub index: u8,
}

impl BitTiming {
    /// A bit rate of the CiA 301 table (selector 0).
    pub const fn standard(rate: BitRate) -> BitTiming {
        BitTiming {
            table: 0,
            index: rate.table_index(),
        }
    }

    /// The CiA 301 bit rate, `None` for other tables and reserved indices.
    pub const fn bit_rate(self) -> Option<BitRate> {
        if self.table == 0 {
            BitRate::from_table_index(self.index)
        } else {
            None
        }
    }
}

/// The bit rates of the CiA 301 bit timing table (table selector 0). Index 5
/// is reserved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BitRate {
    /// 1000 kbit/s (index 0).
    Kbit1000,
    /// 800 kbit/s (index 1).
    Kbit800,
    /// 500 kbit/s (index 2).
    Kbit500,
    /// 250 kbit/s (index 3).
    Kbit250,
    /// 125 kbit/s (index 4).
    Kbit125,
    /// 50 kbit/s (index 6).
    Kbit50,
    /// 20 kbit/s (index 7).
    Kbit20,
    /// 10 kbit/s (index 8).
    Kbit10,
    /// Automatic bit rate detection (index 9).
    Auto,
}

impl BitRate {
    /// The rate at `index` of the CiA 301 table; `None` for 5 (reserved)
    /// and above 9.
    pub const fn from_table_index(index: u8) -> Option<BitRate> {
        match index {
            0 => Some(BitRate::Kbit1000),
            1 => Some(BitRate::Kbit800),
            2 => Some(BitRate::Kbit500),
            3 => Some(BitRate::Kbit250),
            4 => Some(BitRate::Kbit125),
            6 => Some(BitRate::Kbit50),
            7 => Some(BitRate::Kbit20),
            8 => Some(BitRate::Kbit10),
            9 => Some(BitRate::Auto),
            _ => None,
        }
    }

    /// The index in the CiA 301 table.
    pub const fn table_index(self) -> u8 {
        match self {
            BitRate::Kbit1000 => 0,
            BitRate::Kbit800 => 1,
            BitRate::Kbit500 => 2,
            BitRate::Kbit250 => 3,
            BitRate::Kbit125 => 4,
            BitRate::Kbit50 => 6,
            BitRate::Kbit20 => 7,
            BitRate::Kbit10 => 8,
            BitRate::Auto => 9,
        }
    }

    /// The rate in kbit/s; `None` for [`BitRate::Auto`].
    pub const fn kbit_per_s(self) -> Option<u16> {
        match self {
            BitRate::Kbit1000 => Some(1000),
            BitRate::Kbit800 => Some(800),
            BitRate::Kbit500 => Some(500),
            BitRate::Kbit250 => Some(250),
            BitRate::Kbit125 => Some(125),
            BitRate::Kbit50 => Some(50),
            BitRate::Kbit20 => Some(20),
            BitRate::Kbit10 => Some(10),
            BitRate::Auto => None,
        }
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod unit_tests {
    use super::*;

    #[test]
    fn bit_timing_table_is_cia_301() {
        let expected: [(u8, Option<u16>); 10] = [
            (0, Some(1000)),
            (1, Some(800)),
            (2, Some(500)),
            (3, Some(250)),
            (4, Some(125)),
            (5, None),
            (6, Some(50)),
            (7, Some(20)),
            (8, Some(10)),
            (9, None),
        ];
        for (index, kbit) in expected {
            let rate = BitRate::from_table_index(index);
            assert_eq!(rate.and_then(BitRate::kbit_per_s), kbit, "index {index}");
            if let Some(rate) = rate {
                assert_eq!(rate.table_index(), index);
            }
        }
        assert_eq!(BitRate::from_table_index(5), None);
        assert_eq!(BitRate::from_table_index(9), Some(BitRate::Auto));
        assert_eq!(BitRate::from_table_index(10), None);
        assert_eq!(BitTiming { table: 1, index: 0 }.bit_rate(), None);
        assert_eq!(
            BitTiming::standard(BitRate::Kbit250),
            BitTiming { table: 0, index: 3 }
        );
    }

    #[test]
    fn range_bounds_are_inclusive() {
        let id = Identity::new(0x1A, 0x2B, 5, 100);
        let mut range = IdentityRange {
            vendor_id: 0x1A,
            product_code: 0x2B,
            revision_low: 5,
            revision_high: 5,
            serial_low: 100,
            serial_high: 100,
        };
        assert!(range.contains(&id));
        range.serial_low = 101;
        assert!(!range.contains(&id));
        assert!(IdentityRange::product(0x1A, 0x2B).contains(&id));
        assert!(!IdentityRange::product(0x1A, 0x2C).contains(&id));
        assert!(!IdentityRange::product(0x1B, 0x2B).contains(&id));
    }

    #[test]
    fn identity_fields_by_index() {
        let mut id = Identity::default();
        for field in IdentityField::ALL {
            assert_eq!(IdentityField::from_index(field.index()), Some(field));
            id.set(field, u32::from(field.index()) + 10);
        }
        assert_eq!(id, Identity::new(10, 11, 12, 13));
        assert_eq!(IdentityField::from_index(4), None);
        assert_eq!(LssState::from_byte(2), None);
        assert_eq!(node_id_byte(None), 0xFF);
        assert_eq!(node_id_byte(NodeId::new(5)), 5);
    }
}
