//! CiA 406 (encoders): the device profile objects 0x6000–0x6FFF of linear
//! and rotary encoders.

use super::{StdName, obj};

pub(super) const OBJECTS: &[StdName] = &[
    obj(0x6000, "OperatingParameters", "Operating parameters"),
    obj(
        0x6001,
        "MeasuringUnitsPerRevolution",
        "Measuring units per revolution",
    ),
    obj(
        0x6002,
        "TotalMeasuringRangeInMeasuringUnits",
        "Total measuring range in measuring units",
    ),
    obj(0x6003, "PresetValue", "Preset value"),
    obj(0x6004, "PositionValue", "Position value"),
    obj(0x6030, "SpeedValue", "Speed value"),
    obj(0x6040, "AccelerationValue", "Acceleration value"),
    obj(0x6200, "CyclicTimer", "Cyclic timer"),
    obj(0x6500, "OperatingStatus", "Operating status"),
    obj(0x6501, "SingleturnResolution", "Singleturn resolution"),
    obj(
        0x6502,
        "NumberOfDistinguishableRevolutions",
        "Number of distinguishable revolutions",
    ),
    obj(0x6503, "Alarms", "Alarms"),
    obj(0x6504, "SupportedAlarms", "Supported alarms"),
    obj(0x6505, "Warnings", "Warnings"),
    obj(0x6506, "SupportedWarnings", "Supported warnings"),
    obj(
        0x6507,
        "ProfileAndSoftwareVersion",
        "Profile and software version",
    ),
    obj(0x6508, "OperatingTime", "Operating time"),
    obj(0x6509, "OffsetValue", "Offset value"),
    obj(0x650A, "ModuleIdentification", "Module identification"),
    obj(0x650B, "SerialNumber", "Serial number"),
];
