//! CiA 402 (drives and motion control, IEC 61800-7-201): the device profile
//! objects 0x6000–0x6FFF of a drive.

use super::std_meaning::{StdBit, StdMeaning, StdPattern, StdValues, bit, pattern};
use super::{StdName, obj, sub};

pub(super) const OBJECTS: &[StdName] = &[
    obj(
        0x6007,
        "AbortConnectionOptionCode",
        "Abort connection option code",
    ),
    obj(0x603F, "ErrorCode", "Error code"),
    obj(0x6040, "Controlword", "Controlword"),
    obj(0x6041, "Statusword", "Statusword"),
    obj(0x6042, "VlTargetVelocity", "vl target velocity"),
    obj(0x6043, "VlVelocityDemand", "vl velocity demand"),
    obj(0x6044, "VlVelocityActualValue", "vl velocity actual value"),
    obj(
        0x6046,
        "VlVelocityMinMaxAmount",
        "vl velocity min max amount",
    ),
    obj(0x6048, "VlVelocityAcceleration", "vl velocity acceleration"),
    obj(0x6049, "VlVelocityDeceleration", "vl velocity deceleration"),
    obj(0x605A, "QuickStopOptionCode", "Quick stop option code"),
    obj(0x605B, "ShutdownOptionCode", "Shutdown option code"),
    obj(
        0x605C,
        "DisableOperationOptionCode",
        "Disable operation option code",
    ),
    obj(0x605D, "HaltOptionCode", "Halt option code"),
    obj(
        0x605E,
        "FaultReactionOptionCode",
        "Fault reaction option code",
    ),
    obj(0x6060, "ModesOfOperation", "Modes of operation"),
    obj(
        0x6061,
        "ModesOfOperationDisplay",
        "Modes of operation display",
    ),
    obj(0x6062, "PositionDemandValue", "Position demand value"),
    obj(
        0x6063,
        "PositionActualInternalValue",
        "Position actual internal value",
    ),
    obj(0x6064, "PositionActualValue", "Position actual value"),
    obj(0x6065, "FollowingErrorWindow", "Following error window"),
    obj(0x6066, "FollowingErrorTimeOut", "Following error time out"),
    obj(0x6067, "PositionWindow", "Position window"),
    obj(0x6068, "PositionWindowTime", "Position window time"),
    obj(
        0x6069,
        "VelocitySensorActualValue",
        "Velocity sensor actual value",
    ),
    obj(0x606A, "SensorSelectionCode", "Sensor selection code"),
    obj(0x606B, "VelocityDemandValue", "Velocity demand value"),
    obj(0x606C, "VelocityActualValue", "Velocity actual value"),
    obj(0x606D, "VelocityWindow", "Velocity window"),
    obj(0x606E, "VelocityWindowTime", "Velocity window time"),
    obj(0x606F, "VelocityThreshold", "Velocity threshold"),
    obj(0x6070, "VelocityThresholdTime", "Velocity threshold time"),
    obj(0x6071, "TargetTorque", "Target torque"),
    obj(0x6072, "MaxTorque", "Max torque"),
    obj(0x6073, "MaxCurrent", "Max current"),
    obj(0x6074, "TorqueDemand", "Torque demand"),
    obj(0x6075, "MotorRatedCurrent", "Motor rated current"),
    obj(0x6076, "MotorRatedTorque", "Motor rated torque"),
    obj(0x6077, "TorqueActualValue", "Torque actual value"),
    obj(0x6078, "CurrentActualValue", "Current actual value"),
    obj(0x6079, "DcLinkCircuitVoltage", "DC link circuit voltage"),
    obj(0x607A, "TargetPosition", "Target position"),
    obj(0x607B, "PositionRangeLimit", "Position range limit"),
    sub(
        0x607B,
        1,
        "MinPositionRangeLimit",
        "Min position range limit",
    ),
    sub(
        0x607B,
        2,
        "MaxPositionRangeLimit",
        "Max position range limit",
    ),
    obj(0x607C, "HomeOffset", "Home offset"),
    obj(0x607D, "SoftwarePositionLimit", "Software position limit"),
    sub(0x607D, 1, "MinPositionLimit", "Min position limit"),
    sub(0x607D, 2, "MaxPositionLimit", "Max position limit"),
    obj(0x607E, "Polarity", "Polarity"),
    obj(0x607F, "MaxProfileVelocity", "Max profile velocity"),
    obj(0x6080, "MaxMotorSpeed", "Max motor speed"),
    obj(0x6081, "ProfileVelocity", "Profile velocity"),
    obj(0x6082, "EndVelocity", "End velocity"),
    obj(0x6083, "ProfileAcceleration", "Profile acceleration"),
    obj(0x6084, "ProfileDeceleration", "Profile deceleration"),
    obj(0x6085, "QuickStopDeceleration", "Quick stop deceleration"),
    obj(0x6086, "MotionProfileType", "Motion profile type"),
    obj(0x6087, "TorqueSlope", "Torque slope"),
    obj(0x6088, "TorqueProfileType", "Torque profile type"),
    obj(
        0x608F,
        "PositionEncoderResolution",
        "Position encoder resolution",
    ),
    sub(0x608F, 1, "EncoderIncrements", "Encoder increments"),
    sub(0x608F, 2, "MotorRevolutions", "Motor revolutions"),
    obj(
        0x6090,
        "VelocityEncoderResolution",
        "Velocity encoder resolution",
    ),
    obj(0x6091, "GearRatio", "Gear ratio"),
    sub(0x6091, 1, "MotorRevolutions", "Motor revolutions"),
    sub(0x6091, 2, "ShaftRevolutions", "Shaft revolutions"),
    obj(0x6092, "FeedConstant", "Feed constant"),
    sub(0x6092, 1, "Feed", "Feed"),
    sub(0x6092, 2, "ShaftRevolutions", "Shaft revolutions"),
    obj(0x6096, "VelocityFactor", "Velocity factor"),
    obj(0x6097, "AccelerationFactor", "Acceleration factor"),
    obj(0x6098, "HomingMethod", "Homing method"),
    obj(0x6099, "HomingSpeeds", "Homing speeds"),
    sub(
        0x6099,
        1,
        "SpeedDuringSearchForSwitch",
        "Speed during search for switch",
    ),
    sub(
        0x6099,
        2,
        "SpeedDuringSearchForZero",
        "Speed during search for zero",
    ),
    obj(0x609A, "HomingAcceleration", "Homing acceleration"),
    obj(0x60A4, "ProfileJerk", "Profile jerk"),
    obj(0x60B0, "PositionOffset", "Position offset"),
    obj(0x60B1, "VelocityOffset", "Velocity offset"),
    obj(0x60B2, "TorqueOffset", "Torque offset"),
    obj(0x60B8, "TouchProbeFunction", "Touch probe function"),
    obj(0x60B9, "TouchProbeStatus", "Touch probe status"),
    obj(
        0x60BA,
        "TouchProbe1PositiveEdge",
        "Touch probe 1 positive edge",
    ),
    obj(
        0x60BB,
        "TouchProbe1NegativeEdge",
        "Touch probe 1 negative edge",
    ),
    obj(
        0x60BC,
        "TouchProbe2PositiveEdge",
        "Touch probe 2 positive edge",
    ),
    obj(
        0x60BD,
        "TouchProbe2NegativeEdge",
        "Touch probe 2 negative edge",
    ),
    obj(
        0x60C0,
        "InterpolationSubModeSelect",
        "Interpolation sub mode select",
    ),
    obj(
        0x60C1,
        "InterpolationDataRecord",
        "Interpolation data record",
    ),
    obj(
        0x60C2,
        "InterpolationTimePeriod",
        "Interpolation time period",
    ),
    sub(
        0x60C2,
        1,
        "InterpolationTimePeriodValue",
        "Interpolation time period value",
    ),
    sub(
        0x60C2,
        2,
        "InterpolationTimeIndex",
        "Interpolation time index",
    ),
    obj(0x60C5, "MaxAcceleration", "Max acceleration"),
    obj(0x60C6, "MaxDeceleration", "Max deceleration"),
    obj(0x60E3, "SupportedHomingMethods", "Supported homing methods"),
    obj(0x60F2, "PositioningOptionCode", "Positioning option code"),
    obj(
        0x60F4,
        "FollowingErrorActualValue",
        "Following error actual value",
    ),
    obj(0x60FA, "ControlEffort", "Control effort"),
    obj(
        0x60FC,
        "PositionDemandInternalValue",
        "Position demand internal value",
    ),
    obj(0x60FD, "DigitalInputs", "Digital inputs"),
    obj(0x60FE, "DigitalOutputs", "Digital outputs"),
    sub(0x60FE, 1, "PhysicalOutputs", "Physical outputs"),
    sub(0x60FE, 2, "BitMask", "Bit mask"),
    obj(0x60FF, "TargetVelocity", "Target velocity"),
    obj(0x6402, "MotorType", "Motor type"),
    obj(0x6403, "MotorCatalogueNumber", "Motor catalogue number"),
    obj(0x6404, "MotorManufacturer", "Motor manufacturer"),
    obj(0x6502, "SupportedDriveModes", "Supported drive modes"),
    obj(0x6503, "DriveCatalogueNumber", "Drive catalogue number"),
    obj(
        0x6505,
        "HttpDriveCatalogueAddress",
        "Http drive catalogue address",
    ),
];

