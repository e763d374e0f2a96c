//! A network from its bus file: read ([`crate::network::read_file`]),
//! configured ([`crate::network::config::configure`]), then one file per
//! node (its device generated as today, its `pdo` module made from the
//! network's mappings) and a top file with the `network` module.

use std::path::{Path, PathBuf};

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::r#gen::rust::network::{self as gen_network, Master, Network, NodeInput, NodePdo};
use crate::r#gen::rust::{self, Options, check_runtime_path};
use crate::ir::{Origin, PdoDirection};
use crate::network::config::{Configured, Node};
use crate::network::configured::configured_device;
use crate::network::model::{Bus, SlaveSection};
use crate::network::{boot_plan, configure};

/// What generating one network produced.
#[derive(Debug, Clone)]
pub struct GeneratedNetwork {
    /// The files to write, relative to the output directory (`NAME.rs`,
    /// then `NAME/<node>.rs` per node), with the warnings; or every
    /// diagnostic, at least one an error.
    pub result: Result<(Vec<(PathBuf, String)>, Diagnostics), Diagnostics>,
    /// Every file read (or tried): the bus file and each device file.
    pub files: Vec<PathBuf>,
}

/// Reads the bus file `bus_file`, configures it and generates the network
/// `name` (its top file is `NAME.rs`, including `NAME/<node>.rs`). Errors
/// of the bus file, of configuring it and of each node's generation come
/// back together; `read.levels` and `read.strict` (or `options.strict`)
/// apply to all of them.
pub fn generate_network(
    name: &str,
    bus_file: &Path,
    options: &Options,
    read: &crate::read::Options,
) -> GeneratedNetwork {
    let loaded = crate::network::read_file(bus_file, read);
    let mut diagnostics = loaded.diagnostics;
    let result = match &loaded.bus {
        Some(bus) if !diagnostics.has_errors() => {
            let (result, found) = generate_bus(name, bus, options);
            diagnostics.extend(found);
            result
        }
        _ => None,
    };
    GeneratedNetwork {
        result: finish(result, diagnostics, bus_file, options, read),
        files: loaded.files,
    }
}

/// [`generate_network`] of a bus already read: the files (`None` when
/// there is an error) and the diagnostics of configuring and generating
/// (no levels applied).
pub fn generate_bus(
    name: &str,
    bus: &Bus,
    options: &Options,
) -> (Option<Vec<(PathBuf, String)>>, Diagnostics) {
    let (configured, mut diagnostics) = configure(bus);
    if diagnostics.has_errors() {
        return (None, diagnostics);
    }
    let files = generate_configured(name, bus, &configured, options, &mut diagnostics);
    (files, diagnostics)
}

/// The result of a network: its levels applied, an error when nothing
/// came out.
#[allow(clippy::type_complexity)]
fn finish(
    files: Option<Vec<(PathBuf, String)>>,
    mut diagnostics: Diagnostics,
    bus_file: &Path,
    options: &Options,
    read: &crate::read::Options,
) -> Result<(Vec<(PathBuf, String)>, Diagnostics), Diagnostics> {
    diagnostics.apply_levels(&read.levels, options.strict || read.strict);
    diagnostics.sort();
    match files {
        Some(files) if !diagnostics.has_errors() => Ok((files, diagnostics)),
        _ => {
            if !diagnostics.has_errors() {
                diagnostics.push(error_at(
                    "build::no-device",
                    bus_file,
                    None,
                    "no network could be generated from this bus file".into(),
                ));
            }
            Err(diagnostics)
        }
    }
}

