//! The cross-controller analysis on random small hierarchies (2–4
//! controllers, `common/hierarchy.rs`), checked against the interpreter:
//!
//! - every finding with a run replays it (the supervisor's run, statuses
//!   played), and every finding with a system run — the supervisor's
//!   whole subtree running, subordinates on their own plans — passes when
//!   its scenario file is read back and run as `rcsc test` would;
//! - no row the analysis calls unreachable (`unreachable_row`,
//!   `shadowed_row`) ever fires in random runs of the whole hierarchy.
//!
//! The same findings' system runs are run on the generated code by the
//! plan-sets differential test, over a fixed-seed corpus of these
//! hierarchies that the plan-sets build compiles.

mod common;
#[path = "common/hierarchy.rs"]
mod hierarchy;

use rcs_dsl::analysis::run::replay;
use rcs_dsl::diagnostic::Code;
use rcs_dsl::interp::Value;
use rcs_dsl::ir::{CommandId, CtrlId, Ir, RowId};
use rcs_dsl::lint::Lint;
use rcs_dsl::scenario::{self, AnyScenario, SystemScript, SystemStep};
use rcs_dsl::source::SourceFile;
use rcs_dsl::{check, load_folder, Options};
use std::collections::BTreeSet;

/// What the cases found, to show that the property was exercised.
#[derive(Default, Debug)]
struct Seen {
    sets: usize,
    cross: usize,
    system_runs: usize,
    unreachable: usize,
    cycles: u64,
}

const CROSS: [Lint; 4] = [
    Lint::UnhandledError,
    Lint::CommandOverwritten,
    Lint::AlwaysRejected,
    Lint::StaleSubordinateStatus,
];

