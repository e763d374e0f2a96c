//! `od upload` (a live node's values into a DCF, written by the library's
//! EDS writer) and `od download` (a DCF's ParameterValues back into a
//! node, in the CiA 301 order that keeps PDOs consistent, each read back).

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use eds2rust::ir::{Commissioning, DataType, Literal, ObjectKind};
use eds2rust_runtime::blocking::{self, Master};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::SdoError;

use super::bus::{self, LiveBus, Opener};
use super::od::Od;
use super::sdo::transfer_error;
use super::values::{self, Decoded};
use super::{BusArgs, LiveError, node_arg};

#[derive(Args, Debug)]
pub struct UploadArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// The node to read.
    #[arg(long, short = 'n', value_parser = node_arg)]
    pub node: u8,
    /// The node's object dictionary (EDS, DCF or YAML table): which
    /// objects to read, and their types.
    #[arg(long, value_name = "FILE")]
    pub od: PathBuf,
    /// Write the DCF here (replaced only when complete) instead of stdout.
    #[arg(long, short)]
    pub output: Option<PathBuf>,
    /// Read DOMAIN entries too (skipped by default: they can be large).
    #[arg(long)]
    pub domains: bool,
}

#[derive(Args, Debug)]
pub struct DownloadArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    /// The node to write (default: the DCF's [DeviceComissioning] NodeID).
    #[arg(long, short = 'n', value_parser = node_arg)]
    pub node: Option<u8>,
    /// Print the writes in their order; touch no bus.
    #[arg(long)]
    pub dry_run: bool,
    /// Also list the entries skipped (read-only, const, no value).
    #[arg(long, short)]
    pub verbose: bool,
    /// The DCF (or EDS/YAML with ParameterValues) to download.
    #[arg(value_name = "DCF")]
    pub dcf: PathBuf,
}

/// Timeouts in a row after which `od upload` takes the node for gone.
const MAX_TIMEOUTS: usize = 3;

/// Whether `index` is a PDO communication or mapping parameter.
fn pdo_object(index: u16) -> bool {
    (0x1400..=0x1BFF).contains(&index)
}

/// Objects that are commands, not configuration: never downloaded.
fn command_object(index: u16) -> Option<&'static str> {
    match index {
        0x1010 => Some("store parameters (a command)"),
        0x1011 => Some("restore default parameters (a command)"),
        0x1F50..=0x1F5F => Some("program download (a command)"),
        _ => None,
    }
}

pub fn upload(open: impl Opener, a: &UploadArgs, out: &mut dyn Write) -> Result<(), LiveError> {
    let od = Od::load(&a.od)?;
    let node = bus::node_id(a.node)?;
    let mut device = od.device.clone();
    let mut wanted = Vec::new();
    let (mut write_only, mut domains) = (0, 0);
    for object in device.objects.values() {
        if object.index < 0x1000
            || matches!(object.kind, ObjectKind::DefType | ObjectKind::DefStruct)
        {
            continue;
        }
        for entry in object.entries.values() {
            if !entry.access.is_readable() {
                write_only += 1;
            } else if entry.data_type == DataType::Domain && !a.domains {
                domains += 1;
            } else {
                wanted.push((object.index, entry.subindex));
            }
        }
    }
    let mut m = bus::sdo_master(open()?, node, a.bus.timeout);
    let bar = bus::bar(wanted.len() as u64, false);
    bar.set_message(format!("node {} upload", node.get()));
    let mut failed = Vec::new();
    let mut read = 0usize;
    let mut timeouts_in_a_row = 0;
    for (i, &(index, sub)) in wanted.iter().enumerate() {
        bar.set_position(i as u64);
        let label = od.label(index, sub);
        let data = match m.upload(node, index, sub) {
            Ok(data) => {
                timeouts_in_a_row = 0;
                data
            }
            Err(e) => {
                let timeout = matches!(
                    e,
                    blocking::Error::Sdo {
                        error: SdoError::Timeout,
                        ..
                    }
                );
                timeouts_in_a_row = if timeout { timeouts_in_a_row + 1 } else { 0 };
                let err = transfer_error(node, &label, "read", &e, a.bus.timeout);
                // A node that does not answer at all, or no longer: no DCF.
                if timeout && (read == 0 || timeouts_in_a_row >= MAX_TIMEOUTS)
                    || matches!(e, blocking::Error::Io(_))
                {
                    bar.finish_and_clear();
                    return Err(err);
                }
                failed.push(err.to_string());
                continue;
            }
        };
        let Some((_, entry)) = od.entry(index, sub) else {
            continue;
        };
        let node_relative = entry.node_relative();
        let default_offset = entry.default.as_ref().map(|l| &l.value);
        match values::decode(entry.data_type, &data) {
            Ok((value, _)) => {
                let mut literal = Literal {
                    value: values::to_ir(&value),
                    plus_node_id: false,
                    text: values::plain(&value),
                };
                // A value that is still its `$NODEID` default stays one, so
                // the DCF goes to another node id as well.
                if let (true, Decoded::Int(v), Some(eds2rust::ir::Value::Integer(off))) =
                    (node_relative, &value, default_offset)
                    && *v == off + i128::from(node.get())
                {
                    literal.value = eds2rust::ir::Value::Integer(*off);
                    literal.plus_node_id = true;
                }
                if let Some(e) = device
                    .objects
                    .get_mut(&index)
                    .and_then(|o| o.entries.get_mut(&sub))
                {
                    e.parameter_value = Some(literal);
                }
                read += 1;
            }
            Err(why) => failed.push(format!("node {}, {label}: {why}", node.get())),
        }
    }
    bar.finish_and_clear();
    let commissioning = device
        .commissioning
        .get_or_insert_with(Commissioning::default);
    commissioning.node_id = Some(node.get());
    let text = eds2rust::r#gen::to_eds(&device);
    match &a.output {
        None => out.write_all(text.as_bytes())?,
        Some(path) => eds2rust::build::write_whole(path, text.as_bytes())
            .map_err(|e| LiveError::Failed(format!("cannot write {}: {e}", path.display())))?,
    }
    for f in &failed {
        eprintln!("error: {f}");
    }
    let mut skipped = String::new();
    if write_only > 0 {
        skipped.push_str(&format!(", {write_only} write-only skipped"));
    }
    if domains > 0 {
        skipped.push_str(&format!(
            ", {domains} DOMAIN skipped (--domains reads them)"
        ));
    }
    let summary = format!(
        "node {}: {read} entries read, {} failed{skipped}{}",
        node.get(),
        failed.len(),
        a.output
            .as_ref()
            .map(|p| format!("; written to {}", p.display()))
            .unwrap_or_default()
    );
    if failed.is_empty() {
        eprintln!("{summary}");
        Ok(())
    } else {
        Err(LiveError::Failed(summary))
    }
}

