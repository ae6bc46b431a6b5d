//! `rcsc`: the command-line face of the rcsc libraries. A thin layer: it
//! parses arguments, calls `rcs-dsl` and `rcs-codegen`, prints what they
//! return and turns the outcome into an exit status:
//! 0 success (warnings allowed), 1 diagnostics with an error, 2 usage or I/O.

use clap::{Args, Parser, Subcommand, ValueEnum};
use rcs_dsl::lint::{Level, Lint};
use rcs_dsl::render::{self, Format};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "rcsc",
    version,
    about = "Compiler and toolchain for NIST RCS controller plans"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Parse and validate plan sets; print diagnostics.
    #[command(
        after_help = "Examples:\n  rcsc check plans/submarine\n  rcsc check plans/figure13/figure13.rcs --message-format short\n  rcsc check . -D unused -A float_equality"
    )]
    Check(CheckArgs),
    /// Check plan sets, then write their state graphs, state tables and Rust code.
    #[command(after_help = BUILD_HELP)]
    Build(BuildArgs),
}

const BUILD_HELP: &str = "\
Every plan set is checked first; if any has an error, the diagnostics are
printed and nothing is written (exit status 1). Otherwise the outputs go to
DIR (one plan set) or DIR/<system> (several):

  rust/<system>.rs            the generated Rust
  graphs/<CTRL>/<VERB>.dot    one state graph per plan
  graphs/hierarchy.dot        the controller tree
  tables/<CTRL>.md            the state tables

Files are rewritten only when their content changed; generated files under
DIR that are no longer produced are removed (other files are left alone).

Examples:
  rcsc build plans/submarine
  rcsc build plans/submarine plans/figure13 -o docs/generated
  rcsc build . -D unused --message-format short";

