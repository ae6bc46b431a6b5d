//! [`Config`]: rcsc from a `build.rs`, as `prost-build` and `lalrpop` do it.
//!
//! ```no_run
//! // build.rs
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     rcs_codegen::Config::new().compile("plans")?; // writes into $OUT_DIR/rcs
//!     Ok(())
//! }
//! ```
//!
//! and in the crate, `rcs_runtime::include_plans!("submarine");` includes
//! the generated module of the plan set named `submarine`.
//!
//! `compile` loads a plan-set folder or a workspace of them (honouring each
//! `rcs.yaml`, exactly as `rcsc build` does), checks every set and, when
//! none has an error, writes every output of [`crate::generate`] through
//! [`crate::writer::write_tree`] (so outputs it no longer produces are
//! removed, under the output folder's lock, with every promise of the
//! writer): one plan set into `$OUT_DIR/rcs/`, a workspace's sets into
//! `$OUT_DIR/rcs/<system>/`, plus `include.rs`, which maps each compiled
//! set's name to its file for `include_plans!` (and any other name to a
//! compile error that lists them). It talks to cargo on stdout:
//!
//! - `cargo::rerun-if-changed=` for the folder, every input `.rcs` file and
//!   every `rcs.yaml`;
//! - one `cargo::warning=` line per warning (the short format);
//! - on errors, the full human diagnostics on stderr, one `cargo::error=`
//!   summary line, and `Err` (nothing is written).

use crate::writer::{self, WriteError, WriteReport};
use crate::{OutputFile, GENERATED};
/// The lint names and levels of [`Config::lint`], re-exported so that a
/// build script needs no direct dependency on `rcs-dsl`.
pub use rcs_dsl::lint::{Level, Lint};
use rcs_dsl::render::{self, Format};
use rcs_dsl::{LoadError, Severity};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Settings of a build-script compilation. See the [module docs](self).
#[derive(Clone, Debug)]
pub struct Config {
    out_dir: Option<PathBuf>,
    manifest_dir: Option<PathBuf>,
    lints: Vec<(Lint, Level)>,
    graphs: bool,
    rustfmt: bool,
    options: crate::Options,
}

/// Why [`Config::compile`] failed. Its `Debug` is one readable line (for
/// plan errors, a pointer to the diagnostics cargo shows), so that a
/// `build.rs` whose `main` returns the error prints no struct dump and no
/// third copy of the summary.
#[derive(thiserror::Error)]
pub enum CompileError {
    /// A variable cargo sets for build scripts is missing and no explicit
    /// setting replaces it.
    #[error("`{0}` is not set (is this running in a build script?); set it or call `Config::{1}`")]
    MissingEnv(&'static str, &'static str),
    /// The plan set could not be read at all.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// Two plan sets of one compilation have the same system name.
    #[error(transparent)]
    SameSystem(#[from] crate::SameSystem),
    /// The plans have errors; the diagnostics went to stderr.
    #[error("{summary}")]
    Diagnostics {
        /// The one-line summary (also the `cargo::error=` line).
        summary: String,
        /// How many errors.
        errors: usize,
    },
    /// Writing the generated files failed.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// Printing to cargo failed.
    #[error("writing build-script output: {0}")]
    Io(#[from] std::io::Error),
}

impl std::fmt::Debug for CompileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            // Cargo already shows the summary (the `cargo::error=` line) and
            // the diagnostics; `main`'s `Error: …` need not repeat it.
            CompileError::Diagnostics { errors, .. } => write!(
                f,
                "the plans have {errors} error{}, shown above",
                if *errors == 1 { "" } else { "s" }
            ),
            _ => std::fmt::Display::fmt(self, f),
        }
    }
}

impl Default for Config {
    fn default() -> Self {
        Config::new()
    }
}

impl Config {
    /// The defaults: output into `$OUT_DIR/rcs`, paths relative to
    /// `$CARGO_MANIFEST_DIR`, lint levels from the plan set, graphs and
    /// tables included, the Rust formatted by rustfmt when it is installed.
    pub fn new() -> Config {
        Config {
            out_dir: None,
            manifest_dir: None,
            lints: Vec::new(),
            graphs: true,
            rustfmt: true,
            options: crate::Options::default(),
        }
    }