/// One step of a download.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// Sets bit 31 (not valid) of the PDO's COB-ID (sub 1 of `comm`) as the
    /// node has it now, unless it is set already.
    Disable { comm: u16 },
    /// Writes `data`; `check` reads it back and reports it.
    Write {
        index: u16,
        sub: u8,
        data: Vec<u8>,
        value: Decoded,
        check: bool,
        why: &'static str,
    },
    /// Restores the COB-ID read by the `Disable` of `comm` (the DCF has
    /// none for it).
    Restore { comm: u16 },
}

/// The steps of a download, and the entries skipped with why.
pub struct Plan {
    pub steps: Vec<Step>,
    pub skipped: Vec<(u16, u8, String)>,
}

/// The DCF's values in a safe order: communication parameters (not PDOs),
/// then each PDO disabled, its parameters, its mapping (count 0, the
/// entries, the count) and its COB-ID (enabling it as the DCF says), then
/// manufacturer (0x2000–0x5FFF) and profile (0x6000–) parameters.
pub fn plan(od: &Od, node: NodeId) -> Result<Plan, LiveError> {
    let mut skipped = Vec::new();
    let mut values: Vec<(u16, u8, Vec<u8>, Decoded)> = Vec::new();
    for object in od.device.objects.values() {
        if object.index < 0x1000 {
            continue;
        }
        for entry in object.entries.values() {
            let (index, sub) = (object.index, entry.subindex);
            let Some(literal) = &entry.parameter_value else {
                skipped.push((index, sub, "no ParameterValue".into()));
                continue;
            };
            if let Some(why) = command_object(index) {
                skipped.push((index, sub, why.into()));
                continue;
            }
            if !entry.access.is_writable() {
                skipped.push((index, sub, format!("{} entry", entry.access.as_str())));
                continue;
            }
            let value = values::from_ir(&literal.resolve(Some(node.get())));
            let data = values::encode(entry.data_type, &value).map_err(|why| {
                LiveError::Usage(format!(
                    "{}: ParameterValue {}: {why}",
                    od.label(index, sub),
                    literal.text
                ))
            })?;
            values.push((index, sub, data, value));
        }
    }
    let write = |(index, sub, data, value): &(u16, u8, Vec<u8>, Decoded), check, why| Step::Write {
        index: *index,
        sub: *sub,
        data: data.clone(),
        value: value.clone(),
        check,
        why,
    };
    let mut steps = Vec::new();
    for v in values.iter().filter(|v| v.0 < 0x2000 && !pdo_object(v.0)) {
        steps.push(write(v, true, ""));
    }
    // PDOs: RPDOs 0x1400/0x1600, TPDOs 0x1800/0x1A00, by number.
    for base in [0x1400u16, 0x1800] {
        for n in 0..0x200u16 {
            let (comm, map) = (base + n, base + 0x200 + n);
            let ours = |i: u16| values.iter().filter(move |v| v.0 == i);
            if ours(comm).next().is_none() && ours(map).next().is_none() {
                continue;
            }
            let has_cob_id = od.entry(comm, 1).is_some();
            if has_cob_id {
                steps.push(Step::Disable { comm });
            }
            for v in ours(comm).filter(|v| v.1 != 1) {
                steps.push(write(v, true, ""));
            }
            let count = ours(map).find(|v| v.1 == 0);
            if count.is_some() {
                let zero = (map, 0, vec![0], Decoded::Int(0));
                steps.push(write(&zero, false, "mapping off"));
            }
            for v in ours(map).filter(|v| v.1 != 0) {
                steps.push(write(v, true, ""));
            }
            if let Some(count) = count {
                steps.push(write(count, true, ""));
            }
            match ours(comm).find(|v| v.1 == 1) {
                Some(cob) => steps.push(write(cob, true, "")),
                None if has_cob_id => steps.push(Step::Restore { comm }),
                None => {}
            }
        }
    }
    for v in values.iter().filter(|v| v.0 >= 0x2000) {
        steps.push(write(v, true, ""));
    }
    Ok(Plan { steps, skipped })
}

