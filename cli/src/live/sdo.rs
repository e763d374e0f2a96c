//! `sdo read`, `sdo write` and `sdo download-file`.

use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;

use clap::Args;
use eds2rust::ir::{DataType, Semantics};
use eds2rust_runtime::blocking;
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::SdoError;
use eds2rust_runtime::sdo::client::Method;

use super::bus::{self, Opener};
use super::od::{self, Od};
use super::values::{self, Decoded};
use super::{BusArgs, LiveError, load_od, node_arg};

/// The bus, the node and its object dictionary: what every `sdo` command
/// starts from. Each command words the help of `--node` and `--od` its
/// own way (`mut_arg`).
#[derive(Args, Debug)]
pub struct NodeArgs {
    #[command(flatten)]
    pub bus: BusArgs,
    #[arg(long, short = 'n', value_parser = node_arg)]
    pub node: u8,
    #[arg(long, value_name = "FILE")]
    pub od: Option<PathBuf>,
}

impl NodeArgs {
    /// The object dictionary of `--od` (if any) and the node id.
    fn load(&self) -> Result<(Option<Od>, NodeId), LiveError> {
        Ok((load_od(self.od.as_ref())?, bus::node_id(self.node)?))
    }
}

#[derive(Args, Debug)]
#[command(mut_arg("node", |a| a.help("The node to read from")))]
#[command(mut_arg("od", |a| a.help(
    "The node's object dictionary (EDS, DCF or YAML table): objects by name, values by type"
)))]
pub struct ReadArgs {
    #[command(flatten)]
    pub to: NodeArgs,
    /// Decode as this type (u8..u64, i8..i64, bool, f32, f64, str,
    /// unicode, bytes); wins over the type in --od.
    #[arg(long = "type", value_name = "TYPE", value_parser = values::parse_type)]
    pub ty: Option<DataType>,
    /// Print only the values, one a line.
    #[arg(long, short = 'q')]
    pub quiet: bool,
    /// Keys (0x6041, 0x1018.1, 0x1018sub1), or with --od object names and
    /// Rust names (Statusword, identity::VendorId); a whole ARRAY/RECORD
    /// reads every sub.
    #[arg(required = true, value_name = "OBJECT")]
    pub objects: Vec<String>,
}

#[derive(Args, Debug)]
#[command(mut_arg("node", |a| a.help("The node to write to")))]
#[command(mut_arg("od", |a| a.help(
    "The node's object dictionary: objects by name, values by type, unit and named values"
)))]
pub struct WriteArgs {
    #[command(flatten)]
    pub to: NodeArgs,
    /// The value's type (needed without --od; wins over its type).
    #[arg(long = "type", value_name = "TYPE", value_parser = values::parse_type)]
    pub ty: Option<DataType>,
    /// Read the value back and fail (exit 1) when it differs.
    #[arg(long)]
    pub verify: bool,
    /// A key or (with --od) a name of one entry.
    #[arg(value_name = "OBJECT")]
    pub object: String,
    /// The value: 3, 0x7D, -5, true, 1.5, a named value ("profile
    /// position"), a value with the entry's unit (12.5mm), text, hex bytes.
    #[arg(value_name = "VALUE", allow_hyphen_values = true)]
    pub value: String,
}

#[derive(Args, Debug)]
#[command(mut_arg("node", |a| a.help("The node to download to")))]
#[command(mut_arg("od", |a| a.help("The node's object dictionary (for names)")))]
pub struct DownloadFileArgs {
    #[command(flatten)]
    pub to: NodeArgs,
    /// Use segmented instead of block transfer.
    #[arg(long)]
    pub segmented: bool,
    /// The DOMAIN entry (for a program: 0x1F50.1).
    #[arg(value_name = "OBJECT")]
    pub object: String,
    /// The file to download.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
}

/// The (index, sub) pairs of an object argument: by `--od` names and keys,
/// or a key alone (sub 0 when none is given).
pub fn targets(od: Option<&Od>, text: &str) -> Result<Vec<(u16, u8)>, LiveError> {
    match od {
        Some(od) => od.resolve(text),
        None => match od::parse_key(text)? {
            Some((index, sub)) => Ok(vec![(index, sub.unwrap_or(0))]),
            None => Err(LiveError::Usage(format!(
                "`{text}` is not a key (0x6041, 0x1018.1); names need --od FILE"
            ))),
        },
    }
}

/// The one (index, sub) pair of an object argument ([`targets`]); a usage
/// error worded by `too_many` when it names several.
fn one_target(
    od: Option<&Od>,
    text: &str,
    too_many: impl FnOnce(&[(u16, u8)]) -> String,
) -> Result<(u16, u8), LiveError> {
    match targets(od, text)?.as_slice() {
        [one] => Ok(*one),
        many => Err(LiveError::Usage(too_many(many))),
    }
}

