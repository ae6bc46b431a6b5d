//! The [writer](super)'s rules for one file a user names on the command
//! line (`rcsc ir -o F`, `rcsc graph -o F`, `rcsc test --trace F`), and
//! the files a command reads, which no write of it may replace.
//!
//! A named file is written like a file of a build, in the folder that
//! holds it: under that folder's lock, checked before anything changes (a
//! folder or a link to nothing in its place is refused, an existing file
//! must carry [`GENERATED`](crate::GENERATED) in its first line, or an
//! MCAP recording in its header's `library` field), staged
//! to a temporary beside it and renamed over it. What differs: the user
//! chose the path, so a symbolic link there is followed wherever it leads
//! (the file replaced is the one it names), and the folder is not swept
//! for temporaries — it is any folder (`~`, the repository), not an output
//! folder of rcsc's, and a sweep would walk all of it.
//!
//! [`Inputs`] are the files the command reads — the plans, the manifests,
//! the scenarios. A write refuses to replace one whatever its first line
//! says: a witness scenario carries the marker, yet `rcsc test --trace`
//! must not overwrite it.

use super::{guard, io_err, journal, OutputLock, WriteError, WriteReport, TMP_PREFIX};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The files a command reads, by identity (device and inode on Unix, the
/// canonical path elsewhere): a hard link, another spelling of the path
/// or a symbolic link to one of them is the same file.
#[derive(Clone, Debug, Default)]
pub struct Inputs {
    files: Vec<(FileKey, PathBuf)>,
}

#[cfg(unix)]
type FileKey = (u64, u64);
#[cfg(not(unix))]
type FileKey = PathBuf;

#[cfg(unix)]
fn key(path: &Path) -> Option<FileKey> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn key(path: &Path) -> Option<FileKey> {
    std::fs::canonicalize(path).ok()
}

impl Inputs {
    pub fn new() -> Inputs {
        Inputs::default()
    }

    /// Remember a file the command reads (one that does not exist is
    /// nothing to protect).
    pub fn add(&mut self, path: &Path) {
        if let Some(k) = key(path) {
            self.files.push((k, path.to_path_buf()));
        }
    }

    /// The input `path` is, if it is one.
    pub fn find(&self, path: &Path) -> Option<&Path> {
        let k = key(path)?;
        self.files
            .iter()
            .find(|(f, _)| *f == k)
            .map(|(_, p)| p.as_path())
    }

    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }
}

/// Refuse now what [`write_file`] would refuse at `path` (an input, a file
/// rcsc did not generate, a folder): for a command that works a long time
/// before it writes (`rcsc test --trace`), so that it fails first.
pub fn check_file(path: &Path, inputs: &Inputs) -> Result<(), WriteError> {
    if let Some(input) = inputs.find(path) {
        return Err(input_error(path, input));
    }
    match existing(path)? {
        Some(old) if !guard::first_line_generated(&old) => {
            Err(WriteError::NotGenerated(vec![path.display().to_string()]))
        }
        _ => Ok(()),
    }
}

fn input_error(path: &Path, input: &Path) -> WriteError {
    WriteError::Input {
        path: path.display().to_string(),
        input: input.display().to_string(),
    }
}

/// What is at `path` now: nothing, or a regular file's bytes (a link is
/// followed; one to nothing, a folder or a device is refused).
fn existing(path: &Path) -> Result<Option<Vec<u8>>, WriteError> {
    let meta = match std::fs::symlink_metadata(path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(io_err(path, e)),
    };
    let meta = if meta.file_type().is_symlink() {
        std::fs::metadata(path).map_err(|_| WriteError::Symlink {
            path: path.display().to_string(),
            why: "it is a symbolic link to nothing".to_string(),
        })?
    } else {
        meta
    };
    if !meta.is_file() {
        return Err(WriteError::InTheWay {
            path: path.display().to_string(),
            why: "it is a folder (or not a regular file) where rcsc writes a file",
        });
    }
    std::fs::read(path).map(Some).map_err(|e| io_err(path, e))
}

