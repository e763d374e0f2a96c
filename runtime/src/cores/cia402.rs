//! CiA 402 (IEC 61800-7-201) drive profile: the power drive state machine
//! on both sides of the bus.
//!
//! - [`words`]: [`State`] (decoded from the statusword with the CiA 402
//!   masks), [`Statusword`], [`Controlword`] and its [`Command`]s,
//!   [`ModeOfOperation`].
//! - [`Drive`]: the master side, sans-IO. It is fed statuswords and the
//!   time, and yields object writes ([`Write`]: controlword, modes of
//!   operation, targets) for the caller to send by RPDO or SDO, plus
//!   [`Event`]s and deadlines. It enables, disables, quick-stops and resets
//!   a drive, runs profile-position moves with the set-point handshake,
//!   homing, profile velocity and cyclic synchronous position.
//! - [`requirements`]: which objects each [`Operation`] needs, checked
//!   against a device's object table before anything is sent
//!   ([`MissingObject`]).
//! - [`Session`]: the I/O-free loop that runs [`Request`]s (enable, moves,
//!   velocity, homing, csp cycles) on a [`Drive`] over object reads and
//!   writes; the blocking master runs it in
//!   [`blocking::Master::drive`](crate::blocking::Master::drive), an async
//!   master runs the same loop (see [`session`]).
//! - [`DeviceStateMachine`]: the device side for simulators: fed
//!   controlwords, faults and motion-model verdicts, it computes the
//!   statusword with transitions 0 to 16.
//!
//! Only `core`; no heap.

pub mod device;
pub mod drive;
pub mod requirements;
pub mod session;
pub mod types;
pub mod words;

pub use device::{DeviceConfig, DeviceEvent, DeviceStateMachine};
pub use drive::Drive;
pub use requirements::{MissingObject, Operation};
pub use session::{OperationError, Request, Session, SessionConfig};
pub use types::{DriveConfig, DriveError, Event, LeBytes, Move, Step, Write, WriteValue};
pub use words::{Command, Controlword, ModeOfOperation, State, Statusword};

/// Object indexes of the CiA 402 objects the helper uses (sub-index 0).
pub mod object {
    /// Error code (UNSIGNED16) of the last fault.
    pub const ERROR_CODE: u16 = 0x603F;
    /// Controlword (UNSIGNED16).
    pub const CONTROLWORD: u16 = 0x6040;
    /// Statusword (UNSIGNED16).
    pub const STATUSWORD: u16 = 0x6041;
    /// Quick stop option code (INTEGER16).
    pub const QUICK_STOP_OPTION_CODE: u16 = 0x605A;
    /// Modes of operation (INTEGER8).
    pub const MODES_OF_OPERATION: u16 = 0x6060;
    /// Modes of operation display (INTEGER8).
    pub const MODES_OF_OPERATION_DISPLAY: u16 = 0x6061;
    /// Position actual value (INTEGER32).
    pub const POSITION_ACTUAL_VALUE: u16 = 0x6064;
    /// Velocity actual value (INTEGER32).
    pub const VELOCITY_ACTUAL_VALUE: u16 = 0x606C;
    /// Target position (INTEGER32).
    pub const TARGET_POSITION: u16 = 0x607A;
    /// Profile velocity (UNSIGNED32).
    pub const PROFILE_VELOCITY: u16 = 0x6081;
    /// Profile acceleration (UNSIGNED32).
    pub const PROFILE_ACCELERATION: u16 = 0x6083;
    /// Profile deceleration (UNSIGNED32).
    pub const PROFILE_DECELERATION: u16 = 0x6084;
    /// Homing method (INTEGER8).
    pub const HOMING_METHOD: u16 = 0x6098;
    /// Target velocity (INTEGER32).
    pub const TARGET_VELOCITY: u16 = 0x60FF;
}
