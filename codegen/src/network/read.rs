//! A bus file's tree → [`Bus`]: `options:`, `master:` and each slave with
//! typed values (dcfgen's keys and ranges), the keys dcfgen does not use
//! kept in [`Bus::extra_keys`], and each slave's device file read with the
//! project's readers.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::diag::Diagnostics;
use crate::ir::Device;
use crate::read::Options;

use super::expand::{self, SlaveSource};
use super::model::{Bus, BusOptions, ExtraKey, MasterSection, SlaveSection, Spot};
use super::pdo;
use super::values::{Ctx, Entry, at};
use super::yaml::Node;

/// How long an extra key's value text may get.
const EXTRA_VALUE_MAX: usize = 200;

/// What reading the device files gave.
pub(crate) struct Devices<'o> {
    /// The bus file's directory: device paths are relative to it.
    pub dir: &'o Path,
    pub options: &'o Options,
    /// Each device file once: its device, or why it gave none.
    cache: BTreeMap<PathBuf, Result<Device, String>>,
    /// The device files' own diagnostics.
    pub diagnostics: Diagnostics,
    /// Every file read, in order, each once.
    pub files: Vec<PathBuf>,
}

impl<'o> Devices<'o> {
    pub fn new(dir: &'o Path, options: &'o Options) -> Self {
        Devices {
            dir,
            options,
            cache: BTreeMap::new(),
            diagnostics: Diagnostics::new(),
            files: Vec::new(),
        }
    }

    /// The device of `path`, read on first use (its diagnostics kept).
    /// `Err` is why a file that gave no device gave none: its first error,
    /// which then stands for its diagnostics.
    fn get(&mut self, path: &Path) -> Result<Device, String> {
        if !self.cache.contains_key(path) {
            let loaded = crate::input::read_device(path, self.options);
            for file in &loaded.files {
                if !self.files.contains(file) {
                    self.files.push(file.clone());
                }
            }
            match loaded.device {
                Some(device) => {
                    self.diagnostics.extend(loaded.diagnostics);
                    self.cache.insert(path.to_path_buf(), Ok(device));
                }
                None => {
                    let why = loaded
                        .diagnostics
                        .iter()
                        .find(|d| d.severity == crate::diag::Severity::Error)
                        .map_or("it gives no device".into(), |d| {
                            let m = d.message.as_str();
                            m.strip_prefix("cannot read the file: ")
                                .unwrap_or(m)
                                .to_string()
                        });
                    self.cache.insert(path.to_path_buf(), Err(why));
                }
            }
        }
        match self.cache.get(path) {
            Some(Ok(device)) => Ok(device.clone()),
            Some(Err(why)) => Err(why.clone()),
            None => Err("it gives no device".into()),
        }
    }
}

/// Reads the whole tree; `None` when its top level is not a map.
pub(crate) fn bus(ctx: &mut Ctx, root: &Node, file: &Path, devices: &mut Devices) -> Option<Bus> {
    let layout = expand::layout(ctx, root)?;
    let mut extra_keys = Vec::new();
    let options = match &layout.options {
        Some(e) => bus_options(ctx, e, &mut extra_keys),
        None => BusOptions::default(),
    };
    let master = match &layout.master {
        Some(e) => master(ctx, e, &options, &mut extra_keys),
        None => {
            ctx.error(
                "net::missing-key",
                crate::table::At::line(1),
                "master",
                "the bus file has no `master:` section, which dcfgen needs (write at least \
                 `master: {node_id: 1}`)"
                    .into(),
            );
            MasterSection {
                heartbeat_multiplier: options.heartbeat_multiplier,
                ..MasterSection::default()
            }
        }
    };
    let slaves = layout
        .slaves
        .iter()
        .filter_map(|s| slave(ctx, s, devices, &mut extra_keys))
        .collect();
    Some(Bus {
        file: file.to_path_buf(),
        options,
        master,
        slaves,
        extra_keys,
    })
}

fn extra(section: &str, e: &Entry) -> ExtraKey {
    ExtraKey {
        section: section.to_string(),
        key: e.key.clone(),
        value: e.value.brief(EXTRA_VALUE_MAX),
        spot: e.spot(),
    }
}