#[derive(Args)]
struct CheckArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    paths: Vec<PathBuf>,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct BuildArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    paths: Vec<PathBuf>,
    /// Where to write the outputs.
    #[arg(
        short = 'o',
        long = "out-dir",
        value_name = "DIR",
        default_value = "target/rcs"
    )]
    out_dir: PathBuf,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct Common {
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value_t = MessageFormat::Human)]
    message_format: MessageFormat,
    /// When to colour human output.
    #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
    color: ColorChoice,
    /// Print only errors, no warnings or status lines.
    #[arg(short, long)]
    quiet: bool,
    /// Allow a lint (no report).
    #[arg(short = 'A', value_name = "LINT", value_parser = parse_lint)]
    allow: Vec<Lint>,
    /// Warn on a lint.
    #[arg(short = 'W', value_name = "LINT", value_parser = parse_lint)]
    warn: Vec<Lint>,
    /// Deny a lint (report it as an error).
    #[arg(short = 'D', value_name = "LINT", value_parser = parse_lint)]
    deny: Vec<Lint>,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MessageFormat {
    Human,
    Short,
    Json,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ColorChoice {
    Auto,
    Always,
    Never,
}

fn parse_lint(s: &str) -> Result<Lint, String> {
    Lint::from_name(s).ok_or_else(|| {
        format!(
            "unknown lint `{s}`; the lints are: {}",
            Lint::ALL.map(Lint::name).join(", ")
        )
    })
}

impl Common {
    fn format(&self) -> Format {
        match self.message_format {
            MessageFormat::Short => Format::Short,
            MessageFormat::Json => Format::Json,
            MessageFormat::Human => Format::Human {
                color: self.color(),
            },
        }
    }

    /// Whether to colour what goes to stderr.
    fn color(&self) -> bool {
        match self.color {
            ColorChoice::Always => true,
            ColorChoice::Never => false,
            ColorChoice::Auto => {
                std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none()
            }
        }
    }

    /// `-A/-W/-D` in the order clap gives them (allow, then warn, then deny).
    fn options(&self) -> rcs_dsl::Options {
        let mut lint_flags = Vec::new();
        lint_flags.extend(self.allow.iter().map(|l| (*l, Level::Allow)));
        lint_flags.extend(self.warn.iter().map(|l| (*l, Level::Warn)));
        lint_flags.extend(self.deny.iter().map(|l| (*l, Level::Deny)));
        rcs_dsl::Options { lint_flags }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check(args) => check(args),
        Command::Build(args) => build(args),
    }
}

/// A failure outside the plans: exit 2 with one line.
fn fail(reason: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {reason}");
    ExitCode::from(2)
}

fn default_paths(paths: Vec<PathBuf>) -> Vec<PathBuf> {
    if paths.is_empty() {
        vec![PathBuf::from(".")]
    } else {
        paths
    }
}

/// Diagnostics printed so far.
#[derive(Default)]
struct Counts {
    errors: usize,
    warnings: usize,
}

/// Print one plan set's diagnostics (warnings only when not quiet).
fn print_diagnostics(
    set: &rcs_dsl::PlanSet,
    checked: &rcs_dsl::Checked,
    common: &Common,
    counts: &mut Counts,
) {
    let format = common.format();
    let mut out = std::io::stdout().lock();
    let mut err = std::io::stderr().lock();
    for d in &checked.diagnostics {
        if d.severity == rcs_dsl::Severity::Error {
            counts.errors += 1;
        } else {
            counts.warnings += 1;
            if common.quiet {
                continue;
            }
        }
        let text = render::render(d, &set.sources, format);
        // Machine formats go to stdout; human text to stderr, as rustc does.
        let _ = match format {
            Format::Json => out.write_all(text.as_bytes()),
            _ => err.write_all(text.as_bytes()),
        };
    }
}

/// The `N errors, M warnings` line after the diagnostics.
fn print_summary(common: &Common, counts: &Counts) {
    if common.format() != Format::Json && !common.quiet {
        if let Some(s) = render::summary(counts.errors, counts.warnings) {
            eprintln!("{s}");
        }
    }
}

fn check(args: CheckArgs) -> ExitCode {
    let paths = default_paths(args.paths);
    let sets = match rcs_dsl::load_paths(&paths) {
        Ok(sets) => sets,
        Err(e) => return fail(e),
    };
    let options = args.common.options();
    let mut counts = Counts::default();
    for set in &sets {
        let checked = rcs_dsl::check(set, &options);
        print_diagnostics(set, &checked, &args.common, &mut counts);
    }
    print_summary(&args.common, &counts);
    if counts.errors > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// cargo-style progress lines on stderr: a right-aligned verb (bold green
/// with colour), then the message. Silent with `--quiet`.
struct Status {
    color: bool,
    quiet: bool,
}

impl Status {
    fn line(&self, verb: &str, message: impl std::fmt::Display) {
        if self.quiet {
            return;
        }
        if self.color {
            let pad = " ".repeat(12usize.saturating_sub(verb.chars().count()));
            eprintln!("{pad}\x1b[1m\x1b[32m{verb}\x1b[0m {message}");
        } else {
            eprintln!("{verb:>12} {message}");
        }
    }
}

fn plural(n: usize, word: &str) -> String {
    format!("{n} {word}{}", if n == 1 { "" } else { "s" })
}

/// The name a plan set goes by before it is checked.
fn set_name(set: &rcs_dsl::PlanSet) -> &str {
    set.manifest
        .system
        .as_ref()
        .map_or(set.name.as_str(), |(s, _)| s.as_str())
}

fn build(args: BuildArgs) -> ExitCode {
    let start = Instant::now();
    let status = Status {
        color: args.common.color(),
        quiet: args.common.quiet,
    };
    let paths = default_paths(args.paths);
    let sets = match rcs_dsl::load_paths(&paths) {
        Ok(sets) => sets,
        Err(e) => return fail(e),
    };
    let options = args.common.options();

    // Check everything before writing anything.
    let mut counts = Counts::default();
    let mut irs = Vec::with_capacity(sets.len());
    for set in &sets {
        status.line(
            "Checking",
            format!(
                "{} ({})",
                set_name(set),
                plural(set.rcs_files.len(), "file")
            ),
        );
        let checked = rcs_dsl::check(set, &options);
        print_diagnostics(set, &checked, &args.common, &mut counts);
        irs.push(checked.ir);
    }
    print_summary(&args.common, &counts);
    let irs: Vec<_> = irs.into_iter().flatten().collect();
    if counts.errors > 0 || irs.len() != sets.len() {
        return ExitCode::from(1);
    }

    let files = match output_files(&irs) {
        Ok(files) => files,
        Err(reason) => return fail(reason),
    };
    let report = match rcs_codegen::writer::write_tree(&args.out_dir, &files) {
        Ok(report) => report,
        Err(e) => return fail(e),
    };
    let mut message = format!(
        "{} ({} changed",
        plural(files.len(), "file"),
        report.written.len()
    );
    if !report.removed.is_empty() {
        message.push_str(&format!(", {} removed", report.removed.len()));
    }
    message.push(')');
    status.line("Generating", message);
    status.line(
        "Finished",
        format!("in {:.2}s", start.elapsed().as_secs_f64()),
    );
    ExitCode::SUCCESS
}

/// Every output of every plan set: the tree itself for one set, one
/// `<system>/` folder per set for several.
fn output_files(irs: &[rcs_dsl::ir::Ir]) -> Result<Vec<rcs_codegen::OutputFile>, String> {
    if let [ir] = irs {
        return Ok(rcs_codegen::generate(ir));
    }
    let mut files = Vec::new();
    let mut systems: Vec<&str> = Vec::new();
    for ir in irs {
        if systems.contains(&ir.system.as_str()) {
            return Err(format!(
                "two plan sets are both named `{}`; build them separately or rename one (`system:` in rcs.yaml)",
                ir.system
            ));
        }
        systems.push(&ir.system);
        files.extend(rcs_codegen::generate(ir).into_iter().map(|mut f| {
            f.path = format!("{}/{}", ir.system, f.path);
            f
        }));
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_lines_align_like_cargo() {
        // Only the layout is checked here; the binary tests cover the text.
        assert_eq!(format!("{:>12} x", "Checking"), "    Checking x");
        assert_eq!(plural(1, "file"), "1 file");
        assert_eq!(plural(3, "file"), "3 files");
    }

    #[test]
    fn several_sets_with_one_name_are_refused() {
        let set = rcs_dsl::PlanSet::from_texts(
            "a",
            [("a.rcs", "controller A {\n    command GO\n    plan GO {\n        *0 when new_command -> Done\n    }\n}\n")],
            None,
        );
        let ir = rcs_dsl::check(&set, &rcs_dsl::Options::default())
            .ir
            .unwrap();
        let one = output_files(std::slice::from_ref(&ir)).unwrap();
        assert!(one.iter().any(|f| f.path == "graphs/hierarchy.dot"));
        assert!(output_files(&[ir.clone(), ir]).is_err());
    }
}
