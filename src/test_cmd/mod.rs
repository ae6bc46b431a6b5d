//! `rcsc test`: find the scenarios of the plan sets named, check the
//! plans, run every scenario on the chosen backend (the reference
//! interpreter, or the generated code through [`crate::compiled`]), report
//! each like `cargo test` does, and optionally the rows no scenario fired.
//!
//! This module holds the command ([`test`]) and the choice of backend;
//! beside it, `files` which scenario files test which plan set and reading
//! them, `run` running a plan set's scenarios and reporting each, `system`
//! running a system scenario, `coverage` the rows no scenario fired and
//! the counts `rcsc doc --coverage` draws, `recording` the trace of
//! `--trace` (JSON lines or MCAP).

mod coverage;
mod files;
mod recording;
mod run;
mod system;

pub use coverage::{coverage, scenario_counts};
pub use files::{assign, load, own_scenario_texts, targets};
pub use recording::Recording;
pub use run::{run_set, Fired};

use crate::args::*;
use crate::commands::check_sets_to_run;
use crate::output::*;
use crate::{compiled, Status};
use std::path::PathBuf;
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

/// Text from the plans, scenarios and paths, for the terminal.
fn shown(text: &str) -> std::borrow::Cow<'_, str> {
    rcs_dsl::render::escape_controls(text)
}

/// The header of `rcsc test --trace`: the generated marker in the first
/// line (in MCAP, the header's `library` field) lets the next run replace
/// the file.
fn trace_header() -> rcs_runtime::TraceHeader {
    rcs_runtime::TraceHeader {
        generated: Some(format!("{} test --trace", rcs_codegen::GENERATED)),
        ..rcs_runtime::TraceHeader::current()
    }
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
    // The files read (plans, manifests, scenarios): the trace replaces none.
    let mut inputs = inputs_of(&sets);
    for p in &targets.scenarios {
        inputs.add(p);
    }
    for p in per_set.iter().flatten() {
        inputs.add(p);
    }
    // Refuse a trace path the writer would refuse before running anything.
    if let Some(path) = &args.trace {
        if let Err(e) = rcs_codegen::writer::check_file(path, &inputs) {
            return write_failed(&e);
        }
    }
    // A run that tests nothing is a mistake (a wrong path, a misnamed
    // folder), not a success.
    if per_set.iter().all(Vec::is_empty) {
        let looked: Vec<String> = sets
            .iter()
            .map(|s| format!("{}/scenarios/", s.root.trim_end_matches('/')))
            .collect();
        eprintln!(
            "error: no scenarios to run (looked in {}); write `*.scenario.yaml` files there or name them",
            shown(&looked.join(", "))
        );
        return ExitCode::from(1);
    }
    if !args.common.quiet {
        let untested = sets.iter().zip(&irs).zip(&per_set);
        for ((set, ir), _) in untested.filter(|(_, files)| files.is_empty()) {
            eprintln!(
                "warning: plan set `{}` has no scenarios (none under {}/scenarios/)",
                shown(&ir.system),
                shown(set.root.trim_end_matches('/'))
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

    // The trace is gathered in memory and written whole, through the writer.
    let mut trace = match &args.trace {
        None => None,
        Some(path) => match Recording::new(&trace_header(), recording::wants_mcap(path)) {
            Ok(r) => Some(r),
            Err(reason) => return fail(reason),
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
                    outln!("test {} ... ok", shown(&r.path));
                }
                Some(report) => {
                    failed += 1;
                    outln!("test {} ... FAILED", shown(&r.path));
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
    if let (Some(t), Some(path)) = (trace, &args.trace) {
        let bytes = match t.finish() {
            Ok(b) => b,
            Err(reason) => return fail(reason),
        };
        if let Err(e) = rcs_codegen::writer::write_file_bytes(path, &bytes, &inputs, &mut |_| {}) {
            return write_failed(&e);
        }
    }
    if !reports.is_empty() {
        outln!("\nfailures:\n");
        for r in &reports {
            outln!("{}", shown(&r.to_string()));
        }
    }
    if args.coverage {
        out!("{}", shown(&coverage_text));
        outln!("rows fired: {hit}/{all}\n");
    }
    status.line(
        "Finished",
        format!("in {:.2}s", start.elapsed().as_secs_f64()),
    );
    outln!("{passed} passed, {failed} failed");
    if failed > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
