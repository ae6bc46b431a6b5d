//! What the [writer](super) checks before it changes anything: that a
//! generated path stays inside the output folder (as written, and once
//! symbolic links are followed), that a file it would replace or remove is
//! one rcsc generated, and which generated files are stale.

use super::{io_err, WriteError, JOURNAL_FILE, LOCK_FILE, MAX_DEPTH, RESERVED_PREFIX};
use crate::GENERATED;
use std::collections::BTreeSet;
use std::io::{self, Read};
use std::path::{Component, Path, PathBuf};

/// A relative path made only of normal components (pure).
pub(crate) fn safe_relative(path: &str) -> bool {
    let p = Path::new(path);
    !path.is_empty() && p.components().all(|c| matches!(c, Component::Normal(_)))
}

/// Whether a path has a component the writer keeps for itself (pure).
pub(super) fn reserved(path: &str) -> bool {
    path.split('/').any(|c| c.starts_with(RESERVED_PREFIX))
}

/// What is at a generated path now.
#[derive(Debug, PartialEq, Eq)]
pub(super) enum Existing {
    /// Nothing: the file (and maybe folders above it) will be created.
    Nothing,
    /// A file with these bytes (through a link that stays inside).
    File(Vec<u8>),
}

/// Check that writing `rel` under `out_dir` stays inside `root` (the
/// canonical `out_dir`) when symbolic links are followed, and that no
/// file stands where a folder must be or the other way round; return what
/// is there now.
pub(super) fn inspect(root: &Path, out_dir: &Path, rel: &str) -> Result<Existing, WriteError> {
    let parts: Vec<&str> = rel.split('/').collect();
    let mut path = out_dir.to_path_buf();
    for (i, part) in parts.iter().enumerate() {
        path.push(part);
        let last = i + 1 == parts.len();
        let meta = match std::fs::symlink_metadata(&path) {
            Ok(meta) => meta,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Existing::Nothing),
            Err(e) => return Err(io_err(&path, e)),
        };
        let meta = if meta.file_type().is_symlink() {
            let why = match std::fs::canonicalize(&path) {
                Ok(to) if to.starts_with(root) => None,
                Ok(to) => Some(format!(
                    "it is a symbolic link to `{}`, outside the output folder",
                    to.display()
                )),
                Err(_) => Some("it is a symbolic link to nothing".to_string()),
            };
            if let Some(why) = why {
                return Err(WriteError::Symlink {
                    path: path.display().to_string(),
                    why,
                });
            }
            std::fs::metadata(&path).map_err(|e| io_err(&path, e))?
        } else {
            meta
        };
        if !last && !meta.is_dir() {
            return Err(WriteError::InTheWay {
                path: path.display().to_string(),
                why: "it is a file where rcsc needs a folder",
            });
        }
        if last {
            if !meta.is_file() {
                return Err(WriteError::InTheWay {
                    path: path.display().to_string(),
                    why: "it is a folder (or not a regular file) where rcsc writes a file",
                });
            }
            let bytes = std::fs::read(&path).map_err(|e| io_err(&path, e))?;
            return Ok(Existing::File(bytes));
        }
    }
    Ok(Existing::Nothing)
}

/// How much of a file [`is_generated`] reads: the first line of a text
/// file, or the header record of an MCAP recording.
const HEAD: usize = 512;

/// Whether the first line of a file (the header of an MCAP recording)
/// carries the [`GENERATED`] marker.
pub fn is_generated(path: &Path) -> bool {
    let mut head = Vec::with_capacity(HEAD);
    let read = std::fs::File::open(path).and_then(|f| f.take(HEAD as u64).read_to_end(&mut head));
    read.is_ok() && first_line_generated(&head)
}

/// Whether these bytes start with a line carrying [`GENERATED`] or, for
/// an MCAP recording (whose magic bytes end in a newline), whether its
/// header's `library` field carries it (pure).
pub(super) fn first_line_generated(bytes: &[u8]) -> bool {
    let first = match mcap_library(bytes) {
        Some(library) => library,
        None => bytes.split(|&b| b == b'\n').next().unwrap_or(&[]),
    };
    first
        .windows(GENERATED.len())
        .any(|w| w == GENERATED.as_bytes())
}

