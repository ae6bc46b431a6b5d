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

mod compiled;
mod test_cmd;
mod witnesses;

#[derive(Parser)]
#[command(
    name = "rcsc",
    version,
    about = "Compiler and toolchain for NIST RCS controller plans",
    after_help = MAIN_HELP
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
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
}

const TEST_HELP: &str = "\
A scenario (*.scenario.yaml) drives one controller alone: it plays the
supervisor's commands, the subordinates' answers, the buffers the controller
reads and the results of its hooks, and says after each step which row
fired and what state, status, vars, writes and sent commands to expect.

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
struct TestArgs {
    /// Plan sets, scenario files (*.scenario.yaml) or scenarios/ folders [default: .]
    paths: Vec<PathBuf>,
    /// What runs the scenarios.
    #[arg(long, value_enum, default_value_t = test_cmd::Backend::Interp)]
    backend: test_cmd::Backend,
    /// After the run, list per plan the rows no scenario fired.
    #[arg(long)]
    coverage: bool,
    /// Where the compiled backend builds its driver [default: $CARGO_TARGET_DIR or ./target]
    #[arg(long, value_name = "DIR")]
    target_dir: Option<PathBuf>,
    #[command(flatten)]
    common: Common,
}

const MAIN_HELP: &str = "\
A PATH is a plan-set folder (every *.rcs below it, plus its optional rcs.yaml)
or one or more .rcs files; the default is the current folder.

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
struct CheckArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    paths: Vec<PathBuf>,
    /// Write a scenario per finding that has a run (a way to reproduce it)
    /// under DIR: `<lint>_<controller>_<plan>_<state>.scenario.yaml`.
    #[arg(long, value_name = "DIR")]
    witnesses: Option<PathBuf>,
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
        visible_alias = "out",
        value_name = "DIR",
        default_value = "target/rcs"
    )]
    out_dir: PathBuf,
    /// Write the Rust as rcsc prints it, without running rustfmt on it.
    #[arg(long)]
    no_rustfmt: bool,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
#[command(group = clap::ArgGroup::new("what").required(true).args(["plan", "hierarchy"]))]
struct GraphArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    paths: Vec<PathBuf>,
    /// The plan to draw: a controller and one of its command verbs.
    #[arg(long, value_name = "CTRL.VERB", value_parser = parse_plan_name)]
    plan: Option<(String, String)>,
    /// Draw the controller hierarchy (one cluster per CPU) instead of a plan.
    #[arg(long)]
    hierarchy: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = GraphFormat::Dot)]
    format: GraphFormat,
    /// Write to FILE instead of stdout.
    #[arg(short = 'o', long = "out", value_name = "FILE")]
    out: Option<PathBuf>,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct IrArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    paths: Vec<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = IrFormat::Yaml)]
    format: IrFormat,
    /// Write to FILE instead of stdout.
    #[arg(short = 'o', long = "out", value_name = "FILE")]
    out: Option<PathBuf>,
    #[command(flatten)]
    common: Common,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum GraphFormat {
    Dot,
    Svg,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum IrFormat {
    Yaml,
    Json,
}

/// `CTRL.VERB` → (CTRL, VERB).
fn parse_plan_name(s: &str) -> Result<(String, String), String> {
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
        Command::Graph(args) => graph(args),
        Command::Ir(args) => ir(args),
        Command::Test(args) => test(args),
    }
}