    /// Write into `dir` instead of `$OUT_DIR/rcs`. `include_plans!` looks in
    /// `$OUT_DIR/rcs`, so with another folder include the file yourself.
    pub fn out_dir(&mut self, dir: impl Into<PathBuf>) -> &mut Config {
        self.out_dir = Some(dir.into());
        self
    }

    /// Resolve relative plan paths against `dir` instead of
    /// `$CARGO_MANIFEST_DIR`.
    pub fn manifest_dir(&mut self, dir: impl Into<PathBuf>) -> &mut Config {
        self.manifest_dir = Some(dir.into());
        self
    }

    /// Set a lint's level, over the manifest's `lints:` (like `-A/-W/-D`).
    /// Later calls override earlier ones.
    pub fn lint(&mut self, lint: Lint, level: Level) -> &mut Config {
        self.lints.push((lint, level));
        self
    }

    /// Also generate the scenario driver (default: no): per controller a
    /// `Driver` implementing `rcs_runtime::driver::Driven`, and
    /// `new_driver(name)` for the plan set — for tests that run generated
    /// controllers alone against scripted inputs.
    pub fn driver(&mut self, yes: bool) -> &mut Config {
        self.options.driver = yes;
        self
    }

    /// serde derives on the generated buffer types and enums (default:
    /// none); e.g. `SerdeDerives::Feature("serde".into())` for derives
    /// behind your crate's `serde` feature.
    pub fn serde(&mut self, derives: crate::SerdeDerives) -> &mut Config {
        self.options.serde = derives;
        self
    }

    /// Whether to write the state graphs (`graphs/`) and tables (`tables/`)
    /// besides the Rust code (default: yes).
    pub fn graphs(&mut self, yes: bool) -> &mut Config {
        self.graphs = yes;
        self
    }

    /// Whether to format the generated Rust with the `rustfmt` binary
    /// (default: yes): `$RUSTFMT` if set, else `rustfmt` on `PATH`. When it
    /// is missing, fails or hangs (killed after a minute), the code is
    /// written as rcsc prints it, which compiles the same; formatting never
    /// fails the build. See [`crate::rustfmt`].
    pub fn rustfmt(&mut self, yes: bool) -> &mut Config {
        self.rustfmt = yes;
        self
    }

    /// Check the plan sets at `path` (a plan-set folder or a workspace of
    /// them, relative to the manifest directory) and write their outputs.
    /// Prints cargo instructions on stdout and diagnostics on stderr. Call it
    /// once per folder; the outputs of earlier calls stay.
    pub fn compile(&self, path: impl AsRef<Path>) -> Result<WriteReport, CompileError> {
        let mut out = std::io::stdout().lock();
        let mut err = std::io::stderr().lock();
        self.compile_with_io(path.as_ref(), &mut out, &mut err)
    }

