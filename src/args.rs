//! The command line as clap reads it: subcommands, their arguments, and
//! the options every subcommand shares (`Common`: lint levels, message
//! format, colour).

use clap::{Args, Parser, Subcommand, ValueEnum};
use rcs_dsl::lint::{Level, Lint};
use rcs_dsl::render::Format;
use std::io::IsTerminal;
use std::path::PathBuf;

use crate::test_cmd;

#[derive(Parser)]
#[command(
    name = "rcsc",
    version,
    about = "Compiler and toolchain for NIST RCS controller plans",
    after_help = MAIN_HELP
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Parse and validate plan sets; print diagnostics.
    #[command(
        after_help = "Examples:\n  rcsc check plans/submarine\n  rcsc check plans/figure13/figure13.rcs --message-format short\n  rcsc check . -D unused -A float_equality\n  rcsc check plans/submarine --witnesses target/witnesses && rcsc test plans/submarine target/witnesses/*.scenario.yaml"
    )]
    Check(CheckArgs),
    /// Check plan sets, then write their state graphs, state tables and Rust code.
    #[command(after_help = BUILD_HELP)]
    Build(BuildArgs),
    /// Print one state graph (or the controller hierarchy) as DOT or SVG.
    #[command(after_help = GRAPH_HELP)]
    Graph(GraphArgs),
    /// Print the validated intermediate representation, for other tools.
    #[command(after_help = IR_HELP)]
    Ir(IrArgs),
    /// Run scenarios against the plans, on the interpreter or the generated code.
    #[command(after_help = TEST_HELP)]
    Test(TestArgs),
    /// Compare two versions of plan sets (paths or git revisions), by meaning.
    #[command(after_help = DIFF_HELP)]
    Diff(DiffArgs),
    /// Lay out .rcs files in the one canonical layout (in place, or --check).
    #[command(after_help = crate::fmt_cmd::FMT_HELP)]
    Fmt(crate::fmt_cmd::FmtArgs),
    /// Write a static, offline site of the plans: graphs, tables, source, findings.
    #[command(after_help = crate::doc_cmd::DOC_HELP)]
    Doc(crate::doc_cmd::DocArgs),
    /// Sum up runtime traces: row hits and cycles per state, as text.
    #[command(after_help = crate::trace_cmd::TRACE_HELP)]
    Trace(crate::trace_cmd::TraceArgs),
    /// Make a development CA and per-process certificates for a distributed plan set.
    #[command(after_help = crate::certs_cmd::CERTS_HELP)]
    Certs(crate::certs_cmd::CertsArgs),
    /// The language server for editors: JSON-RPC over stdin/stdout
    /// (diagnostics as you type, hover, definition, references, symbols,
    /// completion).
    Lsp,
    /// Watch and act on a running system: the operator's console (over Zenoh with --connect).
    #[cfg(feature = "console")]
    #[command(after_help = crate::console_cmd::CONSOLE_HELP)]
    Console(crate::console_cmd::ConsoleArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    #[command(after_help = crate::completions::COMPLETIONS_HELP)]
    Completions(crate::completions::CompletionsArgs),
    /// Print the man page, or write one page per subcommand into a folder.
    #[command(after_help = crate::completions::MAN_HELP)]
    Man(crate::completions::ManArgs),
}

const DIFF_HELP: &str = "\
Each side is a plan-set path (as `rcsc check` takes) or a git revision of
the repository of the current folder. `rcsc diff REV` compares REV with the
working tree; `rcsc diff A..B` compares two revisions. In a revision, the
plans are read at --path (default `.`), relative to the current folder.

Per controller and plan it lists rows added, removed, changed (condition,
target, jobs, compared after normalising: whitespace and comments are no
change), renumbered, and moved in precedence (with an input for which the
row that fires changes, when the analysis finds one); states added and
removed; commands, statuses, errors, vars, hooks, buffers and subordinates
changed; and the findings of `rcsc check` the change introduced or removed.

