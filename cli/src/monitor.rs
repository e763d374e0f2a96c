//! `eds2rust monitor`: a live SocketCAN bus through the decoder of
//! `eds2rust decode` (the `eds2rust-decode` library), the nodes' files
//! given one by one (`--node N=FILE`) or by a bus file (`--bus bus.yml`:
//! the PDOs as the network configures them): the record stream as
//! `decode` prints it, or a per-node table redrawn in place (`--table`), and
//! the values of chosen PDO fields charted as SVG on exit (`--plot`).
//!
//! The loop runs on any [`Bus`] (the unit tests use the virtual bus) until
//! `--duration` ends or Ctrl-C sets the stop flag. Exit status: 0 when it
//! stopped so, 1 when the interface cannot be opened or fails, a node's file
//! has errors, the chart cannot be written or a `--plot` field was never
//! seen, 2 on usage errors.

mod plot;
mod table;

use std::io::{self, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use clap::Args;
use eds2rust_decode::{Decoder, Record};
use eds2rust_runtime::Frame;
use eds2rust_runtime::transport::Bus;

use crate::decode::{NodeFiles, OutFormat, write_record};
use crate::live::bus::LiveBus;
pub use plot::{Plot, PlotSpec};
pub use table::NodeTable;

/// The longest wait for a frame: how soon a stop is noticed.
const POLL: Duration = Duration::from_millis(100);
/// The record stream is flushed at least this often.
const FLUSH: Duration = Duration::from_millis(100);

#[derive(Args)]
pub struct MonitorArgs {
    /// The SocketCAN interface (can0, vcan0).
    #[arg(long, short = 'i', value_name = "IFACE")]
    pub iface: String,
    #[command(flatten)]
    pub files: NodeFiles,
    /// The record stream, as `eds2rust decode` prints it. A record's time
    /// is in seconds since the monitor started (see --unix-time), its line
    /// the frame's number.
    #[arg(long, value_enum, default_value_t = OutFormat::Text)]
    pub format: OutFormat,
    /// Give the records the system time (seconds since 1970-01-01 UTC) at
    /// which each frame was received, instead of the seconds since the
    /// monitor started.
    #[arg(long)]
    pub unix_time: bool,
    /// Instead of the record stream, a table of the nodes: NMT state, age
    /// of the last heartbeat, last EMCY, PDO rates (frames/s over the last
    /// 2 s), SDO transfers. Redrawn 4 times a second on a terminal; printed
    /// once a second (and at the end) as plain text otherwise.
    #[arg(long, conflicts_with = "format")]
    pub table: bool,
    /// Record these PDO fields and chart them on exit: a name as the
    /// decoder gives it (`Feedback.Position`; see the records), or
    /// `N:NAME` for node N's only. Physical values where the entry is
    /// scaled, raw values otherwise. A field never seen is an error (exit
    /// status 1) naming the fields that were seen.
    #[arg(long, value_name = "FIELD", num_args = 1.., value_parser = plot::parse_spec)]
    pub plot: Vec<PlotSpec>,
    /// The SVG chart of --plot, written when the monitor ends: one line per
    /// field over the seconds since the monitor started.
    #[arg(
        long,
        value_name = "FILE",
        default_value = "monitor.svg",
        requires = "plot"
    )]
    pub plot_file: PathBuf,
    /// Stop after this time (seconds: 2, 0.5, or 500ms, 2s, 1m); without
    /// it, Ctrl-C stops (SIGINT; SIGTERM and SIGHUP too). Either way the
    /// chart is written and the exit status is 0.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub duration: Option<Duration>,
}

/// A flag Ctrl-C (SIGINT; SIGTERM and SIGHUP too) sets, for the commands
/// that run until --duration ends or Ctrl-C (`monitor`, `sim`); when no
/// handler can be set, a warning on `err` says that `what` will not stop
/// cleanly.
pub fn stop_on_ctrl_c(what: &str, err: &mut dyn Write) -> Arc<AtomicBool> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed)) {
        let _ = writeln!(err, "warning: Ctrl-C will not stop {what} cleanly: {e}");
    }
    stop
}

/// Seconds (`2`, `0.5`) or a time with a unit (`500ms`, `2s`, `1m`).
pub fn parse_seconds(text: &str) -> Result<Duration, String> {
    let t = text.trim();
    let (number, scale) = if let Some(n) = t.strip_suffix("ms") {
        (n, 1e-3)
    } else if let Some(n) = t.strip_suffix('s') {
        (n, 1.0)
    } else if let Some(n) = t.strip_suffix('m') {
        (n, 60.0)
    } else {
        (t, 1.0)
    };
    number
        .trim()
        .parse::<f64>()
        .ok()
        .map(|v| v * scale)
        .filter(|v| v.is_finite() && *v > 0.0 && *v < 1e9)
        .map(Duration::from_secs_f64)
        .ok_or_else(|| format!("`{text}` is not a time in seconds (2, 0.5, 500ms, 1m)"))
}

