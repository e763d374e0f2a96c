//! Reading an input file with bounds: the one function every reader of a
//! device file (EDS/DCF, YAML table, a table's `base:`, overlays) goes
//! through, and the rule of where a YAML table's `base:` may lead.
//!
//! [`read_input`] reads only regular files (never a directory, FIFO,
//! socket or device node, never a kernel pseudo-file under `/proc` or
//! `/sys`), never blocks on opening (a FIFO is opened non-blocking and then
//! refused), and reads at most the size limit plus one byte, so that a file
//! that grows while it is read, or says it is empty (as pseudo-files do), is
//! still bounded.

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::diag::{Diagnostic, Location, Severity};

/// The default limit on the size of one input file: 64 MiB, far above any
/// real EDS, DCF or table (the largest real EDS files have a few MB).
pub const DEFAULT_MAX_INPUT_SIZE: u64 = 64 * 1024 * 1024;

/// Why an input file was not read.
#[derive(Debug)]
pub enum Refused {
    /// The operating system's error (missing file, no permission, …).
    Io(std::io::Error),
    /// Not a regular file; says what it is instead ("a directory", …).
    NotAFile(&'static str),
    /// A file of the kernel's pseudo file systems (`/proc`, `/sys`).
    PseudoFile,
    /// Larger than the limit; `size` is the size the file reported, when
    /// that was already above the limit (`None`: it grew while read).
    TooLarge { limit: u64, size: Option<u64> },
}

impl From<std::io::Error> for Refused {
    fn from(err: std::io::Error) -> Refused {
        Refused::Io(err)
    }
}

impl Refused {
    /// The error that reports this refusal for `file`.
    pub fn diagnostic(&self, file: &str) -> Diagnostic {
        let (code, message, notes) = match self {
            Refused::Io(err) => ("io", format!("cannot read the file: {err}"), Vec::new()),
            Refused::NotAFile(what) => (
                "input::not-a-file",
                format!("this is {what}, not a regular file; only regular files are read"),
                vec!["name the EDS/DCF file or YAML table itself".to_string()],
            ),
            Refused::PseudoFile => (
                "input::not-a-file",
                "this is a pseudo-file of the kernel (under /proc or /sys), not a device file; \
                 it is not read"
                    .to_string(),
                Vec::new(),
            ),
            Refused::TooLarge { limit, size } => {
                let has = match size {
                    Some(size) => format!("has {size} bytes"),
                    None => format!("grew beyond {limit} bytes while it was read"),
                };
                (
                    "input::too-large",
                    format!(
                        "the file {has}, more than the limit of {} for one input file",
                        human(*limit)
                    ),
                    vec![
                        "raise the limit with `--max-input-size BYTES` (command line), \
                         `Builder::max_input_size` (build script) or \
                         `Options::max_input_size` (library)"
                            .to_string(),
                    ],
                )
            }
        };
        Diagnostic {
            severity: Severity::Error,
            code,
            file: file.to_string(),
            location: Location::default(),
            message,
            notes,
        }
    }
}

/// `67108864 bytes (64 MiB)`, or just the bytes when not whole MiB.
fn human(bytes: u64) -> String {
    const MIB: u64 = 1024 * 1024;
    if bytes >= MIB && bytes.is_multiple_of(MIB) {
        format!("{bytes} bytes ({} MiB)", bytes / MIB)
    } else {
        format!("{bytes} bytes")
    }
}

/// Reads the whole regular file at `path`, of at most `limit` bytes.
///
/// Refuses without reading: a path that is not a regular file (checked
/// before opening, so that no device is opened, and again on the opened
/// handle, so that a file swapped in between is caught too), a kernel
/// pseudo-file, and a file whose size is above `limit`. Opening never blocks
/// (on Unix the file is opened with `O_NONBLOCK`). At most `limit + 1`
/// bytes are read, whatever the file says its size is.
pub fn read_input(path: &Path, limit: u64) -> Result<Vec<u8>, Refused> {
    check_kind(&std::fs::metadata(path)?)?;
    if is_pseudo_file(path) {
        return Err(Refused::PseudoFile);
    }
    let file = open_nonblocking(path)?;
    let meta = file.metadata()?;
    check_kind(&meta)?;
    if meta.len() > limit {
        return Err(Refused::TooLarge {
            limit,
            size: Some(meta.len()),
        });
    }
    let capacity = usize::try_from(meta.len()).unwrap_or(0);
    let mut bytes = Vec::with_capacity(capacity);
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if u64::try_from(bytes.len()).unwrap_or(u64::MAX) > limit {
        return Err(Refused::TooLarge { limit, size: None });
    }
    Ok(bytes)
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    std::fs::File::open(path)
}

/// `Ok` for a regular file; otherwise what it is.
fn check_kind(meta: &std::fs::Metadata) -> Result<(), Refused> {
    let kind = meta.file_type();
    if kind.is_file() {
        return Ok(());
    }
    if kind.is_dir() {
        return Err(Refused::NotAFile("a directory"));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return Err(Refused::NotAFile("a FIFO (named pipe)"));
        }
        if kind.is_char_device() {
            return Err(Refused::NotAFile("a character device"));
        }
        if kind.is_block_device() {
            return Err(Refused::NotAFile("a block device"));
        }
        if kind.is_socket() {
            return Err(Refused::NotAFile("a socket"));
        }
    }
    Err(Refused::NotAFile("a special file"))
}

/// Does `path` lead into the kernel's pseudo file systems?
fn is_pseudo_file(path: &Path) -> bool {
    if !cfg!(target_os = "linux") {
        return false;
    }
    let Ok(real) = std::fs::canonicalize(path) else {
        return false;
    };
    real.starts_with("/proc") || real.starts_with("/sys")
}

/// Checks that the `base:` file at `path` (already joined to the table's
/// directory) lies inside the `project` directory (by default the current
/// directory) or one of the `allowed` directories,
/// comparing canonical paths so that neither `..` nor a symbolic link
/// leads out. A path that does not resolve passes: reading it then fails
/// with its own error, and reads nothing.
pub fn check_base(path: &Path, project: Option<&Path>, allowed: &[PathBuf]) -> Result<(), String> {
    let Ok(real) = std::fs::canonicalize(path) else {
        return Ok(());
    };
    let project = match project {
        Some(dir) => dir.to_path_buf(),
        None => std::env::current_dir().unwrap_or_default(),
    };
    let roots: Vec<PathBuf> = std::iter::once(&project)
        .chain(allowed)
        .filter_map(|dir| std::fs::canonicalize(dir).ok())
        .collect();
    if roots.iter().any(|root| real.starts_with(root)) {
        return Ok(());
    }
    let shown = if real == path {
        format!("`{}`", path.display())
    } else {
        format!("`{}` (that is `{}`)", path.display(), real.display())
    };
    Err(format!(
        "{shown} lies outside the project directory `{}`; a base EDS is read only from \
         inside the project",
        project.display()
    ))
}

#[cfg(test)]
mod tests;
