//! The one place that writes generated files. Everything else in rcsc is a
//! pure function from the IR to [`OutputFile`]s.
//!
//! Files are written atomically (a temporary file in the same folder, then a
//! rename), only when their bytes changed, and only under the output folder:
//! a path that would leave it is refused before anything is written.
//!
//! [`write_tree`] also removes *stale* outputs: files under the output folder
//! that an earlier run generated (their first line carries [`GENERATED`]) and
//! that the current run no longer produces. Nothing else is ever removed.

use crate::{OutputFile, GENERATED};
use std::collections::BTreeSet;
use std::io::{self, Read};
use std::path::{Component, Path, PathBuf};

/// What a write did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WriteReport {
    /// Files whose bytes changed (or that did not exist).
    pub written: Vec<PathBuf>,
    /// Files already up to date.
    pub unchanged: Vec<PathBuf>,
    /// Stale generated files removed by [`write_tree`].
    pub removed: Vec<PathBuf>,
}

#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    #[error("refusing to write `{0}`: generated paths must stay inside the output folder")]
    OutsideOutput(String),
    #[error("{path}: {source}")]
    Io { path: String, source: io::Error },
}

fn io_err(path: &Path, source: io::Error) -> WriteError {
    WriteError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// A relative path made only of normal components.
fn safe_relative(path: &str) -> bool {
    let p = Path::new(path);
    !path.is_empty() && p.components().all(|c| matches!(c, Component::Normal(_)))
}

/// Write `files` under `out_dir`. Every path is validated first, so an
/// invalid one leaves the folder untouched.
pub fn write_files(out_dir: &Path, files: &[OutputFile]) -> Result<WriteReport, WriteError> {
    if let Some(bad) = files.iter().find(|f| !safe_relative(&f.path)) {
        return Err(WriteError::OutsideOutput(bad.path.clone()));
    }
    let mut report = WriteReport::default();
    for f in files {
        let path = out_dir.join(&f.path);
        if std::fs::read(&path).is_ok_and(|old| old == f.contents.as_bytes()) {
            report.unchanged.push(path);
            continue;
        }
        let dir = path.parent().unwrap_or(out_dir);
        std::fs::create_dir_all(dir).map_err(|e| io_err(dir, e))?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let tmp = dir.join(format!(".{name}.rcsc-{}.tmp", std::process::id()));
        std::fs::write(&tmp, f.contents.as_bytes()).map_err(|e| io_err(&tmp, e))?;
        if let Err(e) = std::fs::rename(&tmp, &path) {
            let _ = std::fs::remove_file(&tmp);
            return Err(io_err(&path, e));
        }
        report.written.push(path);
    }
    Ok(report)
}

/// Write `files` under `out_dir` as the complete output of a run: like
/// [`write_files`], then remove every file below `out_dir` that carries the
/// [`GENERATED`] marker in its first line and is not among `files` (and the
/// folders that this leaves empty). Files without the marker, symbolic
/// links and anything outside `out_dir` are never touched.
pub fn write_tree(out_dir: &Path, files: &[OutputFile]) -> Result<WriteReport, WriteError> {
    let mut report = write_files(out_dir, files)?;
    let keep: BTreeSet<PathBuf> = files.iter().map(|f| out_dir.join(&f.path)).collect();
    let mut stale = Vec::new();
    if out_dir.is_dir() {
        find_stale(out_dir, &keep, &mut stale, 0)?;
    }
    stale.sort();
    for path in &stale {
        match std::fs::remove_file(path) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(io_err(path, e)),
        }
    }
    // Folders emptied by the removal, deepest first; never `out_dir` itself.
    let mut dirs: BTreeSet<PathBuf> = BTreeSet::new();
    for path in &stale {
        let mut d = path.parent();
        while let Some(dir) = d.filter(|d| *d != out_dir && d.starts_with(out_dir)) {
            dirs.insert(dir.to_path_buf());
            d = dir.parent();
        }
    }
    for dir in dirs.iter().rev() {
        // Fails (and is left alone) when the folder still holds something.
        let _ = std::fs::remove_dir(dir);
    }
    report.removed = stale;
    Ok(report)
}

