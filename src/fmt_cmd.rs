//! `rcsc fmt`: lay `.rcs` files out in the one canonical layout
//! ([`rcs_dsl::fmt`]), in place, or with `--check` only say (as a unified
//! diff) what would change. A file that does not parse is refused with
//! its diagnostics and left untouched; files are rewritten through the
//! writer's in-place rewrite ([`rcs_codegen::writer::rewrite_source`]:
//! staged beside the file and renamed over it).

use clap::Args;
use rcs_dsl::fmt::{format, FmtError};
use rcs_dsl::render::{self, Format};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::args::ColorChoice;
use crate::output::{fail, plural, write_failed, Status};

pub(crate) const FMT_HELP: &str = "\
Rows of a plan become a table (label, from-state, condition, target, jobs
in columns); a row too long for the width has its condition broken before
each `&&` or `||`; blocks are indented by 4 spaces; one blank line
separates items; comments stay where they were. Formatting never changes
meaning: the result is parsed again and must give the same syntax tree.

The width comes from the nearest `rcsfmt.toml` in the file's folder or
above (`max_width = 100`, the default).

Row labels are left as written unless --renumber: then, for each plan set
under PATH, every label `EN` and numbered don't-care `*N` becomes its row's
position (rows placed by `use` count), the `fired:` of the set's scenarios
follow their rows, and the files are formatted. Only the numbers change
before the layout, and the set must lower to the same plans afterwards. A
number written on two rows of a plan, or a scenario name the plans a step
may run number differently, is left as written with a warning (file:line).
If any file does not parse, nothing is written.

Exit status: 0 all files formatted (or, with --check, already formatted);
1 with --check when a file would change; 2 when a file does not parse or
cannot be read or written (that file is left as it was; with --renumber,
every file).

Examples:
  rcsc fmt plans/                 # rewrite every .rcs file below plans/
  rcsc fmt --check plans/ examples/   # CI: fail, with a diff, if any would change
  rcsc fmt plans/submarine/propulsion.rcs
  rcsc fmt --renumber plans/figure13      # labels to positions, scenarios too";