    /// [`compile`](Config::compile) with its cargo instructions written to
    /// `cargo` and its diagnostics to `diagnostics` (for tests and tools).
    pub fn compile_with_io(
        &self,
        path: &Path,
        cargo: &mut dyn Write,
        diagnostics: &mut dyn Write,
    ) -> Result<WriteReport, CompileError> {
        let path = self.resolve(path)?;
        // Rerun on any change below the folder, even when loading fails.
        writeln!(cargo, "cargo::rerun-if-changed={}", path.display())?;
        let sets = match rcs_dsl::load_paths(std::slice::from_ref(&path)) {
            Ok(sets) => sets,
            Err(e) => {
                // Cargo shows `cargo::error=` lines as the build's error;
                // a build script's `main` would print only `Error: …`.
                writeln!(cargo, "cargo::error={}", one_line(&e.to_string()))?;
                writeln!(cargo, "cargo::error={}", self.load_hint(&path, &e))?;
                return Err(e.into());
            }
        };
        for set in &sets {
            for id in set.rcs_files.iter().chain(&set.manifest_file) {
                let name = &set.sources.get(*id).path;
                if Path::new(name) != path {
                    writeln!(cargo, "cargo::rerun-if-changed={name}")?;
                }
            }
        }

        let options = rcs_dsl::Options {
            lint_flags: self.lints.clone(),
        };
        let mut errors = 0;
        let mut irs = Vec::with_capacity(sets.len());
        for set in &sets {
            let checked = rcs_dsl::check(set, &options);
            for d in &checked.diagnostics {
                if d.severity == Severity::Error {
                    errors += 1;
                    let text = render::render(d, &set.sources, Format::Human { color: false });
                    diagnostics.write_all(text.as_bytes())?;
                } else {
                    let text = render::render(d, &set.sources, Format::Short);
                    writeln!(cargo, "cargo::warning={}", one_line(&text))?;
                }
            }
            irs.extend(checked.ir);
        }
        if errors > 0 || irs.len() != sets.len() {
            let errors = errors.max(1);
            let summary = format!(
                "could not compile the plans in `{}` due to {errors} error{}",
                path.display(),
                if errors == 1 { "" } else { "s" }
            );
            // Cargo shows this line as the build's error and the full
            // diagnostics (above, on stderr) under it; nothing repeats it.
            writeln!(cargo, "cargo::error={summary}")?;
            return Err(CompileError::Diagnostics { summary, errors });
        }

        let irs: Vec<&rcs_dsl::ir::Ir> = irs.iter().collect();
        let shared = rcs_dsl::load::shares_output(&sets);
        let mut files = crate::generate_sets(&irs, shared, &self.options, self.graphs)?;
        if self.rustfmt {
            crate::rustfmt::format_files(&mut files);
        }
        let out_dir = match &self.out_dir {
            Some(d) => d.clone(),
            None => PathBuf::from(env("OUT_DIR", "out_dir")?).join("rcs"),
        };
        let files = produced_so_far(&out_dir, &path, files)?;
        // The same lock as `rcsc build`'s: a build script and a CLI build
        // into one folder take turns.
        let mut blocked = |dir: &Path| {
            let _ = writeln!(
                diagnostics,
                "    Blocking waiting for file lock on {}",
                dir.display()
            );
        };
        Ok(writer::write_tree(&out_dir, &files, &mut blocked)?)
    }

    /// What to do about a plan folder that cannot be read, for the second
    /// `cargo::error=` line.
    fn load_hint(&self, path: &Path, e: &LoadError) -> String {
        match e {
            LoadError::NotFound { .. } => format!(
                "hint: `Config::compile` takes the plan-set folder relative to the crate's \
                 `Cargo.toml` (`{}` was looked for there); create it or fix the path in build.rs",
                path.display()
            ),
            LoadError::NotPlan { .. } => {
                "hint: `Config::compile` takes a plan-set folder (or a workspace of them)"
                    .to_string()
            }
            LoadError::Io { .. } => format!(
                "hint: check that `{}` and the files below it can be read",
                path.display()
            ),
        }
    }

    /// `path` against the manifest directory. When that is the current
    /// folder (as cargo runs build scripts), the path stays relative, so
    /// diagnostics and generated headers carry no absolute paths.
    fn resolve(&self, path: &Path) -> Result<PathBuf, CompileError> {
        if path.is_absolute() {
            return Ok(path.to_path_buf());
        }
        let base = match &self.manifest_dir {
            Some(d) => d.clone(),
            None => PathBuf::from(env("CARGO_MANIFEST_DIR", "manifest_dir")?),
        };
        let same = std::env::current_dir()
            .ok()
            .and_then(|cwd| cwd.canonicalize().ok())
            .is_some_and(|cwd| base.canonicalize().is_ok_and(|b| b == cwd));
        Ok(if same {
            path.to_path_buf()
        } else {
            base.join(path)
        })
    }
}