/// The node of a download: `--node`, else the DCF's NodeID.
fn download_node(a: &DownloadArgs, od: &Od) -> Result<NodeId, LiveError> {
    let from_dcf = od.device.commissioning.as_ref().and_then(|c| c.node_id);
    match a.node.or(from_dcf) {
        Some(n) => bus::node_id(n),
        None => Err(LiveError::Usage(format!(
            "{} names no node ([DeviceComissioning] NodeID): give --node",
            a.dcf.display()
        ))),
    }
}

fn describe(od: &Od, index: u16, sub: u8, value: &Decoded) -> String {
    match od.entry(index, sub) {
        Some((_, e)) => values::describe(e.data_type, &e.semantics, value),
        None => values::plain(value),
    }
}

pub fn download_plan(a: &DownloadArgs, out: &mut dyn Write) -> Result<(), LiveError> {
    let od = Od::load(&a.dcf)?;
    let node = download_node(a, &od)?;
    let plan = plan(&od, node)?;
    writeln!(
        out,
        "download to node {} ({} steps):",
        node.get(),
        plan.steps.len()
    )?;
    for step in &plan.steps {
        match step {
            Step::Disable { comm } => {
                writeln!(out, "  disable PDO: set bit 31 of {}", od.label(*comm, 1))?
            }
            Step::Restore { comm } => writeln!(out, "  restore {} as it was", od.label(*comm, 1))?,
            Step::Write {
                index,
                sub,
                value,
                why,
                ..
            } => {
                let note = if why.is_empty() {
                    String::new()
                } else {
                    format!(" ({why})")
                };
                writeln!(
                    out,
                    "  write {} := {}{note}",
                    od.label(*index, *sub),
                    describe(&od, *index, *sub, value)
                )?;
            }
        }
    }
    if a.verbose {
        for (index, sub, why) in &plan.skipped {
            writeln!(out, "  skip {}: {why}", od.label(*index, *sub))?;
        }
    }
    writeln!(out, "{} entries skipped", plan.skipped.len())?;
    Ok(())
}

/// Per-entry outcome counts.
#[derive(Default)]
struct Tally {
    equal: usize,
    differed: usize,
    refused: usize,
    unchecked: usize,
}