fn generate_configured(
    name: &str,
    bus: &Bus,
    configured: &Configured,
    options: &Options,
    diagnostics: &mut Diagnostics,
) -> Option<Vec<(PathBuf, String)>> {
    let nodes = &configured.nodes;
    let runtime = match check_runtime_path(&options.runtime_path) {
        Ok(runtime) => runtime,
        Err(problem) => {
            diagnostics.push(error_at(
                "gen::runtime-path",
                &bus.file,
                None,
                format!("runtime path `{}` {problem}", options.runtime_path),
            ));
            return None;
        }
    };
    let source = bus.file.display().to_string();
    let keys: Vec<(&str, u8, Origin)> = nodes
        .iter()
        .map(|n| {
            let line = bus.slaves.get(n.slave).map_or(0, |s| s.spot.line);
            let origin = Origin {
                file: source.clone(),
                line,
            };
            (n.name.as_str(), n.node_id, origin)
        })
        .collect();
    let modules = gen_network::module_names(&keys, diagnostics);
    let lenient = Options {
        strict: false,
        ..options.clone()
    };
    let mut files = vec![(PathBuf::from(format!("{name}.rs")), String::new())];
    let mut inputs = Vec::new();
    for (node, module) in nodes.iter().zip(modules) {
        let Some(slave) = bus.slaves.get(node.slave) else {
            continue;
        };
        let configured = configured_device(&slave.device, node);
        let (output, emitted) = match rust::generate_node(&slave.device, &configured, &lenient) {
            Ok(generated) => generated,
            Err(errors) => {
                diagnostics.extend(errors);
                continue;
            }
        };
        diagnostics.extend(output.warnings);
        let mut pdos = Vec::new();
        for (direction, pdo) in node
            .rpdos
            .iter()
            .map(|p| (PdoDirection::Rpdo, p))
            .chain(node.tpdos.iter().map(|p| (PdoDirection::Tpdo, p)))
        {
            match emitted
                .iter()
                .find(|e| e.direction == direction && e.number == pdo.number)
            {
                Some(e) => pdos.push(NodePdo {
                    pdo: e.clone(),
                    cob_id: pdo.can_id().0,
                    transmission: pdo.transmission,
                }),
                None => diagnostics.push(error_at(
                    "net::pdo-not-generated",
                    &bus.file,
                    Some(pdo.spot.as_ref().map_or(&slave.spot, |s| s)),
                    format!(
                        "{} {direction:?}{} gets no generated struct (the warning of \
                         its device file says why), so the typed network would lack it",
                        node.name, pdo.number
                    )
                    .replace("Rpdo", "RPDO")
                    .replace("Tpdo", "TPDO"),
                )),
            }
        }
        files.push((PathBuf::from(format!("{name}/{module}.rs")), output.code));
        inputs.push(node_input(node, slave, module, pdos));
    }
    if diagnostics.has_errors() {
        return None;
    }
    let plan = boot_plan(bus, configured);
    let network = Network {
        source: &source,
        dir: name,
        master: Master {
            node_id: bus.master.node_id,
            bit_rate_kbit: bus.master.baudrate,
            sync_period_us: bus.master.sync_period,
            sync_window_us: bus.master.sync_window,
            heartbeat_producer_ms: bus.master.heartbeat_producer,
        },
        nodes: inputs,
        plan: &plan,
    };
    match gen_network::generate(&network, &runtime) {
        Ok(code) => files[0].1 = code,
        Err(err) => {
            diagnostics.push(error_at(
                "gen::internal",
                &bus.file,
                None,
                format!("the generator produced invalid Rust (a bug in eds2rust): {err}"),
            ));
            return None;
        }
    }
    Some(files)
}

fn node_input<'a>(
    node: &'a Node,
    slave: &'a SlaveSection,
    module: String,
    pdos: Vec<NodePdo>,
) -> NodeInput<'a> {
    NodeInput {
        name: &node.name,
        module,
        node_id: node.node_id,
        vendor_id: node.vendor_id,
        product_code: node.product_code,
        revision_number: node.revision_number,
        serial_number: node.serial_number,
        heartbeat_producer_ms: node.heartbeat_producer,
        product_name: slave.device.identity.product_name.as_deref(),
        device_file: slave.dcf.value.clone(),
        pdos,
    }
}

fn error_at(
    code: &'static str,
    file: &Path,
    spot: Option<&crate::network::model::Spot>,
    message: String,
) -> Diagnostic {
    Diagnostic {
        severity: Severity::Error,
        code,
        file: file.display().to_string(),
        location: Location {
            line: spot.map(|s| s.line).filter(|&l| l > 0),
            key: spot.map(|s| s.key.clone()).filter(|k| !k.is_empty()),
            ..Location::default()
        },
        message,
        notes: Vec::new(),
    }
}
