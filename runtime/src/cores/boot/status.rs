//! The boot error status of CiA 302-2: why the boot of one slave stopped,
//! as the letters A–O a CANopen manager reports (0x1F82 and its NMT
//! "boot slave" service), each with what it means.

use core::fmt;

/// Why a slave did not boot (CiA 302-2 boot error status).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BootStatus {
    /// A: the node is not (or no longer) in the network list.
    NotListed,
    /// B: no answer to the read of the device type (0x1000).
    NoResponse,
    /// C: the device type (0x1000) differs from the expected one (0x1F84).
    DeviceType,
    /// D: the vendor id (0x1018/1) differs from the expected one (0x1F85).
    VendorId,
    /// E: no heartbeat from the node.
    HeartbeatLost,
    /// F: no answer to node guarding.
    GuardingLost,
    /// G: the objects for a program download are missing or inconsistent.
    ProgramObjects,
    /// H: the software version differs and an update is not allowed.
    SoftwareUpdateNotAllowed,
    /// I: the software version differs and the program download failed.
    SoftwareUpdateFailed,
    /// J: the configuration download failed.
    ConfigurationFailed,
    /// K: no heartbeat while error control was being started.
    HeartbeatNotStarted,
    /// L: the node was operational already (the manager may go on with the
    /// other nodes).
    InitiallyOperational,
    /// M: the product code (0x1018/2) differs from the expected one (0x1F86).
    ProductCode,
    /// N: the revision number (0x1018/3) differs from the expected one (0x1F87).
    RevisionNumber,
    /// O: the serial number (0x1018/4) differs from the expected one (0x1F88).
    SerialNumber,
}

impl BootStatus {
    /// Every status, A to O.
    pub const ALL: [BootStatus; 15] = [
        BootStatus::NotListed,
        BootStatus::NoResponse,
        BootStatus::DeviceType,
        BootStatus::VendorId,
        BootStatus::HeartbeatLost,
        BootStatus::GuardingLost,
        BootStatus::ProgramObjects,
        BootStatus::SoftwareUpdateNotAllowed,
        BootStatus::SoftwareUpdateFailed,
        BootStatus::ConfigurationFailed,
        BootStatus::HeartbeatNotStarted,
        BootStatus::InitiallyOperational,
        BootStatus::ProductCode,
        BootStatus::RevisionNumber,
        BootStatus::SerialNumber,
    ];

    /// The letter CiA 302-2 gives the status.
    pub const fn letter(self) -> char {
        match self {
            BootStatus::NotListed => 'A',
            BootStatus::NoResponse => 'B',
            BootStatus::DeviceType => 'C',
            BootStatus::VendorId => 'D',
            BootStatus::HeartbeatLost => 'E',
            BootStatus::GuardingLost => 'F',
            BootStatus::ProgramObjects => 'G',
            BootStatus::SoftwareUpdateNotAllowed => 'H',
            BootStatus::SoftwareUpdateFailed => 'I',
            BootStatus::ConfigurationFailed => 'J',
            BootStatus::HeartbeatNotStarted => 'K',
            BootStatus::InitiallyOperational => 'L',
            BootStatus::ProductCode => 'M',
            BootStatus::RevisionNumber => 'N',
            BootStatus::SerialNumber => 'O',
        }
    }

    /// What the status means, in one sentence.
    pub const fn meaning(self) -> &'static str {
        match self {
            BootStatus::NotListed => "the node is not in the network list",
            BootStatus::NoResponse => {
                "the node did not answer the read of its device type (0x1000)"
            }
            BootStatus::DeviceType => "the device type (0x1000) is not the expected one",
            BootStatus::VendorId => "the vendor id (0x1018 sub 1) is not the expected one",
            BootStatus::HeartbeatLost => "no heartbeat came from the node",
            BootStatus::GuardingLost => "the node did not answer node guarding",
            BootStatus::ProgramObjects => {
                "the objects for a program download are missing or inconsistent"
            }
            BootStatus::SoftwareUpdateNotAllowed => {
                "the software version is not the expected one, and an update is not allowed"
            }
            BootStatus::SoftwareUpdateFailed => {
                "the software version is not the expected one, and the program download failed"
            }
            BootStatus::ConfigurationFailed => "the configuration download failed",
            BootStatus::HeartbeatNotStarted => {
                "no heartbeat came from the node while error control was being started"
            }
            BootStatus::InitiallyOperational => "the node was operational already",
            BootStatus::ProductCode => "the product code (0x1018 sub 2) is not the expected one",
            BootStatus::RevisionNumber => {
                "the revision number (0x1018 sub 3) is not the expected one"
            }
            BootStatus::SerialNumber => "the serial number (0x1018 sub 4) is not the expected one",
        }
    }
}

impl fmt::Display for BootStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.letter(), self.meaning())
    }
}