/// What CiA 402 fixes about its objects (see `super::meaning`): the
/// controlword and statusword bits and states, the modes of operation and
/// the option codes, and the units the profile itself sets.
#[rustfmt::skip]
pub(super) const MEANINGS: &[StdMeaning] = &[
    StdMeaning::at(0x6040, 0).bits(CONTROLWORD_BITS).runtime("cia402::Controlword", "u16", true),
    StdMeaning::at(0x6041, 0).bits(STATUSWORD_BITS).patterns(STATES).runtime("cia402::Statusword", "u16", true),
    StdMeaning::at(0x605A, 0).values(StdValues { numeric: None, named: QUICK_STOP_OPTIONS, other: "reserved" }),
    StdMeaning::at(0x605B, 0).values(StdValues { numeric: None, named: SHUTDOWN_OPTIONS, other: "reserved" }),
    StdMeaning::at(0x605C, 0).values(StdValues { numeric: None, named: DISABLE_OPERATION_OPTIONS, other: "reserved" }),
    StdMeaning::at(0x605D, 0).values(StdValues { numeric: None, named: HALT_OPTIONS, other: "reserved" }),
    StdMeaning::at(0x605E, 0).values(StdValues { numeric: None, named: FAULT_REACTION_OPTIONS, other: "reserved" }),
    StdMeaning::at(0x6060, 0).values(MODES).runtime("cia402::ModeOfOperation", "i8", false),
    StdMeaning::at(0x6061, 0).values(MODES).runtime("cia402::ModeOfOperation", "i8", false),
    StdMeaning::at(0x6066, 0).unit("ms"),
    StdMeaning::at(0x6068, 0).unit("ms"),
    StdMeaning::at(0x606E, 0).unit("ms"),
    StdMeaning::at(0x6070, 0).unit("ms"),
    // Torques and currents in thousandths of the motor's rated torque
    // (0x6076) and rated current (0x6075).
    StdMeaning::at(0x6071, 0).unit("‰ rated torque"),
    StdMeaning::at(0x6072, 0).unit("‰ rated torque"),
    StdMeaning::at(0x6073, 0).unit("‰ rated current"),
    StdMeaning::at(0x6074, 0).unit("‰ rated torque"),
    StdMeaning::at(0x6075, 0).unit("mA"),
    StdMeaning::at(0x6076, 0).unit("mNm"),
    StdMeaning::at(0x6077, 0).unit("‰ rated torque"),
    StdMeaning::at(0x6078, 0).unit("‰ rated current"),
    StdMeaning::at(0x6079, 0).unit("mV"),
    StdMeaning::at(0x6087, 0).unit("‰ rated torque/s"),
];