fn bus_options(ctx: &mut Ctx, section: &Entry, extra_keys: &mut Vec<ExtraKey>) -> BusOptions {
    let mut options = BusOptions::default();
    for e in ctx.entries(section.value, "options").unwrap_or_default() {
        let (node, path) = (e.value, e.path.as_str());
        match e.key.as_str() {
            "dcf_path" => {
                if let Some(v) = ctx.text(node, path) {
                    options.dcf_path = v;
                }
            }
            "heartbeat_multiplier" => {
                if let Some(v) = ctx.float(node, path) {
                    options.heartbeat_multiplier = v;
                }
            }
            "retry_factor" => {
                if let Some(v) = ctx.unsigned(node, path) {
                    options.retry_factor = v;
                }
            }
            _ => extra_keys.push(extra("options", &e)),
        }
    }
    options
}

/// Sets `$field` from an entry with `$read`, when it reads.
macro_rules! set {
    ($target:expr, $read:expr) => {
        if let Some(v) = $read {
            $target = v;
        }
    };
}

fn master(
    ctx: &mut Ctx,
    section: &Entry,
    options: &BusOptions,
    extra_keys: &mut Vec<ExtraKey>,
) -> MasterSection {
    let mut m = MasterSection {
        spot: section.spot(),
        heartbeat_multiplier: options.heartbeat_multiplier,
        ..MasterSection::default()
    };
    for e in ctx.entries(section.value, "master").unwrap_or_default() {
        let (node, path) = (e.value, e.path.as_str());
        let known = match e.key.as_str() {
            "node_id" => {
                set!(m.node_id, ctx.ranged(node, path, 1, 127, "net::node-id"));
                true
            }
            "baudrate" => {
                set!(m.baudrate, ctx.unsigned(node, path));
                true
            }
            "vendor_id" => {
                set!(m.vendor_id, ctx.unsigned(node, path));
                true
            }
            "product_code" => {
                set!(m.product_code, ctx.unsigned(node, path));
                true
            }
            "revision_number" => {
                set!(m.revision_number, ctx.unsigned(node, path));
                true
            }
            "serial_number" => {
                set!(m.serial_number, ctx.unsigned(node, path));
                true
            }
            "sync_period" => {
                set!(m.sync_period, ctx.unsigned(node, path));
                true
            }
            "sync_window" => {
                set!(m.sync_window, ctx.unsigned(node, path));
                true
            }
            "sync_overflow" => {
                set!(m.sync_overflow, ctx.unsigned(node, path));
                true
            }
            "time_cob_id" => {
                set!(m.time_cob_id, ctx.unsigned(node, path));
                true
            }
            "emcy_inhibit_time" => {
                set!(m.emcy_inhibit_time, ctx.unsigned(node, path));
                true
            }
            "heartbeat_multiplier" => {
                set!(m.heartbeat_multiplier, ctx.float(node, path));
                true
            }
            "heartbeat_consumer" => {
                set!(m.heartbeat_consumer, ctx.truthy(node, path));
                true
            }
            "heartbeat_producer" => {
                set!(m.heartbeat_producer, ctx.unsigned(node, path));
                true
            }
            "error_behavior" => {
                // dcfgen updates its default {1: 0} with the file's.
                for (sub, value) in pdo::error_behavior(ctx, &e) {
                    m.error_behavior.insert(sub, value.value);
                }
                true
            }
            "nmt_inhibit_time" => {
                set!(m.nmt_inhibit_time, ctx.unsigned(node, path));
                true
            }
            "start" => {
                set!(m.start, ctx.int_flag(node, path));
                true
            }
            "start_nodes" => {
                set!(m.start_nodes, ctx.int_flag(node, path));
                true
            }
            "start_all_nodes" => {
                set!(m.start_all_nodes, ctx.int_flag(node, path));
                true
            }
            "reset_all_nodes" => {
                set!(m.reset_all_nodes, ctx.int_flag(node, path));
                true
            }
            "stop_all_nodes" => {
                set!(m.stop_all_nodes, ctx.int_flag(node, path));
                true
            }
            "boot_time" => {
                set!(m.boot_time, ctx.unsigned(node, path));
                true
            }
            _ => false,
        };
        if known {
            m.spots.insert(e.key.clone(), e.spot());
        } else {
            extra_keys.push(extra("master", &e));
        }
    }
    m
}

