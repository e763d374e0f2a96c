//! What [`Drive`](super::Drive) exchanges with its caller: object writes,
//! events, the steps it waits in and their timeouts.

use core::fmt;
use core::ops::Deref;
use core::time::Duration;

use super::object;
use super::words::{Controlword, ModeOfOperation, State};

/// The value of an object write, in the object's data type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum WriteValue {
    /// UNSIGNED16 (controlword).
    U16(u16),
    /// INTEGER8 (modes of operation, homing method).
    I8(i8),
    /// INTEGER32 (target position, target velocity).
    I32(i32),
    /// UNSIGNED32 (profile velocity, acceleration).
    U32(u32),
}

impl WriteValue {
    /// The value's size in bytes (1, 2 or 4).
    pub const fn len(self) -> usize {
        match self {
            WriteValue::I8(_) => 1,
            WriteValue::U16(_) => 2,
            WriteValue::I32(_) | WriteValue::U32(_) => 4,
        }
    }

    /// Always `false`: every value has at least one byte.
    pub const fn is_empty(self) -> bool {
        false
    }

    /// The little-endian bytes CANopen transfers (SDO data, PDO mapping).
    pub const fn to_le_bytes(self) -> LeBytes {
        let mut bytes = [0; 4];
        match self {
            WriteValue::I8(v) => bytes[0] = v.to_le_bytes()[0],
            WriteValue::U16(v) => {
                let b = v.to_le_bytes();
                bytes[0] = b[0];
                bytes[1] = b[1];
            }
            WriteValue::I32(v) => bytes = v.to_le_bytes(),
            WriteValue::U32(v) => bytes = v.to_le_bytes(),
        }
        LeBytes {
            bytes,
            len: self.len(),
        }
    }
}

/// The little-endian bytes of a [`WriteValue`]; dereferences to `[u8]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct LeBytes {
    bytes: [u8; 4],
    len: usize,
}

impl LeBytes {
    /// The bytes, lowest first.
    pub fn as_slice(&self) -> &[u8] {
        self.bytes.get(..self.len).unwrap_or(&[])
    }
}

impl Deref for LeBytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        self.as_slice()
    }
}

/// An object write the caller performs on the drive, by RPDO or SDO
/// download, in the order [`Drive::poll_write`](super::Drive::poll_write)
/// yields them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Write {
    /// Object index (0x6040, 0x6060, 0x607A, ...).
    pub index: u16,
    /// Sub-index (0 for every object the helper writes).
    pub sub: u8,
    /// The value.
    pub value: WriteValue,
}

impl Write {
    /// A write of the controlword (0x6040).
    pub const fn controlword(cw: Controlword) -> Write {
        Write {
            index: object::CONTROLWORD,
            sub: 0,
            value: WriteValue::U16(cw.0),
        }
    }

    /// A write of the modes of operation (0x6060).
    pub const fn mode(mode: ModeOfOperation) -> Write {
        Write {
            index: object::MODES_OF_OPERATION,
            sub: 0,
            value: WriteValue::I8(mode.as_i8()),
        }
    }

    /// A write of an INTEGER32 object.
    pub const fn i32(index: u16, value: i32) -> Write {
        Write {
            index,
            sub: 0,
            value: WriteValue::I32(value),
        }
    }
}

/// Options of a profile-position move (controlword bits 5 and 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Move {
    /// Bit 6: the target is relative to the current target (or position,
    /// per the drive's positioning option code); `false`: absolute.
    pub relative: bool,
    /// Bit 5: abort the running move and start this one at once; `false`:
    /// start it when the running one has finished.
    pub immediate: bool,
}

