//! The CiA 402 words: statusword (0x6041) and its states, controlword
//! (0x6040) and its commands, modes of operation (0x6060).

use core::fmt;

/// The states of the CiA 402 power drive state machine (PDS FSA).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum State {
    /// Low-level power on, the drive initialises (statusword `x0xx 0000`).
    NotReadyToSwitchOn,
    /// Initialised, power stage may not be switched on (`x1xx 0000`).
    SwitchOnDisabled,
    /// Ready for the power stage (`x01x 0001`).
    ReadyToSwitchOn,
    /// Power stage on, no torque (`x01x 0011`).
    SwitchedOn,
    /// Torque on, the drive follows its mode of operation (`x01x 0111`).
    OperationEnabled,
    /// The quick stop function runs (`x00x 0111`).
    QuickStopActive,
    /// A fault occurred, the fault reaction runs (`x0xx 1111`).
    FaultReactionActive,
    /// The fault reaction has ended, power stage off (`x0xx 1000`).
    Fault,
}

impl State {
    /// All eight states, in the order of the CiA 402 table.
    pub const ALL: [State; 8] = [
        State::NotReadyToSwitchOn,
        State::SwitchOnDisabled,
        State::ReadyToSwitchOn,
        State::SwitchedOn,
        State::OperationEnabled,
        State::QuickStopActive,
        State::FaultReactionActive,
        State::Fault,
    ];

    /// Decodes the state bits (0..3, 5, 6) of a statusword with the CiA 402
    /// masks; `None` for a pattern outside the table.
    pub const fn from_statusword(statusword: u16) -> Option<State> {
        match statusword & 0x004F {
            0x0000 => return Some(State::NotReadyToSwitchOn),
            0x0040 => return Some(State::SwitchOnDisabled),
            0x000F => return Some(State::FaultReactionActive),
            0x0008 => return Some(State::Fault),
            _ => {}
        }
        match statusword & 0x006F {
            0x0021 => Some(State::ReadyToSwitchOn),
            0x0023 => Some(State::SwitchedOn),
            0x0027 => Some(State::OperationEnabled),
            0x0007 => Some(State::QuickStopActive),
            _ => None,
        }
    }

    /// The state bits (0..3, 5, 6) a device shows in this state; bits that
    /// are "x" in the table are 0, except bit 5 (quick stop, active low),
    /// which is 1 in the three states where the table has it set.
    pub const fn state_bits(self) -> u16 {
        match self {
            State::NotReadyToSwitchOn => 0x0000,
            State::SwitchOnDisabled => 0x0040,
            State::ReadyToSwitchOn => 0x0021,
            State::SwitchedOn => 0x0023,
            State::OperationEnabled => 0x0027,
            State::QuickStopActive => 0x0007,
            State::FaultReactionActive => 0x000F,
            State::Fault => 0x0008,
        }
    }

    /// Whether this is [`State::FaultReactionActive`] or [`State::Fault`].
    pub const fn is_fault(self) -> bool {
        matches!(self, State::FaultReactionActive | State::Fault)
    }

    /// The state's name as CiA 402 writes it.
    pub const fn name(self) -> &'static str {
        match self {
            State::NotReadyToSwitchOn => "Not ready to switch on",
            State::SwitchOnDisabled => "Switch on disabled",
            State::ReadyToSwitchOn => "Ready to switch on",
            State::SwitchedOn => "Switched on",
            State::OperationEnabled => "Operation enabled",
            State::QuickStopActive => "Quick stop active",
            State::FaultReactionActive => "Fault reaction active",
            State::Fault => "Fault",
        }
    }
}

impl fmt::Display for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The statusword (object 0x6041). Bits 12 and 13 depend on the mode of
/// operation; each meaning has its own accessor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Statusword(pub u16);

impl Statusword {
    /// Bit `n` (0..=15; higher `n` reads as `false`).
    pub const fn bit(self, n: u32) -> bool {
        n < 16 && self.0 & (1 << n) != 0
    }

    /// The decoded state, `None` for a pattern outside the CiA 402 table.
    pub const fn state(self) -> Option<State> {
        State::from_statusword(self.0)
    }

    /// Bit 0: ready to switch on.
    pub const fn ready_to_switch_on(self) -> bool {
        self.bit(0)
    }

    /// Bit 1: switched on.
    pub const fn switched_on(self) -> bool {
        self.bit(1)
    }

    /// Bit 2: operation enabled.
    pub const fn operation_enabled(self) -> bool {
        self.bit(2)
    }

    /// Bit 3: fault.
    pub const fn fault(self) -> bool {
        self.bit(3)
    }

    /// Bit 4: voltage enabled (high voltage applied to the drive).
    pub const fn voltage_enabled(self) -> bool {
        self.bit(4)
    }

