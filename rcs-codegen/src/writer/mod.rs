//! The one place that writes generated files: the last step of the
//! pipeline (`.rcs` → IR → [`crate::generate`] → rustfmt → here). Everything
//! before it is a pure function from the IR to [`OutputFile`]s.
//!
//! # What a write promises
//!
//! [`write_tree`] writes the complete output of a build into a folder (and
//! removes the generated files the build no longer produces);
//! [`write_files`] writes some files and removes nothing. Both:
//!
//! 1. **Take turns.** The folder is locked ([`OutputLock`], `.rcsc-lock`)
//!    for the whole write; a second build into it waits (after the caller
//!    is told, to print "Blocking waiting for file lock on …").
//! 2. **Repair first.** A journal left by a build killed while renaming is
//!    rolled forward, and temporaries left by a killed build (`.rcsc-tmp-*`,
//!    anywhere below the folder) are removed ([`journal`]).
//! 3. **Check everything before changing anything.** Every path must be
//!    relative and stay inside the folder, also once symbolic links are
//!    followed (a link to a place inside is followed; one leading out, or to
//!    nothing, is refused, naming it). The output folder itself may be or
//!    lie under a link. A file to be replaced must carry [`GENERATED`] in its
//!    first line: a hand-written file at a generated path is refused, naming
//!    it, and nothing is written. Stale files are removed only when they carry
//!    the marker, and links are never followed when looking for them.
//! 4. **Stage, then commit.** Every changed file is written to a temporary
//!    beside its target; any error here removes the temporaries (and the
//!    folders made for them) and leaves the old outputs as they were. Then a
//!    journal naming every rename and removal is written (atomically), the
//!    renames and removals run back to back, and the journal is deleted.
//!
//! # What is and is not atomic
//!
//! Each file is replaced atomically (a rename over it), so a reader never
//! sees a half-written file. The build as a whole is not atomic in time: a
//! reader looking *during* the rename phase — a few system calls per file,
//! after all the slow work is done — can see some files new and some old.
//! A build killed in that phase leaves the journal; until the next write
//! into the folder (which finishes it before anything else, under the lock)
//! the folder is mixed, and the journal's presence says so. A build killed
//! before the journal exists leaves the old outputs whole, plus temporaries
//! the next write removes. Files are not `fsync`ed: a power cut (unlike a
//! killed process) may lose recent writes (durability would cost an fsync
//! per file and folder).
//! Checks and writes are separate steps, so another program (not rcsc,
//! which takes the lock) changing the folder between them is not guarded
//! against.
//!
//! Unchanged files are not rewritten (their modification times stay).
//!
//! # One file named by the user, and the files a command reads
//!
//! [`write_file`] writes one file a user named (`rcsc ir -o F`, `rcsc
//! graph -o F`, `rcsc test --trace F`) by the same rules, in the folder
//! that holds it (see [`single`] for what differs). [`Inputs`] are the
//! files a command reads; [`write_file`] and [`write_files_sparing`] never
//! replace one, marker or not. Every refusal has a [`WriteError::code`]
//! and most a [`WriteError::help`], for the CLI's diagnostic.

mod guard;
pub mod journal;
mod lock;
mod single;
#[cfg(test)]
mod tests;

pub use guard::is_generated;
pub(crate) use guard::safe_relative;
pub use lock::OutputLock;
pub use single::{check_file, rewrite_source, write_file, write_file_bytes, Inputs};

use crate::{OutputFile, GENERATED};
use guard::Existing;
use journal::Step;
use std::collections::BTreeSet;
use std::io;
use std::path::{Path, PathBuf};

/// Every name the writer keeps for itself starts with this; no generated
/// path may have such a component, and the stale sweep skips them.
pub const RESERVED_PREFIX: &str = ".rcsc-";
/// The lock file, in the output folder.
pub const LOCK_FILE: &str = ".rcsc-lock";
/// The journal of an unfinished commit, in the output folder.
pub const JOURNAL_FILE: &str = ".rcsc-journal";
/// How every temporary's name starts.
pub const TMP_PREFIX: &str = ".rcsc-tmp-";
/// How deep the sweeps look below the output folder.
const MAX_DEPTH: usize = 32;

/// What a write did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WriteReport {
    /// Files whose bytes changed (or that did not exist).
    pub written: Vec<PathBuf>,
    /// Files already up to date.
    pub unchanged: Vec<PathBuf>,
    /// Stale generated files removed by [`write_tree`].
    pub removed: Vec<PathBuf>,
    /// Whether an interrupted build's journal was found and finished.
    pub recovered: bool,
    /// Temporaries of killed builds that were removed.
    pub swept: Vec<PathBuf>,
}

