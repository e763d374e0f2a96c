//! The network description as read from a bus file (lely dcfgen's YAML, as
//! ros2_canopen users write it): plain data, every value with where it was
//! written. Defaults are dcfgen's: a key absent from the file is `None`
//! (or the documented default) here, and [`super::config`] applies what
//! dcfgen does with it.

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::ir::Device;

/// Where a value was written in the bus file.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Spot {
    /// 1-based line of the key (or of the item, in a list).
    pub line: u32,
    /// The key path, dotted as a user would say it:
    /// `prbt_joint_1.tpdo.1.mapping[0].index`. For a node expanded from
    /// `defaults:`, the path of the node (`nodes.prbt_joint_1` becomes
    /// `prbt_joint_1`) and the line where the value was written (in
    /// `defaults:` or in the node).
    pub key: String,
}

/// A value and where it was written.
#[derive(Debug, Clone, PartialEq)]
pub struct At<T> {
    pub value: T,
    pub spot: Spot,
}

impl<T> At<T> {
    pub fn new(value: T, spot: Spot) -> Self {
        At { value, spot }
    }
}

/// A whole bus file.
#[derive(Debug, Clone)]
pub struct Bus {
    /// The bus file, as given.
    pub file: PathBuf,
    /// `options:`.
    pub options: BusOptions,
    /// `master:`.
    pub master: MasterSection,
    /// The slaves in dcfgen's order: file order, or, in a file with
    /// `nodes:` (which only ros2_canopen reads: it expands the nodes, drops
    /// other slave sections and writes the file with its keys sorted before
    /// dcfgen reads it), the nodes ordered by name. That order numbers the
    /// master's PDOs.
    pub slaves: Vec<SlaveSection>,
    /// Keys dcfgen does not use (ros2_canopen's `driver`, `package`,
    /// `period`, ...), kept in file order. Listed at info level, never an
    /// error.
    pub extra_keys: Vec<ExtraKey>,
}

/// A key dcfgen does not read, kept as written.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtraKey {
    /// `master`, `options` or the slave's name.
    pub section: String,
    pub key: String,
    /// The value as YAML-ish text (`"ros2_canopen::MasterDriver"`, `10`, `[...]`).
    pub value: String,
    pub spot: Spot,
}

/// `options:` (dcfgen's defaults when absent).
#[derive(Debug, Clone, PartialEq)]
pub struct BusOptions {
    /// `dcf_path` (default ""), where the master finds the `.bin` files at
    /// run time; written into master.dcf, not used to find device files.
    pub dcf_path: String,
    /// `heartbeat_multiplier` (default 3.0).
    pub heartbeat_multiplier: f64,
    /// `retry_factor` (default 3).
    pub retry_factor: u32,
}

impl Default for BusOptions {
    fn default() -> Self {
        BusOptions {
            dcf_path: String::new(),
            heartbeat_multiplier: 3.0,
            retry_factor: 3,
        }
    }
}

/// The first COB-ID dcfgen gives a PDO with `cob_id: auto` beyond the four
/// pre-defined ones; it counts up to 0x6DF.
pub const AUTO_COB_ID_FIRST: u32 = 0x680;
/// The first COB-ID past the `auto` range.
pub const AUTO_COB_ID_END: u32 = 0x6E0;