/// How the table is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum View {
    /// Redrawn in place (ANSI cursor home and clear), 4 times a second.
    Terminal,
    /// Printed whole once a second, ASCII only: for a pipe or a file.
    Plain,
}

impl View {
    fn period(self) -> Duration {
        match self {
            View::Terminal => Duration::from_millis(250),
            View::Plain => Duration::from_secs(1),
        }
    }
}

/// Why the loop ended early.
#[derive(Debug)]
pub enum Failure {
    /// Receiving failed.
    Bus(io::Error),
    /// Writing the output failed (other than a closed pipe).
    Output(io::Error),
}

/// The state of one run: the decoder, the table, the plot.
pub struct Monitor {
    decoder: Decoder,
    format: OutFormat,
    unix_time: bool,
    view: Option<View>,
    /// Shown above the table.
    title: String,
    pub table: Option<NodeTable>,
    pub plot: Option<Plot>,
    /// Frames received.
    pub frames: usize,
    /// Seconds since the start when the loop ended.
    pub elapsed: f64,
    records: Vec<Record>,
    /// The reader of the output left (a closed pipe): stop.
    closed: bool,
}

impl Monitor {
    /// `nodes`: the nodes with a file (rows of the table from the start).
    pub fn new(decoder: Decoder, nodes: &[u8], view: Option<View>, plot: Vec<PlotSpec>) -> Monitor {
        Monitor {
            decoder,
            format: OutFormat::Text,
            unix_time: false,
            view,
            title: "eds2rust monitor".into(),
            table: view.map(|_| NodeTable::new(nodes.iter().copied())),
            plot: (!plot.is_empty()).then(|| Plot::new(plot)),
            frames: 0,
            elapsed: 0.0,
            records: Vec::new(),
            closed: false,
        }
    }

    pub fn with_format(mut self, format: OutFormat, unix_time: bool) -> Monitor {
        self.format = format;
        self.unix_time = unix_time;
        self
    }

    pub fn with_title(mut self, title: String) -> Monitor {
        self.title = title;
        self
    }

    /// Names the table's nodes (a bus file's slaves).
    pub fn with_names(mut self, names: Vec<(u8, String)>) -> Monitor {
        if let Some(table) = &mut self.table {
            table.names = names.into_iter().collect();
        }
        self
    }

    /// Receives and decodes frames from `bus` until `duration` has passed
    /// (forever without one) or `stop` is set, writing to `out` the record
    /// stream or the table; the table once more at the end.
    pub fn run(
        &mut self,
        bus: &mut dyn Bus,
        duration: Option<Duration>,
        stop: &AtomicBool,
        out: &mut dyn Write,
    ) -> Result<(), Failure> {
        let start = Instant::now();
        let deadline = duration.map(|d| start + d);
        let period = self.view.map(View::period);
        let mut next_draw = period.map(|p| start + p);
        let mut last_flush = start;
        if self.view == Some(View::Terminal) {
            self.output(out, |out| out.write_all(b"\x1b[2J"))?;
        }
        let result = loop {
            let now = Instant::now();
            if self.closed || stop.load(Ordering::Relaxed) || deadline.is_some_and(|d| now >= d) {
                break Ok(());
            }
            let mut wait = POLL;
            for until in [deadline, next_draw].into_iter().flatten() {
                wait = wait.min(until.saturating_duration_since(now));
            }
            let frame = match bus.recv(wait) {
                Ok(f) => f,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => None,
                Err(e) => break Err(Failure::Bus(e)),
            };
            let now = Instant::now();
            let t = now.duration_since(start).as_secs_f64();
            if let Some(frame) = &frame {
                self.frame(t, frame, out)?;
            }
            if frame.is_none() || now.duration_since(last_flush) >= FLUSH {
                self.output(out, |out| out.flush())?;
                last_flush = now;
            }
            // At the end the table is drawn once, after the loop.
            if let (Some(due), Some(p)) = (next_draw, period)
                && now >= due
                && deadline.is_none_or(|d| now < d)
            {
                self.draw(t, out)?;
                next_draw = Some((due + p).max(now));
            }
        };
        self.elapsed = start.elapsed().as_secs_f64();
        if self.view.is_some() {
            self.draw(self.elapsed, out)?;
        }
        self.output(out, |out| out.flush())?;
        result
    }

