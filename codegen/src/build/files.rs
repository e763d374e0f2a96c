//! Writing output files: whole (a reader never sees half a file), only over
//! regular files (never a device or FIFO), through symlinks, and only when
//! their bytes change (cargo does not rebuild for nothing).

use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `bytes` to `path` unless it holds them already: `Ok(true)` when
/// written, `Ok(false)` when unchanged. The builder's own output directory
/// (and those under it) is created when missing; the rest is
/// [`write_whole`].
pub(crate) fn write_if_changed(path: &Path, bytes: &[u8]) -> io::Result<bool> {
    let dir = path.parent().unwrap_or(Path::new(""));
    if !dir.as_os_str().is_empty() {
        std::fs::create_dir_all(dir)?;
    }
    let target = target(path)?;
    if target.existing && std::fs::read(&target.path).is_ok_and(|old| old == bytes) {
        return Ok(false);
    }
    write_at(&target, bytes)?;
    Ok(true)
}

/// Writes `bytes` whole to `path`, so that no reader ever sees half a file
/// and a failed write leaves the old file as it was: a temporary file in the
/// same directory, synced to disk, then renamed over `path`.
///
/// - A new path, or a regular file (whose permissions the new file keeps).
/// - A symlink is followed: the file it points to is replaced, in that
///   file's directory; the link stays. A dangling link is refused.
/// - Anything else at `path` (a directory, a FIFO, a device such as
///   `/dev/null`) is refused with [`io::ErrorKind::InvalidInput`]: a rename
///   would replace it.
/// - A missing parent directory is an error naming it; nothing is created.
pub fn write_whole(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_at(&target(path)?, bytes)
}

/// Where a write goes: `path` itself or, through symlinks, the file they
/// name.
struct Target {
    path: PathBuf,
    existing: bool,
    permissions: Option<std::fs::Permissions>,
}

fn target(path: &Path) -> io::Result<Target> {
    let resolved = match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => match std::fs::canonicalize(path) {
            Ok(real) => real,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                return Err(io::Error::new(
                    io::ErrorKind::NotFound,
                    format!(
                        "{} is a symlink to a missing file; it is followed, not replaced",
                        path.display()
                    ),
                ));
            }
            Err(e) => return Err(e),
        },
        Ok(_) => path.to_path_buf(),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            let dir = path.parent().unwrap_or(Path::new(""));
            if !dir.as_os_str().is_empty() && !dir.is_dir() {
                return Err(io::Error::new(
                    io::ErrorKind::NotFound,
                    format!("directory {} does not exist", dir.display()),
                ));
            }
            return Ok(Target {
                path: path.to_path_buf(),
                existing: false,
                permissions: None,
            });
        }
        Err(e) => return Err(e),
    };
    let meta = std::fs::metadata(&resolved)?;
    if !meta.is_file() {
        let kind = kind_of(&meta.file_type());
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is {kind}, not a regular file; only a regular file or a new path is replaced",
                resolved.display()
            ),
        ));
    }
    Ok(Target {
        path: resolved,
        existing: true,
        permissions: Some(meta.permissions()),
    })
}

/// "a directory", "a FIFO", "a character device", ... for messages.
fn kind_of(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a file"
    }
}

fn write_at(target: &Target, bytes: &[u8]) -> io::Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let path = &target.path;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(path.file_name().unwrap_or_default());
    tmp_name.push(format!(
        ".{}.{}.tmp",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let tmp = dir.join(tmp_name);
    let written = (|| {
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        file.write_all(bytes)?;
        if let Some(permissions) = &target.permissions {
            file.set_permissions(permissions.clone())?;
        }
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written?;
    // The rename itself is durable once the directory is synced; not every
    // platform or file system can open a directory for that.
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn write_only_when_changed() {
        let dir = std::env::temp_dir().join(format!("eds2rust-build-unit-{}", std::process::id()));
        let path = dir.join("x.rs");
        assert!(write_if_changed(&path, b"one").unwrap());
        assert!(!write_if_changed(&path, b"one").unwrap());
        assert!(write_if_changed(&path, b"two").unwrap());
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        let leftovers = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(leftovers, 1, "no temporary file is left behind");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn only_regular_files_or_new_paths_are_replaced() {
        let dir = std::env::temp_dir().join(format!("eds2rust-files-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A missing directory is named, not created.
        let err = write_whole(&dir.join("missing/x.rs"), b"x").unwrap_err();
        assert!(err.to_string().contains("missing"), "{err}");
        assert!(!dir.join("missing").exists());
        // A directory is refused.
        let err = write_whole(&dir, b"x").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput, "{err}");
        assert!(err.to_string().contains("a directory"), "{err}");
        #[cfg(unix)]
        {
            let err = write_whole(Path::new("/dev/null"), b"x").unwrap_err();
            assert!(err.to_string().contains("a character device"), "{err}");
            assert!(
                std::fs::metadata("/dev/null")
                    .unwrap()
                    .file_type()
                    .is_char_device()
            );
            // A symlink is followed: the file it names changes, the link stays.
            use std::os::unix::fs::{FileTypeExt, PermissionsExt, symlink};
            let real = dir.join("real.rs");
            std::fs::write(&real, b"old").unwrap();
            std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).unwrap();
            let link = dir.join("link.rs");
            symlink(&real, &link).unwrap();
            write_whole(&link, b"new").unwrap();
            assert!(
                std::fs::symlink_metadata(&link)
                    .unwrap()
                    .file_type()
                    .is_symlink()
            );
            assert_eq!(std::fs::read(&real).unwrap(), b"new");
            let mode = std::fs::metadata(&real).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o640);
            // A dangling symlink is refused.
            let dangling = dir.join("dangling.rs");
            symlink(dir.join("nowhere.rs"), &dangling).unwrap();
            let err = write_whole(&dangling, b"x").unwrap_err();
            assert!(err.to_string().contains("symlink"), "{err}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