/// `master:`. Every field holds dcfgen's default when the key is absent;
/// `spots` says which keys were written and where.
#[derive(Debug, Clone, PartialEq)]
pub struct MasterSection {
    /// Where `master:` is (line 0 when the file has none).
    pub spot: Spot,
    /// `node_id` (default 255: unconfigured).
    pub node_id: u8,
    /// `baudrate` in kbit/s (default 1000).
    pub baudrate: u32,
    pub vendor_id: u32,
    pub product_code: u32,
    pub revision_number: u32,
    pub serial_number: u32,
    /// `sync_period` in µs (0: no SYNC).
    pub sync_period: u32,
    /// `sync_window` in µs.
    pub sync_window: u32,
    /// `sync_overflow` (0: no counter).
    pub sync_overflow: u8,
    /// `time_cob_id` (default 0x100).
    pub time_cob_id: u32,
    /// `emcy_inhibit_time` in 100 µs.
    pub emcy_inhibit_time: u16,
    /// `heartbeat_multiplier` (default: the options').
    pub heartbeat_multiplier: f64,
    /// `heartbeat_consumer` (default true): slaves consume the master's heartbeat.
    pub heartbeat_consumer: bool,
    /// `heartbeat_producer` in ms (0: none).
    pub heartbeat_producer: u16,
    /// `error_behavior` (default {1: 0}).
    pub error_behavior: BTreeMap<u8, u8>,
    /// `nmt_inhibit_time` in 100 µs.
    pub nmt_inhibit_time: u16,
    pub start: bool,
    pub start_nodes: bool,
    pub start_all_nodes: bool,
    pub reset_all_nodes: bool,
    pub stop_all_nodes: bool,
    /// `boot_time` in ms (0: none).
    pub boot_time: u32,
    /// Key → where it was written, for the keys the file gives.
    pub spots: BTreeMap<String, Spot>,
}

impl Default for MasterSection {
    fn default() -> Self {
        MasterSection {
            spot: Spot::default(),
            node_id: 255,
            baudrate: 1000,
            vendor_id: 0,
            product_code: 0,
            revision_number: 0,
            serial_number: 0,
            sync_period: 0,
            sync_window: 0,
            sync_overflow: 0,
            time_cob_id: 0x100,
            emcy_inhibit_time: 0,
            heartbeat_multiplier: 3.0,
            heartbeat_consumer: true,
            heartbeat_producer: 0,
            error_behavior: BTreeMap::from([(1, 0)]),
            nmt_inhibit_time: 0,
            start: true,
            start_nodes: true,
            start_all_nodes: false,
            reset_all_nodes: false,
            stop_all_nodes: false,
            boot_time: 0,
            spots: BTreeMap::new(),
        }
    }
}

/// One slave section. `None` means the key is absent (dcfgen then keeps
/// the device file's value or its own default).
#[derive(Debug, Clone)]
pub struct SlaveSection {
    /// The YAML key naming the slave (`prbt_joint_1`); the `.bin` file and
    /// the generated module are named after it.
    pub name: String,
    pub spot: Spot,
    /// `dcf` as written.
    pub dcf: At<String>,
    /// The device file, resolved relative to the bus file.
    pub device_file: PathBuf,
    /// The device read from it, `$NODEID` not yet resolved (the IR keeps
    /// formulas; resolve with [`node_id`](Self::node_id)).
    pub device: Box<Device>,
    /// `node_id`; `None` falls back to the DCF's `[DeviceComissioning]`
    /// NodeID, and a slave with neither is ignored as dcfgen ignores it
    /// (with a warning).
    pub node_id: Option<At<u8>>,
    /// `dcf_path` (default: the options').
    pub dcf_path: Option<At<String>>,
    pub revision_number: Option<At<u32>>,
    pub serial_number: Option<At<u32>>,
    pub time_cob_id: Option<At<u32>>,
    pub heartbeat_multiplier: Option<At<f64>>,
    /// `heartbeat_consumer` (default false): this slave consumes the master's heartbeat.
    pub heartbeat_consumer: Option<At<bool>>,
    /// `heartbeat_producer` in ms.
    pub heartbeat_producer: Option<At<u16>>,
    pub retry_factor: Option<At<u32>>,
    /// `guard_time` in ms.
    pub guard_time: Option<At<u16>>,
    pub life_time_factor: Option<At<u8>>,
    /// `error_behavior`: 0x1029 sub-index → value.
    pub error_behavior: BTreeMap<u8, At<u8>>,
    /// `rpdo`: PDO number (1-based) → section, as the slave receives.
    pub rpdo: BTreeMap<u16, PdoSection>,
    /// `tpdo`: PDO number (1-based) → section, as the slave transmits.
    pub tpdo: BTreeMap<u16, PdoSection>,
    pub boot: Option<At<bool>>,
    pub mandatory: Option<At<bool>>,
    pub reset_communication: Option<At<bool>>,
    pub software_file: Option<At<String>>,
    pub software_version: Option<At<u32>>,
    pub configuration_file: Option<At<String>>,
    pub restore_configuration: Option<At<u8>>,
    /// `sdo`: writes at boot, in file order.
    pub sdo: Vec<SdoItem>,
}

