//! CiA 301 (CANopen application layer and communication profile): the
//! communication objects every device may have, 0x1000–0x1FFF.

use super::std_meaning::{StdBit, StdMeaning, StdValues, bit, field};
use super::{NumberedRange, StdName, obj, sub};

/// Objects with one fixed index, and their standard sub-entries.
pub(super) const OBJECTS: &[StdName] = &[
    obj(0x1000, "DeviceType", "Device type"),
    obj(0x1001, "ErrorRegister", "Error register"),
    obj(
        0x1002,
        "ManufacturerStatusRegister",
        "Manufacturer status register",
    ),
    obj(0x1003, "PreDefinedErrorField", "Pre-defined error field"),
    sub(0x1003, 0, "NumberOfErrors", "Number of errors"),
    obj(0x1005, "CobIdSync", "COB-ID SYNC message"),
    obj(
        0x1006,
        "CommunicationCyclePeriod",
        "Communication cycle period",
    ),
    obj(
        0x1007,
        "SynchronousWindowLength",
        "Synchronous window length",
    ),
    obj(0x1008, "ManufacturerDeviceName", "Manufacturer device name"),
    obj(
        0x1009,
        "ManufacturerHardwareVersion",
        "Manufacturer hardware version",
    ),
    obj(
        0x100A,
        "ManufacturerSoftwareVersion",
        "Manufacturer software version",
    ),
    obj(0x100C, "GuardTime", "Guard time"),
    obj(0x100D, "LifeTimeFactor", "Life time factor"),
    obj(0x1010, "StoreParameters", "Store parameters"),
    sub(0x1010, 1, "SaveAllParameters", "Save all parameters"),
    sub(
        0x1010,
        2,
        "SaveCommunicationParameters",
        "Save communication parameters",
    ),
    sub(
        0x1010,
        3,
        "SaveApplicationParameters",
        "Save application parameters",
    ),
    obj(
        0x1011,
        "RestoreDefaultParameters",
        "Restore default parameters",
    ),
    sub(
        0x1011,
        1,
        "RestoreAllDefaultParameters",
        "Restore all default parameters",
    ),
    sub(
        0x1011,
        2,
        "RestoreCommunicationDefaultParameters",
        "Restore communication default parameters",
    ),
    sub(
        0x1011,
        3,
        "RestoreApplicationDefaultParameters",
        "Restore application default parameters",
    ),
    obj(0x1012, "CobIdTime", "COB-ID TIME"),
    obj(
        0x1013,
        "HighResolutionTimeStamp",
        "High resolution time stamp",
    ),
    obj(0x1014, "CobIdEmcy", "COB-ID EMCY"),
    obj(0x1015, "InhibitTimeEmcy", "Inhibit time EMCY"),
    obj(0x1016, "ConsumerHeartbeatTime", "Consumer heartbeat time"),
    obj(0x1017, "ProducerHeartbeatTime", "Producer heartbeat time"),
    obj(0x1018, "Identity", "Identity object"),
    sub(0x1018, 1, "VendorId", "Vendor-ID"),
    sub(0x1018, 2, "ProductCode", "Product code"),
    sub(0x1018, 3, "RevisionNumber", "Revision number"),
    sub(0x1018, 4, "SerialNumber", "Serial number"),
    obj(
        0x1019,
        "SynchronousCounterOverflowValue",
        "Synchronous counter overflow value",
    ),
    obj(0x1020, "VerifyConfiguration", "Verify configuration"),
    sub(0x1020, 1, "ConfigurationDate", "Configuration date"),
    sub(0x1020, 2, "ConfigurationTime", "Configuration time"),
    obj(0x1021, "StoreEds", "Store EDS"),
    obj(0x1022, "StoreFormat", "Store format"),
    obj(0x1023, "OsCommand", "OS command"),
    obj(0x1024, "OsCommandMode", "OS command mode"),
    obj(0x1025, "OsDebuggerInterface", "OS debugger interface"),
    obj(0x1026, "OsPrompt", "OS prompt"),
    obj(0x1027, "ModuleList", "Module list"),
    obj(0x1028, "EmergencyConsumer", "Emergency consumer object"),
    obj(0x1029, "ErrorBehavior", "Error behavior object"),
    // Sub 1 is the standard's; subs 2 and up are profile or vendor errors.
    sub(0x1029, 1, "CommunicationError", "Communication error"),
    // The default SDO server; the further ones are numbered below.
    obj(0x1200, "SdoServerParameter", "SDO server parameter"),
    sub(
        0x1200,
        1,
        "CobIdClientToServer",
        "COB-ID client to server (rx)",
    ),
    sub(
        0x1200,
        2,
        "CobIdServerToClient",
        "COB-ID server to client (tx)",
    ),
];