    /// Bit 5 as transmitted: `true` when quick stop is NOT active (the bit
    /// is active low).
    pub const fn quick_stop(self) -> bool {
        self.bit(5)
    }

    /// Bit 6: switch on disabled.
    pub const fn switch_on_disabled(self) -> bool {
        self.bit(6)
    }

    /// Bit 7: warning.
    pub const fn warning(self) -> bool {
        self.bit(7)
    }

    /// Bit 9: remote (the controlword is processed).
    pub const fn remote(self) -> bool {
        self.bit(9)
    }

    /// Bit 10: target reached (pp, homing: position; pv: velocity; with
    /// halt: the axis stands still).
    pub const fn target_reached(self) -> bool {
        self.bit(10)
    }

    /// Bit 11: internal limit active.
    pub const fn internal_limit_active(self) -> bool {
        self.bit(11)
    }

    /// Bit 12 in profile position mode: set-point acknowledge.
    pub const fn set_point_acknowledge(self) -> bool {
        self.bit(12)
    }

    /// Bit 12 in profile velocity mode: speed is 0.
    pub const fn speed_zero(self) -> bool {
        self.bit(12)
    }

    /// Bit 12 in homing mode: homing attained.
    pub const fn homing_attained(self) -> bool {
        self.bit(12)
    }

    /// Bit 12 in the cyclic synchronous modes: the drive follows the
    /// command value (0: target ignored).
    pub const fn drive_follows_command(self) -> bool {
        self.bit(12)
    }

    /// Bit 13 in profile position and cyclic synchronous position mode:
    /// following error.
    pub const fn following_error(self) -> bool {
        self.bit(13)
    }

    /// Bit 13 in profile velocity mode: maximum slippage error.
    pub const fn max_slippage(self) -> bool {
        self.bit(13)
    }

    /// Bit 13 in homing mode: homing error.
    pub const fn homing_error(self) -> bool {
        self.bit(13)
    }
}

/// The device-control commands of the controlword (bits 0..3 and 7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Command {
    /// `0 x110` (written as 0x0006): transitions 2, 6, 8.
    Shutdown,
    /// `0 0111` (0x0007): transition 3.
    SwitchOn,
    /// `0 1111` (0x000F): transitions 4 and 16; from Ready to switch on
    /// also "switch on + enable operation" (3 then 4).
    EnableOperation,
    /// `0 xx0x` (0x0000): transitions 7, 9, 10, 12.
    DisableVoltage,
    /// `0 x01x` (0x0002): transitions 7, 10, 11.
    QuickStop,
    /// `0 0111` (0x0007): transition 5.
    DisableOperation,
    /// A rising edge of bit 7 (0x0080 after a word with bit 7 clear):
    /// transition 15.
    FaultReset,
}

impl Command {
    /// The controlword bits 0..3 and 7 of the command, "x" bits as 0.
    pub const fn bits(self) -> u16 {
        match self {
            Command::Shutdown => 0x0006,
            Command::SwitchOn | Command::DisableOperation => 0x0007,
            Command::EnableOperation => 0x000F,
            Command::DisableVoltage => 0x0000,
            Command::QuickStop => 0x0002,
            Command::FaultReset => 0x0080,
        }
    }
}

/// The controlword (object 0x6040).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Controlword(pub u16);

impl Controlword {
    /// The bits a command sets: 0..3 and 7.
    pub const COMMAND_MASK: u16 = 0x008F;

    /// The controlword of a command with every other bit 0.
    pub const fn from_command(command: Command) -> Controlword {
        Controlword(command.bits())
    }

    /// This word with bits 0..3 and 7 replaced by `command`.
    pub const fn with_command(self, command: Command) -> Controlword {
        Controlword((self.0 & !Self::COMMAND_MASK) | command.bits())
    }

    /// Bit `n` (0..=15; higher `n` reads as `false`).
    pub const fn bit(self, n: u32) -> bool {
        n < 16 && self.0 & (1 << n) != 0
    }

    /// This word with bit `n` set to `on` (`n` above 15: unchanged).
    pub const fn with_bit(self, n: u32, on: bool) -> Controlword {
        if n >= 16 {
            return self;
        }
        let mask = 1 << n;
        Controlword(if on { self.0 | mask } else { self.0 & !mask })
    }

    /// Bit 0: switch on.
    pub const fn switch_on(self) -> bool {
        self.bit(0)
    }

    /// Bit 1: enable voltage.
    pub const fn enable_voltage(self) -> bool {
        self.bit(1)
    }

    /// Bit 2 as transmitted: `true` means NO quick stop (active low).
    pub const fn quick_stop(self) -> bool {
        self.bit(2)
    }