const CONTROLWORD_BITS: &[StdBit] = &[
    bit(0, "switch on", None),
    bit(1, "enable voltage", None),
    bit(
        2,
        "quick stop",
        Some("0 = quick stop (the bit is active low)"),
    ),
    bit(3, "enable operation", None),
    bit(
        4,
        "new set-point",
        Some(
            "Profile position: new set-point; homing: homing operation start; other modes: operation mode specific",
        ),
    ),
    bit(
        5,
        "change set immediately",
        Some("Profile position: 1 = the new set-point replaces the running one"),
    ),
    bit(
        6,
        "relative",
        Some("Profile position: 0 = absolute target, 1 = relative target"),
    ),
    bit(7, "fault reset", Some("A rising edge resets a fault")),
    bit(8, "halt", None),
    bit(
        9,
        "change on set-point",
        Some("Profile position: 1 = the next set-point follows without stopping"),
    ),
];

const STATUSWORD_BITS: &[StdBit] = &[
    bit(0, "ready to switch on", None),
    bit(1, "switched on", None),
    bit(2, "operation enabled", None),
    bit(3, "fault", None),
    bit(4, "voltage enabled", None),
    bit(
        5,
        "quick stop",
        Some("0 = a quick stop is active (the bit is active low)"),
    ),
    bit(6, "switch on disabled", None),
    bit(7, "warning", None),
    bit(9, "remote", Some("1 = the controlword is processed")),
    bit(10, "target reached", None),
    bit(11, "internal limit active", None),
    bit(
        12,
        "set-point acknowledge",
        Some(
            "Profile position: set-point acknowledge; profile velocity: speed 0; homing: homing attained; cyclic synchronous modes: drive follows the command value",
        ),
    ),
    bit(
        13,
        "following error",
        Some(
            "Profile position and cyclic synchronous position: following error; profile velocity: max slippage error; homing: homing error",
        ),
    ),
];