fn one(seed: u64, seen: &mut Seen) -> Result<(), String> {
    let h = hierarchy::random_hierarchy(seed);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("hierarchy_{seed}"));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("plans.rcs"), &h.plans).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("rcs.yaml"), &h.manifest).map_err(|e| e.to_string())?;
    let set = load_folder(&dir).map_err(|e| format!("{e:?}"))?;
    let checked = check(&set, &Options::default());
    let shown = || {
        let codes: Vec<String> = checked
            .diagnostics
            .iter()
            .map(|d| format!("{}: {}", d.code.name(), d.message))
            .collect();
        format!(
            "seed {seed}:\n{}\n{}\n{}",
            h.plans,
            h.manifest,
            codes.join("\n")
        )
    };
    let Some(ir) = checked.ir.as_ref().or(checked.rejected_by_checks.as_ref()) else {
        return Err(format!("the generated set does not lower: {}", shown()));
    };
    seen.sets += 1;
    let mut never: BTreeSet<(CtrlId, CommandId, RowId)> = BTreeSet::new();
    for d in &checked.diagnostics {
        if matches!(d.code, Code::Lint(l) if CROSS.contains(&l)) {
            seen.cross += 1;
        }
        if matches!(d.code, Code::UnreachableRow | Code::Lint(Lint::ShadowedRow)) {
            if let Some(at) = row_at(ir, d.primary_span()) {
                never.insert(at);
            }
        }
        let Some(w) = &d.witness else { continue };
        if let Some(run) = &w.run {
            let ctrl = ir.controller_by_name(&run.controller).ok_or_else(shown)?;
            replay(ir, ctrl, run).map_err(|e| {
                format!(
                    "{}: the run does not replay: {e}\n{}",
                    d.code.name(),
                    shown()
                )
            })?;
        }
        if let Some(script) = &w.system {
            let text = script.to_yaml(ir);
            let file = SourceFile::new("witness.scenario.yaml", text.clone());
            let s = match scenario::parse_any(ir, &file, "witness") {
                Ok(AnyScenario::System(s)) => s,
                Ok(AnyScenario::One(_)) => return Err(format!("not a system scenario:\n{text}")),
                Err(e) => return Err(format!("line {}: {}\n{text}", e.line, e.message)),
            };
            let out = scenario::run_system(ir, &s);
            if let Some((line, report)) = out.failure {
                return Err(format!(
                    "{}: the system run fails at line {line}: {report}\n{text}\n{}",
                    d.code.name(),
                    shown()
                ));
            }
            seen.system_runs += 1;
        }
    }
    seen.unreachable += never.len();
    // Random runs of the whole hierarchy: no unreachable row fires.
    let mut rng = hierarchy::Rng::new(seed ^ 0x5EED);
    for run in 0..8 {
        let script = random_script(ir, &mut rng, run);
        let out = scenario::run_script(ir, &script).map_err(|e| e.message)?;
        seen.cycles += out.ticks;
        for (c, o) in &out.controllers {
            for (verb, row) in &o.rows {
                if never.contains(&(*c, *verb, *row)) {
                    return Err(format!(
                        "row {} of `{}`, called unreachable, fired in a random run:\n{}\n{}",
                        row.0,
                        ir.controller(*c).name,
                        script.to_yaml(ir),
                        shown()
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The row (controller, its plan's verb, position) a span lies in.
fn row_at(ir: &Ir, span: rcs_dsl::source::Span) -> Option<(CtrlId, CommandId, RowId)> {
    ir.controllers.iter().enumerate().find_map(|(ci, c)| {
        c.plans.iter().find_map(|p| {
            p.rows.iter().find_map(|r| {
                (r.span.file == span.file && r.span.start <= span.start && span.end <= r.span.end)
                    .then_some((CtrlId(ci as u32), p.verb, RowId(r.position)))
            })
        })
    })
}

/// A random run: `C0` commanded now and then, every sensor and hook set
/// to random values, 1–5 ticks a step and now and then 40–80.
fn random_script(ir: &Ir, rng: &mut hierarchy::Rng, run: u64) -> SystemScript {
    let mut steps = Vec::new();
    for k in 0..(4 + rng.below(12)) {
        let mut step = SystemStep {
            cycles: if rng.chance(15) {
                40 + rng.below(41)
            } else {
                1 + rng.below(5)
            },
            ..Default::default()
        };
        if k == 0 || rng.chance(10) {
            step.commands.push((
                "C0".into(),
                "GO".into(),
                vec![Value::Int(rng.below(8) as i128)],
            ));
        }
        for (i, c) in ir.controllers.iter().enumerate() {
            if rng.chance(60) {
                step.reads.push((
                    format!("s{i}"),
                    Value::Buffer(vec![
                        Value::Bool(rng.chance(50)),
                        Value::Int(rng.below(10) as i128),
                    ]),
                ));
            }
            if !c.hooks.is_empty() && rng.chance(60) {
                step.hooks
                    .push((c.name.clone(), "ok".into(), Value::Bool(rng.chance(50))));
            }
        }
        steps.push(step);
    }
    SystemScript {
        name: format!("random {run}"),
        controllers: None,
        initial: SystemStep::default(),
        steps,
    }
}

#[test]
fn cross_controller_findings_reproduce_and_unreachable_rows_never_fire() {
    let mut runner = common::deterministic_runner("RCS_HIERARCHY_CASES", 300);
    let mut seen = Seen::default();
    let cell = std::cell::RefCell::new(&mut seen);
    runner
        .run(&proptest::prelude::any::<u64>(), |seed| {
            one(seed, &mut cell.borrow_mut()).map_err(proptest::test_runner::TestCaseError::fail)
        })
        .unwrap_or_else(|e| panic!("{e}"));
    println!("hierarchies: {seen:?}");
    // The generator must exercise what the property is about.
    assert!(seen.cross >= 20, "few cross-controller findings: {seen:?}");
    assert!(seen.system_runs >= 10, "few system runs: {seen:?}");
    assert!(seen.unreachable >= 5, "few unreachable rows: {seen:?}");
}