    /// Decodes one frame received at `t` (seconds since the start).
    pub fn frame(&mut self, t: f64, frame: &Frame, out: &mut dyn Write) -> Result<(), Failure> {
        self.frames += 1;
        let stamp = if self.unix_time {
            SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0.0, |d| d.as_secs_f64())
        } else {
            t
        };
        self.decoder
            .frame(self.frames, Some(stamp), frame, &mut self.records);
        let mut records = std::mem::take(&mut self.records);
        for r in records.drain(..) {
            if let Some(table) = &mut self.table {
                table.record(t, &r);
            }
            if let Some(plot) = &mut self.plot {
                plot.record(t, &r);
            }
            if self.view.is_none() {
                let format = self.format;
                self.output(out, |mut out| write_record(&mut out, format, &r))?;
            }
        }
        self.records = records;
        Ok(())
    }

    /// Writes the table at `t`.
    fn draw(&mut self, t: f64, out: &mut dyn Write) -> Result<(), Failure> {
        let (Some(view), Some(table)) = (self.view, &mut self.table) else {
            return Ok(());
        };
        let text = format!(
            "{}: {t:.1} s, {} frames\n{}\n",
            self.title,
            self.frames,
            table.render(t, view == View::Plain)
        );
        // Names come from the device files: terminal-safe before our own
        // escape sequences are added.
        let text = eds2rust::text::terminal(&text).into_owned();
        let text = match view {
            View::Plain => format!("{text}\n"),
            // Home, each line cleared to its end, the rest of the screen cleared.
            View::Terminal => format!("\x1b[H{}\x1b[J", text.replace('\n', "\x1b[K\n")),
        };
        self.output(out, |out| {
            out.write_all(text.as_bytes())?;
            out.flush()
        })
    }

    /// Runs `f` on the output unless its reader left; a closed pipe ends
    /// the run quietly.
    fn output(
        &mut self,
        out: &mut dyn Write,
        f: impl FnOnce(&mut dyn Write) -> io::Result<()>,
    ) -> Result<(), Failure> {
        if self.closed {
            return Ok(());
        }
        match f(out) {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == io::ErrorKind::BrokenPipe => {
                self.closed = true;
                Ok(())
            }
            Err(e) => Err(Failure::Output(e)),
        }
    }

    /// Writes the chart of `--plot` to `path` and reports the fields never
    /// seen on stderr; `false` when either went wrong.
    pub fn finish_plot(&self, path: &std::path::Path, err: &mut dyn Write) -> bool {
        let Some(plot) = &self.plot else { return true };
        let mut ok = true;
        match plot.svg(self.elapsed) {
            Some(Ok(svg)) => {
                if let Err(e) = eds2rust::build::write_whole(path, svg.as_bytes()) {
                    let _ = writeln!(err, "error: cannot write {}: {e}", path.display());
                    ok = false;
                } else {
                    let n = plot.series.iter().filter(|s| !s.points.is_empty()).count();
                    let _ = writeln!(err, "monitor: wrote {} ({n} fields)", path.display());
                }
            }
            Some(Err(e)) => {
                let _ = writeln!(err, "error: cannot draw {}: {e}", path.display());
                ok = false;
            }
            None => {
                let _ = writeln!(
                    err,
                    "monitor: no --plot field was seen; {} not written",
                    path.display()
                );
            }
        }
        if let Some(text) = plot.unknown() {
            let _ = err.write_all(text.as_bytes());
            ok = false;
        }
        ok
    }
}

/// The exit status: 0 stopped by --duration or Ctrl-C (chart written), 1
/// the interface cannot be opened or failed, a file has errors, the chart
/// failed or a field was never seen, 2 usage errors.
pub fn run(args: MonitorArgs) -> ExitCode {
    let (decoder, names) = match args.files.decoder_named() {
        Ok(d) => d,
        Err(code) => return code,
    };
    let mut err = io::stderr();
    let mut bus = match LiveBus::open(&args.iface) {
        Ok(bus) => bus,
        Err(e) => {
            let _ = writeln!(err, "error: {e}");
            return ExitCode::from(1);
        }
    };
    let stop = stop_on_ctrl_c("the monitor", &mut err);
    let view = args.table.then(|| match io::stdout().is_terminal() {
        true => View::Terminal,
        false => View::Plain,
    });
    // The nodes with a file: of --node or of the bus file.
    let nodes: Vec<u8> = (1..=127)
        .filter(|&n| decoder.dictionary(n).is_some())
        .collect();
    let mut monitor = Monitor::new(decoder, &nodes, view, args.plot.clone())
        .with_format(args.format, args.unix_time)
        .with_names(names)
        .with_title(format!("eds2rust monitor {}", args.iface));
    let until = match args.duration {
        Some(d) => format!("for {:.1} s", d.as_secs_f64()),
        None => "until Ctrl-C".into(),
    };
    let _ = writeln!(err, "monitor: listening on {} {until}", args.iface);
    let stdout = io::stdout();
    let mut out = io::BufWriter::with_capacity(1 << 16, stdout.lock());
    let result = monitor.run(&mut bus, args.duration, &stop, &mut out);
    drop(out);
    let mut code = ExitCode::SUCCESS;
    match result {
        Ok(()) => {
            let _ = writeln!(
                err,
                "monitor: {} frames in {:.1} s",
                monitor.frames, monitor.elapsed
            );
        }
        Err(Failure::Bus(e)) => {
            let _ = writeln!(err, "error: {}: {e}", args.iface);
            code = ExitCode::from(1);
        }
        Err(Failure::Output(e)) => {
            let _ = writeln!(err, "error: cannot write the output: {e}");
            code = ExitCode::from(1);
        }
    }
    if !monitor.finish_plot(&args.plot_file, &mut err) {
        code = ExitCode::from(1);
    }
    code
}

#[cfg(test)]
mod bus_tests;
#[cfg(test)]
mod tests;