#[derive(Args)]
pub(crate) struct FmtArgs {
    /// .rcs files, or folders searched for them recursively [default: .]
    pub(crate) paths: Vec<PathBuf>,
    /// Write nothing: print a unified diff of what would change and exit
    /// with 1 if any file would.
    #[arg(long)]
    pub(crate) check: bool,
    /// Also set every row label `EN` and numbered don't-care `*N` to its
    /// row's position, and the `fired:` of the plan sets' scenarios with
    /// them.
    #[arg(long)]
    pub(crate) renumber: bool,
    /// When to colour diagnostics.
    #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
    pub(crate) color: ColorChoice,
    /// Print only errors (and, with --check, the diff).
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

pub(crate) fn fmt(args: FmtArgs) -> ExitCode {
    if args.renumber {
        return crate::renumber_cmd::fmt_renumber(&args);
    }
    let paths = crate::output::default_paths(args.paths.clone());
    let mut files = Vec::new();
    for path in &paths {
        if let Err(reason) = collect(path, &mut files) {
            return fail(reason);
        }
    }
    let color = args.color();
    let status = Status {
        color,
        quiet: args.quiet,
    };
    let (mut refused, mut changed) = (0usize, 0usize);
    for file in &files {
        let shown = rcs_dsl::load::display(file);
        let text = match std::fs::read_to_string(file) {
            Ok(text) => text,
            Err(e) => {
                eprintln!(
                    "error: cannot read {}: {e}",
                    render::escape_controls(&shown)
                );
                refused += 1;
                continue;
            }
        };
        let Some(formatted) = format_file(file, &text, color) else {
            refused += 1;
            continue;
        };
        if formatted == text {
            continue;
        }
        changed += 1;
        if args.check {
            crate::output::print_stdout(&unified_diff(&shown, &text, &formatted, "formatted"))
                .unwrap_or_else(|e| eprintln!("error: cannot write to stdout: {e}"));
            continue;
        }
        let mut blocked = |dir: &Path| {
            status.line(
                "Blocking",
                format!("waiting for file lock on {}", rcs_dsl::load::display(dir)),
            )
        };
        match rcs_codegen::writer::rewrite_source(file, &formatted, &mut blocked) {
            Ok(_) => status.line("Formatted", &shown),
            Err(e) => {
                let _ = write_failed(&e);
                refused += 1;
            }
        }
    }
    if refused > 0 {
        return ExitCode::from(2);
    }
    if args.check && changed > 0 {
        if !args.quiet {
            eprintln!(
                "{} of {} would be reformatted (run `rcsc fmt` without --check)",
                plural(changed, "file"),
                files.len()
            );
        }
        return ExitCode::from(1);
    }
    ExitCode::SUCCESS
}

/// `text` (of `file`) in the canonical layout with the width of the
/// file's `rcsfmt.toml`; `None`, the reason printed, when it cannot be.
pub(crate) fn format_file(file: &Path, text: &str, color: bool) -> Option<String> {
    let shown = rcs_dsl::load::display(file);
    let options = match rcs_dsl::fmt::config::options_for(file) {
        Ok((options, _)) => options,
        Err(reason) => {
            eprintln!("error: {}", render::escape_controls(&reason));
            return None;
        }
    };
    match format(text, &options) {
        Ok(formatted) => Some(formatted),
        Err(FmtError::Syntax(diags)) => {
            let mut sources = rcs_dsl::source::SourceMap::new();
            sources.add(shown.clone(), text.to_string());
            for d in &diags {
                eprint!("{}", render::render(d, &sources, Format::Human { color }));
            }
            eprintln!(
                "error: {} does not parse; it was not formatted",
                render::escape_controls(&shown)
            );
            None
        }
        Err(e @ FmtError::Changed(_)) => {
            eprintln!("error: {}: {e}", render::escape_controls(&shown));
            None
        }
    }
}

impl FmtArgs {
    pub(crate) fn color(&self) -> bool {
        use std::io::IsTerminal;
        match self.color {
            ColorChoice::Always => true,
            ColorChoice::Never => false,
            ColorChoice::Auto => {
                std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none()
            }
        }
    }
}

/// The `.rcs` files `path` names: itself, or those below the folder
/// (sorted; hidden folders and `target/` skipped).
fn collect(path: &Path, files: &mut Vec<PathBuf>) -> Result<(), String> {
    let meta = std::fs::metadata(path)
        .map_err(|e| format!("cannot read {}: {e}", rcs_dsl::load::display(path)))?;
    if meta.is_file() {
        files.push(path.to_path_buf());
        return Ok(());
    }
    let mut found = Vec::new();
    let mut stack = vec![path.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let entries = std::fs::read_dir(&dir)
            .map_err(|e| format!("cannot read {}: {e}", rcs_dsl::load::display(&dir)))?;
        for entry in entries {
            let entry =
                entry.map_err(|e| format!("cannot read {}: {e}", rcs_dsl::load::display(&dir)))?;
            let p = entry.path();
            let name = entry.file_name().to_string_lossy().into_owned();
            let kind = entry.file_type().map_err(|e| e.to_string())?;
            if kind.is_dir() {
                if !name.starts_with('.') && name != "target" {
                    stack.push(p);
                }
            } else if name.ends_with(".rcs") {
                found.push(p);
            }
        }
    }
    found.sort();
    files.extend(found);
    Ok(())
}

/// What `rcsc fmt` would change in one file, as `diff -u` prints it.
/// `done` says what made the new text (`formatted`).
pub(crate) fn unified_diff(path: &str, old: &str, new: &str, done: &str) -> String {
    similar::TextDiff::from_lines(old, new)
        .unified_diff()
        .context_radius(3)
        .header(path, &format!("{path} ({done})"))
        .to_string()
}