/// Write `contents` to the file `path` (its folder made if missing),
/// replacing it only when it is no input and carries the marker; unchanged
/// bytes are not rewritten. `blocked` is called before waiting for another
/// write's lock on the folder.
pub fn write_file(
    path: &Path,
    contents: &str,
    inputs: &Inputs,
    blocked: &mut dyn FnMut(&Path),
) -> Result<WriteReport, WriteError> {
    write_file_bytes(path, contents.as_bytes(), inputs, blocked)
}

/// [`write_file`] for bytes that are not text (an MCAP recording, whose
/// marker is in its header's `library` field).
pub fn write_file_bytes(
    path: &Path,
    contents: &[u8],
    inputs: &Inputs,
    blocked: &mut dyn FnMut(&Path),
) -> Result<WriteReport, WriteError> {
    if path.file_name().is_none() || path.as_os_str().is_empty() {
        return Err(WriteError::InTheWay {
            path: path.display().to_string(),
            why: "it names a folder, not a file",
        });
    }
    // A link is followed (through any chain of links): the file replaced
    // is the one it names, in its folder.
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    let target = match std::fs::canonicalize(path) {
        Ok(real) if is_link => real,
        _ => path.to_path_buf(),
    };
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if name.starts_with(super::RESERVED_PREFIX) {
        return Err(WriteError::Reserved(path.display().to_string()));
    }
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|e| io_err(&dir, e))?;
    let _lock = OutputLock::acquire(&dir, blocked)?;
    let root = std::fs::canonicalize(&dir).map_err(|e| io_err(&dir, e))?;
    let mut report = WriteReport {
        recovered: journal::recover(&root, &dir)?,
        ..WriteReport::default()
    };
    check_file(path, inputs)?;
    let target = dir.join(&name);
    if existing(&target)?.is_some_and(|old| old == contents) {
        report.unchanged.push(path.to_path_buf());
        return Ok(report);
    }
    let tmp = dir.join(format!("{TMP_PREFIX}{}-{name}", std::process::id()));
    let staged = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .and_then(|mut f| f.write_all(contents));
    if let Err(e) = staged.and_then(|()| std::fs::rename(&tmp, &target)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_err(&target, e));
    }
    report.written.push(path.to_path_buf());
    Ok(report)
}

/// Rewrite a source file the user named in place (`rcsc fmt`): the one
/// write that replaces an input on purpose, so it skips the marker and
/// input checks of [`write_file`] but keeps the rest of its rules — the
/// folder's lock, a link followed to the file it names, the contents staged
/// to a temporary beside the file and renamed over it (a failure leaves the
/// original whole), the file's permissions kept. The file must exist:
/// this replaces, never creates. Unchanged bytes are not rewritten.
pub fn rewrite_source(
    path: &Path,
    contents: &str,
    blocked: &mut dyn FnMut(&Path),
) -> Result<WriteReport, WriteError> {
    let target = std::fs::canonicalize(path).map_err(|e| io_err(path, e))?;
    let meta = std::fs::metadata(&target).map_err(|e| io_err(path, e))?;
    if !meta.is_file() {
        return Err(WriteError::InTheWay {
            path: path.display().to_string(),
            why: "it is not a file",
        });
    }
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if name.starts_with(super::RESERVED_PREFIX) {
        return Err(WriteError::Reserved(path.display().to_string()));
    }
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let _lock = OutputLock::acquire(&dir, blocked)?;
    let mut report = WriteReport::default();
    if existing(&target)?.is_some_and(|old| old == contents.as_bytes()) {
        report.unchanged.push(path.to_path_buf());
        return Ok(report);
    }
    let tmp = dir.join(format!("{TMP_PREFIX}{}-{name}", std::process::id()));
    let staged = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .and_then(|mut f| {
            f.write_all(contents.as_bytes())?;
            f.sync_all()?;
            std::fs::set_permissions(&tmp, meta.permissions())
        });
    if let Err(e) = staged.and_then(|()| std::fs::rename(&tmp, &target)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_err(&target, e));
    }
    report.written.push(path.to_path_buf());
    Ok(report)
}