/// MCAP's magic bytes.
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// The `library` field of an MCAP file's header record, which follows the
/// magic bytes: opcode 0x01, the record's length (u64), then `profile` and
/// `library`, each a u32 length and its bytes, little-endian (pure).
/// `None`: not MCAP, or too short to hold the field.
fn mcap_library(bytes: &[u8]) -> Option<&[u8]> {
    let header = bytes.strip_prefix(MCAP_MAGIC)?;
    if *header.first()? != 0x01 {
        return None;
    }
    let string_at = |at: usize| -> Option<(&[u8], usize)> {
        let len: [u8; 4] = header.get(at..at + 4)?.try_into().ok()?;
        let len = usize::try_from(u32::from_le_bytes(len)).ok()?;
        let start = at + 4;
        Some((header.get(start..start.checked_add(len)?)?, start + len))
    };
    let (_profile, next) = string_at(1 + 8)?;
    string_at(next).map(|(library, _)| library)
}

/// Generated regular files below `dir` that are not in `keep` (relative
/// `/`-separated paths), skipping symbolic links and the writer's own
/// files, sorted.
pub(super) fn find_stale(dir: &Path, keep: &BTreeSet<String>) -> Result<Vec<String>, WriteError> {
    let mut out = Vec::new();
    let mut folders = vec![(dir.to_path_buf(), String::new(), 0)];
    while let Some((folder, rel, depth)) = folders.pop() {
        let entries = std::fs::read_dir(&folder).map_err(|e| io_err(&folder, e))?;
        for entry in entries {
            let entry = entry.map_err(|e| io_err(&folder, e))?;
            let path = entry.path();
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.starts_with(RESERVED_PREFIX) {
                continue;
            }
            let rel = format!("{rel}{name}");
            // `file_type` does not follow symbolic links: links are skipped.
            let ty = entry.file_type().map_err(|e| io_err(&path, e))?;
            if ty.is_dir() && depth < MAX_DEPTH && !another_root(&path) {
                folders.push((path, format!("{rel}/"), depth + 1));
            } else if ty.is_file()
                && !keep.contains(&rel)
                && !same_as_kept(dir, &rel, keep)
                && is_generated(&path)
            {
                out.push(rel);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Whether a folder below the output folder is, right now, the output
/// folder of another build (it holds that build's lock or journal): the
/// sweeps leave it to that build.
pub(super) fn another_root(dir: &Path) -> bool {
    [LOCK_FILE, JOURNAL_FILE]
        .iter()
        .any(|f| std::fs::symlink_metadata(dir.join(f)).is_ok())
}

/// Whether `rel` is, on a case-insensitive file system, the same file as
/// a kept path that differs from it only in case (then it is not stale).
fn same_as_kept(dir: &Path, rel: &str, keep: &BTreeSet<String>) -> bool {
    let lower = rel.to_lowercase();
    keep.iter()
        .filter(|k| k.to_lowercase() == lower)
        .any(|k| same_file(&dir.join(rel), &dir.join(k)))
}

#[cfg(unix)]
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::symlink_metadata(a), std::fs::symlink_metadata(b)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Without inode numbers, a case-only difference is taken as the same
/// file: at worst a stale file stays.
#[cfg(not(unix))]
fn same_file(_a: &Path, b: &Path) -> bool {
    b.exists()
}

/// The parent folders of `files` up to (not including) `out_dir`, deepest
/// first (pure).
pub(super) fn parents_deepest_first(out_dir: &Path, files: &[PathBuf]) -> Vec<PathBuf> {
    let mut dirs: BTreeSet<PathBuf> = BTreeSet::new();
    for path in files {
        let mut d = path.parent();
        while let Some(dir) = d.filter(|d| *d != out_dir && d.starts_with(out_dir)) {
            dirs.insert(dir.to_path_buf());
            d = dir.parent();
        }
    }
    let mut dirs: Vec<PathBuf> = dirs.into_iter().collect();
    dirs.sort_by_key(|d| std::cmp::Reverse(d.components().count()));
    dirs
}