const SDO_SERVER_SUBS: &[(u8, &str, &str)] = &[
    (1, "CobIdClientToServer", "COB-ID client to server (rx)"),
    (2, "CobIdServerToClient", "COB-ID server to client (tx)"),
    (3, "NodeIdOfSdoClient", "Node-ID of the SDO client"),
];

const SDO_CLIENT_SUBS: &[(u8, &str, &str)] = &[
    (1, "CobIdClientToServer", "COB-ID client to server (tx)"),
    (2, "CobIdServerToClient", "COB-ID server to client (rx)"),
    (3, "NodeIdOfSdoServer", "Node-ID of the SDO server"),
];

const RPDO_COMM_SUBS: &[(u8, &str, &str)] = &[
    (1, "CobIdUsedByRpdo", "COB-ID used by RPDO"),
    (2, "TransmissionType", "Transmission type"),
    (3, "InhibitTime", "Inhibit time"),
    (5, "EventTimer", "Event-timer"),
];

const TPDO_COMM_SUBS: &[(u8, &str, &str)] = &[
    (1, "CobIdUsedByTpdo", "COB-ID used by TPDO"),
    (2, "TransmissionType", "Transmission type"),
    (3, "InhibitTime", "Inhibit time"),
    (5, "EventTimer", "Event-timer"),
    (6, "SyncStartValue", "SYNC start value"),
];

/// The numbered communication objects: `{n}` is 1 for the range's first
/// index (`first_number` for the SDO servers, whose first is 0x1200 above).
pub(super) const RANGES: &[NumberedRange] = &[
    NumberedRange {
        first: 0x1201,
        last: 0x127F,
        first_number: 2,
        name: ("SdoServer", "Parameter"),
        text: "SDO server parameter",
        subs: SDO_SERVER_SUBS,
        list: false,
    },
    NumberedRange {
        first: 0x1280,
        last: 0x12FF,
        first_number: 1,
        name: ("SdoClient", "Parameter"),
        text: "SDO client parameter",
        subs: SDO_CLIENT_SUBS,
        list: false,
    },
    NumberedRange {
        first: 0x1400,
        last: 0x15FF,
        first_number: 1,
        name: ("Rpdo", "CommunicationParameter"),
        text: "RPDO communication parameter",
        subs: RPDO_COMM_SUBS,
        list: false,
    },
    NumberedRange {
        first: 0x1600,
        last: 0x17FF,
        first_number: 1,
        name: ("Rpdo", "MappingParameter"),
        text: "RPDO mapping parameter",
        subs: &[],
        // Subs 1 to 64 are the mapped application objects: one list.
        list: true,
    },
    NumberedRange {
        first: 0x1800,
        last: 0x19FF,
        first_number: 1,
        name: ("Tpdo", "CommunicationParameter"),
        text: "TPDO communication parameter",
        subs: TPDO_COMM_SUBS,
        list: false,
    },
    NumberedRange {
        first: 0x1A00,
        last: 0x1BFF,
        first_number: 1,
        name: ("Tpdo", "MappingParameter"),
        text: "TPDO mapping parameter",
        subs: &[],
        // Subs 1 to 64 are the mapped application objects: one list.
        list: true,
    },
];