/// The states of the power drive state machine (the statusword masks).
const STATES: &[StdPattern] = &[
    pattern("not ready to switch on", 0x004F, 0x0000),
    pattern("switch on disabled", 0x004F, 0x0040),
    pattern("ready to switch on", 0x006F, 0x0021),
    pattern("switched on", 0x006F, 0x0023),
    pattern("operation enabled", 0x006F, 0x0027),
    pattern("quick stop active", 0x006F, 0x0007),
    pattern("fault reaction active", 0x004F, 0x000F),
    pattern("fault", 0x004F, 0x0008),
];

/// Modes of operation (0x6060, 0x6061); negative values are the
/// manufacturer's own modes.
const MODES: StdValues = StdValues {
    numeric: None,
    named: &[
        (-128, -1, "manufacturer specific"),
        (0, 0, "no mode"),
        (1, 1, "profile position"),
        (2, 2, "velocity"),
        (3, 3, "profile velocity"),
        (4, 4, "profile torque"),
        (6, 6, "homing"),
        (7, 7, "interpolated position"),
        (8, 8, "cyclic synchronous position"),
        (9, 9, "cyclic synchronous velocity"),
        (10, 10, "cyclic synchronous torque"),
    ],
    other: "reserved",
};

const QUICK_STOP_OPTIONS: &[(i128, i128, &str)] = &[
    (-32768, -1, "manufacturer specific"),
    (0, 0, "disable drive function"),
    (1, 1, "slow down ramp then switch on disabled"),
    (2, 2, "quick stop ramp then switch on disabled"),
    (3, 3, "current limit then switch on disabled"),
    (4, 4, "voltage limit then switch on disabled"),
    (5, 5, "slow down ramp and stay in quick stop active"),
    (6, 6, "quick stop ramp and stay in quick stop active"),
    (7, 7, "current limit and stay in quick stop active"),
    (8, 8, "voltage limit and stay in quick stop active"),
];

const SHUTDOWN_OPTIONS: &[(i128, i128, &str)] = &[
    (-32768, -1, "manufacturer specific"),
    (0, 0, "disable drive function"),
    (1, 1, "slow down ramp then disable drive function"),
];

const DISABLE_OPERATION_OPTIONS: &[(i128, i128, &str)] = &[
    (-32768, -1, "manufacturer specific"),
    (0, 0, "disable drive function"),
    (1, 1, "slow down ramp then disable drive function"),
];

const HALT_OPTIONS: &[(i128, i128, &str)] = &[
    (-32768, -1, "manufacturer specific"),
    (1, 1, "slow down ramp"),
    (2, 2, "quick stop ramp"),
    (3, 3, "current limit"),
    (4, 4, "voltage limit"),
];

const FAULT_REACTION_OPTIONS: &[(i128, i128, &str)] = &[
    (-32768, -1, "manufacturer specific"),
    (0, 0, "disable drive function, motor free to rotate"),
    (1, 1, "slow down ramp"),
    (2, 2, "quick stop ramp"),
    (3, 3, "current limit"),
    (4, 4, "voltage limit"),
];