/// How a node, an object and the transfer's error read in a message.
pub fn transfer_error(
    node: NodeId,
    label: &str,
    what: &str,
    error: &blocking::Error,
    timeout: Duration,
) -> LiveError {
    let why = match error {
        blocking::Error::Sdo {
            error: SdoError::Timeout,
            ..
        } => format!(
            "no answer within {} ms (is node {} on the bus?)",
            timeout.as_millis(),
            node.get()
        ),
        // The message names the node and the object already.
        blocking::Error::Sdo { error, .. } => error.to_string(),
        other => other.to_string(),
    };
    LiveError::Failed(format!(
        "node {}, {label}: {what} failed: {why}",
        node.get()
    ))
}

/// What an entry's value is to the printer: type and semantics.
fn typing(
    od: Option<&Od>,
    ty: Option<DataType>,
    index: u16,
    sub: u8,
) -> Option<(DataType, &Semantics)> {
    static NONE: std::sync::OnceLock<Semantics> = std::sync::OnceLock::new();
    let entry = od.and_then(|od| od.entry(index, sub)).map(|(_, e)| e);
    match (ty, entry) {
        (Some(t), Some(e)) if t == e.data_type => Some((t, &e.semantics)),
        (Some(t), _) => Some((t, NONE.get_or_init(Semantics::default))),
        (None, Some(e)) => Some((e.data_type, &e.semantics)),
        (None, None) => None,
    }
}

fn label(od: Option<&Od>, index: u16, sub: u8) -> String {
    match od {
        Some(od) => od.label(index, sub),
        None => od::key(index, sub),
    }
}

pub fn read(open: impl Opener, a: &ReadArgs, out: &mut dyn Write) -> Result<(), LiveError> {
    let (od, node) = a.to.load()?;
    let mut wanted = Vec::new();
    for text in &a.objects {
        wanted.extend(targets(od.as_ref(), text)?);
    }
    let mut m = bus::sdo_master(open()?, node, a.to.bus.timeout);
    let mut failed = Vec::new();
    for (index, sub) in wanted {
        let label = label(od.as_ref(), index, sub);
        let data = match m.upload(node, index, sub) {
            Ok(data) => data,
            Err(e) => {
                // A node that does not answer or a bus that fails ends the
                // command; an abort only this read.
                let stop = matches!(
                    e,
                    blocking::Error::Sdo {
                        error: SdoError::Timeout,
                        ..
                    } | blocking::Error::Io(_)
                );
                failed.push(transfer_error(node, &label, "read", &e, a.to.bus.timeout));
                if stop {
                    break;
                }
                continue;
            }
        };
        let text = match typing(od.as_ref(), a.ty, index, sub) {
            Some((t, sem)) => match values::decode(t, &data) {
                Ok((value, note)) => {
                    if let Some(note) = note {
                        eprintln!("warning: node {}, {label}: {note}", node.get());
                    }
                    if a.quiet {
                        values::plain(&value)
                    } else {
                        values::describe(t, sem, &value)
                    }
                }
                Err(why) => {
                    failed.push(LiveError::Failed(format!(
                        "node {}, {label}: {why}; raw {}",
                        node.get(),
                        values::hex_bytes(&data)
                    )));
                    continue;
                }
            },
            None if a.quiet => values::plain(&Decoded::Bytes(data)),
            None => values::hex_bytes(&data),
        };
        if a.quiet {
            writeln!(out, "{text}")?;
        } else {
            writeln!(out, "{label} = {text}")?;
        }
    }
    report_failures(failed)
}

/// Ok without failures; one failure as itself; several listed, then a count.
pub fn report_failures(failed: Vec<LiveError>) -> Result<(), LiveError> {
    let n = failed.len();
    let mut iter = failed.into_iter();
    match (iter.next(), n) {
        (None, _) => Ok(()),
        (Some(one), 1) => Err(one),
        (Some(first), _) => {
            eprintln!("error: {first}");
            for e in iter {
                eprintln!("error: {e}");
            }
            Err(LiveError::Failed(format!("{n} reads failed")))
        }
    }
}

