//! The lock on an output folder: step one of every write (see the
//! [writer](super) docs), so that builds into one folder take turns.
//!
//! Cargo's `target/` lock is the model: an advisory lock (`flock` on Unix,
//! `LockFileEx` on Windows) on a file in the folder, `.rcsc-lock`, taken
//! with a non-blocking attempt first so that the caller can say
//! "Blocking waiting for file lock on …" before it waits.
//!
//! Why a kernel lock (through the `fs4` crate) rather than an `O_EXCL`
//! lock file holding a PID: the kernel releases the lock when the holder
//! dies, even by `kill -9`, so there is no stale lock to detect and no
//! PID-reuse race to get wrong; `std::fs::File::lock` would do the same
//! but needs Rust 1.89, above the workspace's MSRV (1.88). `fs4` is small,
//! maintained, and its only dependencies (`rustix`, `windows-sys`) were
//! already in the lock file.
//!
//! On Unix the lock file is removed when the lock is released (so an
//! output folder holds only outputs between builds). That is safe because
//! a process that obtains the lock checks that the path still names the
//! file it locked, and starts again when it does not (the previous holder
//! removed it). Elsewhere the file stays, like cargo's `.cargo-lock`. A
//! file system without locks (some network mounts) is written unlocked,
//! as cargo does.

use super::{io_err, WriteError, LOCK_FILE};
use std::fs::{File, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};

/// A held lock on an output folder; released (and on Unix its file
/// removed) on drop.
#[derive(Debug)]
pub struct OutputLock {
    file: Option<File>,
    path: PathBuf,
}

impl OutputLock {
    /// Lock the folder `dir` (which must exist), waiting as long as another
    /// process holds it; `blocked(dir)` is called once before waiting.
    pub fn acquire(dir: &Path, blocked: &mut dyn FnMut(&Path)) -> Result<OutputLock, WriteError> {
        let path = dir.join(LOCK_FILE);
        let mut told = false;
        loop {
            if std::fs::symlink_metadata(&path).is_ok_and(|m| m.file_type().is_symlink()) {
                return Err(WriteError::Symlink {
                    path: path.display().to_string(),
                    why: "the lock file is a symbolic link".to_string(),
                });
            }
            let file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(|e| io_err(&path, e))?;
            match <File as fs4::FileExt>::try_lock(&file) {
                Ok(()) => {}
                Err(fs4::TryLockError::WouldBlock) => {
                    if !told {
                        blocked(dir);
                        told = true;
                    }
                    <File as fs4::FileExt>::lock(&file).map_err(|e| io_err(&path, e))?;
                }
                Err(fs4::TryLockError::Error(e)) if unsupported(&e) => {
                    return Ok(OutputLock { file: None, path });
                }
                Err(fs4::TryLockError::Error(e)) => return Err(io_err(&path, e)),
            }
            if names_file(&path, &file) {
                return Ok(OutputLock {
                    file: Some(file),
                    path,
                });
            }
            // The previous holder removed the file after we opened it: the
            // lock we hold is on a file no one else will see. Start again.
        }
    }
}

/// Errors of a file system that has no advisory locks.
fn unsupported(e: &io::Error) -> bool {
    // ENOLCK is 37 on Linux, 77 on the BSDs and macOS.
    let enolck = if cfg!(target_os = "linux") { 37 } else { 77 };
    e.kind() == io::ErrorKind::Unsupported || (cfg!(unix) && e.raw_os_error() == Some(enolck))
}

/// Whether `path` still names the open `file`.
#[cfg(unix)]
fn names_file(path: &Path, file: &File) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::symlink_metadata(path), file.metadata()) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn names_file(_path: &Path, _file: &File) -> bool {
    true
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        // Removed while still held (see the module docs), then released.
        if cfg!(unix) && self.file.is_some() {
            let _ = std::fs::remove_file(&self.path);
        }
        self.file = None;
    }
}
