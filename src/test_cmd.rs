//! `rcsc test`: find the scenarios of the plan sets named, check the
//! plans, run every scenario on the chosen backend (the reference
//! interpreter, or the generated code through [`crate::compiled`]), report
//! each like `cargo test` does, and optionally the rows no scenario fired.

use crate::args::*;
use crate::commands::check_sets_to_run;
use crate::output::*;
use crate::{compiled, Status};
use rcs_codegen::site::RunCounts;
use rcs_dsl::ir::Ir;
use rcs_dsl::scenario::{self, AnyScenario, Outcome, SystemOutcome};
use rcs_dsl::source::SourceFile;
use rcs_dsl::PlanSet;
use rcs_runtime::{TraceRecord, TraceSink};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Which code runs the scenarios.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    /// The reference interpreter of the IR (no compilation).
    Interp,
    /// The generated Rust, built into a driver crate under the target folder.
    Compiled,
}

impl Backend {
    pub fn describe(self) -> &'static str {
        match self {
            Backend::Interp => "the interpreter",
            Backend::Compiled => "the generated code",
        }
    }
}

/// What to run: plan-set paths, and scenario files named explicitly.
#[derive(Debug, Default, PartialEq)]
pub struct Targets {
    pub plan_paths: Vec<PathBuf>,
    pub scenarios: Vec<PathBuf>,
}

/// Whether a path names a scenario file.
fn is_scenario(path: &Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy())
        .unwrap_or_default();
    name.ends_with(".scenario.yaml") || name.ends_with(".scenario.yml")
}

/// The `*.scenario.yaml` files of a folder, sorted.
fn scenarios_in(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(format!("cannot read {}: {e}", rcs_dsl::load::display(dir))),
    };
    let mut out = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|e| format!("cannot read {}: {e}", rcs_dsl::load::display(dir)))?
            .path();
        if path.is_file() && is_scenario(&path) {
            out.push(path);
        }
    }
    out.sort();
    Ok(out)
}

/// Split the command line into plan sets and scenarios. A `scenarios/`
/// folder stands for its scenario files; a scenario named without any
/// plan set tests the set it lives in (the folder above `scenarios/`, or
/// the nearest folder with an `rcs.yaml`).
pub fn targets(paths: Vec<PathBuf>) -> Result<Targets, String> {
    let mut t = Targets::default();
    for p in paths {
        if is_scenario(&p) {
            t.scenarios.push(p);
        } else if p.is_dir() && p.file_name().is_some_and(|n| n == "scenarios") {
            t.scenarios.extend(scenarios_in(&p)?);
        } else {
            t.plan_paths.push(p);
        }
    }
    if t.plan_paths.is_empty() {
        let mut homes = Vec::new();
        for s in &t.scenarios {
            let home = home_of(s).ok_or_else(|| {
                format!(
                    "cannot tell which plan set {} tests; name the plan set too (`rcsc test PLANS {}`)",
                    rcs_dsl::load::display(s),
                    rcs_dsl::load::display(s)
                )
            })?;
            if !homes.contains(&home) {
                homes.push(home);
            }
        }
        t.plan_paths = homes;
    }
    if t.plan_paths.is_empty() {
        t.plan_paths.push(PathBuf::from("."));
    }
    Ok(t)
}

/// The plan-set folder a scenario file belongs to.
fn home_of(scenario: &Path) -> Option<PathBuf> {
    let dir = scenario.parent()?;
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    if dir.file_name().is_some_and(|n| n == "scenarios") {
        let up = dir.parent()?;
        return Some(if up.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            up.to_path_buf()
        });
    }
    dir.ancestors()
        .find(|a| a.join("rcs.yaml").is_file())
        .map(Path::to_path_buf)
}

