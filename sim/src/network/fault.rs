//! What goes wrong on real machines, as typed faults a simulated network
//! applies per node ([`NodeFault`]): the cases of a CiA 302-2 boot's
//! error statuses and of supervision.

use std::fmt;
use std::time::Duration;

use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::abort::AbortCode;

/// One of the identity values a CiA 302-2 master checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IdentityField {
    /// 0x1000 sub 0 (boot status C when wrong).
    DeviceType,
    /// 0x1018 sub 1 (D).
    VendorId,
    /// 0x1018 sub 2 (M).
    ProductCode,
    /// 0x1018 sub 3 (N).
    RevisionNumber,
    /// 0x1018 sub 4 (O).
    SerialNumber,
}

impl IdentityField {
    /// Every field, in the order a master reads them.
    pub const ALL: [IdentityField; 5] = [
        IdentityField::DeviceType,
        IdentityField::VendorId,
        IdentityField::ProductCode,
        IdentityField::RevisionNumber,
        IdentityField::SerialNumber,
    ];

    /// The object (index, sub-index) that holds it.
    pub const fn object(self) -> (u16, u8) {
        match self {
            IdentityField::DeviceType => (0x1000, 0),
            IdentityField::VendorId => (0x1018, 1),
            IdentityField::ProductCode => (0x1018, 2),
            IdentityField::RevisionNumber => (0x1018, 3),
            IdentityField::SerialNumber => (0x1018, 4),
        }
    }

    /// Its name in the object dictionary.
    pub const fn name(self) -> &'static str {
        match self {
            IdentityField::DeviceType => "Device type",
            IdentityField::VendorId => "Vendor-ID",
            IdentityField::ProductCode => "Product code",
            IdentityField::RevisionNumber => "Revision number",
            IdentityField::SerialNumber => "Serial number",
        }
    }
}

/// What goes wrong with one simulated node. Times count from the start of
/// the simulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// The node is never on the bus (a master sees no boot-up, no answer).
    Missing,
    /// The identity object holds this value instead of the device file's
    /// (a wrong device type, vendor, product, revision or serial number).
    Identity(IdentityField, u32),
    /// The node is powered on (boot-up message) this long after the start.
    LateBoot(Duration),
    /// The node loses power at `at` and is silent for `off`; then it
    /// boots again with its defaults (what it was configured with is gone).
    PowerLoss {
        /// When it loses power.
        at: Duration,
        /// How long it stays off.
        off: Duration,
    },
    /// A write (SDO download or RPDO) to (index, sub) is refused with
    /// `code`, as a device refuses a value it cannot take.
    SdoAbort {
        /// The object's index.
        index: u16,
        /// The sub-index.
        sub: u8,
        /// The abort code of the refusal.
        code: AbortCode,
    },
    /// The node's error control stops at `at`: no heartbeat, no answer to
    /// node guarding (it runs on otherwise, its boot-up message
    /// included); with `resume`, it comes back that long after it stopped.
    HeartbeatStops {
        /// When it stops.
        at: Duration,
        /// How long it stays away (`None`: for good).
        resume: Option<Duration>,
    },
    /// The node was configured with the network's configuration before
    /// and saved it (0x1010): it holds every value the configuration
    /// writes, 0x1020 (configuration date and time) included, from its
    /// power-on; a master finds the configuration current and downloads
    /// nothing. An error for a node whose configuration carries no date
    /// and time.
    ConfigurationCurrent,
    /// 0x1020 sub 1 and 2 hold this date and time.
    ConfigurationDate {
        /// 0x1020 sub 1: days since 1 January 1984.
        date: u32,
        /// 0x1020 sub 2: milliseconds after midnight.
        time: u32,
    },
}

/// The abort code of [`Fault::SdoAbort`] when none is given: CiA 301's
/// "data cannot be transferred or stored to the application".
pub const DEFAULT_ABORT: AbortCode = AbortCode::from_code(0x0800_0020);

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let secs = |d: &Duration| d.as_secs_f64();
        match self {
            Fault::Missing => write!(f, "missing (never on the bus)"),
            Fault::Identity(field, value) => {
                let (index, sub) = field.object();
                write!(
                    f,
                    "{} (0x{index:04X} sub {sub}) is 0x{value:08X}",
                    field.name()
                )
            }
            Fault::LateBoot(d) => write!(f, "boots {:.3} s late", secs(d)),
            Fault::PowerLoss { at, off } => {
                write!(f, "loses power at {:.3} s for {:.3} s", secs(at), secs(off))
            }
            Fault::SdoAbort { index, sub, code } => write!(
                f,
                "refuses writes to 0x{index:04X} sub {sub} with abort 0x{:08X} ({code})",
                code.code()
            ),
            Fault::HeartbeatStops { at, resume: None } => {
                write!(f, "heartbeat stops at {:.3} s", secs(at))
            }
            Fault::HeartbeatStops {
                at,
                resume: Some(r),
            } => write!(
                f,
                "heartbeat stops at {:.3} s for {:.3} s",
                secs(at),
                secs(r)
            ),
            Fault::ConfigurationCurrent => write!(f, "configuration already current (0x1020)"),
            Fault::ConfigurationDate { date, time } => {
                write!(f, "0x1020 holds date {date}, time {time}")
            }
        }
    }
}

/// A fault of one node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeFault {
    /// The node.
    pub node: NodeId,
    /// What goes wrong with it.
    pub fault: Fault,
}

impl NodeFault {
    /// `fault` on `node`.
    pub const fn new(node: NodeId, fault: Fault) -> NodeFault {
        NodeFault { node, fault }
    }
}

impl fmt::Display for NodeFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "node {}: {}", self.node, self.fault)
    }
}