impl SlaveSection {
    /// The node id dcfgen gives the slave: its `node_id` key, else the
    /// device file's `[DeviceComissioning]` NodeID (a DCF's); `None` when
    /// neither says (dcfgen then ignores the slave).
    pub fn effective_node_id(&self) -> Option<u8> {
        self.node_id
            .as_ref()
            .map(|n| n.value)
            .or_else(|| self.device.commissioning.as_ref()?.node_id)
    }
}

/// One `rpdo`/`tpdo` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct PdoSection {
    pub spot: Spot,
    /// `enabled` (default true).
    pub enabled: At<bool>,
    pub cob_id: Option<At<CobIdSetting>>,
    pub transmission: Option<At<u8>>,
    /// `inhibit_time` in 100 µs.
    pub inhibit_time: Option<At<u16>>,
    /// `event_timer` in ms.
    pub event_timer: Option<At<u16>>,
    /// `event_deadline` in ms (RPDO).
    pub event_deadline: Option<At<u16>>,
    pub sync_start: Option<At<u8>>,
    /// `mapping`; `None` keeps the device file's mapping.
    pub mapping: Option<Vec<MappingItem>>,
}

/// `cob_id:` of a PDO.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CobIdSetting {
    /// `auto`: the pre-defined COB-ID for PDOs 1–4, the next free one from
    /// [`AUTO_COB_ID_FIRST`] for the others.
    Auto,
    /// A number, written as is (bit 31 set: the PDO is not valid).
    Value(u32),
}

/// One `mapping:` item.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MappingItem {
    pub spot: Spot,
    pub index: u16,
    /// `sub_index` (default 0).
    pub sub_index: u8,
}

/// One `sdo:` item.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SdoItem {
    pub spot: Spot,
    pub index: u16,
    /// `sub_index` (default 0).
    pub sub_index: u8,
    /// `value` (default 0), packed by the entry's data type.
    pub value: i128,
}

impl Spot {
    /// The diagnostics location of this spot (line and key).
    pub fn location(&self) -> crate::diag::Location {
        crate::diag::Location {
            line: (self.line > 0).then_some(self.line),
            span: None,
            section: None,
            key: (!self.key.is_empty()).then(|| self.key.clone()),
        }
    }

    /// A diagnostic about the value written here, in bus file `file`.
    pub fn diagnostic(
        &self,
        file: &std::path::Path,
        severity: crate::diag::Severity,
        code: &'static str,
        message: String,
    ) -> crate::diag::Diagnostic {
        crate::diag::Diagnostic {
            severity,
            code,
            file: file.display().to_string(),
            location: self.location(),
            message,
            notes: Vec::new(),
        }
    }
}

impl SlaveSection {
    /// A section that gives only its device file: every other key absent.
    pub fn new(
        name: String,
        spot: Spot,
        dcf: At<String>,
        device_file: PathBuf,
        device: Box<Device>,
    ) -> Self {
        SlaveSection {
            name,
            spot,
            dcf,
            device_file,
            device,
            node_id: None,
            dcf_path: None,
            revision_number: None,
            serial_number: None,
            time_cob_id: None,
            heartbeat_multiplier: None,
            heartbeat_consumer: None,
            heartbeat_producer: None,
            retry_factor: None,
            guard_time: None,
            life_time_factor: None,
            error_behavior: BTreeMap::new(),
            rpdo: BTreeMap::new(),
            tpdo: BTreeMap::new(),
            boot: None,
            mandatory: None,
            reset_communication: None,
            software_file: None,
            software_version: None,
            configuration_file: None,
            restore_configuration: None,
            sdo: Vec::new(),
        }
    }
}