/// The steps [`Drive`](super::Drive) waits in; each has its own timeout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Step {
    /// Waiting for a first statusword.
    Statusword,
    /// Waiting for Not ready to switch on to end (transition 1).
    StartUp,
    /// Waiting for Fault reaction active to end (transition 14).
    FaultReaction,
    /// Fault reset sent, waiting for the drive to leave Fault.
    FaultReset,
    /// Shutdown sent, waiting for Ready to switch on.
    Shutdown,
    /// Switch on sent, waiting for Switched on.
    SwitchOn,
    /// Enable operation sent, waiting for Operation enabled.
    EnableOperation,
    /// Disable voltage sent, waiting for Switch on disabled.
    DisableVoltage,
    /// Quick stop sent, waiting for Quick stop active or Switch on disabled.
    QuickStop,
    /// A new set-point waits for the previous acknowledge (bit 12) to clear.
    SetPointRelease,
    /// New set-point (bit 4) sent, waiting for set-point acknowledge.
    SetPointAcknowledge,
    /// Waiting for target reached (bit 10) after the acknowledge.
    TargetReached,
    /// Homing started, waiting for homing attained or homing error.
    Homing,
    /// Target velocity written, waiting for target reached (bit 10; used
    /// by [`Session`](super::Session), not by the helper).
    VelocityReached,
}

impl Step {
    /// Number of steps.
    pub const COUNT: usize = 14;

    /// Every step, in declaration order.
    pub const ALL: [Step; Step::COUNT] = [
        Step::Statusword,
        Step::StartUp,
        Step::FaultReaction,
        Step::FaultReset,
        Step::Shutdown,
        Step::SwitchOn,
        Step::EnableOperation,
        Step::DisableVoltage,
        Step::QuickStop,
        Step::SetPointRelease,
        Step::SetPointAcknowledge,
        Step::TargetReached,
        Step::Homing,
        Step::VelocityReached,
    ];

    /// The default timeout: 1 s for most steps, 2 s to enable operation
    /// (brake release), 5 s for start-up and fault reaction, 60 s for a
    /// move or a velocity change, 120 s for homing.
    pub const fn default_timeout(self) -> Duration {
        match self {
            Step::EnableOperation => Duration::from_secs(2),
            Step::StartUp | Step::FaultReaction => Duration::from_secs(5),
            Step::TargetReached | Step::VelocityReached => Duration::from_secs(60),
            Step::Homing => Duration::from_secs(120),
            _ => Duration::from_secs(1),
        }
    }
}

impl Step {
    /// What the step waits for ("set-point acknowledge (statusword bit
    /// 12)").
    pub const fn waits_for(self) -> &'static str {
        match self {
            Step::Statusword => "a statusword",
            Step::StartUp => "the end of Not ready to switch on",
            Step::FaultReaction => "the end of Fault reaction active",
            Step::FaultReset => "the drive to leave Fault after a fault reset",
            Step::Shutdown => "Ready to switch on after Shutdown",
            Step::SwitchOn => "Switched on after Switch on",
            Step::EnableOperation => "Operation enabled after Enable operation",
            Step::DisableVoltage => "Switch on disabled after Disable voltage",
            Step::QuickStop => "Quick stop active after Quick stop",
            Step::SetPointRelease => "the previous set-point acknowledge (bit 12) to clear",
            Step::SetPointAcknowledge => "set-point acknowledge (statusword bit 12)",
            Step::TargetReached => "target reached (statusword bit 10)",
            Step::Homing => "homing attained or homing error (statusword bits 12, 13)",
            Step::VelocityReached => "target velocity reached (statusword bit 10)",
        }
    }
}

impl fmt::Display for Step {
    /// "waiting for ..." (see [`Step::waits_for`]).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "waiting for {}", self.waits_for())
    }
}

/// Configuration of a [`Drive`](super::Drive).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct DriveConfig {
    timeouts: [Duration; Step::COUNT],
    /// How many fault resets one operation tries before it gives up.
    pub fault_reset_attempts: u8,
}

impl Default for DriveConfig {
    /// [`Step::default_timeout`] for every step, 3 fault-reset attempts.
    fn default() -> DriveConfig {
        let mut timeouts = [Duration::ZERO; Step::COUNT];
        for (slot, step) in timeouts.iter_mut().zip(Step::ALL) {
            *slot = step.default_timeout();
        }
        DriveConfig {
            timeouts,
            fault_reset_attempts: 3,
        }
    }
}

impl DriveConfig {
    /// The timeout of `step` (`Duration::MAX` waits for ever).
    pub fn timeout(&self, step: Step) -> Duration {
        self.timeouts
            .get(step as usize)
            .copied()
            .unwrap_or(step.default_timeout())
    }

    /// Sets the timeout of `step`.
    pub fn set_timeout(&mut self, step: Step, timeout: Duration) {
        if let Some(slot) = self.timeouts.get_mut(step as usize) {
            *slot = timeout;
        }
    }