    /// Bit 3: enable operation.
    pub const fn enable_operation(self) -> bool {
        self.bit(3)
    }

    /// Bit 4: new set-point (pp) / homing operation start (homing).
    pub const fn new_set_point(self) -> bool {
        self.bit(4)
    }

    /// Bit 5 (pp): change set immediately.
    pub const fn change_set_immediately(self) -> bool {
        self.bit(5)
    }

    /// Bit 6 (pp): the target is relative (`false`: absolute).
    pub const fn relative(self) -> bool {
        self.bit(6)
    }

    /// Bit 7: fault reset (acts on its rising edge).
    pub const fn fault_reset(self) -> bool {
        self.bit(7)
    }

    /// Bit 8: halt.
    pub const fn halt(self) -> bool {
        self.bit(8)
    }

    /// With bit 4 (new set-point / homing start) set to `on`.
    pub const fn with_new_set_point(self, on: bool) -> Controlword {
        self.with_bit(4, on)
    }

    /// With bit 5 (change set immediately) set to `on`.
    pub const fn with_change_set_immediately(self, on: bool) -> Controlword {
        self.with_bit(5, on)
    }

    /// With bit 6 (relative) set to `on`.
    pub const fn with_relative(self, on: bool) -> Controlword {
        self.with_bit(6, on)
    }

    /// With bit 8 (halt) set to `on`.
    pub const fn with_halt(self, on: bool) -> Controlword {
        self.with_bit(8, on)
    }
}

impl From<Command> for Controlword {
    fn from(command: Command) -> Controlword {
        Controlword::from_command(command)
    }
}

/// Modes of operation (object 0x6060, displayed in 0x6061).
#[derive(Debug, Clone, Copy)]
pub enum ModeOfOperation {
    /// 0: no mode assigned.
    NoMode,
    /// 1: profile position (pp).
    ProfilePosition,
    /// 2: velocity (vl).
    Velocity,
    /// 3: profile velocity (pv).
    ProfileVelocity,
    /// 4: profile torque (tq).
    ProfileTorque,
    /// 6: homing (hm).
    Homing,
    /// 7: interpolated position (ip).
    InterpolatedPosition,
    /// 8: cyclic synchronous position (csp).
    CyclicSynchronousPosition,
    /// 9: cyclic synchronous velocity (csv).
    CyclicSynchronousVelocity,
    /// 10: cyclic synchronous torque (cst).
    CyclicSynchronousTorque,
    /// Any other value (reserved or manufacturer specific, negative).
    /// Compares equal to the named variant of the same value.
    Other(i8),
}

impl ModeOfOperation {
    /// The mode of a 0x6060/0x6061 value.
    pub const fn from_i8(value: i8) -> ModeOfOperation {
        match value {
            0 => ModeOfOperation::NoMode,
            1 => ModeOfOperation::ProfilePosition,
            2 => ModeOfOperation::Velocity,
            3 => ModeOfOperation::ProfileVelocity,
            4 => ModeOfOperation::ProfileTorque,
            6 => ModeOfOperation::Homing,
            7 => ModeOfOperation::InterpolatedPosition,
            8 => ModeOfOperation::CyclicSynchronousPosition,
            9 => ModeOfOperation::CyclicSynchronousVelocity,
            10 => ModeOfOperation::CyclicSynchronousTorque,
            other => ModeOfOperation::Other(other),
        }
    }

    /// The 0x6060 value of the mode.
    pub const fn as_i8(self) -> i8 {
        match self {
            ModeOfOperation::NoMode => 0,
            ModeOfOperation::ProfilePosition => 1,
            ModeOfOperation::Velocity => 2,
            ModeOfOperation::ProfileVelocity => 3,
            ModeOfOperation::ProfileTorque => 4,
            ModeOfOperation::Homing => 6,
            ModeOfOperation::InterpolatedPosition => 7,
            ModeOfOperation::CyclicSynchronousPosition => 8,
            ModeOfOperation::CyclicSynchronousVelocity => 9,
            ModeOfOperation::CyclicSynchronousTorque => 10,
            ModeOfOperation::Other(value) => value,
        }
    }
}

impl PartialEq for ModeOfOperation {
    fn eq(&self, other: &ModeOfOperation) -> bool {
        self.as_i8() == other.as_i8()
    }
}

impl Eq for ModeOfOperation {}

impl core::hash::Hash for ModeOfOperation {
    fn hash<H: core::hash::Hasher>(&self, state: &mut H) {
        self.as_i8().hash(state);
    }
}

impl From<i8> for ModeOfOperation {
    fn from(value: i8) -> ModeOfOperation {
        ModeOfOperation::from_i8(value)
    }
}