/// Everything the build script of this process generated into `out_dir`
/// so far — the outputs of each plan-set folder it compiled there, those of
/// `folder` now replaced by `files` — plus the `include.rs` that
/// `rcs_runtime::include_plans!` reads. A build script may call
/// [`Config::compile`] once per plan-set folder: each call writes the whole
/// tree, so none removes the outputs of another as stale.
fn produced_so_far(
    out_dir: &Path,
    folder: &Path,
    files: Vec<OutputFile>,
) -> Result<Vec<OutputFile>, crate::SameSystem> {
    type Folders = BTreeMap<PathBuf, Vec<OutputFile>>;
    static PRODUCED: Mutex<BTreeMap<PathBuf, Folders>> = Mutex::new(BTreeMap::new());
    let mut produced = PRODUCED.lock().unwrap_or_else(|p| p.into_inner());
    let folders = produced.entry(out_dir.to_path_buf()).or_default();
    // Another folder's plan set of the same name would be overwritten.
    for f in &files {
        let Some(system) = rust_system(&f.path) else {
            continue;
        };
        let others = folders.iter().filter(|(k, _)| k.as_path() != folder);
        if others
            .flat_map(|(_, fs)| fs)
            .any(|g| rust_system(&g.path) == Some(system))
        {
            return Err(crate::SameSystem(system.to_string()));
        }
    }
    folders.insert(folder.to_path_buf(), files);
    let mut all: BTreeMap<&str, &OutputFile> = BTreeMap::new();
    for f in folders.values().flatten() {
        all.insert(&f.path, f);
    }
    let include = include_file(out_dir, all.keys().copied());
    let mut all: Vec<OutputFile> = all.into_values().cloned().collect();
    all.push(include);
    Ok(all)
}

/// `submarine` for `rust/submarine.rs` or `submarine/rust/submarine.rs`.
fn rust_system(path: &str) -> Option<&str> {
    let (folder, file) = path.rsplit_once('/')?;
    let system = file.strip_suffix(".rs")?;
    (folder == "rust" || folder.strip_suffix("/rust") == Some(system)).then_some(system)
}

/// `include.rs`: the macro behind [`rcs_runtime::include_plans!`], one arm
/// per plan set compiled into `out_dir`, and a clear error for any other
/// name.
fn include_file<'a>(out_dir: &Path, paths: impl Iterator<Item = &'a str>) -> OutputFile {
    // Relative to `$OUT_DIR` where the folder is inside it (the default).
    let base = std::env::var_os("OUT_DIR")
        .and_then(|o| out_dir.strip_prefix(o).ok().map(Path::to_path_buf));
    let mut arms = String::new();
    let mut names = Vec::new();
    for path in paths {
        let Some(system) = rust_system(path) else {
            continue;
        };
        let target = match &base {
            Some(rel) => format!(
                "concat!(env!(\"OUT_DIR\"), {:?})",
                format!("/{}/{path}", rel.display()).replace("//", "/")
            ),
            None => format!("{:?}", out_dir.join(path).display().to_string()),
        };
        arms.push_str(&format!("    ({system:?}) => {{ include!({target}); }};\n"));
        names.push(format!("`{system}`"));
    }
    let compiled = if names.is_empty() {
        "none".to_string()
    } else {
        names.join(", ")
    };
    let contents = format!(
        "// {GENERATED}: the plan sets this crate's build script compiled, for\n\
         // `rcs_runtime::include_plans!`. Do not edit.\n\
         #[allow(unused_macros)]\n\
         macro_rules! __rcsc_plan_set {{\n\
         {arms}    \
         ($other:literal) => {{ ::core::compile_error!(::core::concat!(\"no plan set named `\", $other, \"`: this crate's build.rs compiled {compiled} (a plan set's name is its rcs.yaml `system:`, or its folder's name)\")); }};\n\
         }}\n"
    );
    OutputFile {
        path: INCLUDE_FILE.to_string(),
        contents,
    }
}

/// The file `include_plans!` reads, relative to the output folder.
pub const INCLUDE_FILE: &str = "include.rs";

fn env(name: &'static str, setter: &'static str) -> Result<String, CompileError> {
    std::env::var(name).map_err(|_| CompileError::MissingEnv(name, setter))
}

/// A rendered diagnostic as one cargo line.
fn one_line(text: &str) -> String {
    text.trim_end().replace(['\r', '\n'], " ")
}

#[cfg(test)]
mod tests {
    use super::*;

