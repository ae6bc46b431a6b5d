//! Stage 0: paths on disk → [`PlanSet`]s (a [`SourceMap`] plus which file is
//! the manifest). The only module of the front end that reads files.
//!
//! As a Cargo package owns the files below its `Cargo.toml`, every
//! `rcs.yaml` starts a plan set that owns the `*.rcs` files below it, up to
//! the next `rcs.yaml` (or those its `plans:` names). A folder without a
//! manifest whose subfolders hold plans is a *workspace*: each such
//! subfolder is a plan set of its own (named after the folder), and `.rcs`
//! files standing loose beside them are a `loose_file` error. A manifest
//! with `workspace: [folders]` makes its folder a workspace of those
//! folders. Any other folder is one plan set. Loose `.rcs` files named
//! together on a command line form one more set. Files and sets are ordered
//! by path so that the result never depends on the order the file system
//! lists them in.

use crate::diagnostic::{Code, Diagnostic};
use crate::manifest::{self, Manifest};
use crate::parser::MAX_FILE_BYTES;
use crate::source::{FileId, SourceMap, Span};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

mod no_plans;

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
    /// The workspace folder the set was found in (`/`-separated), when it
    /// was reached through a workspace or below another set rather than
    /// named itself. `rcsc build` puts such sets into `DIR/<system>/`.
    pub workspace: Option<String>,
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
                let (id, offset) = self.add_lossy(display.clone(), &e);
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

/// Load the plan sets named on a command line, in order: each folder stands
/// for every plan set in it (see the module docs), and all loose `.rcs`
/// files named together form one more set, last. A set reached twice (a
/// workspace and one of its members both named) is loaded once.
pub fn load_paths(paths: &[PathBuf]) -> Result<Vec<PlanSet>, LoadError> {
    let mut sets = Vec::new();
    let mut loose: Vec<PathBuf> = Vec::new();
    for path in paths {
        let meta = std::fs::metadata(path).map_err(|e| io_error(path, e))?;
        if meta.is_dir() {
            load_tree(path, None, &mut sets, 0)?;
        } else if path.extension().is_some_and(|e| e == "rcs") {
            loose.push(path.clone());
        } else if path.file_name().is_some_and(|n| n == MANIFEST) {
            load_tree(parent_folder(path), None, &mut sets, 0)?;
        } else {
            return Err(LoadError::NotPlan {
                path: display(path),
            });
        }
    }
    let mut seen = BTreeSet::new();
    sets.retain(|set: &PlanSet| {
        let key = std::fs::canonicalize(&set.root).unwrap_or_else(|_| PathBuf::from(&set.root));
        seen.insert(key)
    });
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
    if shares_output(&sets) {
        report_case_collisions(&mut sets);
    }
    Ok(sets)
}

/// The system name a plan set will have (its folder is `<system>/` in a
/// shared output folder).
fn system_name(set: &PlanSet) -> (String, Option<Span>) {
    match &set.manifest.system {
        Some((name, span)) => (name.clone(), Some(*span)),
        None => (crate::sanitize(&set.name), None),
    }
}

/// `case_collision` for plan sets sharing an output folder whose system
/// names differ only in case (`Sub/` and `sub/` are one folder on a
/// case-insensitive file system), reported at the `system:` that named one
/// (equal names are refused when the outputs are generated).
fn report_case_collisions(sets: &mut [PlanSet]) {
    let names: Vec<(String, Option<Span>)> = sets.iter().map(system_name).collect();
    let indexed = names
        .iter()
        .enumerate()
        .map(|(i, (name, _))| (name.as_str(), i));
    for ((_, ai), (_, bi)) in crate::checks::names::case_pairs(indexed) {
        // Report at whichever `system:` is written (at least one is: folder
        // names are lowercased).
        let (here, other) = match (names[bi].1, names[ai].1) {
            (Some(span), _) => ((bi, span), ai),
            (None, Some(span)) => ((ai, span), bi),
            (None, None) => continue,
        };
        let (this, that) = (&names[here.0].0, &names[other].0);
        let other_root = sets[other].root.clone();
        sets[here.0].diagnostics.push(
            Diagnostic::error(
                Code::CaseCollision,
                format!("plan sets `{this}` and `{that}` differ only in case"),
                here.1,
                format!("`{that}` but for case"),
            )
            .with_note(format!(
                "`{that}` is the plan set at `{other_root}`; their outputs go to `{this}/` and \
                 `{that}/` of one output folder, which case-insensitive file systems (macOS \
                 and Windows by default) see as one folder"
            ))
            .with_help("rename one (`system:` in its rcs.yaml)"),
        );
    }
}