/// What CiA 301 (and CiA 302 for the NMT start-up) fixes about its objects
/// (see `super::meaning`).
#[rustfmt::skip]
pub(super) const MEANINGS: &[StdMeaning] = &[
    StdMeaning::at(0x1001, 0).bits(ERROR_REGISTER_BITS),
    StdMeaning::at(0x1005, 0).bits(COB_ID_SYNC_BITS),
    StdMeaning::at(0x1006, 0).unit("µs"),
    StdMeaning::at(0x1007, 0).unit("µs"),
    StdMeaning::at(0x100C, 0).unit("ms"),
    StdMeaning::at(0x1014, 0).bits(COB_ID_EMCY_BITS),
    StdMeaning::at(0x1015, 0).scaled("ms", 0.1),
    StdMeaning::at(0x1016, 1).subs(1, 127).bits(HEARTBEAT_CONSUMER_BITS),
    StdMeaning::at(0x1017, 0).unit("ms"),
    // PDO communication parameters: RPDOs, then TPDOs. Their value types
    // are the runtime's (`od::standard`), not generated per PDO.
    StdMeaning::at(0x1400, 1).objects(0x15FF).bits(PDO_COB_ID_BITS).runtime_value("od::standard::PdoCobId", "u32"),
    StdMeaning::at(0x1400, 2).objects(0x15FF).values(TRANSMISSION_TYPES).runtime_value("od::standard::TransmissionType", "u8"),
    StdMeaning::at(0x1400, 3).objects(0x15FF).scaled("ms", 0.1).runtime_value("od::standard::InhibitTime", "u16"),
    StdMeaning::at(0x1400, 5).objects(0x15FF).unit("ms").runtime_value("od::standard::EventTimer", "u16"),
    StdMeaning::at(0x1800, 1).objects(0x19FF).bits(PDO_COB_ID_BITS).runtime_value("od::standard::PdoCobId", "u32"),
    StdMeaning::at(0x1800, 2).objects(0x19FF).values(TRANSMISSION_TYPES).runtime_value("od::standard::TransmissionType", "u8"),
    StdMeaning::at(0x1800, 3).objects(0x19FF).scaled("ms", 0.1).runtime_value("od::standard::InhibitTime", "u16"),
    StdMeaning::at(0x1800, 5).objects(0x19FF).unit("ms").runtime_value("od::standard::EventTimer", "u16"),
    StdMeaning::at(0x1F80, 0).bits(NMT_STARTUP_BITS),
];

const ERROR_REGISTER_BITS: &[StdBit] = &[
    bit(0, "generic error", None),
    bit(1, "current", None),
    bit(2, "voltage", None),
    bit(3, "temperature", None),
    bit(4, "communication error", Some("Overrun, error state")),
    bit(5, "device profile specific", None),
    bit(7, "manufacturer specific", None),
];

/// Bits 0 to 28 of every COB-ID: the CAN-ID.
const CAN_ID: StdBit = field(0, 29, "CAN-ID", None);

/// Bit 29 of every COB-ID: an 11-bit or a 29-bit CAN-ID.
const EXTENDED_FRAME: StdBit = bit(
    29,
    "extended frame",
    Some("1 = 29-bit CAN-ID, 0 = 11-bit (bits 11 to 28 zero)"),
);

const COB_ID_SYNC_BITS: &[StdBit] = &[
    CAN_ID,
    EXTENDED_FRAME,
    bit(
        30,
        "generate",
        Some("1 = this device produces the SYNC message"),
    ),
];

const COB_ID_EMCY_BITS: &[StdBit] = &[
    CAN_ID,
    EXTENDED_FRAME,
    bit(
        31,
        "not valid",
        Some("1 = the EMCY message does not exist (is not valid)"),
    ),
];

const PDO_COB_ID_BITS: &[StdBit] = &[
    CAN_ID,
    EXTENDED_FRAME,
    bit(
        30,
        "no RTR",
        Some("1 = no remote transmission request allowed on this PDO"),
    ),
    bit(
        31,
        "not valid",
        Some("1 = the PDO does not exist (is not valid); its mapping may be changed"),
    ),
];

/// A PDO's transmission type.
const TRANSMISSION_TYPES: StdValues = StdValues {
    numeric: Some((1, 240)),
    named: &[
        (0, 0, "synchronous acyclic"),
        (241, 251, "reserved"),
        (252, 252, "RTR only synchronous"),
        (253, 253, "RTR only event driven"),
        (254, 254, "event driven manufacturer specific"),
        (255, 255, "event driven device profile"),
    ],
    other: "reserved",
};

const HEARTBEAT_CONSUMER_BITS: &[StdBit] = &[
    field(0, 16, "heartbeat time", Some("ms")),
    field(16, 8, "node id", None),
];

const NMT_STARTUP_BITS: &[StdBit] = &[
    bit(0, "NMT master", Some("1 = this device is the NMT master")),
    bit(
        1,
        "start all nodes",
        Some("1 = the master starts all nodes at once (NMT start all); 0 = each assigned slave"),
    ),
    bit(
        2,
        "no auto operational",
        Some("1 = the master does not enter operational by itself"),
    ),
    bit(
        3,
        "no slave start",
        Some("1 = the application, not the master, starts the slaves"),
    ),
    bit(
        4,
        "reset all on error",
        Some("1 = an error control event of a mandatory slave resets all nodes"),
    ),
    bit(
        5,
        "flying master",
        Some("1 = the device takes part in the flying master process"),
    ),
    bit(
        6,
        "stop all on error",
        Some("1 = an error control event of a mandatory slave stops all nodes (bit 4 = 0)"),
    ),
];
