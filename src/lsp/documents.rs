//! What the server knows: the open documents (their text as the editor has
//! it, saved or not) and, for any of them, its plan set checked with those
//! texts in place of the files on disk.
//!
//! A file's plan set is found as `rcsc check` finds sets: the nearest
//! folder above it with an `rcs.yaml`; failing that its own folder, unless
//! that folder is a workspace (it holds plan-set subfolders), where a
//! file standing loose is a set alone. The set is loaded from disk
//! ([`rcs_dsl::load::load_folder`]) and rebuilt in memory with every open
//! document's text, then checked as the CLI checks it: same pipeline, same
//! codes, spans and help.

use std::cell::OnceCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rcs_dsl::ir::Ir;
use rcs_dsl::load::{load_folder, PlanSet};
use rcs_dsl::source::FileId;
use rcs_dsl::{check, Checked, Options};

use super::symbols::Index;

/// Open documents by path, with their texts.
#[derive(Default)]
pub struct Documents {
    open: BTreeMap<PathBuf, String>,
}

impl Documents {
    pub fn open(&mut self, path: PathBuf, text: String) {
        self.open.insert(path, text);
    }

    pub fn close(&mut self, path: &Path) {
        self.open.remove(path);
    }

    /// The text of `path` as the editor has it, else as it is on disk.
    pub fn current(&self, path: &Path) -> Option<String> {
        self.open
            .get(path)
            .cloned()
            .or_else(|| std::fs::read_to_string(path).ok())
    }
}

/// One plan set checked with the editor's texts.
pub struct Analysis {
    pub set: PlanSet,
    pub checked: Checked,
    /// The absolute path of every file of the set, by `FileId`.
    pub paths: Vec<PathBuf>,
    /// The names as written, built on the first request that needs them
    /// (an edit only publishes diagnostics).
    symbols: OnceCell<Index>,
}

impl Analysis {
    pub fn symbols(&self) -> &Index {
        self.symbols.get_or_init(|| Index::of_set(&self.set))
    }

    /// The IR, also when only stage 3's checks rejected the plans (their
    /// names and spans are whole then).
    pub fn ir(&self) -> Option<&Ir> {
        self.checked
            .ir
            .as_ref()
            .or(self.checked.rejected_by_checks.as_ref())
    }

    pub fn file_of(&self, path: &Path) -> Option<FileId> {
        self.paths
            .iter()
            .position(|p| p == path)
            .map(|i| FileId(u32::try_from(i).unwrap_or(u32::MAX)))
    }

    pub fn path(&self, file: FileId) -> Option<&Path> {
        self.paths.get(file.0 as usize).map(PathBuf::as_path)
    }

    pub fn text(&self, file: FileId) -> &str {
        &self.set.sources.get(file).text
    }
}

/// Where a file's plan set is.
enum Place {
    Folder(PathBuf),
    Alone,
}

fn place_of(file: &Path) -> Place {
    let Some(folder) = file.parent() else {
        return Place::Alone;
    };
    if let Some(root) = folder.ancestors().find(|d| d.join("rcs.yaml").is_file()) {
        return Place::Folder(root.to_path_buf());
    }
    let is_workspace = std::fs::read_dir(folder).is_ok_and(|entries| {
        entries.flatten().any(|e| {
            e.path().is_dir()
                && std::fs::read_dir(e.path()).is_ok_and(|inner| {
                    inner
                        .flatten()
                        .any(|f| f.path().extension().is_some_and(|x| x == "rcs"))
                })
        })
    });
    if is_workspace {
        Place::Alone
    } else {
        Place::Folder(folder.to_path_buf())
    }
}

/// Check the plan set of `file` with the open documents' texts.
pub fn analyse(docs: &Documents, file: &Path) -> Analysis {
    let mut files: Vec<(PathBuf, String)> = Vec::new();
    let mut manifest: Option<(PathBuf, String)> = None;
    let mut root: Option<PathBuf> = None;
    let mut name = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "plans".into());
    if let Place::Folder(folder) = place_of(file) {
        if let Ok(set) = load_folder(&folder) {
            name = set.name.clone();
            root = Some(folder.clone());
            for &id in &set.rcs_files {
                let path = PathBuf::from(&set.sources.get(id).path);
                let path = if path.is_absolute() {
                    path
                } else {
                    std::env::current_dir().unwrap_or_default().join(path)
                };
                if let Some(text) = docs.current(&path) {
                    files.push((path, text));
                }
            }
            let yaml = folder.join("rcs.yaml");
            manifest = docs.current(&yaml).map(|t| (yaml, t));
        }
    }
    if !files.iter().any(|(p, _)| p == file) {
        if let Some(text) = docs.current(file) {
            files.push((file.to_path_buf(), text));
        }
    }
    let names: Vec<(String, String)> = files
        .iter()
        .map(|(p, t)| (p.to_string_lossy().into_owned(), t.clone()))
        .collect();
    let mut set = PlanSet::from_texts(
        &name,
        names.iter().map(|(p, t)| (p.as_str(), t.as_str())),
        manifest.as_ref().map(|(_, t)| t.as_str()),
    );
    // Where the set's `scenarios/` are (and paths are shown from).
    if let Some(root) = root {
        set.root = root.to_string_lossy().into_owned();
    }
    let paths = set
        .sources
        .files()
        .map(|(id, f)| {
            if Some(id) == set.manifest_file {
                manifest
                    .as_ref()
                    .map(|(p, _)| p.clone())
                    .unwrap_or_default()
            } else {
                PathBuf::from(&f.path)
            }
        })
        .collect();
    let checked = check(&set, &Options::default());
    Analysis {
        set,
        checked,
        paths,
        symbols: OnceCell::new(),
    }
}
