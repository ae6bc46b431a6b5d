//! `rcsc`: the command-line face of the rcsc libraries. A thin layer: it
//! parses arguments, calls `rcs-dsl` (and later `rcs-codegen`), prints what
//! they return and turns the outcome into an exit status:
//! 0 success (warnings allowed), 1 diagnostics with an error, 2 usage or I/O.

use clap::{Args, Parser, Subcommand, ValueEnum};
use rcs_dsl::lint::{Level, Lint};
use rcs_dsl::render::{self, Format};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

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
}

#[derive(Args)]
struct CheckArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    paths: Vec<PathBuf>,
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
                color: match self.color {
                    ColorChoice::Always => true,
                    ColorChoice::Never => false,
                    ColorChoice::Auto => {
                        std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none()
                    }
                },
            },
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
    }
}

/// A failure outside the plans: exit 2 with one line.
fn fail(reason: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {reason}");
    ExitCode::from(2)
}

fn check(args: CheckArgs) -> ExitCode {
    let paths = if args.paths.is_empty() {
        vec![PathBuf::from(".")]
    } else {
        args.paths
    };
    let sets = match rcs_dsl::load_paths(&paths) {
        Ok(sets) => sets,
        Err(e) => return fail(e),
    };
    let format = args.common.format();
    let options = args.common.options();
    let (mut errors, mut warnings) = (0, 0);
    let mut out = std::io::stdout().lock();
    let mut err = std::io::stderr().lock();
    for set in &sets {
        let checked = rcs_dsl::check(set, &options);
        for d in &checked.diagnostics {
            let is_error = d.severity == rcs_dsl::Severity::Error;
            if is_error {
                errors += 1;
            } else {
                warnings += 1;
                if args.common.quiet {
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
    if format != Format::Json && !args.common.quiet {
        if let Some(s) = render::summary(errors, if args.common.quiet { 0 } else { warnings }) {
            let _ = writeln!(err, "{s}");
        }
    }
    if errors > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