/// Why a write refused or failed. Every refusal happens before anything
/// in the folder changed.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    #[error("refusing to write `{0}`: generated paths must stay inside the output folder")]
    OutsideOutput(String),
    #[error("refusing to write `{0}`: names starting with `{RESERVED_PREFIX}` are rcsc's own")]
    Reserved(String),
    #[error(
        "refusing to write both `{0}` and `{1}`: names that differ only in case are one file \
         on case-insensitive file systems (macOS, Windows); rename one"
    )]
    Collision(String, String),
    #[error("refusing to write through `{path}`: {why}; nothing was written")]
    Symlink { path: String, why: String },
    #[error("cannot write `{path}`: {why}; nothing was written")]
    InTheWay { path: String, why: &'static str },
    #[error(
        "refusing to overwrite {}: {} not generated by rcsc (no `{GENERATED}` in the first \
         line); nothing was written",
        list(.0), if .0.len() == 1 { "it was" } else { "they were" }
    )]
    NotGenerated(Vec<String>),
    #[error(
        "refusing to overwrite `{path}`: it is {}a file this command reads (a plan, a \
         manifest or a scenario); nothing was written",
        if .path == .input { String::new() } else { format!("`{}`, ", .input) }
    )]
    Input { path: String, input: String },
    #[error("{path}: {source}")]
    Io { path: String, source: io::Error },
}

impl WriteError {
    /// A short name for the kind of refusal, as a diagnostic's code;
    /// `None` for an I/O error, which is no refusal.
    pub fn code(&self) -> Option<&'static str> {
        Some(match self {
            WriteError::OutsideOutput(_) => "outside_output",
            WriteError::Reserved(_) => "reserved_path",
            WriteError::Collision(..) => "path_collision",
            WriteError::Symlink { .. } => "symlink",
            WriteError::InTheWay { .. } => "in_the_way",
            WriteError::NotGenerated(_) => "not_generated",
            WriteError::Input { .. } => "overwrites_input",
            WriteError::Io { .. } => return None,
        })
    }

    /// What the user can do about a refusal.
    pub fn help(&self) -> Option<&'static str> {
        match self {
            WriteError::NotGenerated(_) => Some(
                "move or remove it if rcsc may replace it, or write to another path (another \
                 output folder, for a build)",
            ),
            WriteError::Input { .. } => Some("choose another output path"),
            WriteError::InTheWay { .. } | WriteError::Symlink { .. } => {
                Some("remove it or choose another output path")
            }
            _ => None,
        }
    }
}

fn list(paths: &[String]) -> String {
    let quoted: Vec<String> = paths.iter().map(|p| format!("`{p}`")).collect();
    quoted.join(", ")
}