fn test(args: TestArgs) -> ExitCode {
    let start = Instant::now();
    let status = Status {
        color: args.common.color(),
        quiet: args.common.quiet,
    };
    let targets = match test_cmd::targets(args.paths) {
        Ok(t) => t,
        Err(reason) => return fail(reason),
    };
    let sets = match rcs_dsl::load_paths(&targets.plan_paths) {
        Ok(sets) => sets,
        Err(e) => return fail(e),
    };
    let per_set = match test_cmd::assign(&sets, &targets.scenarios) {
        Ok(p) => p,
        Err(reason) => return fail(reason),
    };
    let irs = match check_sets(&sets, &args.common, false, None, None) {
        Ok(irs) => irs,
        Err(code) => return code,
    };
    // A run that tests nothing is a mistake (a wrong path, a misnamed
    // folder), not a success.
    if per_set.iter().all(Vec::is_empty) {
        let looked: Vec<String> = sets
            .iter()
            .map(|s| format!("{}/scenarios/", s.root.trim_end_matches('/')))
            .collect();
        eprintln!(
            "error: no scenarios to run (looked in {}); write `*.scenario.yaml` files there or name them",
            looked.join(", ")
        );
        return ExitCode::from(1);
    }
    if !args.common.quiet {
        let untested = sets.iter().zip(&irs).zip(&per_set);
        for ((set, ir), _) in untested.filter(|(_, files)| files.is_empty()) {
            eprintln!(
                "warning: plan set `{}` has no scenarios (none under {}/scenarios/)",
                ir.system,
                set.root.trim_end_matches('/')
            );
        }
    }

    let mut driver = None;
    if args.backend == test_cmd::Backend::Compiled {
        let target = args
            .target_dir
            .or_else(|| std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from))
            .unwrap_or_else(|| PathBuf::from("target"));
        let refs: Vec<&rcs_dsl::ir::Ir> = irs.iter().collect();
        let mut blocked = |dir: &std::path::Path| {
            status.line(
                "Blocking",
                format!("waiting for file lock on {}", rcs_dsl::load::display(dir)),
            )
        };
        match compiled::build(&refs, &target, &test_cmd::status_fn(&status), &mut blocked) {
            Ok(d) => driver = Some(d),
            Err(reason) => return fail(reason),
        }
    }

    let (mut passed, mut failed) = (0, 0);
    let mut reports = Vec::new();
    let mut coverage = String::new();
    let (mut hit, mut all) = (0, 0);
    for (i, (set, ir)) in sets.iter().zip(&irs).enumerate() {
        let loaded: Vec<_> = per_set[i].iter().map(|p| test_cmd::load(ir, p)).collect();
        status.line(
            "Running",
            format!(
                "{} of {} on {}",
                plural(loaded.len(), "scenario"),
                ir.system,
                args.backend.describe()
            ),
        );
        let mut fired = test_cmd::Fired::new();
        let remote = driver.as_mut().map(|d| (d, i));
        let results = match test_cmd::run_set(ir, &loaded, remote, &mut fired) {
            Ok(r) => r,
            Err(reason) => return fail(reason),
        };
        for r in results {
            match r.failure {
                None => {
                    passed += 1;
                    println!("test {} ... ok", r.path);
                }
                Some(report) => {
                    failed += 1;
                    println!("test {} ... FAILED", r.path);
                    reports.push(report);
                }
            }
        }
        if args.coverage {
            let (text, h, a) = test_cmd::coverage(set, ir, &fired);
            coverage.push_str(&format!("\ncoverage of {}:\n{text}", ir.system));
            hit += h;
            all += a;
        }
    }
    if !reports.is_empty() {
        println!("\nfailures:\n");
        for r in &reports {
            println!("{r}");
        }
    }
    if args.coverage {
        print!("{coverage}");
        println!("rows fired: {hit}/{all}\n");
    }
    status.line(
        "Finished",
        format!("in {:.2}s", start.elapsed().as_secs_f64()),
    );
    println!("{passed} passed, {failed} failed");
    if failed > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
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