/// Generated files below `dir` that are not in `keep`.
fn find_stale(
    dir: &Path,
    keep: &BTreeSet<PathBuf>,
    out: &mut Vec<PathBuf>,
    depth: usize,
) -> Result<(), WriteError> {
    if depth > 32 {
        return Ok(());
    }
    let entries = std::fs::read_dir(dir).map_err(|e| io_err(dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| io_err(dir, e))?;
        let path = entry.path();
        // `file_type` does not follow symbolic links: links are skipped.
        let ty = entry.file_type().map_err(|e| io_err(&path, e))?;
        if ty.is_dir() {
            find_stale(&path, keep, out, depth + 1)?;
        } else if ty.is_file() && !keep.contains(&path) && is_generated(&path) {
            out.push(path);
        }
    }
    Ok(())
}

/// Whether the first line of a file carries the [`GENERATED`] marker.
pub fn is_generated(path: &Path) -> bool {
    let mut head = Vec::with_capacity(512);
    let read = std::fs::File::open(path).and_then(|f| f.take(512).read_to_end(&mut head));
    if read.is_err() {
        return false;
    }
    let first = head.split(|&b| b == b'\n').next().unwrap_or(&[]);
    first
        .windows(GENERATED.len())
        .any(|w| w == GENERATED.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("rcs-writer-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn file(path: &str, body: &str) -> OutputFile {
        OutputFile {
            path: path.to_string(),
            contents: format!("// {GENERATED}\n{body}"),
        }
    }

    #[test]
    fn writes_only_what_changed() {
        let dir = scratch("changed");
        let files = [file("a/x.dot", "1"), file("y.md", "2")];
        let r = write_files(&dir, &files).unwrap();
        assert_eq!(r.written.len(), 2);
        let r = write_files(&dir, &files).unwrap();
        assert_eq!((r.written.len(), r.unchanged.len()), (0, 2));
        let r = write_files(&dir, &[file("a/x.dot", "3")]).unwrap();
        assert_eq!(r.written, vec![dir.join("a/x.dot")]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn refuses_paths_leaving_the_folder() {
        let dir = scratch("outside");
        for bad in ["../x", "/etc/x", "", "a/../../x"] {
            let err = write_files(&dir, &[file("ok", ""), file(bad, "")]).unwrap_err();
            assert!(matches!(err, WriteError::OutsideOutput(_)), "{bad}");
        }
        assert!(!dir.join("ok").exists(), "nothing written before the check");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn removes_stale_generated_files_only() {
        let dir = scratch("stale");
        write_tree(
            &dir,
            &[file("graphs/A/GO.dot", ""), file("graphs/h.dot", "")],
        )
        .unwrap();
        std::fs::write(dir.join("graphs/A/notes.txt"), "mine").unwrap();
        std::fs::create_dir_all(dir.join("old")).unwrap();
        std::fs::write(dir.join("old/x.md"), format!("<!-- {GENERATED} -->")).unwrap();
        std::fs::write(dir.join("late.md"), format!("one\n{GENERATED}")).unwrap();
        let r = write_tree(&dir, &[file("graphs/h.dot", "")]).unwrap();
        assert_eq!(
            r.removed,
            vec![dir.join("graphs/A/GO.dot"), dir.join("old/x.md")]
        );
        assert!(dir.join("graphs/A/notes.txt").exists(), "no marker: kept");
        assert!(
            dir.join("late.md").exists(),
            "marker not on the first line: kept"
        );
        assert!(!dir.join("old").exists(), "emptied folder removed");
        assert!(dir.join("graphs/A").exists(), "non-empty folder kept");
        assert!(dir.join("graphs/h.dot").exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_missing_output_folder_is_created() {
        let dir = scratch("missing").join("deep/er");
        let r = write_tree(&dir, &[file("x.dot", "")]).unwrap();
        assert_eq!(r.written.len(), 1);
        assert!(r.removed.is_empty());
        let _ = std::fs::remove_dir_all(dir.parent().unwrap().parent().unwrap());
    }
}
