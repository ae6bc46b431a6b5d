//! System scenarios on both backends: every `*.scenario.yaml` of a plan
//! set's `scenarios/` folder that runs several controllers (`system: true`,
//! `controllers: [...]`) runs on the interpreter (`rcs_dsl::interp::System`)
//! and on the generated code (`SystemDriver`, `new_system_driver`), and the
//! two must pass and give the same record for every controller cycle, in
//! the same order. And every plan set whose controllers command each other
//! runs whole at random on both, tick by tick, with the same records.

use super::inputs::Values;
use super::running::{load, seed};
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use rcs_dsl::scenario::{self, AnyScenario};
use rcs_dsl::source::SourceFile;
use rcs_plan_sets::SETS;
use rcs_runtime::driver::Record;
use rcs_runtime::driver::Value;
use std::path::Path;

/// A record as text, floats as `{:?}` prints them (NaN equals NaN).
fn shown(c: &str, r: &Record) -> String {
    format!("{c}: {r:?}")
}

/// Run every system scenario of every plan set on both backends; returns
/// (scenarios, controller cycles compared).
fn run_all() -> Result<(usize, usize), String> {
    let (mut scenarios, mut cycles) = (0, 0);
    for set in SETS {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../..")
            .join(set.path)
            .join("scenarios");
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        let mut paths: Vec<_> = entries.map(|e| e.expect("entry").path()).collect();
        paths.sort();
        let mut ir = None;
        for p in paths {
            let text = std::fs::read_to_string(&p).expect("readable");
            if !text
                .lines()
                .any(|l| l.starts_with("system:") || l.starts_with("controllers:"))
            {
                continue;
            }
            let ir = ir.get_or_insert_with(|| load(set.path));
            let file = SourceFile::new(p.display().to_string(), text);
            let s = match scenario::parse_any(ir, &file, "s") {
                Ok(AnyScenario::System(s)) => s,
                Ok(AnyScenario::One(_)) => continue,
                Err(e) => return Err(format!("{}:{}: {}", p.display(), e.line, e.message)),
            };
            cycles += both_backends(ir, set, &s, &p.display().to_string())?;
            scenarios += 1;
        }
    }
    Ok((scenarios, cycles))
}

/// Run system scenario `s` of `set` on the interpreter and on the
/// generated code: both must pass and give the same record for every
/// controller cycle, in the same order. Returns the cycles compared;
/// `what` names the scenario in a failure.
pub(crate) fn both_backends(
    ir: &rcs_dsl::ir::Ir,
    set: &rcs_plan_sets::PlanSet,
    s: &scenario::SystemScenario,
    what: &str,
) -> Result<usize, String> {
    let names: Vec<&str> = s
        .controllers
        .iter()
        .map(|c| ir.controller(*c).name.as_str())
        .collect();
    let mut interp_trace = Vec::new();
    let a = scenario::run_system_on(
        ir,
        s,
        &mut rcs_dsl::interp::System::new(ir, &s.controllers),
        &mut |c, r| interp_trace.push(shown(&ir.controller(c).name, r)),
    );
    let mut compiled = (set.new_system_driver)(&names).map_err(|e| format!("{}: {e}", what))?;
    let mut compiled_trace = Vec::new();
    let b = scenario::run_system_on(ir, s, compiled.as_mut(), &mut |c, r| {
        compiled_trace.push(shown(&ir.controller(c).name, r))
    });
    if let Some(i) = (0..interp_trace.len().max(compiled_trace.len()))
        .find(|i| interp_trace.get(*i) != compiled_trace.get(*i))
    {
        return Err(format!(
            "{}: the interpreter and the generated code diverge at controller cycle {i}:\n  interp:   {:?}\n  compiled: {:?}",
            what,
            interp_trace.get(i),
            compiled_trace.get(i)
        ));
    }
    for (backend, o) in [("interpreter", &a), ("generated code", &b)] {
        if let Some((line, report)) = &o.failure {
            return Err(format!(
                "{}:{line}: fails on the {backend}:\n{report}",
                what
            ));
        }
    }
    Ok(interp_trace.len())
}

#[test]
fn system_scenarios_run_the_same_on_interpreter_and_generated_code() {
    let (scenarios, cycles) = run_all().unwrap_or_else(|e| panic!("{e}"));
    println!("differential: {scenarios} system scenarios, {cycles} controller cycles compared");
    assert!(
        scenarios >= 2,
        "the system scenarios of plans/ were found ({scenarios})"
    );
}

/// Random runs per plan set of several controllers.
const SYSTEM_RUNS: u32 = 100;

/// One draw of `s`.
fn draw<S: proptest::strategy::Strategy>(runner: &mut TestRunner, s: S) -> S::Value {
    use proptest::strategy::ValueTree;
    s.new_tree(runner).expect("a value").current()
}

