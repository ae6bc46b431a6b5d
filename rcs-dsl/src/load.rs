//! Stage 0: paths on disk → [`PlanSet`]s (a [`SourceMap`] plus which file is
//! the manifest). The only module of the front end that reads files.
//!
//! A folder is one plan set: its `rcs.yaml` (if any) decides which files
//! belong to it, otherwise every `*.rcs` below it does. Loose `.rcs` files
//! named together form one more set. Files are ordered by path so that the
//! result never depends on the order the file system lists them in.

use crate::diagnostic::{Code, Diagnostic};
use crate::manifest::{self, Manifest};
use crate::parser::MAX_FILE_BYTES;
use crate::source::{FileId, SourceMap, Span};
use std::path::{Path, PathBuf};

/// A failure that is not a diagnostic: a path that cannot be read at all.
/// The CLI exits with status 2 and this one-line reason.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error("{path}: no such file or directory")]
    NotFound { path: String },
    #[error("{path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: not a `.rcs` file or a plan-set folder")]
    NotPlan { path: String },
}

/// One plan set, loaded: sources, the manifest and what went wrong reading them.
#[derive(Debug, Default)]
pub struct PlanSet {
    /// The folder's name (default system name), or `plans` for loose files.
    pub name: String,
    /// The plan-set folder as the user named it (`/`-separated); empty for
    /// loose files and in-memory sets. Generated outputs name files
    /// relative to it, so they never depend on where the set lives.
    pub root: String,
    pub sources: SourceMap,
    /// The `.rcs` files, sorted by path.
    pub rcs_files: Vec<FileId>,
    pub manifest_file: Option<FileId>,
    pub manifest: Manifest,
    /// Encoding and manifest problems found while loading.
    pub diagnostics: Vec<Diagnostic>,
}

impl PlanSet {
    /// A plan set from in-memory texts (tests, build tools, editors).
    pub fn from_texts<'a>(
        name: &str,
        files: impl IntoIterator<Item = (&'a str, &'a str)>,
        manifest_text: Option<&str>,
    ) -> PlanSet {
        let mut set = PlanSet {
            name: name.to_string(),
            ..PlanSet::default()
        };
        let mut files: Vec<_> = files.into_iter().collect();
        files.sort();
        if let Some(text) = manifest_text {
            set.add_manifest("rcs.yaml", text.to_string());
        }
        for (path, text) in files {
            let id = set.sources.add(path, text);
            set.rcs_files.push(id);
        }
        set
    }

    /// A file's path relative to the set's root (its file name for loose files).
    pub fn relative_path(&self, id: FileId) -> String {
        let path = &self.sources.get(id).path;
        let root = self.root.trim_end_matches('/');
        if !root.is_empty() {
            if let Some(rest) = path.strip_prefix(root).and_then(|r| r.strip_prefix('/')) {
                return rest.to_string();
            }
        }
        if self.root.is_empty() && !path.starts_with('/') {
            if let Some(name) = std::path::Path::new(path).file_name() {
                return name.to_string_lossy().into_owned();
            }
        }
        path.rsplit('/').next().unwrap_or(path).to_string()
    }

    fn add_manifest(&mut self, path: &str, text: String) {
        let id = self.sources.add(path, text);
        self.manifest_file = Some(id);
        match manifest::parse(id, self.sources.get(id)) {
            Ok(m) => self.manifest = m,
            Err(d) => self.diagnostics.extend(d),
        }
    }

    fn add_bytes(&mut self, display: String, bytes: Vec<u8>) -> FileId {
        if bytes.len() > MAX_FILE_BYTES {
            // Keep only a little text: the diagnostic needs a file, not its contents.
            let id = self.sources.add(display, String::new());
            self.diagnostics.push(
                Diagnostic::error(
                    Code::Syntax,
                    format!(
                        "file is too large ({} bytes; the limit is {MAX_FILE_BYTES} bytes)",
                        bytes.len()
                    ),
                    Span::new(id, 0, 0),
                    "this file",
                )
                .with_help("split the plan set into smaller files"),
            );
            return id;
        }
        match String::from_utf8(bytes) {
            Ok(text) => self.sources.add(display, text),
            Err(e) => {
                let offset = e.utf8_error().valid_up_to();
                let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
                // The lossy text has the same prefix, so the offset is valid in it.
                let id = self.sources.add(display.clone(), text);
                self.diagnostics.push(
                    Diagnostic::error(
                        Code::Syntax,
                        format!(
                            "`{display}` is not valid UTF-8 (first bad byte at offset {offset})"
                        ),
                        // The lossy text holds U+FFFD where the bad byte was.
                        Span::new(id, offset, offset + '\u{FFFD}'.len_utf8()),
                        "invalid UTF-8 here",
                    )
                    .with_help("save the file as UTF-8"),
                );
                id
            }
        }
    }
}

