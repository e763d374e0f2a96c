//! `eds2rust net check BUS`: reads the bus file and its device files,
//! configures the network as dcfgen does and checks it as a whole
//! (`eds2rust::network::check`); prints the diagnostics with their source
//! lines, the bus load estimate and a summary line. Exit status as `check`:
//! 0 without errors, 1 with, 2 on usage errors.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use eds2rust::network::check::{CheckLimits, DEFAULT_MAX_BUS_LOAD_PERCENT, bus_load, check};

use crate::ReadArgs;

#[derive(Args)]
pub(crate) struct CheckArgs {
    #[command(flatten)]
    read: ReadArgs,
    /// The highest estimated bus load, in percent of the bit rate, that is
    /// not a warning (`net::bus-load`).
    #[arg(long, value_name = "PERCENT", default_value_t = DEFAULT_MAX_BUS_LOAD_PERCENT)]
    max_bus_load: f64,
    /// The bus file (bus.yml).
    bus: PathBuf,
}

pub(crate) fn run(args: CheckArgs) -> ExitCode {
    let options = match args.read.options() {
        Ok(options) => options,
        Err(message) => return usage(&message),
    };
    if !(args.max_bus_load.is_finite() && args.max_bus_load >= 0.0) {
        return usage(&format!(
            "--max-bus-load {} is not a percentage (0 or more)",
            args.max_bus_load
        ));
    }
    let limits = CheckLimits {
        max_bus_load_percent: args.max_bus_load,
    };
    let loaded = eds2rust::network::read_file(&args.bus, &options);
    let mut diagnostics = loaded.diagnostics;
    let mut load = None;
    let mut nodes = 0;
    let mut extra = String::new();
    if let Some(bus) = &loaded.bus {
        extra = extra_keys(bus);
        let (configured, mut found) = eds2rust::network::configure(bus);
        found.extend(check(bus, &configured, &limits));
        found.apply_levels(&options.levels, options.strict);
        diagnostics.extend(found);
        load = Some(bus_load(bus, &configured));
        nodes = configured.nodes.len();
    }
    diagnostics.span_lines();
    let mut text = diagnostics.render();
    if let Some(load) = load {
        text.push_str(&load.to_string());
    }
    text.push_str(&extra);
    text.push_str(&format!(
        "{}: {} nodes, {} errors, {} warnings\n",
        eds2rust::text::terminal_line(&args.bus.display().to_string()),
        nodes,
        diagnostics.error_count(),
        diagnostics.warning_count()
    ));
    if let Err(code) = crate::print(&text) {
        return code;
    }
    if diagnostics.has_errors() {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// The keys dcfgen does not use (ros2_canopen's `driver`, `package`, ...),
/// listed at info level: kept, never an error.
fn extra_keys(bus: &eds2rust::network::model::Bus) -> String {
    if bus.extra_keys.is_empty() {
        return String::new();
    }
    let path = bus.file.display().to_string();
    let file = eds2rust::text::terminal_line(&path);
    let mut text = format!(
        "info: {} keys that dcfgen does not use (kept for other tools, such as ros2_canopen's drivers):\n",
        bus.extra_keys.len()
    );
    for key in &bus.extra_keys {
        text.push_str(&format!(
            "  {file}:{}: {}.{} = {}\n",
            key.spot.line,
            eds2rust::text::terminal_line(&key.section),
            eds2rust::text::terminal_line(&key.key),
            eds2rust::text::terminal_line(&key.value)
        ));
    }
    text
}

fn usage(message: &str) -> ExitCode {
    let _ = writeln!(std::io::stderr().lock(), "error: {message}");
    ExitCode::from(2)
}