/// [`SYSTEM_RUNS`] random runs of every controller of `set` on both
/// backends, tick by tick on the set's schedule: the roots commanded with
/// random verbs and arguments, the external buffers and the hooks set to
/// random values of their types, 1–5 ticks a step and now and then
/// 50–300 (so that timeouts fire). Every call must answer alike and every
/// CPU cycle give the same records. Returns the controller cycles compared.
pub(crate) fn random_runs(
    set: &rcs_plan_sets::PlanSet,
    ir: &rcs_dsl::ir::Ir,
) -> Result<u64, String> {
    use rcs_dsl::ir::{CtrlId, Type};
    use rcs_runtime::driver::DrivenSystem;
    let run: Vec<CtrlId> = (0..ir.controllers.len())
        .map(|i| CtrlId(i as u32))
        .collect();
    let names: Vec<&str> = ir.controllers.iter().map(|c| c.name.as_str()).collect();
    let roots: Vec<CtrlId> = run
        .iter()
        .copied()
        .filter(|c| {
            ir.controller(*c).supervisor.is_none() && !ir.controller(*c).commands.is_empty()
        })
        .collect();
    let externals: Vec<usize> = (0..ir.buffers.len())
        .filter(|b| ir.buffers[*b].writer.is_none() && !ir.buffers[*b].readers.is_empty())
        .collect();
    let hooks: Vec<(CtrlId, usize)> = run
        .iter()
        .flat_map(|c| (0..ir.controller(*c).hooks.len()).map(move |h| (*c, h)))
        .collect();
    let values: Vec<Values> = ir.controllers.iter().map(|c| Values::new(ir, c)).collect();
    let (cpus, _) = rcs_dsl::scenario::schedule(ir, &run);
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed(&format!("{}/system", set.path))),
    );
    let mut cycles = 0u64;
    for r in 0..SYSTEM_RUNS {
        let mut a = rcs_dsl::interp::System::new(ir, &run);
        let mut b = (set.new_system_driver)(&names).map_err(|e| format!("{}: {e}", set.path))?;
        let mut calls: Vec<String> = Vec::new();
        let diverged = |calls: &[String], what: &str, x: &str, y: &str| {
            format!(
                "{} run {r}: the interpreter and the generated code diverge on {what}:\n  interp:   {x}\n  compiled: {y}\ncalls so far:\n  {}",
                set.path,
                calls.join("\n  ")
            )
        };
        let mut tick = 0u64;
        for _ in 0..draw(&mut runner, 1usize..20) {
            if !roots.is_empty() && draw(&mut runner, proptest::bool::weighted(0.4)) {
                let root = roots[draw(&mut runner, 0..roots.len())];
                let c = ir.controller(root);
                let k = &c.commands[draw(&mut runner, 0..c.commands.len())];
                let args: Vec<Value> = k
                    .params
                    .iter()
                    .map(|p| draw(&mut runner, values[root.index()].of(&p.ty)))
                    .collect();
                let (x, y) = (
                    a.command(&c.name, &k.name, &args),
                    b.command(&c.name, &k.name, &args),
                );
                calls.push(format!("command {} <- {} {args:?}", c.name, k.name));
                if x != y {
                    return Err(diverged(
                        &calls,
                        "a command",
                        &format!("{x:?}"),
                        &format!("{y:?}"),
                    ));
                }
            }
            for ext in &externals {
                if draw(&mut runner, proptest::bool::weighted(0.3)) {
                    let buf = &ir.buffers[*ext];
                    let reader = buf.readers[0];
                    let v = draw(
                        &mut runner,
                        values[reader.index()].of(&Type::Buffer(buf.ty)),
                    );
                    let (x, y) = (a.set_read(&buf.name, &v), b.set_read(&buf.name, &v));
                    calls.push(format!("set_read {} {v:?}", buf.name));
                    if x != y {
                        return Err(diverged(
                            &calls,
                            "set_read",
                            &format!("{x:?}"),
                            &format!("{y:?}"),
                        ));
                    }
                }
            }
            for (c, h) in &hooks {
                if draw(&mut runner, proptest::bool::weighted(0.2)) {
                    let ctrl = ir.controller(*c);
                    let hook = &ctrl.hooks[*h];
                    let v = draw(&mut runner, values[c.index()].of(&hook.ret));
                    let (x, y) = (
                        a.set_hook(&ctrl.name, &hook.name, &v),
                        b.set_hook(&ctrl.name, &hook.name, &v),
                    );
                    calls.push(format!("set_hook {}.{} {v:?}", ctrl.name, hook.name));
                    if x != y {
                        return Err(diverged(
                            &calls,
                            "set_hook",
                            &format!("{x:?}"),
                            &format!("{y:?}"),
                        ));
                    }
                }
            }
            let ticks = if draw(&mut runner, proptest::bool::weighted(0.08)) {
                draw(&mut runner, 50u64..300)
            } else {
                draw(&mut runner, 1u64..6)
            };
            calls.push(format!("{ticks} ticks from tick {tick}"));
            for _ in 0..ticks {
                for (cpu, every) in &cpus {
                    if !tick.is_multiple_of(*every) {
                        continue;
                    }
                    let (x, y) = (a.run_cpu(cpu), b.run_cpu(cpu));
                    // Name the first controller whose record differs.
                    let first = match (&x, &y) {
                        (Ok(xs), Ok(ys)) if xs.len() == ys.len() => xs
                            .iter()
                            .zip(ys)
                            .map(|(x, y)| (format!("{x:?}"), format!("{y:?}")))
                            .find(|(x, y)| x != y),
                        _ => Some((format!("{x:?}"), format!("{y:?}"))).filter(|(x, y)| x != y),
                    };
                    if let Some((x, y)) = first {
                        return Err(diverged(
                            &calls,
                            &format!("CPU {cpu} at tick {tick}"),
                            &x,
                            &y,
                        ));
                    }
                    cycles += 1;
                }
                tick += 1;
            }
        }
    }
    Ok(cycles)
}

#[test]
fn random_system_runs_are_the_same_on_interpreter_and_generated_code() {
    let mut sets = 0;
    let mut cycles = 0;
    for set in SETS {
        let ir = load(set.path);
        // Only sets where controllers command each other.
        if !ir.controllers.iter().any(|c| !c.subordinates.is_empty()) {
            continue;
        }
        cycles += random_runs(set, &ir).unwrap_or_else(|e| panic!("{e}"));
        sets += 1;
    }
    println!("differential: {sets} plan sets run whole at random, {cycles} CPU cycles compared");
    assert!(
        sets >= 5,
        "the multi-controller sets of plans/ ran ({sets})"
    );
}
