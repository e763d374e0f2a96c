//! `eds2rust decode`: a recorded CAN trace as named, typed CANopen values
//! (docs/decode.md), with the `eds2rust-decode` library.

use std::fs::File;
use std::io::{self, BufRead, BufReader, BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

use clap::{Args, ValueEnum};
use eds2rust::input::Options;
use eds2rust_decode::{Decoder, Record, TraceDecodeError, render};

use crate::refusal::device_or_refuse;

/// Output forms.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OutFormat {
    /// One line per frame, transfer and bad trace line.
    Text,
    /// One JSON object per line (JSON Lines).
    Json,
}

/// The files of the nodes: `--node N=FILE`, `--overlay N=FILE`, or a bus
/// file (`--bus FILE`).
#[derive(Args, Clone)]
pub struct NodeFiles {
    /// The object dictionary of node N (1 to 127): an EDS/DCF file or a YAML
    /// table, as `N=FILE`; may be given once per node.
    #[arg(long = "node", value_name = "N=FILE", value_parser = node_file)]
    pub nodes: Vec<(u8, PathBuf)>,
    /// A YAML overlay on node N's file, as `N=FILE`; may be given several
    /// times, applied in order.
    #[arg(long = "overlay", value_name = "N=FILE", value_parser = node_file)]
    pub overlays: Vec<(u8, PathBuf)>,
    /// A bus file (bus.yml) instead of --node: its slaves and their device
    /// files, with the PDOs the network configures (COB-IDs, mappings),
    /// not the device files' defaults.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["nodes", "overlays"])]
    pub bus: Option<PathBuf>,
}

#[derive(Args)]
pub struct DecodeArgs {
    #[command(flatten)]
    pub files: NodeFiles,
    #[arg(long, value_enum, default_value_t = OutFormat::Text)]
    pub format: OutFormat,
    /// The trace: candump `-l` log, candump text output, compact
    /// `123#11223344` lines, or a PCAN-View `.trc` file (told apart from the
    /// content). `-` or none: standard input.
    pub trace: Option<PathBuf>,
}

fn node_file(text: &str) -> Result<(u8, PathBuf), String> {
    let Some((node, file)) = text.split_once('=') else {
        return Err(format!(
            "`{text}` is not N=FILE (for example 32=eds/linak.yaml)"
        ));
    };
    let node: u8 = node
        .trim()
        .parse()
        .ok()
        .filter(|n| (1..=127).contains(n))
        .ok_or_else(|| format!("`{node}` is not a node id (1 to 127)"))?;
    if file.is_empty() {
        return Err(format!("no file after `{node}=`"));
    }
    Ok((node, PathBuf::from(file)))
}

impl NodeFiles {
    /// A decoder with every node's file read; the diagnostics of a file
    /// with errors (printed to stderr) make it `Err`. With a bus file, each
    /// slave's device as the network configures it
    /// (`eds2rust::network::configured::configured_device`, as the
    /// generated network and `api` of a bus file have it).
    pub fn decoder(&self) -> Result<Decoder, ExitCode> {
        self.decoder_named().map(|(decoder, _)| decoder)
    }

    /// [`NodeFiles::decoder`], with the names of the nodes a bus file
    /// names (none with `--node`).
    pub fn decoder_named(&self) -> Result<(Decoder, Vec<(u8, String)>), ExitCode> {
        if let Some(path) = &self.bus {
            return bus_decoder(path);
        }
        let mut decoder = Decoder::new();
        let mut seen = std::collections::BTreeSet::new();
        let mut err = io::stderr().lock();
        for (node, _) in &self.overlays {
            if !self.nodes.iter().any(|(n, _)| n == node) {
                let _ = writeln!(
                    err,
                    "error: --overlay {node}=...: node {node} has no --node {node}=FILE"
                );
                return Err(ExitCode::from(2));
            }
        }
        for (node, path) in &self.nodes {
            if !seen.insert(*node) {
                let _ = writeln!(err, "error: --node {node} is given twice");
                return Err(ExitCode::from(2));
            }
            let overlays: Vec<PathBuf> = self
                .overlays
                .iter()
                .filter(|(n, _)| n == node)
                .map(|(_, p)| p.clone())
                .collect();
            let what = format!("used for node {node}");
            let options = Options::default();
            match device_or_refuse(path, &overlays, &options, &what, &mut err) {
                Some(device) => decoder.add_node(*node, Arc::new(device)),
                None => return Err(ExitCode::from(1)),
            }
        }
        Ok((decoder, Vec::new()))
    }
}