/// One slave; `None` (with an error) when it has no readable device file.
fn slave(
    ctx: &mut Ctx,
    source: &SlaveSource,
    devices: &mut Devices,
    extra_keys: &mut Vec<ExtraKey>,
) -> Option<SlaveSection> {
    let name = source.name.as_str();
    let spot = Spot {
        line: source.key_node.at.line,
        key: name.to_string(),
    };
    let mut s = SlaveSection {
        ..SlaveSection::new(
            name.to_string(),
            spot,
            at(String::new(), &source_entry(source)),
            PathBuf::new(),
            Box::default(),
        )
    };
    let mut dcf: Option<(String, Entry)> = None;
    let mut dcf_written = false;
    for e in &source.entries {
        let (node, path) = (e.value, e.path.as_str());
        match e.key.as_str() {
            "dcf" => {
                dcf_written = true;
                dcf = ctx.text(node, path).map(|d| (d, e.clone()));
            }
            "node_id" => {
                s.node_id = ctx
                    .ranged(node, path, 1, 127, "net::node-id")
                    .map(|v| at(v, e))
            }
            "dcf_path" => s.dcf_path = ctx.text(node, path).map(|v| at(v, e)),
            "revision_number" => s.revision_number = ctx.unsigned(node, path).map(|v| at(v, e)),
            "serial_number" => s.serial_number = ctx.unsigned(node, path).map(|v| at(v, e)),
            "time_cob_id" => s.time_cob_id = ctx.unsigned(node, path).map(|v| at(v, e)),
            "heartbeat_multiplier" => {
                s.heartbeat_multiplier = ctx.float(node, path).map(|v| at(v, e));
            }
            "heartbeat_consumer" => s.heartbeat_consumer = ctx.truthy(node, path).map(|v| at(v, e)),
            "heartbeat_producer" => {
                s.heartbeat_producer = ctx.unsigned(node, path).map(|v| at(v, e));
            }
            "retry_factor" => s.retry_factor = ctx.unsigned(node, path).map(|v| at(v, e)),
            "guard_time" => s.guard_time = ctx.unsigned(node, path).map(|v| at(v, e)),
            "life_time_factor" => s.life_time_factor = ctx.unsigned(node, path).map(|v| at(v, e)),
            "error_behavior" => s.error_behavior = pdo::error_behavior(ctx, e),
            "rpdo" => s.rpdo = pdo::pdos(ctx, e),
            "tpdo" => s.tpdo = pdo::pdos(ctx, e),
            "boot" => s.boot = ctx.truthy(node, path).map(|v| at(v, e)),
            "mandatory" => s.mandatory = ctx.truthy(node, path).map(|v| at(v, e)),
            "reset_communication" => {
                s.reset_communication = ctx.truthy(node, path).map(|v| at(v, e));
            }
            "software_file" => s.software_file = ctx.text(node, path).map(|v| at(v, e)),
            "software_version" => s.software_version = ctx.unsigned(node, path).map(|v| at(v, e)),
            "configuration_file" => s.configuration_file = ctx.text(node, path).map(|v| at(v, e)),
            "restore_configuration" => {
                s.restore_configuration = ctx.unsigned(node, path).map(|v| at(v, e));
            }
            "sdo" => s.sdo = pdo::sdo(ctx, e),
            _ => extra_keys.push(extra(name, e)),
        }
    }
    let Some((dcf, entry)) = dcf else {
        if !dcf_written {
            ctx.error(
                "net::missing-key",
                source.key_node.at,
                name,
                "the slave has no `dcf:` (its device file: EDS, DCF or YAML table), which dcfgen \
                 needs"
                    .into(),
            );
        }
        return None;
    };
    let path = devices.dir.join(&dcf);
    match devices.get(&path) {
        Ok(device) => s.device = Box::new(device),
        Err(why) => {
            ctx.error(
                "net::device-file",
                entry.value.at,
                &entry.path,
                format!("cannot read the device file {}: {why}", path.display()),
            );
            return None;
        }
    }
    s.dcf = at(dcf, &entry);
    s.device_file = path;
    Some(s)
}

/// The slave's own key as an entry, for the spot of a value not written.
fn source_entry<'n>(source: &SlaveSource<'n>) -> Entry<'n> {
    Entry {
        key: source.name.clone(),
        key_node: source.key_node,
        value: source.key_node,
        path: source.name.clone(),
    }
}
