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
//! `$OUT_DIR/rcs/rust/submarine.rs`.
//!
//! `compile` loads the plan-set folder (honouring its `rcs.yaml`), checks it
//! and, when it has no error, writes every output of [`crate::generate`]
//! through [`crate::writer::write_tree`] (so outputs it no longer produces
//! are removed). It talks to cargo on stdout:
//!
//! - `cargo::rerun-if-changed=` for the folder, every input `.rcs` file and
//!   the `rcs.yaml`;
//! - one `cargo::warning=` line per warning (the short format);
//! - on errors, the full human diagnostics on stderr, one `cargo::error=`
//!   summary line, and `Err` (nothing is written).

use crate::writer::{self, WriteError, WriteReport};
/// The lint names and levels of [`Config::lint`], re-exported so that a
/// build script needs no direct dependency on `rcs-dsl`.
pub use rcs_dsl::lint::{Level, Lint};
use rcs_dsl::render::{self, Format};
use rcs_dsl::{LoadError, Severity};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Settings of a build-script compilation. See the [module docs](self).
#[derive(Clone, Debug)]
pub struct Config {
    out_dir: Option<PathBuf>,
    manifest_dir: Option<PathBuf>,
    lints: Vec<(Lint, Level)>,
    graphs: bool,
    options: crate::Options,
}

/// Why [`Config::compile`] failed. Its `Debug` is its message, so that a
/// `build.rs` whose `main` returns the error prints one readable line.
#[derive(thiserror::Error)]
pub enum CompileError {
    /// A variable cargo sets for build scripts is missing and no explicit
    /// setting replaces it.
    #[error("`{0}` is not set (is this running in a build script?); set it or call `Config::{1}`")]
    MissingEnv(&'static str, &'static str),
    /// The plan set could not be read at all.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// The path is not a single plan-set folder.
    #[error("{0}: expected one plan-set folder, a `.rcs` file or an `rcs.yaml`")]
    NotOneSet(String),
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
        std::fmt::Display::fmt(self, f)
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
    /// tables included.
    pub fn new() -> Config {
        Config {
            out_dir: None,
            manifest_dir: None,
            lints: Vec::new(),
            graphs: true,
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

    /// Check the plan set at `path` (a folder, relative to the manifest
    /// directory) and write its outputs. Prints cargo instructions on stdout
    /// and diagnostics on stderr.
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
        let mut sets = rcs_dsl::load_paths(std::slice::from_ref(&path))?;
        if sets.len() != 1 {
            return Err(CompileError::NotOneSet(path.display().to_string()));
        }
        let set = sets.remove(0);
        let inputs = set.rcs_files.iter().chain(&set.manifest_file);
        for id in inputs {
            let name = &set.sources.get(*id).path;
            if Path::new(name) != path {
                writeln!(cargo, "cargo::rerun-if-changed={name}")?;
            }
        }

        let options = rcs_dsl::Options {
            lint_flags: self.lints.clone(),
        };
        let checked = rcs_dsl::check(&set, &options);
        let mut errors = 0;
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
        let ir = match checked.ir {
            Some(ir) if errors == 0 => ir,
            _ => {
                let errors = errors.max(1);
                let summary = format!(
                    "could not compile the plans in `{}` due to {errors} error{}",
                    path.display(),
                    if errors == 1 { "" } else { "s" }
                );
                writeln!(diagnostics, "error: {summary}")?;
                writeln!(cargo, "cargo::error={summary}")?;
                return Err(CompileError::Diagnostics { summary, errors });
            }
        };

        let mut files = crate::generate_with(&ir, &self.options);
        if !self.graphs {
            files.retain(|f| !f.path.starts_with("graphs/") && !f.path.starts_with("tables/"));
        }
        let out_dir = match &self.out_dir {
            Some(d) => d.clone(),
            None => PathBuf::from(env("OUT_DIR", "out_dir")?).join("rcs"),
        };
        Ok(writer::write_tree(&out_dir, &files)?)
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
        assert_eq!(cargo, "cargo::rerun-if-changed=DIR/plans\n");
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