/// Print one plan set's diagnostics (warnings only when not quiet). JSON
/// goes to stdout unless `stdout_busy` (the command prints its product there).
fn print_diagnostics(
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
    let mut found = witnesses::Witnesses::default();
    let gather = args.witnesses.is_some().then_some(&mut found);
    let result = check_sets(&sets, &args.common, false, None, gather);
    if let Some(dir) = &args.witnesses {
        if let Err(reason) = found.write(dir) {
            return fail(reason);
        }
        if args.common.format() != Format::Json && !args.common.quiet {
            eprintln!(
                "wrote {} to {}",
                plural(found.len(), "witness scenario"),
                rcs_dsl::load::display(dir)
            );
        }
    }
    match result {
        Ok(_) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}

/// Check every plan set, printing diagnostics (JSON to stdout unless
/// `stdout_busy`) and the summary line; with `status`, a `Checking` line
/// per set; with `witnesses`, the runs of the findings gathered. `Err` is
/// exit status 1 when any set has an error.
fn check_sets(
    sets: &[rcs_dsl::PlanSet],
    common: &Common,
    stdout_busy: bool,
    status: Option<&Status>,
    mut witnesses: Option<&mut witnesses::Witnesses>,
) -> Result<Vec<rcs_dsl::ir::Ir>, ExitCode> {
    let options = common.options();
    let mut counts = Counts::default();
    let mut irs = Vec::with_capacity(sets.len());
    for set in sets {
        if let Some(status) = status {
            status.line(
                "Checking",
                format!(
                    "{} ({})",
                    set_name(set),
                    plural(set.rcs_files.len(), "file")
                ),
            );
        }
        let checked = rcs_dsl::check(set, &options);
        print_diagnostics(set, &checked, common, stdout_busy, &mut counts);
        if let Some(w) = witnesses.as_deref_mut() {
            w.collect(&checked);
        }
        irs.extend(checked.ir);
    }
    print_summary(common, &counts);
    if counts.errors > 0 || irs.len() != sets.len() {
        return Err(ExitCode::from(1));
    }
    Ok(irs)
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
    // Check everything before writing anything.
    let irs = match check_sets(&sets, &args.common, false, Some(&status), None) {
        Ok(irs) => irs,
        Err(code) => return code,
    };

    let mut files = match output_files(&sets, &irs) {
        Ok(files) => files,
        Err(reason) => return fail(reason),
    };
    if !args.no_rustfmt {
        rcs_codegen::rustfmt::format_files(&mut files);
    }
    let mut blocked = |dir: &std::path::Path| {
        status.line(
            "Blocking",
            format!("waiting for file lock on {}", rcs_dsl::load::display(dir)),
        )
    };
    let report = match rcs_codegen::writer::write_tree(&args.out_dir, &files, &mut blocked) {
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

/// Every output of every plan set: the tree itself for one plan set named
/// alone, one `<system>/` folder per set for a workspace or several sets.
fn output_files(
    sets: &[rcs_dsl::PlanSet],
    irs: &[rcs_dsl::ir::Ir],
) -> Result<Vec<rcs_codegen::OutputFile>, rcs_codegen::SameSystem> {
    let irs: Vec<&rcs_dsl::ir::Ir> = irs.iter().collect();
    let shared = rcs_dsl::load::shares_output(sets);
    rcs_codegen::generate_sets(&irs, shared, &rcs_codegen::Options::default(), true)
}

/// Load and check plan sets for a command that prints a product on stdout
/// (`graph`, `ir`): diagnostics go to stderr. `Err` is the exit status when
/// the plans cannot be read (2) or have an error (1).
fn checked_irs(
    paths: Vec<PathBuf>,
    common: &Common,
) -> Result<Vec<(rcs_dsl::PlanSet, rcs_dsl::ir::Ir)>, ExitCode> {
    let sets = rcs_dsl::load_paths(&default_paths(paths)).map_err(fail)?;
    let irs = check_sets(&sets, common, true, None, None)?;
    Ok(sets.into_iter().zip(irs).collect())
}

/// Write a command's product to `out` (a file) or to stdout.
fn emit(out: Option<&std::path::Path>, bytes: &[u8]) -> ExitCode {
    let result = match out {
        Some(path) => std::fs::write(path, bytes)
            .map_err(|e| format!("cannot write {}: {e}", rcs_dsl::load::display(path))),
        None => {
            let mut stdout = std::io::stdout().lock();
            match stdout.write_all(bytes).and_then(|()| stdout.flush()) {
                // A closed pipe (`rcsc ir | head`) is the reader's choice, not a failure.
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
                r => r.map_err(|e| format!("cannot write to stdout: {e}")),
            }
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(reason) => fail(reason),
    }
}

/// Every `CTRL.VERB` with a plan, in declaration order.
fn plan_names(irs: &[(rcs_dsl::PlanSet, rcs_dsl::ir::Ir)]) -> Vec<String> {
    let mut names = Vec::new();
    for (_, ir) in irs {
        for c in &ir.controllers {
            for cmd in c.commands.iter().filter(|cmd| cmd.plan.is_some()) {
                names.push(format!("{}.{}", c.name, cmd.name));
            }
        }
    }
    names
}

fn graph(args: GraphArgs) -> ExitCode {
    let irs = match checked_irs(args.paths, &args.common) {
        Ok(irs) => irs,
        Err(code) => return code,
    };
    let dot = match &args.plan {
        Some((ctrl_name, verb)) => {
            let found: Vec<String> = irs
                .iter()
                .filter_map(|(_, ir)| {
                    let ctrl = ir.controller(ir.controller_by_name(ctrl_name)?);
                    let plan = ctrl.plan_of(verb)?;
                    Some(rcs_codegen::dot::plan_graph(ir, ctrl, plan))
                })
                .collect();
            match <[String; 1]>::try_from(found) {
                Ok([dot]) => dot,
                Err(found) if found.is_empty() => {
                    let names = plan_names(&irs);
                    let known = if names.is_empty() {
                        "there are no plans".to_string()
                    } else {
                        format!("the plans are: {}", names.join(", "))
                    };
                    return fail(format!("no plan `{ctrl_name}.{verb}`; {known}"));
                }
                Err(_) => {
                    return fail(format!(
                        "`{ctrl_name}.{verb}` is in several plan sets; name only the one to draw"
                    ))
                }
            }
        }
        None => match irs.as_slice() {
            [(_, ir)] => rcs_codegen::dot::hierarchy_graph(ir),
            [] => return fail("no plan set to draw"),
            _ => {
                return fail(
                    "--hierarchy draws one plan set, but several were named; name only one",
                )
            }
        },
    };
    let bytes = match args.format {
        GraphFormat::Dot => dot.into_bytes(),
        GraphFormat::Svg => match render_svg(&dot) {
            Ok(svg) => svg,
            Err(reason) => return fail(reason),
        },
    };
    emit(args.out.as_deref(), &bytes)
}

/// DOT → SVG through Graphviz `dot`, the one program the CLI runs.
fn render_svg(dot: &str) -> Result<Vec<u8>, String> {
    use std::process::{Command, Stdio};
    let mut child = Command::new("dot")
        .arg("-Tsvg")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => "Graphviz `dot` not found: install the `graphviz` \
                package (e.g. apt-get install graphviz) or use --format dot"
                .to_string(),
            _ => format!("cannot run Graphviz `dot`: {e}"),
        })?;
    // Feed stdin from a thread so a large graph cannot deadlock on full pipes.
    let mut stdin = child.stdin.take().expect("stdin is piped");
    let input = dot.to_string();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let output = child
        .wait_with_output()
        .map_err(|e| format!("cannot run Graphviz `dot`: {e}"))?;
    let written = writer
        .join()
        .unwrap_or_else(|e| std::panic::resume_unwind(e));
    if !output.status.success() {
        let why = String::from_utf8_lossy(&output.stderr);
        let why = why.lines().next().unwrap_or("").trim();
        return Err(format!(
            "Graphviz `dot -Tsvg` failed ({}): {why}",
            output.status
        ));
    }
    written.map_err(|e| format!("cannot feed Graphviz `dot`: {e}"))?;
    Ok(output.stdout)
}

fn ir(args: IrArgs) -> ExitCode {
    let irs = match checked_irs(args.paths, &args.common) {
        Ok(irs) => irs,
        Err(code) => return code,
    };
    let irs: Vec<&rcs_dsl::ir::Ir> = irs.iter().map(|(_, ir)| ir).collect();
    let text = match (args.format, irs.as_slice()) {
        (IrFormat::Json, [one]) => serde_json::to_string_pretty(one).map_err(|e| e.to_string()),
        (IrFormat::Json, all) => serde_json::to_string_pretty(all).map_err(|e| e.to_string()),
        (IrFormat::Yaml, [one]) => rcs_dsl::manifest::to_yaml(one).map_err(|e| e.to_string()),
        (IrFormat::Yaml, all) => rcs_dsl::manifest::to_yaml(&all).map_err(|e| e.to_string()),
    };
    match text {
        Ok(mut text) => {
            if !text.ends_with('\n') {
                text.push('\n');
            }
            emit(args.out.as_deref(), text.as_bytes())
        }
        Err(e) => fail(format!("cannot serialise the IR: {e}")),
    }
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

    /// The IR of a one-controller, one-plan set named `a`.
    pub(crate) fn one_controller() -> rcs_dsl::ir::Ir {
        let set = rcs_dsl::PlanSet::from_texts(
            "a",
            [("a.rcs", "controller A {\n    command GO\n    plan GO {\n        *0 when new_command -> Done\n    }\n}\n")],
            None,
        );
        rcs_dsl::check(&set, &rcs_dsl::Options::default())
            .ir
            .unwrap()
    }

    #[test]
    fn several_sets_with_one_name_are_refused() {
        let ir = one_controller();
        let set = rcs_dsl::PlanSet::default();
        let one = output_files(std::slice::from_ref(&set), std::slice::from_ref(&ir)).unwrap();
        assert!(one.iter().any(|f| f.path == "graphs/hierarchy.dot"));
        let member = rcs_dsl::PlanSet {
            workspace: Some("plans".into()),
            ..rcs_dsl::PlanSet::default()
        };
        let one = output_files(std::slice::from_ref(&member), std::slice::from_ref(&ir)).unwrap();
        assert!(one.iter().any(|f| f.path == "a/graphs/hierarchy.dot"));
        let two = [rcs_dsl::PlanSet::default(), rcs_dsl::PlanSet::default()];
        assert!(output_files(&two, &[ir.clone(), ir]).is_err());
    }
}