Exit status: 0 no change, 1 changes, 2 an error.

Examples:
  rcsc diff HEAD~1 --path plans/submarine
  rcsc diff main..feature --path plans --format markdown > comment.md
  rcsc diff old/plans new/plans --graphs target/diff";

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum DiffFormat {
    Text,
    Markdown,
    Json,
}

#[derive(Args)]
pub(crate) struct DiffArgs {
    /// The old version: a path or a git revision (`A..B`: both sides).
    pub(crate) old: String,
    /// The new version: a path or a git revision [default: the working tree]
    pub(crate) new: Option<String>,
    /// The plan sets to compare in a revision (and in the working tree),
    /// relative to the current folder [default: .]
    #[arg(short = 'p', long = "path", value_name = "PATH")]
    pub(crate) paths: Vec<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = DiffFormat::Text)]
    pub(crate) format: DiffFormat,
    /// Also write a diff-coloured DOT graph per changed plan under DIR.
    #[arg(long, value_name = "DIR")]
    pub(crate) graphs: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) common: Common,
}

const TEST_HELP: &str = "\
A scenario (*.scenario.yaml) drives one controller alone: it plays the
supervisor's commands, the subordinates' answers, the buffers the controller
reads and the results of its hooks, and says after each step which row
fired and what state, status, vars, writes and sent commands to expect.
A system scenario (`system: true`, or `controllers: [A, B]` for whole
subtrees) runs several controllers on their schedule instead, playing only
the external buffers, the hooks and each root's supervisor, and expects
per controller (docs/scenarios.md, \"System scenarios\").

Scenarios are found under `scenarios/` beside each plan set's rcs.yaml (or
its .rcs files), or named on the command line (a scenario named alone tests
the plan set above its `scenarios/` folder). The plans are checked first;
an error stops the run (exit status 1).

Each scenario prints `ok` or `FAILED`; a failure names the file and line of
the step, expected against actual, and the rows fired so far. The run ends
with `N passed, N failed`; any failure exits with status 1.

`--backend compiled` runs the same scenarios on the generated Rust: rcsc
writes a small driver crate under TARGET/rcsc/ and builds it with cargo
(offline, once; later runs rebuild only what changed).

Examples:
  rcsc test plans/submarine
  rcsc test plans/submarine --backend compiled --coverage
  rcsc test plans/submarine/scenarios/pr_ahead_servo_loop.scenario.yaml";

#[derive(Args)]
pub(crate) struct TestArgs {
    /// Plan sets, scenario files (*.scenario.yaml) or scenarios/ folders [default: .]
    pub(crate) paths: Vec<PathBuf>,
    /// What runs the scenarios.
    #[arg(long, value_enum, default_value_t = test_cmd::Backend::Interp)]
    pub(crate) backend: test_cmd::Backend,
    /// After the run, list per plan the rows no scenario fired.
    #[arg(long)]
    pub(crate) coverage: bool,
    /// Write every cycle of every scenario to FILE as a trace (JSON lines,
    /// or an MCAP recording for Foxglove, Lichtblick or PlotJuggler when
    /// FILE ends in .mcap; docs/trace-format.md), for `rcsc trace` and
    /// `rcsc doc --trace`.
    #[arg(long, value_name = "FILE")]
    pub(crate) trace: Option<PathBuf>,
    /// Where the compiled backend builds its driver [default: $CARGO_TARGET_DIR or ./target]
    #[arg(long, value_name = "DIR")]
    pub(crate) target_dir: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) common: Common,
}

const MAIN_HELP: &str = "\
A PATH is a plan-set folder (every *.rcs below it, plus its optional rcs.yaml),
a workspace (a folder whose subfolders are plan sets, or an rcs.yaml with
`workspace: [folder, ...]`), or one or more .rcs files; the default is the
current folder.

Exit status: 0 success (warnings allowed), 1 a diagnostic with an error,
2 a usage or I/O problem (with a one-line reason).