    /// This configuration with the timeout of `step` set.
    pub fn with_timeout(mut self, step: Step, timeout: Duration) -> DriveConfig {
        self.set_timeout(step, timeout);
        self
    }
}

/// What [`Drive`](super::Drive) reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Event {
    /// The decoded state changed (`None`: no statusword yet, or a pattern
    /// outside the CiA 402 table).
    StateChanged {
        /// The state before.
        from: Option<State>,
        /// The state now.
        to: Option<State>,
    },
    /// [`Drive::enable`](super::Drive::enable) reached Operation enabled.
    Enabled,
    /// [`Drive::disable`](super::Drive::disable) reached Switch on disabled
    /// (or found the drive without voltage: Not ready, Fault).
    Disabled,
    /// [`Drive::quick_stop`](super::Drive::quick_stop) reached Quick stop
    /// active or Switch on disabled.
    QuickStopped,
    /// The drive entered Fault reaction active or Fault.
    FaultDetected,
    /// The drive left the fault states.
    FaultCleared,
    /// Statusword bit 12 acknowledged a new set-point (pp).
    SetPointAcknowledged,
    /// Target reached (bit 10) after an acknowledged set-point (pp).
    TargetReached,
    /// Homing attained (bit 12) and target reached (bit 10).
    HomingAttained,
    /// Homing error (bit 13).
    HomingError,
    /// Following error (bit 13 rose in pp or csp mode).
    FollowingError,
    /// The drive did not answer within the timeout of `step`; `state` is
    /// the state reached. The operation has ended.
    Timeout {
        /// The step that timed out.
        step: Step,
        /// The state reached.
        state: Option<State>,
    },
    /// The operation gave up in `step` without a timeout: fault resets used
    /// up, the drive left Operation enabled during a move or homing, or the
    /// state kept changing without reaching the goal.
    Failed {
        /// The step the operation was in.
        step: Step,
        /// The state reached.
        state: Option<State>,
    },
}

/// Why [`Drive`](super::Drive) refused a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum DriveError {
    /// The request needs Operation enabled.
    NotEnabled {
        /// The current state.
        state: Option<State>,
    },
    /// The request needs another mode of operation (see
    /// [`Drive::set_mode`](super::Drive::set_mode)).
    WrongMode {
        /// The mode set through the helper, if any.
        mode: Option<ModeOfOperation>,
    },
    /// A set-point handshake or homing is in progress, or (for motion) a
    /// state-machine operation.
    Busy,
}

impl fmt::Display for DriveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DriveError::NotEnabled { state: Some(state) } => {
                write!(f, "drive is in state {state}, not Operation enabled")
            }
            DriveError::NotEnabled { state: None } => {
                f.write_str("drive state is unknown, not Operation enabled")
            }
            DriveError::WrongMode { mode } => {
                write!(
                    f,
                    "request needs another mode of operation (mode set: {:?})",
                    mode.map(ModeOfOperation::as_i8)
                )
            }
            DriveError::Busy => f.write_str("another drive operation is in progress"),
        }
    }
}

impl core::error::Error for DriveError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn le_bytes_of_each_type() {
        assert_eq!(
            WriteValue::U16(0x1234).to_le_bytes().as_slice(),
            [0x34, 0x12]
        );
        assert_eq!(&*WriteValue::I8(-1).to_le_bytes(), [0xFF]);
        assert_eq!(
            &*WriteValue::I32(-2).to_le_bytes(),
            [0xFE, 0xFF, 0xFF, 0xFF]
        );
        assert_eq!(&*WriteValue::U32(0x0102_0304).to_le_bytes(), [4, 3, 2, 1]);
        assert_eq!(WriteValue::I32(0).len(), 4);
    }

    #[test]
    fn config_timeouts() {
        let config = DriveConfig::default().with_timeout(Step::Homing, Duration::from_secs(9));
        assert_eq!(config.timeout(Step::Homing), Duration::from_secs(9));
        assert_eq!(config.timeout(Step::Shutdown), Duration::from_secs(1));
        for (i, step) in Step::ALL.into_iter().enumerate() {
            assert_eq!(step as usize, i);
        }
    }
}
