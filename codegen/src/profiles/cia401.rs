//! CiA 401 (generic I/O modules): the device profile objects 0x6000–0x6FFF
//! of digital and analogue I/O.

use super::{StdName, obj};

pub(super) const OBJECTS: &[StdName] = &[
    obj(0x6000, "ReadInput8Bit", "Read input 8-bit"),
    obj(0x6002, "PolarityInput8Bit", "Polarity input 8-bit"),
    obj(
        0x6003,
        "FilterConstantInput8Bit",
        "Filter constant input 8-bit",
    ),
    obj(
        0x6005,
        "GlobalInterruptEnableDigital8Bit",
        "Global interrupt enable digital 8-bit",
    ),
    obj(
        0x6006,
        "InterruptMaskAnyChange8Bit",
        "Interrupt mask any change 8-bit",
    ),
    obj(
        0x6007,
        "InterruptMaskLowToHigh8Bit",
        "Interrupt mask low-to-high 8-bit",
    ),
    obj(
        0x6008,
        "InterruptMaskHighToLow8Bit",
        "Interrupt mask high-to-low 8-bit",
    ),
    obj(0x6100, "ReadInput16Bit", "Read input 16-bit"),
    obj(0x6120, "ReadInput32Bit", "Read input 32-bit"),
    obj(0x6200, "WriteOutput8Bit", "Write output 8-bit"),
    obj(
        0x6202,
        "ChangePolarityOutput8Bit",
        "Change polarity output 8-bit",
    ),
    obj(0x6206, "ErrorModeOutput8Bit", "Error mode output 8-bit"),
    obj(0x6207, "ErrorValueOutput8Bit", "Error value output 8-bit"),
    obj(0x6208, "FilterMaskOutput8Bit", "Filter mask output 8-bit"),
    obj(0x6300, "WriteOutput16Bit", "Write output 16-bit"),
    obj(0x6320, "WriteOutput32Bit", "Write output 32-bit"),
    obj(0x6400, "ReadAnalogueInput8Bit", "Read analogue input 8-bit"),
    obj(
        0x6401,
        "ReadAnalogueInput16Bit",
        "Read analogue input 16-bit",
    ),
    obj(
        0x6402,
        "ReadAnalogueInput32Bit",
        "Read analogue input 32-bit",
    ),
    obj(
        0x6403,
        "ReadAnalogueInputFloat",
        "Read analogue input float",
    ),
    obj(
        0x6410,
        "WriteAnalogueOutput8Bit",
        "Write analogue output 8-bit",
    ),
    obj(
        0x6411,
        "WriteAnalogueOutput16Bit",
        "Write analogue output 16-bit",
    ),
    obj(
        0x6412,
        "WriteAnalogueOutput32Bit",
        "Write analogue output 32-bit",
    ),
    obj(
        0x6413,
        "WriteAnalogueOutputFloat",
        "Write analogue output float",
    ),
    obj(
        0x6421,
        "AnalogueInputInterruptTriggerSelection",
        "Analogue input interrupt trigger selection",
    ),
    obj(
        0x6422,
        "AnalogueInputInterruptSource",
        "Analogue input interrupt source",
    ),
    obj(
        0x6423,
        "AnalogueInputGlobalInterruptEnable",
        "Analogue input global interrupt enable",
    ),
    obj(
        0x6424,
        "AnalogueInputInterruptUpperLimitInteger",
        "Analogue input interrupt upper limit integer",
    ),
    obj(
        0x6425,
        "AnalogueInputInterruptLowerLimitInteger",
        "Analogue input interrupt lower limit integer",
    ),
    obj(
        0x6426,
        "AnalogueInputInterruptDeltaUnsigned",
        "Analogue input interrupt delta unsigned",
    ),
    obj(
        0x6427,
        "AnalogueInputInterruptNegativeDeltaUnsigned",
        "Analogue input interrupt negative delta unsigned",
    ),
    obj(
        0x6428,
        "AnalogueInputInterruptPositiveDeltaUnsigned",
        "Analogue input interrupt positive delta unsigned",
    ),
    obj(
        0x6443,
        "AnalogueOutputErrorMode",
        "Analogue output error mode",
    ),
    obj(
        0x6444,
        "AnalogueOutputErrorValueInteger",
        "Analogue output error value integer",
    ),
];