/// Load exactly one plan-set folder: its `.rcs` files (honouring its
/// `rcs.yaml`), without the plan sets nested below it. For tools that know
/// they hold one set; [`load_paths`] is what the commands use.
pub fn load_folder(root: &Path) -> Result<PlanSet, LoadError> {
    let mut nested = Vec::new();
    let mut set = new_set(root, None);
    let manifest_path = root.join(MANIFEST);
    if manifest_path.is_file() {
        set.read_manifest(&manifest_path)?;
    }
    set.collect_files(root, &mut nested)?;
    Ok(set)
}

/// Whether the outputs of `sets` share one output folder, each set in a
/// `<system>/` folder of its own: always, except for one plan set named
/// alone (not reached through a workspace).
pub fn shares_output(sets: &[PlanSet]) -> bool {
    !matches!(sets, [one] if one.workspace.is_none())
}

const MANIFEST: &str = "rcs.yaml";

/// How deep folders are searched for plan sets and `.rcs` files.
const MAX_DEPTH: usize = 32;

/// The folder of a file path (`.` for a bare file name).
fn parent_folder(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The plan sets in the tree at `dir`, appended to `sets` in path order.
///
/// - A folder with an `rcs.yaml` is a plan set owning the `.rcs` files below
///   it, up to the next `rcs.yaml` (nested sets are loaded as sets of their
///   own, never dropped) — unless the manifest has `workspace:`, which makes
///   the folder a workspace of the folders it lists.
/// - A folder without one whose subfolders hold `.rcs` files or manifests
///   is a workspace: each such subfolder is loaded the same way. `.rcs`
///   files directly in it stand loose beside those plan sets: an error.
/// - Any other folder is one plan set named after it.
fn load_tree(
    dir: &Path,
    workspace: Option<&str>,
    sets: &mut Vec<PlanSet>,
    depth: usize,
) -> Result<(), LoadError> {
    if depth > MAX_DEPTH {
        return Ok(());
    }
    let manifest_path = dir.join(MANIFEST);
    if manifest_path.is_file() {
        let mut set = new_set(dir, workspace);
        set.read_manifest(&manifest_path)?;
        if let Some(members) = set.manifest.workspace.clone() {
            let here = display(dir);
            for (member, span) in members {
                let p = dir.join(&member);
                if p.is_dir() {
                    load_tree(&p, Some(&here), sets, depth + 1)?;
                } else {
                    set.diagnostics.push(Diagnostic::error(
                        Code::Manifest,
                        format!("`workspace` names `{member}`, which is not a folder"),
                        span,
                        "no such folder",
                    ));
                }
            }
            // A workspace manifest has no plans; it is reported only when wrong.
            if !set.diagnostics.is_empty() {
                sets.push(set);
            }
            return Ok(());
        }
        let mut nested = Vec::new();
        set.collect_files(dir, &mut nested)?;
        set.report_no_plans(dir, !nested.is_empty());
        let here = display(dir);
        sets.push(set);
        for n in nested {
            load_tree(&n, Some(&here), sets, depth + 1)?;
        }
        return Ok(());
    }

    let (direct, subdirs) = list_folder(dir)?;
    let mut members = Vec::new();
    for sub in subdirs {
        if holds_plans(&sub, depth + 1).map_err(|e| io_error(&sub, e))? {
            members.push(sub);
        }
    }
    if members.is_empty() {
        let mut set = new_set(dir, workspace);
        for p in direct {
            set.add_file(&p)?;
        }
        set.report_no_plans(dir, false);
        sets.push(set);
        return Ok(());
    }
    let here = display(dir);
    if !direct.is_empty() {
        let mut set = new_set(dir, workspace);
        let names: Vec<String> = members
            .iter()
            .map(|m| format!("`{}/`", file_name(m)))
            .collect();
        for p in direct {
            let id = set.add_file(&p)?;
            set.diagnostics.push(
                Diagnostic::error(
                    Code::LooseFile,
                    format!(
                        "`{}` stands loose beside the plan-set folders {}",
                        file_name(&p),
                        names.join(", ")
                    ),
                    Span::new(id, 0, 0),
                    "belongs to no plan set",
                )
                .with_note(format!(
                    "`{here}` has no `rcs.yaml` and subfolders that hold plans, so it is a \
                     workspace: each of those subfolders is a plan set of its own"
                ))
                .with_help(format!(
                    "move the file into one of the plan-set folders, or add an `rcs.yaml` to \
                     `{here}` to make the whole folder one plan set"
                )),
            );
        }
        sets.push(set);
    }
    for m in members {
        load_tree(&m, Some(&here), sets, depth + 1)?;
    }
    Ok(())
}

fn new_set(dir: &Path, workspace: Option<&str>) -> PlanSet {
    let name = std::fs::canonicalize(dir)
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "plans".to_string());
    PlanSet {
        name,
        root: display(dir),
        workspace: workspace.map(str::to_string),
        ..PlanSet::default()
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| display(path))
}

