//! The one place that writes generated files. Everything else in rcsc is a
//! pure function from the IR to [`OutputFile`]s.
//!
//! Files are written atomically (a temporary file in the same folder, then a
//! rename), only when their bytes changed, and only under the output folder:
//! a path that would leave it is refused before anything is written.

use crate::OutputFile;
use std::io;
use std::path::{Component, Path, PathBuf};

/// What a write did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WriteReport {
    /// Files whose bytes changed (or that did not exist).
    pub written: Vec<PathBuf>,
    /// Files already up to date.
    pub unchanged: Vec<PathBuf>,
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