fn io_err(path: &Path, source: io::Error) -> WriteError {
    WriteError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// Write `files` under `out_dir` (made if missing) and remove nothing.
/// `blocked` is called before waiting for another build's lock.
pub fn write_files(
    out_dir: &Path,
    files: &[OutputFile],
    blocked: &mut dyn FnMut(&Path),
) -> Result<WriteReport, WriteError> {
    write(out_dir, files, false, &Inputs::new(), blocked)
}

/// [`write_files`], refusing also to replace any of `inputs` (the files
/// the command read), marker or not.
pub fn write_files_sparing(
    out_dir: &Path,
    files: &[OutputFile],
    inputs: &Inputs,
    blocked: &mut dyn FnMut(&Path),
) -> Result<WriteReport, WriteError> {
    write(out_dir, files, false, inputs, blocked)
}

/// Write `files` under `out_dir` as the complete output of a build: like
/// [`write_files`], and in the same commit remove every generated file
/// below `out_dir` that is not among `files` (then the folders this leaves
/// empty). Files without the marker, symbolic links and anything outside
/// `out_dir` are never touched.
pub fn write_tree(
    out_dir: &Path,
    files: &[OutputFile],
    blocked: &mut dyn FnMut(&Path),
) -> Result<WriteReport, WriteError> {
    write(out_dir, files, true, &Inputs::new(), blocked)
}

/// Paths that are relative, inside, not reserved and distinct even on a
/// case-insensitive file system (pure).
fn validate(files: &[OutputFile]) -> Result<(), WriteError> {
    let mut seen: std::collections::BTreeMap<String, &str> = Default::default();
    for f in files {
        if !safe_relative(&f.path) {
            return Err(WriteError::OutsideOutput(f.path.clone()));
        }
        if guard::reserved(&f.path) {
            return Err(WriteError::Reserved(f.path.clone()));
        }
        if let Some(other) = seen.insert(f.path.to_lowercase(), &f.path) {
            return Err(WriteError::Collision(other.to_string(), f.path.clone()));
        }
    }
    Ok(())
}

fn write(
    out_dir: &Path,
    files: &[OutputFile],
    sweep: bool,
    inputs: &Inputs,
    blocked: &mut dyn FnMut(&Path),
) -> Result<WriteReport, WriteError> {
    validate(files)?;
    std::fs::create_dir_all(out_dir).map_err(|e| io_err(out_dir, e))?;
    let _lock = OutputLock::acquire(out_dir, blocked)?;
    let root = std::fs::canonicalize(out_dir).map_err(|e| io_err(out_dir, e))?;
    let mut report = WriteReport {
        recovered: journal::recover(&root, out_dir)?,
        swept: journal::sweep_temporaries(out_dir)?,
        ..WriteReport::default()
    };

    // Check: nothing changes until every file has passed.
    let mut changed = Vec::new();
    let mut foreign = Vec::new();
    for f in files {
        let at = out_dir.join(&f.path);
        if let Some(input) = inputs.find(&at) {
            return Err(WriteError::Input {
                path: at.display().to_string(),
                input: input.display().to_string(),
            });
        }
        match guard::inspect(&root, out_dir, &f.path)? {
            Existing::File(old) if old == f.contents.as_bytes() => {
                report.unchanged.push(out_dir.join(&f.path));
            }
            Existing::File(old) if !guard::first_line_generated(&old) => {
                foreign.push(out_dir.join(&f.path).display().to_string());
            }
            _ => changed.push(f),
        }
    }
    if !foreign.is_empty() {
        return Err(WriteError::NotGenerated(foreign));
    }
    let stale = if sweep {
        let keep: BTreeSet<String> = files.iter().map(|f| f.path.clone()).collect();
        guard::find_stale(out_dir, &keep)?
    } else {
        Vec::new()
    };

    // Stage.
    let staged = stage(out_dir, &changed)?;

    // Commit.
    let mut steps: Vec<Step> = staged.renames.clone();
    steps.extend(stale.into_iter().map(Step::Remove));
    if !steps.is_empty() {
        if let Err(e) = journal::write(out_dir, &steps) {
            staged.undo(out_dir);
            return Err(e);
        }
        let removed = apply(out_dir, &steps)?;
        remove_emptied_folders(out_dir, &removed);
        journal::finish(out_dir)?;
        report.removed = removed;
    }
    report.written = changed.iter().map(|f| out_dir.join(&f.path)).collect();
    Ok(report)
}

/// The temporaries of a staged write and the folders made for them.
struct Staged {
    renames: Vec<Step>,
    made: Vec<PathBuf>,
}

impl Staged {
    /// Remove the temporaries and the folders made for them.
    fn undo(&self, out_dir: &Path) {
        for step in &self.renames {
            if let Step::Rename(tmp, _) = step {
                let _ = std::fs::remove_file(out_dir.join(tmp));
            }
        }
        for dir in self.made.iter().rev() {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

/// Write every changed file to a temporary beside its target; on any
/// error, undo and fail.
fn stage(out_dir: &Path, changed: &[&OutputFile]) -> Result<Staged, WriteError> {
    let mut staged = Staged {
        renames: Vec::new(),
        made: Vec::new(),
    };
    for (n, f) in changed.iter().enumerate() {
        if let Err(e) = stage_one(out_dir, f, n, &mut staged) {
            staged.undo(out_dir);
            return Err(e);
        }
    }
    Ok(staged)
}

fn stage_one(
    out_dir: &Path,
    f: &OutputFile,
    n: usize,
    staged: &mut Staged,
) -> Result<(), WriteError> {
    let (folder, _) = f.path.rsplit_once('/').unwrap_or(("", &f.path));
    // Make the missing folders, outermost first, remembering each.
    let mut dir = out_dir.to_path_buf();
    for part in folder.split('/').filter(|p| !p.is_empty()) {
        dir.push(part);
        match std::fs::create_dir(&dir) {
            Ok(()) => staged.made.push(dir.clone()),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
            Err(e) => return Err(io_err(&dir, e)),
        }
    }
    #[cfg(test)]
    tests::fault("stage", n)?;
    let name = format!("{TMP_PREFIX}{}-{n}", std::process::id());
    let tmp_rel = if folder.is_empty() {
        name
    } else {
        format!("{folder}/{name}")
    };
    let tmp = out_dir.join(&tmp_rel);
    // `create_new` never follows a link and never reuses a file.
    let file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .map_err(|e| io_err(&tmp, e))?;
    staged
        .renames
        .push(Step::Rename(tmp_rel.clone(), f.path.clone()));
    io::Write::write_all(&mut &file, f.contents.as_bytes()).map_err(|e| io_err(&tmp, e))
}

/// Carry out the journal's steps (in tests, maybe stopping part-way as a
/// killed build would).
fn apply(out_dir: &Path, steps: &[Step]) -> Result<Vec<PathBuf>, WriteError> {
    #[cfg(test)]
    if let Some(k) = tests::crash_after() {
        journal::apply(out_dir, &steps[..k.min(steps.len())])?;
        return Err(tests::crashed());
    }
    journal::apply(out_dir, steps)
}

/// Remove the folders that removing `files` left empty, deepest first;
/// never `out_dir` itself, never a folder that still holds something.
fn remove_emptied_folders(out_dir: &Path, files: &[PathBuf]) {
    for dir in guard::parents_deepest_first(out_dir, files) {
        // Fails (and is left alone) when the folder still holds something.
        let _ = std::fs::remove_dir(dir);
    }
}