impl From<ModeOfOperation> for i8 {
    fn from(mode: ModeOfOperation) -> i8 {
        mode.as_i8()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statusword_patterns_of_every_state() {
        let table: [(u16, State); 12] = [
            (0x0200, State::NotReadyToSwitchOn),
            (0x0210, State::NotReadyToSwitchOn),
            (0x0250, State::SwitchOnDisabled),
            (0x0270, State::SwitchOnDisabled),
            (0x0231, State::ReadyToSwitchOn),
            (0x0221, State::ReadyToSwitchOn),
            (0x0233, State::SwitchedOn),
            (0x0237, State::OperationEnabled),
            (0x0217, State::QuickStopActive),
            (0x021F, State::FaultReactionActive),
            (0x0218, State::Fault),
            (0x0238, State::Fault),
        ];
        for (sw, state) in table {
            assert_eq!(State::from_statusword(sw), Some(state), "{sw:#06x}");
            assert_eq!(Statusword(sw).state(), Some(state));
        }
        // Bits outside the state bits do not matter.
        assert_eq!(
            State::from_statusword(0xFCB7),
            Some(State::OperationEnabled)
        );
        // Patterns outside the table.
        for sw in [
            0x0001, 0x0003, 0x0041, 0x0061, 0x0067, 0x0004, 0x0025, 0x0002,
        ] {
            assert_eq!(State::from_statusword(sw), None, "{sw:#06x}");
        }
        for state in State::ALL {
            assert_eq!(State::from_statusword(state.state_bits()), Some(state));
        }
    }

    #[test]
    fn statusword_bits() {
        let sw = Statusword(0x3E97);
        assert!(sw.ready_to_switch_on() && sw.switched_on() && sw.operation_enabled());
        assert!(!sw.fault() && sw.voltage_enabled() && !sw.quick_stop());
        assert!(!sw.switch_on_disabled() && sw.warning() && sw.remote());
        assert!(sw.target_reached() && sw.internal_limit_active());
        assert!(sw.set_point_acknowledge() && sw.homing_attained() && sw.speed_zero());
        assert!(sw.following_error() && sw.homing_error() && sw.max_slippage());
        assert!(sw.drive_follows_command());
        assert!(!sw.bit(16));
        assert!(Statusword(0x0237).quick_stop());
    }

    #[test]
    fn controlword_commands() {
        assert_eq!(Controlword::from(Command::Shutdown), Controlword(0x0006));
        assert_eq!(Controlword::from(Command::SwitchOn), Controlword(0x0007));
        assert_eq!(
            Controlword::from(Command::EnableOperation),
            Controlword(0x000F)
        );
        assert_eq!(
            Controlword::from(Command::DisableVoltage),
            Controlword(0x0000)
        );
        assert_eq!(Controlword::from(Command::QuickStop), Controlword(0x0002));
        assert_eq!(
            Controlword::from(Command::DisableOperation),
            Controlword(0x0007)
        );
        assert_eq!(Controlword::from(Command::FaultReset), Controlword(0x0080));
        // Commands keep the other bits (halt, operation-mode bits).
        let cw = Controlword(0x017F).with_command(Command::Shutdown);
        assert_eq!(cw, Controlword(0x0176));
        assert!(cw.halt() && cw.new_set_point() && cw.relative());
        assert!(cw.change_set_immediately() && !cw.fault_reset());
        let pp = Controlword(0x000F)
            .with_new_set_point(true)
            .with_change_set_immediately(true)
            .with_relative(true)
            .with_halt(true);
        assert_eq!(pp, Controlword(0x017F));
        assert_eq!(
            pp.with_relative(false).with_halt(false),
            Controlword(0x003F)
        );
        assert_eq!(pp.with_bit(16, false), pp);
    }

    #[test]
    fn modes_of_operation() {
        let table = [
            (1, ModeOfOperation::ProfilePosition),
            (3, ModeOfOperation::ProfileVelocity),
            (4, ModeOfOperation::ProfileTorque),
            (6, ModeOfOperation::Homing),
            (8, ModeOfOperation::CyclicSynchronousPosition),
            (9, ModeOfOperation::CyclicSynchronousVelocity),
            (10, ModeOfOperation::CyclicSynchronousTorque),
            (-3, ModeOfOperation::Other(-3)),
        ];
        for (value, mode) in table {
            assert_eq!(ModeOfOperation::from_i8(value), mode);
            assert_eq!(mode.as_i8(), value);
        }
        assert!(matches!(
            ModeOfOperation::from_i8(5),
            ModeOfOperation::Other(5)
        ));
        assert_eq!(ModeOfOperation::Other(6), ModeOfOperation::Homing);
    }
}