pub fn write(open: impl Opener, a: &WriteArgs, out: &mut dyn Write) -> Result<(), LiveError> {
    let (od, node) = a.to.load()?;
    let (index, sub) = one_target(od.as_ref(), &a.object, |many| {
        format!(
            "`{}` names {} entries; write one at a time (e.g. {})",
            a.object,
            many.len(),
            many.get(1).map_or(String::new(), |(i, s)| od::key(*i, *s))
        )
    })?;
    let label = label(od.as_ref(), index, sub);
    if let Some((_, entry)) = od.as_ref().and_then(|od| od.entry(index, sub))
        && !entry.access.is_writable()
    {
        return Err(LiveError::Usage(format!(
            "{label} is {} ({}); not written",
            if entry.access.as_str() == "const" {
                "constant"
            } else {
                "read-only"
            },
            entry.access.as_str()
        )));
    }
    let Some((t, sem)) = typing(od.as_ref(), a.ty, index, sub) else {
        return Err(LiveError::Usage(format!(
            "the type of {label} is unknown: give --type (u8, u16, u32, i16, f32, str, bytes, ..) \
             or --od FILE"
        )));
    };
    let value = values::parse(t, sem, &a.value)
        .map_err(|why| LiveError::Usage(format!("{label}: {why}")))?;
    let data =
        values::encode(t, &value).map_err(|why| LiveError::Usage(format!("{label}: {why}")))?;
    let mut m = bus::sdo_master(open()?, node, a.to.bus.timeout);
    m.download(node, index, sub, &data)
        .map_err(|e| transfer_error(node, &label, "write", &e, a.to.bus.timeout))?;
    writeln!(out, "{label} := {}", values::describe(t, sem, &value))?;
    if a.verify {
        let back = m
            .upload(node, index, sub)
            .map_err(|e| transfer_error(node, &label, "read-back", &e, a.to.bus.timeout))?;
        let (read, _) = values::decode(t, &back).map_err(|why| {
            LiveError::Failed(format!("node {}, {label}: read-back: {why}", node.get()))
        })?;
        // Compared on the wire: a REAL32 reads back as the f32 of the
        // decimal typed, a string without trailing NULs.
        if values::encode(t, &read).as_ref() != Ok(&data) {
            return Err(LiveError::Failed(format!(
                "node {}, {label}: wrote {}, read back {}",
                node.get(),
                values::describe(t, sem, &value),
                values::describe(t, sem, &read)
            )));
        }
        writeln!(
            out,
            "{label} = {} (read back)",
            values::describe(t, sem, &read)
        )?;
    }
    Ok(())
}

pub fn download_file(
    open: impl Opener,
    a: &DownloadFileArgs,
    out: &mut dyn Write,
) -> Result<(), LiveError> {
    let (od, node) = a.to.load()?;
    let (index, sub) = one_target(od.as_ref(), &a.object, |_| {
        format!("`{}` names more than one entry", a.object)
    })?;
    let label = label(od.as_ref(), index, sub);
    let cannot_read =
        |e: std::io::Error| LiveError::Usage(format!("cannot read {}: {e}", a.file.display()));
    // The transfer announces its size first: only a regular file has one
    // (and opening a FIFO would wait for a writer).
    if !std::fs::metadata(&a.file).map_err(cannot_read)?.is_file() {
        return Err(LiveError::Usage(format!(
            "{} is not a regular file; an SDO download sends a regular file, whose size it announces first",
            a.file.display()
        )));
    }
    let mut file = std::fs::File::open(&a.file).map_err(cannot_read)?;
    let len = file.metadata().map_err(cannot_read)?.len();
    if u32::try_from(len).is_err() {
        return Err(LiveError::Usage(format!(
            "{} has {len} bytes; an SDO transfer holds at most 4 GiB",
            a.file.display(),
        )));
    }
    let mut m = bus::sdo_master(open()?, node, a.to.bus.timeout);
    let bar = bus::bar(len, true);
    bar.set_message(format!("node {} {}", node.get(), od::key(index, sub)));
    let (method, how) = if a.segmented {
        (Method::Segmented, "segmented")
    } else {
        (Method::Block, "block")
    };
    // Streamed from the file: the image is never held whole.
    let shown = bar.clone();
    let result = m.download_from(node, index, sub, &mut file, Some(len), method, move |p| {
        shown.set_position(p.done as u64)
    });
    bar.finish_and_clear();
    result.map_err(|e| {
        let mut err = transfer_error(node, &label, "download", &e, a.to.bus.timeout);
        // What a server without block transfer answers a block initiate with.
        let no_block = matches!(
            &e,
            blocking::Error::Sdo { error: SdoError::RemoteAbort(code), .. }
                if matches!(code.code(), 0x0504_0001 | 0x0504_0002 | 0x0601_0000 | 0x0800_0000)
        );
        if !a.segmented
            && no_block
            && let LiveError::Failed(m) = &mut err
        {
            m.push_str(" (if the node has no block transfer, try --segmented)");
        }
        err
    })?;
    writeln!(
        out,
        "{label}: downloaded {len} bytes from {} ({how} transfer)",
        a.file.display()
    )?;
    Ok(())
}