/// The decoder of a bus file's network (see [`NodeFiles::decoder`]) and
/// its slaves' names.
fn bus_decoder(path: &std::path::Path) -> Result<(Decoder, Vec<(u8, String)>), ExitCode> {
    let network = crate::net::load::read_configured(path, &Options::default(), "used")
        .ok_or(ExitCode::from(1))?;
    let _ = write!(io::stderr().lock(), "{}", network.warnings.render());
    let mut decoder = Decoder::new();
    let mut names = Vec::new();
    for node in &network.configured.nodes {
        let Some(slave) = network.bus.slaves.get(node.slave) else {
            continue;
        };
        let device = eds2rust::network::configured::configured_device(&slave.device, node);
        decoder.add_node(node.node_id, Arc::new(device));
        names.push((node.node_id, node.name.clone()));
    }
    Ok((decoder, names))
}

/// Writes one record in `format`. Text is one terminal-safe line: names
/// from the device files and the trace's own text cannot break the line or
/// send escape sequences or bidi controls ([`eds2rust::text::terminal_line`]).
pub fn write_record(out: &mut impl Write, format: OutFormat, record: &Record) -> io::Result<()> {
    match format {
        OutFormat::Text => writeln!(
            out,
            "{}",
            eds2rust::text::terminal_line(&render::text(record))
        ),
        OutFormat::Json => {
            render::write_json(&mut *out, record)?;
            out.write_all(b"\n")
        }
    }
}

/// Exit status: 0 when the trace was read to its end (bad lines are
/// reported in the output and counted on stderr), 1 when a node's file has
/// errors or the trace cannot be read, 2 on usage errors.
pub fn run(args: DecodeArgs) -> ExitCode {
    let mut decoder = match args.files.decoder() {
        Ok(d) => d,
        Err(code) => return code,
    };
    let input: Box<dyn BufRead> = match &args.trace {
        None => Box::new(io::stdin().lock()),
        Some(p) if p.as_os_str() == "-" => Box::new(io::stdin().lock()),
        Some(p) => match File::open(p) {
            Ok(f) => Box::new(BufReader::with_capacity(1 << 16, f)),
            Err(e) => {
                let _ = writeln!(io::stderr(), "error: {}: {e}", p.display());
                return ExitCode::from(1);
            }
        },
    };
    let mut out = BufWriter::with_capacity(1 << 16, io::stdout().lock());
    let result = eds2rust_decode::decode_trace(&mut decoder, input, |r| {
        write_record(&mut out, args.format, r)
    });
    let result = result.and_then(|summary| {
        out.flush()
            .map(|()| summary)
            .map_err(TraceDecodeError::Sink)
    });
    match result {
        Ok(summary) => {
            if summary.bad_lines > 0 {
                let _ = writeln!(
                    io::stderr(),
                    "{} frames decoded; {} lines could not be read (see the diagnostics in the output)",
                    summary.frames,
                    summary.bad_lines
                );
            }
            ExitCode::SUCCESS
        }
        // `eds2rust decode trace.log | head`: the reader left; not an error.
        Err(TraceDecodeError::Sink(e)) if e.kind() == io::ErrorKind::BrokenPipe => {
            ExitCode::SUCCESS
        }
        Err(e) => {
            let _ = writeln!(io::stderr(), "error: {e}");
            ExitCode::from(1)
        }
    }
}
