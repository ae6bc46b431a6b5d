//! What the subcommands print and how they end: diagnostics and their
//! summary, cargo-like status lines, writing to a file (through the one
//! writer's rules, [`rcs_codegen::writer`]) or stdout, and exit statuses.
//!
//! Text that came from the user (paths, names, messages) may hold control
//! characters; every failure line goes through [`rcs_dsl::render::escape_controls`]
//! so that none reaches a terminal as itself.

use crate::args::*;
use rcs_dsl::render::{self, Format};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// A failure outside the plans: exit 2 with one line.
pub(crate) fn fail(reason: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {}", render::escape_controls(&reason.to_string()));
    ExitCode::from(2)
}

/// A write the writer refused or that failed: exit 2 with
/// `error[code]: why` (`error: why` for an I/O error) and, for most
/// refusals, a `help:` line.
pub(crate) fn write_failed(e: &rcs_codegen::writer::WriteError) -> ExitCode {
    let code = e.code().map(|c| format!("[{c}]")).unwrap_or_default();
    eprintln!("error{code}: {}", render::escape_controls(&e.to_string()));
    if let Some(help) = e.help() {
        eprintln!("  = help: {help}");
    }
    ExitCode::from(2)
}

/// The files of `sets` (plans and manifests): no output may replace one.
pub(crate) fn inputs_of<'a>(
    sets: impl IntoIterator<Item = &'a rcs_dsl::PlanSet>,
) -> rcs_codegen::writer::Inputs {
    let mut inputs = rcs_codegen::writer::Inputs::new();
    for set in sets {
        for (_, f) in set.sources.files() {
            inputs.add(std::path::Path::new(&f.path));
        }
    }
    inputs
}

pub(crate) fn default_paths(paths: Vec<PathBuf>) -> Vec<PathBuf> {
    if paths.is_empty() {
        vec![PathBuf::from(".")]
    } else {
        paths
    }
}

/// Diagnostics printed so far.
#[derive(Default)]
pub(crate) struct Counts {
    pub(crate) errors: usize,
    pub(crate) warnings: usize,
}

/// Print one plan set's diagnostics (warnings only when not quiet). JSON
/// goes to stdout unless `stdout_busy` (the command prints its product there).
pub(crate) fn print_diagnostics(
    set: &rcs_dsl::PlanSet,
    checked: &rcs_dsl::Checked,
    common: &Common,
    stdout_busy: bool,
    counts: &mut Counts,
) {
    let format = common.format();
    let mut out = std::io::stdout().lock();
    let mut err = std::io::stderr().lock();
    for d in &checked.diagnostics {
        if d.severity == rcs_dsl::Severity::Error {
            counts.errors += 1;
        } else if d.severity == rcs_dsl::Severity::Note {
            if common.quiet {
                continue;
            }
        } else {
            counts.warnings += 1;
            if common.quiet {
                continue;
            }
        }
        let text = render::render(d, &set.sources, format);
        // Machine formats go to stdout; human text to stderr, as rustc does.
        let _ = match format {
            Format::Json if !stdout_busy => out.write_all(text.as_bytes()),
            _ => err.write_all(text.as_bytes()),
        };
    }
}

/// The `N errors, M warnings` line after the diagnostics.
pub(crate) fn print_summary(common: &Common, counts: &Counts) {
    if common.format() != Format::Json && !common.quiet {
        if let Some(s) = render::summary(counts.errors, counts.warnings) {
            eprintln!("{s}");
        }
    }
}

/// cargo-style progress lines on stderr: a right-aligned verb (bold green
/// with colour), then the message. Silent with `--quiet`.
pub(crate) struct Status {
    pub(crate) color: bool,
    pub(crate) quiet: bool,
}

impl Status {
    pub(crate) fn line(&self, verb: &str, message: impl std::fmt::Display) {
        if self.quiet {
            return;
        }
        let message = render::escape_controls(&message.to_string()).into_owned();
        if self.color {
            let pad = " ".repeat(12usize.saturating_sub(verb.chars().count()));
            eprintln!("{pad}\x1b[1m\x1b[32m{verb}\x1b[0m {message}");
        } else {
            eprintln!("{verb:>12} {message}");
        }
    }
}

pub(crate) fn plural(n: usize, word: &str) -> String {
    format!("{n} {word}{}", if n == 1 { "" } else { "s" })
}

/// The name a plan set goes by before it is checked.
pub(crate) fn set_name(set: &rcs_dsl::PlanSet) -> &str {
    set.manifest
        .system
        .as_ref()
        .map_or(set.name.as_str(), |(s, _)| s.as_str())
}

/// Write a command's product to `out` (a file, through the writer: it
/// must carry [`rcs_codegen::GENERATED`] in its first line, and may replace
/// neither a file of `inputs` nor one rcsc did not generate) or to stdout.
pub(crate) fn emit(
    out: Option<&std::path::Path>,
    text: &str,
    inputs: &rcs_codegen::writer::Inputs,
) -> ExitCode {
    if let Some(path) = out {
        return match rcs_codegen::writer::write_file(path, text, inputs, &mut |_| {}) {
            Ok(_) => ExitCode::SUCCESS,
            Err(e) => write_failed(&e),
        };
    }
    match print_stdout(text) {
        Err(e) => fail(format!("cannot write to stdout: {e}")),
        Ok(()) => ExitCode::SUCCESS,
    }
}

/// Write `text` to stdout. A closed pipe (`rcsc ir | head`, `rcsc fmt
/// --check | head`) is the reader's choice, not a failure: it is `Ok`, and
/// never the panic `print!` would make of it.
pub(crate) fn print_stdout(text: &str) -> std::io::Result<()> {
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
    {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other,
    }
}
