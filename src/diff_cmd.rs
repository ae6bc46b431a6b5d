//! `rcsc diff OLD [NEW]`: the semantic diff of two versions of plan sets,
//! each a path or a git revision of the current repository. Thin: it
//! resolves the sides (a revision is extracted with `git archive` into a
//! temporary folder, removed afterwards), checks them, and hands them to
//! `rcs_dsl::diff` and the `rcs_codegen::diff` renderers.
//!
//! Exit status: 0 no change, 1 changes (like `diff`), 2 an error (a side
//! that cannot be read, is not a revision, or does not parse).

use rcs_dsl::diff::{check_side, PlanSetDiff, Side};
use rcs_dsl::render;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

use crate::args::{ColorChoice, DiffArgs, DiffFormat};
use crate::output::{default_paths, emit, fail, inputs_of, write_failed};

/// Where one side's plans are.
enum Where {
    /// Paths on disk, as given.
    Paths(Vec<PathBuf>),
    /// A git revision.
    Rev(String),
}

impl Where {
    fn name(&self) -> String {
        match self {
            Where::Paths(p) => p
                .iter()
                .map(|p| rcs_dsl::load::display(p))
                .collect::<Vec<_>>()
                .join(" "),
            Where::Rev(r) => r.clone(),
        }
    }
}

/// A temporary folder, removed when dropped.
struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

pub(crate) fn diff(args: DiffArgs) -> ExitCode {
    match run(&args) {
        Ok(code) => code,
        Err(reason) => fail(reason),
    }
}

