//! `eds2rust net dcf BUS -o DIR`: the files lely's dcfgen writes for a bus
//! (`master.dcf`, a concise DCF per slave, `master.bin`), equal to
//! `dcfgen -r -S` but where dcfgen is wrong on purpose (listed on stderr).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Args;
use eds2rust::network::dcf::OutputFile;

use crate::ReadArgs;
use crate::refusal::failed;

#[derive(Args)]
pub(crate) struct DcfArgs {
    #[command(flatten)]
    read: ReadArgs,
    /// Write the master's PDOs as remote PDO mappings (dcfgen's `-r`).
    #[arg(long, short = 'r')]
    remote_pdo: bool,
    /// The directory to write into (created when missing).
    #[arg(long, short)]
    output: PathBuf,
    /// The bus file (bus.yml).
    bus: PathBuf,
}

pub(crate) fn run(args: DcfArgs) -> ExitCode {
    let options = match args.read.options() {
        Ok(options) => options,
        Err(message) => {
            let _ = writeln!(std::io::stderr().lock(), "error: {message}");
            return ExitCode::from(2);
        }
    };
    let loaded = eds2rust::network::read_file(&args.bus, &options);
    let mut diagnostics = loaded.diagnostics;
    let Some(bus) = loaded.bus else {
        return failed(&args.bus, diagnostics, "written");
    };
    let (configured, mut configure_diagnostics) = eds2rust::network::configure(&bus);
    configure_diagnostics.apply_levels(&options.levels, options.strict);
    diagnostics.extend(configure_diagnostics);
    if diagnostics.has_errors() {
        return failed(&args.bus, diagnostics, "written");
    }
    let written = eds2rust::network::dcf::files(&bus, &configured, args.remote_pdo);
    let mut err = std::io::stderr().lock();
    let _ = write!(err, "{}", diagnostics.render());
    if let Err(message) = check_names(&written.files) {
        let _ = writeln!(err, "{}: not written: {message}", args.bus.display());
        return ExitCode::from(1);
    }
    if let Err(e) = std::fs::create_dir_all(&args.output) {
        let _ = writeln!(err, "{}: cannot create: {e}", args.output.display());
        return ExitCode::from(1);
    }
    for file in &written.files {
        let path = args.output.join(&file.name);
        if let Err(e) = eds2rust::build::write_whole(&path, &file.bytes) {
            let _ = writeln!(err, "{}: cannot write: {e}", path.display());
            return ExitCode::from(1);
        }
    }
    for difference in &written.differences {
        let _ = writeln!(err, "note: differs from dcfgen on purpose: {difference}");
    }
    let names: Vec<&str> = written.files.iter().map(|f| f.name.as_str()).collect();
    let _ = writeln!(
        err,
        "{}: wrote {} to {} ({} errors, {} warnings)",
        eds2rust::text::terminal_line(&args.bus.display().to_string()),
        names.join(", "),
        args.output.display(),
        diagnostics.error_count(),
        diagnostics.warning_count()
    );
    ExitCode::SUCCESS
}

/// Every file name is a plain name (a slave named `../x` or `a/b` would
/// write outside the directory) and no two are the same (a slave named
/// `master` would overwrite master.bin).
fn check_names(files: &[OutputFile]) -> Result<(), String> {
    for (n, file) in files.iter().enumerate() {
        let plain = Path::new(&file.name)
            .file_name()
            .is_some_and(|f| f == file.name.as_str())
            && !file.name.contains(['/', '\\']);
        if !plain {
            return Err(format!(
                "`{}` is not a plain file name; rename the slave",
                file.name
            ));
        }
        if files[..n].iter().any(|f| f.name == file.name) {
            return Err(format!(
                "two files would be named `{}`; rename the slave",
                file.name
            ));
        }
    }
    Ok(())
}