Examples:
  rcsc check plans/submarine
  rcsc build plans/submarine -o target/rcs
  rcsc graph plans/submarine --plan PR.AHEAD --format svg -o ahead.svg
  rcsc ir plans/submarine --format json

Run `rcsc help <COMMAND>` for a command's options and more examples.";

const GRAPH_HELP: &str = "\
The plans are checked first; diagnostics are printed as by `rcsc check` (on
stderr, in every format, since stdout carries the graph) and an error stops
the command with exit status 1. An unknown CTRL.VERB is a usage problem
(exit status 2) whose message lists the plans there are.

`--format svg` runs Graphviz `dot -Tsvg` on the DOT text; install the
`graphviz` package for it, or render the DOT yourself.

Examples:
  rcsc graph plans/submarine --plan PR.AHEAD
  rcsc graph plans/submarine --plan PR.AHEAD --format svg -o ahead.svg
  rcsc graph plans/submarine --hierarchy | dot -Tpng -o hierarchy.png
  rcsc graph plans/figure13/figure13.rcs --plan GX.RUN";

const IR_HELP: &str = "\
The plans are checked first; diagnostics are printed as by `rcsc check` (on
stderr, in every format, since stdout carries the IR) and an error stops the
command with exit status 1. One plan set gives one IR object; several give a
list of them, in the order named. Entities refer to each other by index
(`controllers[i]`, `plans[i]`, `states[i]`, ...); spans are byte ranges
`{file, start, end}` into `files[file]`, relative to the plan-set folder.

Examples:
  rcsc ir plans/submarine
  rcsc ir plans/submarine --format json -o submarine.json
  rcsc ir plans/submarine --format json | jq '.controllers[].name'";

const BUILD_HELP: &str = "\
Every plan set is checked first; if any has an error, the diagnostics are
printed and nothing is written (exit status 1). Otherwise the outputs go to
DIR (one plan set) or DIR/<system> (several):

  rust/<system>.rs            the generated Rust
  graphs/<CTRL>/<VERB>.dot    one state graph per plan
  graphs/hierarchy.dot        the controller tree
  tables/<CTRL>.md            the state tables

The Rust is formatted with rustfmt (`$RUSTFMT`, else `rustfmt` on PATH)
when it runs, else written as rcsc prints it; `--no-rustfmt` skips it.
Files are rewritten only when their content changed; generated files under
DIR that are no longer produced are removed (other files are left alone).
Every file is staged first and then renamed into place, under a lock on DIR
(a second build waits); a file at a generated path without `@generated by
rcsc` in its first line, or a symbolic link leading out of DIR, stops the
build before anything is written (exit status 2).

Examples:
  rcsc build plans/submarine
  rcsc build plans/submarine plans/figure13 -o docs/generated
  rcsc build . -D unused --message-format short";

#[derive(Args)]
pub(crate) struct CheckArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    pub(crate) paths: Vec<PathBuf>,
    /// Write a scenario per finding that has a run (a way to reproduce it)
    /// under DIR: `<lint>_<controller>_<plan>_<state>.scenario.yaml`.
    #[arg(long, value_name = "DIR")]
    pub(crate) witnesses: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Args)]
pub(crate) struct BuildArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    pub(crate) paths: Vec<PathBuf>,
    /// Where to write the outputs.
    #[arg(
        short = 'o',
        long = "out-dir",
        visible_alias = "out",
        value_name = "DIR",
        default_value = "target/rcs"
    )]
    pub(crate) out_dir: PathBuf,
    /// Write the Rust as rcsc prints it, without running rustfmt on it.
    #[arg(long)]
    pub(crate) no_rustfmt: bool,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Args)]