/// The folder a plan set's `scenarios/` sits in.
fn set_folder(set: &PlanSet) -> PathBuf {
    if !set.root.is_empty() {
        return PathBuf::from(&set.root);
    }
    // Loose files: the folder of the first one.
    set.rcs_files
        .first()
        .and_then(|f| Path::new(&set.sources.get(*f).path).parent())
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn same_place(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// Scenario files per plan set: those named for it, else its `scenarios/`.
pub fn assign(sets: &[PlanSet], named: &[PathBuf]) -> Result<Vec<Vec<PathBuf>>, String> {
    let folders: Vec<PathBuf> = sets.iter().map(set_folder).collect();
    let mut per_set = vec![Vec::new(); sets.len()];
    for s in named {
        let home = home_of(s);
        let i = match home
            .as_ref()
            .and_then(|h| folders.iter().position(|f| same_place(f, h)))
        {
            Some(i) => i,
            None if sets.len() == 1 => 0,
            None => {
                return Err(format!(
                    "{} is not under any of the plan sets named; run it with its own plan set",
                    rcs_dsl::load::display(s)
                ))
            }
        };
        per_set[i].push(s.clone());
    }
    for (i, list) in per_set.iter_mut().enumerate() {
        if list.is_empty() && named.is_empty() {
            *list = scenarios_in(&folders[i].join("scenarios"))?;
        }
    }
    Ok(per_set)
}

/// One scenario to run, or a file that could not be read as one.
pub struct Loaded {
    pub path: String,
    /// One controller's scenario or a system scenario.
    pub scenario: Result<AnyScenario, (usize, String)>,
}

pub fn load(ir: &Ir, path: &Path) -> Loaded {
    let shown = rcs_dsl::load::display(path);
    let text = std::fs::read(path).map(String::from_utf8);
    let scenario = match text {
        Err(e) => Err((0, format!("cannot read: {e}"))),
        Ok(Err(e)) => {
            // Where the first bad byte is, as for a plan file.
            let mut offset = e.utf8_error().valid_up_to();
            let lossy = String::from_utf8_lossy(e.as_bytes());
            if lossy.starts_with(rcs_dsl::source::BOM) {
                offset -= rcs_dsl::source::BOM.len_utf8();
            }
            let file = SourceFile::new(shown.clone(), lossy.into_owned());
            let (line, column) = file.line_col(offset);
            Err((
                line,
                format!("not valid UTF-8 (first bad byte at line {line}, column {column}); save the file as UTF-8"),
            ))
        }
        Ok(Ok(text)) => {
            let stem = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let stem = stem
                .trim_end_matches(".yaml")
                .trim_end_matches(".yml")
                .trim_end_matches(".scenario")
                .to_string();
            scenario::parse_any(ir, &SourceFile::new(shown.clone(), text), &stem)
                .map_err(|e| (e.line, e.message))
        }
    };
    Loaded {
        path: shown,
        scenario,
    }
}

/// The rows fired, cycle by cycle, with runs of one name shortened
/// (`- ×200`), so a long wait reads as one item.
fn fired_so_far(fired: &[(String, u64)]) -> String {
    let mut parts: Vec<String> = Vec::new();
    for (name, n) in fired {
        parts.push(if *n > 2 {
            format!("{name} ×{n}")
        } else {
            vec![name.as_str(); *n as usize].join(", ")
        });
    }
    if parts.is_empty() {
        "none (no cycle ran)".to_string()
    } else {
        parts.join(", ")
    }
}

/// One scenario's result line and, if it failed, its report.
pub struct ScenarioResult {
    pub path: String,
    pub failure: Option<String>,
}

/// The report of a failed scenario: file and line, expected against
/// actual (one line each), and the rows fired so far.
fn failure_report(path: &str, o: &Outcome) -> Option<String> {
    let (line, report) = o.failure.as_ref()?;
    let mut text = format!("{path}:{line}: scenario `{}` failed here\n", o.name);
    for problem in report.lines() {
        text.push_str(&format!("    {problem}\n"));
    }
    text.push_str(&format!(
        "  rows fired so far: {}\n",
        fired_so_far(&o.fired)
    ));
    Some(text)
}

/// Rows fired and cycles per state over a plan set's scenarios: what
/// `--coverage` reports and `rcsc doc --coverage` draws.
pub type Fired = RunCounts;

/// Run the loaded scenarios of one plan set. `remote`: the compiled
/// backend's driver and this set's number in it. Each scenario's hits go
/// into `fired`, and with `trace`, its cycles into the trace.
pub fn run_set(
    ir: &Ir,
    loaded: &[Loaded],
    mut remote: Option<(&mut compiled::Driver, usize)>,
    fired: &mut Fired,
    mut trace: Option<&mut TraceSink>,
) -> Result<Vec<ScenarioResult>, String> {
    let mut results = Vec::new();
    for l in loaded {
        let s = match &l.scenario {
            Err((line, message)) => {
                let at = if *line == 0 {
                    l.path.clone()
                } else {
                    format!("{}:{line}", l.path)
                };
                results.push(ScenarioResult {
                    path: l.path.clone(),
                    failure: Some(format!("{at}: error: {message}\n")),
                });
                continue;
            }
            Ok(AnyScenario::System(s)) => {
                results.push(run_system(ir, &l.path, s, &mut remote, fired, &mut trace)?);
                continue;
            }
            Ok(AnyScenario::One(s)) => s,
        };
        let name = &ir.controller(s.controller).name;
        let executive = format!("scenario {}", s.name);
        let mut on_cycle = |rec: &rcs_runtime::driver::Record, new_command: bool| {
            if let Some(t) = trace.as_deref_mut() {
                t.write(&TraceRecord {
                    executive: executive.as_str(),
                    cycle: rec.cycle,
                    controller: name.as_str(),
                    verb: rec.verb,
                    state: rec.verb.map(|_| rec.state),
                    status: Some(rec.status.0),
                    error: Some(rec.error.0),
                    fired: rec.fired,
                    new_command,
                });
            }
        };
        let outcome = match remote.as_mut() {
            None => scenario::run_observed(
                ir,
                s,
                &mut rcs_dsl::interp::Driven::new(ir, s.controller),
                &mut on_cycle,
            ),
            Some((driver, set)) => {
                let mut r = driver.open(*set, name)?;
                let outcome = scenario::run_observed(ir, s, &mut r, &mut on_cycle);
                if let Some(reason) = r.failure() {
                    return Err(format!("the scenario driver failed: {reason}"));
                }
                driver.close(r);
                outcome
            }
        };
        for ((verb, row), n) in &outcome.hits {
            fired.add_row(name, verb.0, row.0, *n);
        }
        for ((verb, state), n) in &outcome.states {
            fired.add_state(name, verb.0, state.0, *n);
        }
        results.push(ScenarioResult {
            path: l.path.clone(),
            failure: failure_report(&l.path, &outcome),
        });
    }
    Ok(results)
}

/// Run one system scenario (on the interpreter, or on the generated
/// code's `SystemDriver` through the driver process), count its rows for
/// every controller of the run, and write its cycles to the trace.
fn run_system(
    ir: &Ir,
    path: &str,
    s: &scenario::SystemScenario,
    remote: &mut Option<(&mut compiled::Driver, usize)>,
    fired: &mut Fired,
    trace: &mut Option<&mut TraceSink>,
) -> Result<ScenarioResult, String> {
    let executive = format!("scenario {}", s.name);
    let mut echoes = std::collections::BTreeMap::new();
    let mut on_cycle = |c: rcs_dsl::ir::CtrlId, rec: &rcs_runtime::driver::Record| {
        // A new command is one whose serial the controller now echoes.
        let before = echoes.insert(c, rec.echo_serial);
        if let Some(t) = trace.as_deref_mut() {
            t.write(&TraceRecord {
                executive: executive.as_str(),
                cycle: rec.cycle,
                controller: ir.controller(c).name.as_str(),
                verb: rec.verb,
                state: rec.verb.map(|_| rec.state),
                status: Some(rec.status.0),
                error: Some(rec.error.0),
                fired: rec.fired,
                new_command: before.is_some_and(|b| b != rec.echo_serial)
                    || before.is_none() && rec.echo_serial != 0,
            });
        }
    };
    let outcome = match remote.as_mut() {
        None => scenario::run_system_on(
            ir,
            s,
            &mut rcs_dsl::interp::System::new(ir, &s.controllers),
            &mut on_cycle,
        ),
        Some((driver, set)) => {
            let names: Vec<&str> = s
                .controllers
                .iter()
                .map(|c| ir.controller(*c).name.as_str())
                .collect();
            let mut r = driver.open_system(*set, &names)?;
            let outcome = scenario::run_system_on(ir, s, &mut r, &mut on_cycle);
            if let Some(reason) = r.failure() {
                return Err(format!("the scenario driver failed: {reason}"));
            }
            driver.close_system(r);
            outcome
        }
    };
    for (c, o) in &outcome.controllers {
        let name = &ir.controller(*c).name;
        for ((verb, row), n) in &o.hits {
            fired.add_row(name, verb.0, row.0, *n);
        }
        for ((verb, state), n) in &o.states {
            fired.add_state(name, verb.0, state.0, *n);
        }
    }
    Ok(ScenarioResult {
        path: path.to_string(),
        failure: system_failure_report(path, &outcome),
    })
}

/// The report of a failed system scenario: file and line, each
/// expectation that did not hold (step, controller, key), and the rows
/// each controller of the run fired so far.
fn system_failure_report(path: &str, o: &SystemOutcome) -> Option<String> {
    let (line, report) = o.failure.as_ref()?;
    let mut text = format!("{path}:{line}: scenario `{}` failed here\n", o.name);
    for problem in report.lines() {
        text.push_str(&format!("    {problem}\n"));
    }
    text.push_str(&format!("  rows fired so far ({} ticks):\n", o.ticks));
    for (_, c) in &o.controllers {
        text.push_str(&format!("    {}: {}\n", c.name, fired_so_far(&c.fired)));
    }
    Some(text)
}

/// Per plan of the set: rows fired out of rows, and where each unfired row is.
pub fn coverage(set: &PlanSet, ir: &Ir, fired: &Fired) -> (String, usize, usize) {
    let mut text = String::new();
    let (mut hit, mut all) = (0, 0);
    for c in &ir.controllers {
        for (vi, k) in c.commands.iter().enumerate() {
            let Some(pid) = k.plan else { continue };
            let plan = &c.plans[pid.index()];
            // A shared plan (`plan A | B`) is counted once, as its first verb.
            if plan.verb.index() != vi {
                continue;
            }
            let missing: Vec<_> = plan
                .rows
                .iter()
                .filter(|r| fired.row(&c.name, vi as u32, r.position) == 0)
                .collect();
            let n = plan.rows.len();
            hit += n - missing.len();
            all += n;
            text.push_str(&format!(
                "  {:<24} {}/{} rows\n",
                format!("{}.{}", c.name, c.plan_title(plan)),
                n - missing.len(),
                n
            ));
            for r in missing {
                let file = set.sources.get(r.span.file);
                let (line, col) = file.line_col(r.span.start as usize);
                text.push_str(&format!(
                    "      not fired: {:<10} {}:{line}:{col}\n",
                    r.display_name(),
                    file.path
                ));
            }
        }
    }
    (text, hit, all)
}

/// Row hits and cycles per state of each plan set's own scenarios (its
/// `scenarios/` folder), run on the interpreter: what `rcsc doc
/// --coverage` draws. A scenario that fails still counts what it ran.
pub fn scenario_counts(sets: &[PlanSet], irs: &[Ir]) -> Result<Vec<RunCounts>, String> {
    let per_set = assign(sets, &[])?;
    let mut out = Vec::new();
    for ((ir, files), set) in irs.iter().zip(&per_set).zip(sets) {
        let loaded: Vec<_> = files.iter().map(|p| load(ir, p)).collect();
        let mut fired = Fired {
            source: format!(
                "{} of {}",
                crate::output::plural(loaded.len(), "scenario"),
                rcs_dsl::load::display(&set_folder(set).join("scenarios"))
            ),
            ..Fired::default()
        };
        run_set(ir, &loaded, None, &mut fired, None)?;
        out.push(fired);
    }
    Ok(out)
}

/// Print a status line through the CLI's `Status`.
pub fn status_fn(status: &Status) -> impl Fn(&str) + '_ {
    move |m| status.line("Compiling", m)
}

pub(crate) fn test(args: TestArgs) -> ExitCode {
    let start = Instant::now();
    let status = args.common.status();
    let targets = match targets(args.paths) {
        Ok(t) => t,
        Err(reason) => return fail(reason),
    };
    let sets = match rcs_dsl::load_paths(&targets.plan_paths) {
        Ok(sets) => sets,
        Err(e) => return fail(e),
    };
    let per_set = match assign(&sets, &targets.scenarios) {
        Ok(p) => p,
        Err(reason) => return fail(reason),
    };
    let irs = match check_sets_to_run(&sets, &args.common) {
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
    if args.backend == Backend::Compiled {
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
        match compiled::build(&refs, &target, &status_fn(&status), &mut blocked) {
            Ok(d) => driver = Some(d),
            Err(reason) => return fail(reason),
        }
    }

    let mut trace = match &args.trace {
        None => None,
        Some(path) => match std::fs::File::create(path) {
            Ok(f) => Some(TraceSink::new(std::io::BufWriter::new(f))),
            Err(e) => {
                return fail(format!(
                    "cannot write the trace {}: {e}",
                    rcs_dsl::load::display(path)
                ))
            }
        },
    };
    let (mut passed, mut failed) = (0, 0);
    let mut reports = Vec::new();
    let mut coverage_text = String::new();
    let (mut hit, mut all) = (0, 0);
    for (i, (set, ir)) in sets.iter().zip(&irs).enumerate() {
        let loaded: Vec<_> = per_set[i].iter().map(|p| load(ir, p)).collect();
        status.line(
            "Running",
            format!(
                "{} of {} on {}",
                plural(loaded.len(), "scenario"),
                ir.system,
                args.backend.describe()
            ),
        );
        let mut fired = Fired::default();
        let remote = driver.as_mut().map(|d| (d, i));
        let results = match run_set(ir, &loaded, remote, &mut fired, trace.as_mut()) {
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
            let (text, h, a) = coverage(set, ir, &fired);
            coverage_text.push_str(&format!("\ncoverage of {}:\n{text}", ir.system));
            hit += h;
            all += a;
        }
    }
    if let Some(mut t) = trace {
        if t.flush().is_err() || t.errors() > 0 {
            return fail("the trace could not be written whole (a write failed)");
        }
    }
    if !reports.is_empty() {
        println!("\nfailures:\n");
        for r in &reports {
            println!("{r}");
        }
    }
    if args.coverage {
        print!("{coverage_text}");
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_runs_of_one_row_are_shortened() {
        let f: Vec<(String, u64)> = [("E0", 1), ("-", 4), ("E2", 1), ("E3", 2)]
            .iter()
            .map(|(s, n)| (s.to_string(), *n))
            .collect();
        assert_eq!(fired_so_far(&f), "E0, - ×4, E2, E3, E3");
        assert_eq!(fired_so_far(&[]), "none (no cycle ran)");
    }

    #[test]
    fn scenario_files_are_told_from_plan_paths() {
        let t = targets(vec![
            "plans/submarine".into(),
            "x/scenarios/a.scenario.yaml".into(),
        ])
        .unwrap();
        assert_eq!(t.plan_paths, [PathBuf::from("plans/submarine")]);
        assert_eq!(t.scenarios, [PathBuf::from("x/scenarios/a.scenario.yaml")]);
        // A scenario alone tests the set above its `scenarios/` folder.
        let t = targets(vec!["x/scenarios/a.scenario.yaml".into()]).unwrap();
        assert_eq!(t.plan_paths, [PathBuf::from("x")]);
        assert!(targets(vec!["/nowhere/a.scenario.yaml".into()]).is_err());
    }
}