pub fn download(open: impl Opener, a: &DownloadArgs, out: &mut dyn Write) -> Result<(), LiveError> {
    let od = Od::load(&a.dcf)?;
    let node = download_node(a, &od)?;
    let plan = plan(&od, node)?;
    let mut m = bus::sdo_master(open()?, node, a.bus.timeout);
    let bar = bus::bar(plan.steps.len() as u64, false);
    bar.set_message(format!("node {} download", node.get()));
    let mut tally = Tally::default();
    let mut cob_ids: Vec<(u16, Vec<u8>)> = Vec::new();
    let mut lines = Vec::new();
    let result = run_steps(
        &mut m,
        &od,
        node,
        a,
        &plan,
        &bar,
        &mut tally,
        &mut cob_ids,
        &mut lines,
    );
    bar.finish_and_clear();
    for line in &lines {
        writeln!(out, "{line}")?;
    }
    if a.verbose {
        for (index, sub, why) in &plan.skipped {
            writeln!(out, "{}: skipped ({why})", od.label(*index, *sub))?;
        }
    }
    result?;
    let summary = format!(
        "node {}: {} written: {} equal on read-back, {} differed, {} refused, {} not read back; {} skipped",
        node.get(),
        tally.equal + tally.differed + tally.unchecked,
        tally.equal,
        tally.differed,
        tally.refused,
        tally.unchecked,
        plan.skipped.len()
    );
    writeln!(out, "{summary}")?;
    if tally.differed + tally.refused > 0 {
        return Err(LiveError::Failed(format!(
            "node {}: {} entries differed, {} were refused",
            node.get(),
            tally.differed,
            tally.refused
        )));
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn run_steps(
    m: &mut Master<LiveBus>,
    od: &Od,
    node: NodeId,
    a: &DownloadArgs,
    plan: &Plan,
    bar: &indicatif::ProgressBar,
    tally: &mut Tally,
    cob_ids: &mut Vec<(u16, Vec<u8>)>,
    lines: &mut Vec<String>,
) -> Result<(), LiveError> {
    let stop = |e: &blocking::Error| {
        matches!(
            e,
            blocking::Error::Sdo {
                error: SdoError::Timeout,
                ..
            } | blocking::Error::Io(_)
        )
    };
    for (i, step) in plan.steps.iter().enumerate() {
        bar.set_position(i as u64);
        match step {
            Step::Disable { comm } => {
                let label = od.label(*comm, 1);
                let now = m
                    .upload(node, *comm, 1)
                    .map_err(|e| transfer_error(node, &label, "read", &e, a.bus.timeout))?;
                cob_ids.push((*comm, now.clone()));
                let Some(mut cob) = now.get(..4).and_then(|b| <[u8; 4]>::try_from(b).ok()) else {
                    return Err(LiveError::Failed(format!(
                        "node {}, {label}: a COB-ID of {} bytes",
                        node.get(),
                        now.len()
                    )));
                };
                if cob[3] & 0x80 == 0 {
                    cob[3] |= 0x80;
                    if let Err(e) = m.download(node, *comm, 1, &cob) {
                        let err =
                            transfer_error(node, &label, "disabling the PDO", &e, a.bus.timeout);
                        if stop(&e) {
                            return Err(err);
                        }
                        tally.refused += 1;
                        lines.push(format!("{label}: refused disabling the PDO: {e}"));
                    }
                }
            }
            Step::Restore { comm } => {
                let label = od.label(*comm, 1);
                if let Some((_, cob)) = cob_ids.iter().find(|(c, _)| c == comm)
                    && let Err(e) = m.download(node, *comm, 1, cob)
                {
                    if stop(&e) {
                        return Err(transfer_error(node, &label, "restore", &e, a.bus.timeout));
                    }
                    tally.refused += 1;
                    lines.push(format!("{label}: refused restoring the COB-ID: {e}"));
                }
            }
            Step::Write {
                index,
                sub,
                data,
                value,
                check,
                ..
            } => {
                let (index, sub) = (*index, *sub);
                let label = od.label(index, sub);
                let shown = describe(od, index, sub, value);
                if let Err(e) = m.download(node, index, sub, data) {
                    if stop(&e) {
                        return Err(transfer_error(node, &label, "write", &e, a.bus.timeout));
                    }
                    if *check {
                        tally.refused += 1;
                        let code = match &e {
                            blocking::Error::Sdo { error: s, .. } => s.code().to_string(),
                            other => other.to_string(),
                        };
                        lines.push(format!("{label}: refused {shown}: {code}"));
                    }
                    continue;
                }
                if !*check {
                    continue;
                }
                let Some((_, entry)) = od.entry(index, sub) else {
                    continue;
                };
                if !entry.access.is_readable() {
                    tally.unchecked += 1;
                    lines.push(format!(
                        "{label}: written {shown} (write-only, not read back)"
                    ));
                    continue;
                }
                let back = m
                    .upload(node, index, sub)
                    .map_err(|e| transfer_error(node, &label, "read-back", &e, a.bus.timeout));
                let back = match back.map(|b| values::decode(entry.data_type, &b)) {
                    Ok(Ok((v, _))) => v,
                    Ok(Err(why)) => {
                        tally.differed += 1;
                        lines.push(format!("{label}: wrote {shown}, read back: {why}"));
                        continue;
                    }
                    Err(e) => return Err(e),
                };
                // Compared on the wire: a REAL32 read back is the f32 of the
                // DCF's decimal, a string without its trailing NULs.
                if values::encode(entry.data_type, &back).as_ref() == Ok(data) {
                    tally.equal += 1;
                    lines.push(format!("{label}: ok {shown}"));
                } else {
                    tally.differed += 1;
                    lines.push(format!(
                        "{label}: differs: wrote {shown}, read back {}",
                        describe(od, index, sub, &back)
                    ));
                }
            }
        }
    }
    Ok(())
}