#[command(group = clap::ArgGroup::new("what").required(true).args(["plan", "hierarchy"]))]
pub(crate) struct GraphArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    pub(crate) paths: Vec<PathBuf>,
    /// The plan to draw: a controller and one of its command verbs.
    #[arg(long, value_name = "CTRL.VERB", value_parser = parse_plan_name)]
    pub(crate) plan: Option<(String, String)>,
    /// Draw the controller hierarchy (one cluster per CPU) instead of a plan.
    #[arg(long)]
    pub(crate) hierarchy: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = GraphFormat::Dot)]
    pub(crate) format: GraphFormat,
    /// Write to FILE instead of stdout.
    #[arg(short = 'o', long = "out", value_name = "FILE")]
    pub(crate) out: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Args)]
pub(crate) struct IrArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    pub(crate) paths: Vec<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = IrFormat::Yaml)]
    pub(crate) format: IrFormat,
    /// Write to FILE instead of stdout.
    #[arg(short = 'o', long = "out", value_name = "FILE")]
    pub(crate) out: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum GraphFormat {
    Dot,
    Svg,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum IrFormat {
    Yaml,
    Json,
}

/// `CTRL.VERB` → (CTRL, VERB).
pub(crate) fn parse_plan_name(s: &str) -> Result<(String, String), String> {
    match s.split_once('.') {
        Some((c, v)) if !c.is_empty() && !v.is_empty() && !v.contains('.') => {
            Ok((c.to_string(), v.to_string()))
        }
        _ => Err(format!(
            "`{s}` is not CTRL.VERB (a controller and one of its commands, e.g. PR.AHEAD)"
        )),
    }
}

#[derive(Args)]
pub(crate) struct Common {
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value_t = MessageFormat::Human)]
    pub(crate) message_format: MessageFormat,
    /// When to colour human output.
    #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
    pub(crate) color: ColorChoice,
    /// Print only errors, no warnings or status lines.
    #[arg(short, long)]
    pub(crate) quiet: bool,
    /// Allow a lint (no report).
    #[arg(short = 'A', value_name = "LINT", value_parser = parse_lint)]
    pub(crate) allow: Vec<Lint>,
    /// Warn on a lint.
    #[arg(short = 'W', value_name = "LINT", value_parser = parse_lint)]
    pub(crate) warn: Vec<Lint>,
    /// Deny a lint (report it as an error).
    #[arg(short = 'D', value_name = "LINT", value_parser = parse_lint)]
    pub(crate) deny: Vec<Lint>,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum MessageFormat {
    Human,
    Short,
    Json,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum ColorChoice {
    Auto,
    Always,
    Never,
}

pub(crate) fn parse_lint(s: &str) -> Result<Lint, String> {
    Lint::from_name(s).ok_or_else(|| {
        format!(
            "unknown lint `{s}`; the lints are: {}",
            Lint::ALL.map(Lint::name).join(", ")
        )
    })
}

impl Common {
    pub(crate) fn format(&self) -> Format {
        match self.message_format {
            MessageFormat::Short => Format::Short,
            MessageFormat::Json => Format::Json,
            MessageFormat::Human => Format::Human {
                color: self.color(),
            },
        }
    }

    /// The cargo-style progress lines these options ask for.
    pub(crate) fn status(&self) -> crate::output::Status {
        crate::output::Status {
            color: self.color(),
            quiet: self.quiet,
        }
    }

    /// Whether to colour what goes to stderr.
    pub(crate) fn color(&self) -> bool {
        match self.color {
            ColorChoice::Always => true,
            ColorChoice::Never => false,
            ColorChoice::Auto => {
                std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none()
            }
        }
    }

    /// `-A/-W/-D` in the order clap gives them (allow, then warn, then deny).
    pub(crate) fn options(&self) -> rcs_dsl::Options {
        let mut lint_flags = Vec::new();
        lint_flags.extend(self.allow.iter().map(|l| (*l, Level::Allow)));
        lint_flags.extend(self.warn.iter().map(|l| (*l, Level::Warn)));
        lint_flags.extend(self.deny.iter().map(|l| (*l, Level::Deny)));
        rcs_dsl::Options { lint_flags }
    }
}