/// Load the plan sets named on a command line: each folder is a set; all
/// loose `.rcs` files together are one more set (last).
pub fn load_paths(paths: &[PathBuf]) -> Result<Vec<PlanSet>, LoadError> {
    let mut sets = Vec::new();
    let mut loose: Vec<PathBuf> = Vec::new();
    for path in paths {
        let meta = std::fs::metadata(path).map_err(|e| io_error(path, e))?;
        if meta.is_dir() {
            sets.push(load_folder(path)?);
        } else if path.extension().is_some_and(|e| e == "rcs") {
            loose.push(path.clone());
        } else if path.file_name().is_some_and(|n| n == "rcs.yaml") {
            sets.push(load_folder(path.parent().unwrap_or(Path::new(".")))?);
        } else {
            return Err(LoadError::NotPlan {
                path: display(path),
            });
        }
    }
    if !loose.is_empty() {
        loose.sort();
        loose.dedup();
        let mut set = PlanSet {
            name: loose[0]
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "plans".to_string()),
            ..PlanSet::default()
        };
        for p in loose {
            let bytes = read(&p)?;
            let id = set.add_bytes(display(&p), bytes);
            set.rcs_files.push(id);
        }
        sets.push(set);
    }
    Ok(sets)
}

/// Load one plan-set folder.
pub fn load_folder(root: &Path) -> Result<PlanSet, LoadError> {
    let name = std::fs::canonicalize(root)
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "plans".to_string());
    let mut set = PlanSet {
        name,
        root: display(root),
        ..PlanSet::default()
    };
    let manifest_path = root.join("rcs.yaml");
    if manifest_path.is_file() {
        let bytes = read(&manifest_path)?;
        match String::from_utf8(bytes) {
            Ok(text) => set.add_manifest(&display(&manifest_path), text),
            Err(_) => {
                let id = set.sources.add(display(&manifest_path), String::new());
                set.diagnostics.push(Diagnostic::error(
                    Code::Manifest,
                    "`rcs.yaml` is not valid UTF-8",
                    Span::new(id, 0, 0),
                    "this file",
                ));
            }
        }
    }
    let mut files: Vec<PathBuf> = Vec::new();
    match set.manifest.plans.clone() {
        Some(entries) => {
            for (entry, span) in entries {
                let p = root.join(&entry);
                if p.is_dir() {
                    collect_rcs(&p, &mut files, 0).map_err(|e| io_error(&p, e))?;
                } else if p.is_file() {
                    files.push(p);
                } else {
                    set.diagnostics.push(Diagnostic::error(
                        Code::Manifest,
                        format!("`plans` names `{entry}`, which does not exist"),
                        span,
                        "no such file or folder",
                    ));
                }
            }
        }
        None => collect_rcs(root, &mut files, 0).map_err(|e| io_error(root, e))?,
    }
    files.sort();
    files.dedup();
    for p in files {
        let bytes = read(&p)?;
        let id = set.add_bytes(display(&p), bytes);
        set.rcs_files.push(id);
    }
    Ok(set)
}

/// Every `*.rcs` below `dir`, not following symlinked folders or hidden ones.
fn collect_rcs(dir: &Path, out: &mut Vec<PathBuf>, depth: usize) -> std::io::Result<()> {
    if depth > 32 {
        return Ok(());
    }
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let path = entry.path();
        let ty = entry.file_type()?;
        let hidden = entry.file_name().to_string_lossy().starts_with('.');
        if ty.is_dir() && !hidden {
            collect_rcs(&path, out, depth + 1)?;
        } else if (ty.is_file() || ty.is_symlink()) && path.extension().is_some_and(|e| e == "rcs")
        {
            out.push(path);
        }
    }
    Ok(())
}

fn read(path: &Path) -> Result<Vec<u8>, LoadError> {
    std::fs::read(path).map_err(|e| io_error(path, e))
}

fn io_error(path: &Path, e: std::io::Error) -> LoadError {
    if e.kind() == std::io::ErrorKind::NotFound {
        LoadError::NotFound {
            path: display(path),
        }
    } else {
        LoadError::Io {
            path: display(path),
            source: e,
        }
    }
}

/// A path as the user would type it: `/`-separated, without a leading `./`.
pub fn display(path: &Path) -> String {
    let s = path.to_string_lossy().replace('\\', "/");
    s.strip_prefix("./").map(str::to_string).unwrap_or(s)
}