/// Whether an entry is hidden (`.git`, editor folders): never searched.
fn hidden(name: &std::ffi::OsStr) -> bool {
    name.to_string_lossy().starts_with('.')
}

/// The `.rcs` files directly in `dir` and its subfolders (not hidden, not
/// through symlinks), each sorted.
fn list_folder(dir: &Path) -> Result<(Vec<PathBuf>, Vec<PathBuf>), LoadError> {
    let mut files = Vec::new();
    let mut dirs = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(|e| io_error(dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| io_error(dir, e))?;
        let path = entry.path();
        let ty = entry.file_type().map_err(|e| io_error(&path, e))?;
        if hidden(&entry.file_name()) {
            continue;
        }
        if ty.is_dir() {
            dirs.push(path);
        } else if is_rcs(&path, ty) {
            files.push(path);
        }
    }
    files.sort();
    dirs.sort();
    Ok((files, dirs))
}

fn is_rcs(path: &Path, ty: std::fs::FileType) -> bool {
    (ty.is_file() || ty.is_symlink()) && path.extension().is_some_and(|e| e == "rcs")
}

/// Whether a `.rcs` file or an `rcs.yaml` lies anywhere below `dir`.
fn holds_plans(dir: &Path, depth: usize) -> std::io::Result<bool> {
    if depth > MAX_DEPTH {
        return Ok(false);
    }
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        if hidden(&entry.file_name()) {
            continue;
        }
        let path = entry.path();
        let ty = entry.file_type()?;
        if ty.is_dir() {
            if holds_plans(&path, depth + 1)? {
                return Ok(true);
            }
        } else if is_rcs(&path, ty) || entry.file_name() == MANIFEST {
            return Ok(true);
        }
    }
    Ok(false)
}

impl PlanSet {
    /// Read and parse the set's manifest.
    fn read_manifest(&mut self, path: &Path) -> Result<(), LoadError> {
        let bytes = read(path)?;
        match String::from_utf8(bytes) {
            Ok(text) => self.add_manifest(&display(path), text),
            Err(e) => {
                // Shown, not read: the manifest's settings are left out.
                let (id, offset) = self.add_lossy(display(path), &e);
                self.diagnostics.push(
                    Diagnostic::error(
                        Code::Manifest,
                        format!(
                            "`rcs.yaml` is not valid UTF-8 (first bad byte at offset {offset})"
                        ),
                        Span::new(id, offset, offset + '\u{FFFD}'.len_utf8()),
                        "invalid UTF-8 here",
                    )
                    .with_help("save the file as UTF-8"),
                );
            }
        }
        Ok(())
    }