fn run(args: &DiffArgs) -> Result<ExitCode, String> {
    let (old, new) = sides(
        &args.old,
        args.new.as_deref(),
        &default_paths(args.paths.clone()),
    )?;
    // A revision compared with a path reads the same path in the revision.
    let paths = match (&old, &new) {
        (Where::Rev(_), Where::Paths(p)) | (Where::Paths(p), Where::Rev(_))
            if args.paths.is_empty() =>
        {
            p.clone()
        }
        _ => default_paths(args.paths.clone()),
    };
    let mut temps = Vec::new();
    let old_sets = load(&old, &paths, &mut temps)?;
    let new_sets = load(&new, &paths, &mut temps)?;
    let options = args.common.options();
    let mut checked = Vec::new();
    for (label, sets) in [("old", &old_sets), ("new", &new_sets)] {
        let mut side = Vec::new();
        for set in sets {
            let (ir, diags) = check_side(set, &options);
            let Some(ir) = ir else {
                for d in diags
                    .iter()
                    .filter(|d| d.severity == rcs_dsl::Severity::Error)
                {
                    eprint!("{}", render::render(d, &set.sources, args.common.format()));
                }
                return Err(format!(
                    "the {label} side does not parse; nothing to compare"
                ));
            };
            side.push((ir, diags));
        }
        checked.push(side);
    }
    let sides: Vec<Vec<Side>> = checked
        .iter()
        .map(|s| {
            s.iter()
                .map(|(ir, diagnostics)| Side { ir, diagnostics })
                .collect()
        })
        .collect();
    let diff = rcs_dsl::diff::diff(&sides[0], &sides[1]);
    drop(temps);

    if let Some(dir) = &args.graphs {
        // A revision's files were in a temporary folder, gone by now.
        let inputs = inputs_of(old_sets.iter().chain(&new_sets));
        let source = format!("{}..{}", old.name(), new.name());
        if let Err(e) = write_graphs(dir, &diff, &source, &inputs) {
            return Ok(write_failed(&e));
        }
    }
    let text = match args.format {
        DiffFormat::Text => rcs_codegen::diff::text(&diff, color(args.common.color)),
        DiffFormat::Markdown => rcs_codegen::diff::markdown(&diff),
        DiffFormat::Json => serde_json::to_string_pretty(&diff).map_err(|e| e.to_string())? + "\n",
    };
    let code = emit(None, &text, &Default::default());
    if code != ExitCode::SUCCESS {
        return Ok(code);
    }
    Ok(if diff.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The older side of `rcsc doc --diff OLD`, read as `rcsc diff OLD` reads
/// it: a path, or a revision (its `paths`, extracted into a temporary
/// folder that lives as long as the value).
pub(crate) struct OldSide {
    pub(crate) sets: Vec<rcs_dsl::PlanSet>,
    /// `OLD` as named.
    pub(crate) name: String,
    _temps: Vec<TempDir>,
}

pub(crate) fn old_side(old: &str, paths: &[PathBuf]) -> Result<OldSide, String> {
    let old = side(old)?;
    let mut temps = Vec::new();
    let sets = load(&old, paths, &mut temps)?;
    Ok(OldSide {
        sets,
        name: old.name(),
        _temps: temps,
    })
}

/// The two sides from `OLD [NEW]`: `A..B` names two revisions; a lone
/// side is compared with the working tree.
fn sides(old: &str, new: Option<&str>, paths: &[PathBuf]) -> Result<(Where, Where), String> {
    if new.is_none() && !Path::new(old).exists() {
        if let Some((a, b)) = old.split_once("..") {
            let b = b.trim_start_matches('.');
            return Ok((
                revision(a)?,
                revision(if b.is_empty() { "HEAD" } else { b })?,
            ));
        }
    }
    let old = side(old)?;
    let new =
        match (new, &old) {
            (Some(n), _) => side(n)?,
            (None, Where::Rev(_)) => Where::Paths(paths.to_vec()),
            (None, Where::Paths(_)) => return Err(
                "OLD is a path: name NEW too (a revision alone is compared with the working tree)"
                    .to_string(),
            ),
        };
    Ok((old, new))
}

fn side(arg: &str) -> Result<Where, String> {
    if Path::new(arg).exists() {
        Ok(Where::Paths(vec![PathBuf::from(arg)]))
    } else {
        revision(arg)
    }
}

fn revision(rev: &str) -> Result<Where, String> {
    let ok = Command::new("git")
        .args(["rev-parse", "--verify", "--quiet"])
        .arg(format!("{rev}^{{commit}}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if ok {
        Ok(Where::Rev(rev.to_string()))
    } else {
        Err(format!(
            "`{rev}` is neither a file or folder nor a git revision of the current repository"
        ))
    }
}

fn git(args: &[&str]) -> Result<String, String> {
    let out = Command::new("git")
        .args(args)
        .output()
        .map_err(|e| format!("cannot run git: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "git {} failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// Load one side; a revision is extracted first, under a folder named as
/// the repository's so a plan set keeps its name.
fn load(
    side: &Where,
    paths: &[PathBuf],
    temps: &mut Vec<TempDir>,
) -> Result<Vec<rcs_dsl::PlanSet>, String> {
    let paths = match side {
        Where::Paths(p) => p.clone(),
        Where::Rev(rev) => {
            let top = PathBuf::from(git(&["rev-parse", "--show-toplevel"])?);
            let prefix = git(&["rev-parse", "--show-prefix"])?;
            let n = temps.len();
            let tmp = std::env::temp_dir().join(format!("rcsc-diff-{}-{n}", std::process::id()));
            let root = tmp.join(top.file_name().unwrap_or_else(|| "repo".as_ref()));
            temps.push(TempDir(tmp));
            extract(rev, &top, &root)?;
            let here = root.join(prefix);
            paths
                .iter()
                .map(|p| {
                    if p.is_absolute() {
                        Err(format!(
                            "{}: a revision's plans are named relative to the current folder",
                            p.display()
                        ))
                    } else {
                        Ok(here.join(p))
                    }
                })
                .collect::<Result<_, _>>()?
        }
    };
    rcs_dsl::load_paths(&paths).map_err(|e| format!("{}: {e}", side.name()))
}

/// `git archive REV | tar -x -C root`, run at the top of the repository
/// (in a subfolder, `git archive` would take only that subtree).
fn extract(rev: &str, top: &Path, root: &Path) -> Result<(), String> {
    std::fs::create_dir_all(root).map_err(|e| format!("cannot create {}: {e}", root.display()))?;
    let mut archive = Command::new("git")
        .args(["archive", "--format=tar", rev])
        .current_dir(top)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot run git: {e}"))?;
    let stdout = archive.stdout.take().ok_or("git archive has no output")?;
    let tar = Command::new("tar")
        .arg("-x")
        .arg("-C")
        .arg(root)
        .stdin(stdout)
        .output()
        .map_err(|e| format!("cannot run tar: {e}"))?;
    let archived = archive
        .wait_with_output()
        .map_err(|e| format!("git archive: {e}"))?;
    if !archived.status.success() || !tar.status.success() {
        return Err(format!(
            "cannot extract revision `{rev}`: {}{}",
            String::from_utf8_lossy(&archived.stderr).trim(),
            String::from_utf8_lossy(&tar.stderr).trim()
        ));
    }
    Ok(())
}

/// Colour text output on a terminal (stdout), unless `NO_COLOR`.
fn color(choice: ColorChoice) -> bool {
    match choice {
        ColorChoice::Always => true,
        ColorChoice::Never => false,
        ColorChoice::Auto => {
            std::io::stdout().is_terminal() && std::env::var_os("NO_COLOR").is_none()
        }
    }
}

/// One DOT file per changed plan: `DIR/CTRL.VERB.dot`, under
/// `DIR/<system>/` when several systems changed; written through the one
/// writer (no file of the plans read is replaced, nor any file rcsc did
/// not generate).
fn write_graphs(
    dir: &Path,
    diff: &PlanSetDiff,
    source: &str,
    inputs: &rcs_codegen::writer::Inputs,
) -> Result<(), rcs_codegen::writer::WriteError> {
    let several = diff.systems.len() > 1;
    let mut files = Vec::new();
    for s in &diff.systems {
        for p in s.controllers.iter().flat_map(|c| &c.plans) {
            let name = format!("{}.dot", p.name());
            files.push(rcs_codegen::OutputFile {
                path: if several {
                    format!("{}/{name}", s.name)
                } else {
                    name
                },
                contents: rcs_codegen::diff::diff_dot(p, source),
            });
        }
    }
    if files.is_empty() {
        return Ok(());
    }
    rcs_codegen::writer::write_files_sparing(dir, &files, inputs, &mut |_| {}).map(|_| ())
}