    const ROOT: &str = env!("CARGO_MANIFEST_DIR");

    fn scratch(name: &str, files: &[(&str, &str)]) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("rcs-config-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for (path, body) in files {
            let p = dir.join("plans").join(path);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, body).unwrap();
        }
        dir
    }

    fn run(config: &Config, dir: &Path) -> (Result<WriteReport, CompileError>, String, String) {
        let (mut cargo, mut diags) = (Vec::new(), Vec::new());
        let r = config.compile_with_io(Path::new("plans"), &mut cargo, &mut diags);
        let s = |b: Vec<u8>| {
            String::from_utf8(b)
                .unwrap()
                .replace(&dir.display().to_string(), "DIR")
        };
        (r, s(cargo), s(diags))
    }

    const UNUSED: &str = "controller A {\n    command GO\n    var spare: u8 = 0\n    plan GO {\n        *0 when new_command -> Done\n    }\n}\n";

    #[test]
    fn writes_the_outputs_and_tells_cargo_what_to_watch() {
        let dir = scratch("ok", &[("a.rcs", UNUSED), ("rcs.yaml", "system: demo\n")]);
        let out = dir.join("out");
        let (r, cargo, diags) = run(Config::new().manifest_dir(&dir).out_dir(&out), &dir);
        let report = r.unwrap();
        assert_eq!(
            cargo,
            "cargo::rerun-if-changed=DIR/plans\n\
             cargo::rerun-if-changed=DIR/plans/a.rcs\n\
             cargo::rerun-if-changed=DIR/plans/rcs.yaml\n\
             cargo::warning=DIR/plans/a.rcs:3:9: warning[unused]: var `spare` of `A` is never used\n"
        );
        assert_eq!(diags, "");
        assert!(out.join("graphs/A/GO.dot").is_file());
        assert!(out.join("tables/A.md").is_file());
        assert!(!report.written.is_empty());
        // Again: nothing changes.
        let (r, _, _) = run(Config::new().manifest_dir(&dir).out_dir(&out), &dir);
        assert!(r.unwrap().written.is_empty());
        // Without graphs: the graphs and tables are stale, hence removed.
        let (r, _, _) = run(
            Config::new().manifest_dir(&dir).out_dir(&out).graphs(false),
            &dir,
        );
        let r = r.unwrap();
        assert!(r.removed.contains(&out.join("graphs/A/GO.dot")), "{r:?}");
        assert!(!out.join("tables/A.md").exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn errors_print_diagnostics_and_one_cargo_error_and_write_nothing() {
        let bad = "controller A {\n    command GO\n    plan GO {\n        *0 when nope -> Done\n    }\n}\n";
        let dir = scratch("err", &[("a.rcs", bad)]);
        let out = dir.join("out");
        let (r, cargo, diags) = run(
            Config::new()
                .manifest_dir(&dir)
                .out_dir(&out)
                .lint(Lint::Unused, Level::Deny),
            &dir,
        );
        let err = r.unwrap_err();
        assert!(
            matches!(err, CompileError::Diagnostics { errors: 1, .. }),
            "{err}"
        );
        let lines: Vec<&str> = cargo.lines().collect();
        assert_eq!(
            lines.last().copied(),
            Some("cargo::error=could not compile the plans in `DIR/plans` due to 1 error")
        );
        assert_eq!(
            lines
                .iter()
                .filter(|l| l.starts_with("cargo::error="))
                .count(),
            1
        );
        assert!(diags.contains("error[unknown_name]"), "{diags}");
        assert!(
            diags.contains("--> DIR/plans/a.rcs:4:"),
            "full human rendering: {diags}"
        );
        assert!(!out.exists(), "nothing written");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn lint_levels_override_the_manifest() {
        let dir = scratch(
            "lint",
            &[
                ("a.rcs", UNUSED),
                ("rcs.yaml", "lints: { unused: allow }\n"),
            ],
        );
        let out = dir.join("out");
        let (r, cargo, _) = run(Config::new().manifest_dir(&dir).out_dir(&out), &dir);
        r.unwrap();
        assert!(!cargo.contains("cargo::warning"), "{cargo}");
        let (r, cargo, _) = run(
            Config::new()
                .manifest_dir(&dir)
                .out_dir(&out)
                .lint(Lint::Unused, Level::Deny),
            &dir,
        );
        assert!(r.is_err());
        assert!(cargo.contains("cargo::error="), "{cargo}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_missing_folder_is_a_load_error() {
        let dir = scratch("missing", &[]);
        let (r, cargo, _) = run(
            Config::new().manifest_dir(&dir).out_dir(dir.join("o")),
            &dir,
        );
        assert!(matches!(r, Err(CompileError::Load(_))));
        let lines: Vec<&str> = cargo.lines().collect();
        assert_eq!(lines[0], "cargo::rerun-if-changed=DIR/plans");
        assert_eq!(
            lines[1],
            "cargo::error=DIR/plans: no such file or directory"
        );
        assert!(lines[2].starts_with("cargo::error=hint: "), "{cargo}");
        assert!(
            lines[2].contains("DIR/plans") && lines[2].contains("Cargo.toml"),
            "{cargo}"
        );
        assert_eq!(lines.len(), 3, "{cargo}");
        // `main`'s `Error: …` is one readable line, not a struct dump.
        let shown = format!("{:?}", r.unwrap_err());
        assert_eq!(
            shown,
            "DIR/plans: no such file or directory".replace("DIR", &dir.display().to_string())
        );
    }

    #[test]
    fn an_empty_folder_is_a_no_plans_error() {
        let dir = scratch("empty", &[]);
        std::fs::create_dir_all(dir.join("plans")).unwrap();
        let (r, cargo, diags) = run(
            Config::new().manifest_dir(&dir).out_dir(dir.join("o")),
            &dir,
        );
        assert!(matches!(
            r,
            Err(CompileError::Diagnostics { errors: 1, .. })
        ));
        assert!(diags.contains("error[no_plans]"), "{diags}");
        assert!(
            cargo
                .contains("cargo::error=could not compile the plans in `DIR/plans` due to 1 error"),
            "{cargo}"
        );
        assert!(!dir.join("o").exists(), "nothing written");
        let _ = std::fs::remove_dir_all(&dir);
    }

    const GO: &str = "controller A {\n    command GO\n    plan GO {\n        *0 when new_command -> Done\n    }\n}\n";

    #[test]
    fn a_workspace_compiles_every_plan_set_into_its_own_folder() {
        let dir = scratch(
            "workspace",
            &[
                ("one/a.rcs", GO),
                ("two/a.rcs", GO),
                ("two/rcs.yaml", "system: second\n"),
            ],
        );
        let out = dir.join("out");
        let (r, cargo, diags) = run(Config::new().manifest_dir(&dir).out_dir(&out), &dir);
        r.unwrap();
        assert_eq!(diags, "");
        assert!(cargo.contains("cargo::rerun-if-changed=DIR/plans/two/rcs.yaml"));
        assert!(out.join("one/rust/one.rs").is_file());
        assert!(out.join("second/rust/second.rs").is_file());
        assert!(out.join("second/graphs/A/GO.dot").is_file());
        let include = std::fs::read_to_string(out.join(INCLUDE_FILE)).unwrap();
        assert!(include.contains("(\"one\") => {"), "{include}");
        assert!(include.contains("(\"second\") => {"), "{include}");
        assert!(include.contains("compiled `one`, `second`"), "{include}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn two_calls_into_one_folder_keep_each_others_outputs() {
        let dir = scratch(
            "two-calls",
            &[("one/a.rcs", GO), ("two/a.rcs", GO), ("two/rcs.yaml", "")],
        );
        let out = dir.join("out");
        let config = Config::new().manifest_dir(&dir).out_dir(&out).clone();
        let mut sink = Vec::new();
        config
            .compile_with_io(Path::new("plans/one"), &mut sink, &mut Vec::new())
            .unwrap();
        let report = config
            .compile_with_io(Path::new("plans/two"), &mut sink, &mut Vec::new())
            .unwrap();
        assert!(report.removed.is_empty(), "{report:?}");
        assert!(out.join("rust/one.rs").is_file());
        assert!(out.join("rust/two.rs").is_file());
        let include = std::fs::read_to_string(out.join(INCLUDE_FILE)).unwrap();
        assert!(include.contains("compiled `one`, `two`"), "{include}");
        // The same folder again replaces its own outputs.
        let report = config
            .compile_with_io(Path::new("plans/two"), &mut sink, &mut Vec::new())
            .unwrap();
        assert!(report.written.is_empty() && report.removed.is_empty());
        // Another folder with a system name compiled before is refused.
        std::fs::write(dir.join("plans/two/rcs.yaml"), "system: one\n").unwrap();
        let err = config
            .compile_with_io(Path::new("plans/two"), &mut sink, &mut Vec::new())
            .unwrap_err();
        assert!(matches!(err, CompileError::SameSystem(_)), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn two_sets_with_one_system_name_are_refused() {
        let dir = scratch(
            "same-name",
            &[
                ("one/a.rcs", GO),
                ("one/rcs.yaml", "system: same\n"),
                ("two/a.rcs", GO),
                ("two/rcs.yaml", "system: same\n"),
            ],
        );
        let out = dir.join("out");
        let (r, _, _) = run(Config::new().manifest_dir(&dir).out_dir(&out), &dir);
        let err = r.unwrap_err();
        assert!(matches!(err, CompileError::SameSystem(_)), "{err}");
        assert!(err.to_string().contains("both named `same`"), "{err}");
        assert!(!out.exists(), "nothing written");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_error_main_prints_does_not_repeat_the_summary() {
        let err = CompileError::Diagnostics {
            summary: "could not compile the plans in `plans` due to 2 errors".into(),
            errors: 2,
        };
        assert_eq!(format!("{err:?}"), "the plans have 2 errors, shown above");
        assert_eq!(
            err.to_string(),
            "could not compile the plans in `plans` due to 2 errors"
        );
    }

    #[test]
    fn the_rust_is_formatted_by_rustfmt_unless_turned_off() {
        let dir = scratch("rustfmt", &[("a.rcs", GO)]);
        let read =
            |out: &str, file: &str| std::fs::read_to_string(dir.join(out).join(file)).unwrap();
        let config = |out: &str| {
            Config::new()
                .manifest_dir(&dir)
                .out_dir(dir.join(out))
                .clone()
        };
        let mut sink = Vec::new();
        config("on")
            .compile_with_io(Path::new("plans"), &mut sink, &mut Vec::new())
            .unwrap();
        config("off")
            .rustfmt(false)
            .compile_with_io(Path::new("plans"), &mut sink, &mut Vec::new())
            .unwrap();
        let (on, off) = (read("on", "rust/plans.rs"), read("off", "rust/plans.rs"));
        let program = crate::rustfmt::program();
        let timeout = crate::rustfmt::TIMEOUT;
        match crate::rustfmt::format_source(&program, timeout, &off) {
            Some(formatted) => {
                assert_eq!(on, formatted);
                assert_ne!(on, off, "prettyplease and rustfmt differ here");
                // include.rs is written rustfmt-clean.
                let include = read("on", INCLUDE_FILE);
                assert_eq!(
                    crate::rustfmt::format_source(&program, timeout, &include).as_deref(),
                    Some(include.as_str())
                );
            }
            None => assert_eq!(on, off, "no rustfmt: written as printed"),
        }
        assert_eq!(read("on", "tables/A.md"), read("off", "tables/A.md"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_reference_plans_compile() {
        let dir = scratch("reference", &[]);
        let mut cargo = Vec::new();
        let report = Config::new()
            .manifest_dir(Path::new(ROOT).join(".."))
            .out_dir(&dir)
            .compile_with_io(Path::new("plans/submarine"), &mut cargo, &mut Vec::new())
            .unwrap();
        assert!(report.written.contains(&dir.join("graphs/hierarchy.dot")));
        let cargo = String::from_utf8(cargo).unwrap();
        assert_eq!(
            cargo.lines().count(),
            5,
            "folder, 3 files, rcs.yaml: {cargo}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