    /// A file that is not valid UTF-8, added with U+FFFD for each bad
    /// sequence so that it can be shown; with the offset of the first bad
    /// byte in the added text.
    fn add_lossy(&mut self, display: String, e: &std::string::FromUtf8Error) -> (FileId, usize) {
        let mut offset = e.utf8_error().valid_up_to();
        let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
        // The lossy text has the same prefix, so the offset is valid in it,
        // less the byte-order mark the source map drops.
        if text.starts_with(crate::source::BOM) {
            offset -= crate::source::BOM.len_utf8();
        }
        (self.sources.add(display, text), offset)
    }

    /// Read one `.rcs` file into the set.
    fn add_file(&mut self, path: &Path) -> Result<FileId, LoadError> {
        let bytes = read(path)?;
        let id = self.add_bytes(display(path), bytes);
        self.rcs_files.push(id);
        Ok(id)
    }

    /// The set's `.rcs` files below `root` (those its manifest's `plans:`
    /// names, or all of them), stopping at folders with their own manifest,
    /// which go to `nested`.
    fn collect_files(&mut self, root: &Path, nested: &mut Vec<PathBuf>) -> Result<(), LoadError> {
        let mut files: Vec<PathBuf> = Vec::new();
        match self.manifest.plans.clone() {
            Some(entries) => {
                // Nested sets are found by walking the whole folder either way.
                let mut ignored = Vec::new();
                collect_rcs(root, &mut ignored, nested, 0).map_err(|e| io_error(root, e))?;
                for (entry, span) in entries {
                    let p = root.join(&entry);
                    if p.is_dir() && p.join(MANIFEST).is_file() && p != root {
                        self.diagnostics.push(
                            Diagnostic::error(
                                Code::Manifest,
                                format!(
                                    "`plans` names `{entry}`, which has an `rcs.yaml` of its own"
                                ),
                                span,
                                "a plan set of its own",
                            )
                            .with_help(
                                "a folder with its own `rcs.yaml` is a separate plan set; \
                                 remove it from `plans`, or remove its `rcs.yaml`",
                            ),
                        );
                    } else if p.is_dir() {
                        collect_rcs(&p, &mut files, &mut Vec::new(), 0)
                            .map_err(|e| io_error(&p, e))?;
                    } else if p.is_file() {
                        files.push(p);
                    } else {
                        self.diagnostics.push(Diagnostic::error(
                            Code::Manifest,
                            format!("`plans` names `{entry}`, which does not exist"),
                            span,
                            "no such file or folder",
                        ));
                    }
                }
            }
            None => collect_rcs(root, &mut files, nested, 0).map_err(|e| io_error(root, e))?,
        }
        files.sort();
        files.dedup();
        for p in files {
            self.add_file(&p)?;
        }
        Ok(())
    }
}

/// Every `*.rcs` below `dir`, not following symlinked folders or hidden
/// ones; subfolders with their own manifest go to `nested` instead.
fn collect_rcs(
    dir: &Path,
    out: &mut Vec<PathBuf>,
    nested: &mut Vec<PathBuf>,
    depth: usize,
) -> std::io::Result<()> {
    if depth > MAX_DEPTH {
        return Ok(());
    }
    let mut entries: Vec<_> = std::fs::read_dir(dir)?.collect::<Result<_, _>>()?;
    entries.sort_by_key(|e| e.file_name());
    for entry in entries {
        let path = entry.path();
        let ty = entry.file_type()?;
        if hidden(&entry.file_name()) {
            continue;
        }
        if ty.is_dir() && path.join(MANIFEST).is_file() {
            nested.push(path);
        } else if ty.is_dir() {
            collect_rcs(&path, out, nested, depth + 1)?;
        } else if is_rcs(&path, ty) {
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
