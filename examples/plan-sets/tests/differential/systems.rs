//! System scenarios on both backends: every `*.scenario.yaml` of a plan
//! set's `scenarios/` folder that runs several controllers (`system: true`,
//! `controllers: [...]`) runs on the interpreter (`rcs_dsl::interp::System`)
//! and on the generated code (`SystemDriver`, `new_system_driver`), and the
//! two must pass and give the same record for every controller cycle, in
//! the same order.

use super::running::load;
use rcs_dsl::scenario::{self, AnyScenario};
use rcs_dsl::source::SourceFile;
use rcs_plan_sets::SETS;
use rcs_runtime::driver::Record;
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
            let names: Vec<&str> = s
                .controllers
                .iter()
                .map(|c| ir.controller(*c).name.as_str())
                .collect();
            let mut interp_trace = Vec::new();
            let a = scenario::run_system_on(
                ir,
                &s,
                &mut rcs_dsl::interp::System::new(ir, &s.controllers),
                &mut |c, r| interp_trace.push(shown(&ir.controller(c).name, r)),
            );
            let mut compiled =
                (set.new_system_driver)(&names).map_err(|e| format!("{}: {e}", p.display()))?;
            let mut compiled_trace = Vec::new();
            let b = scenario::run_system_on(ir, &s, compiled.as_mut(), &mut |c, r| {
                compiled_trace.push(shown(&ir.controller(c).name, r))
            });
            if let Some(i) = (0..interp_trace.len().max(compiled_trace.len()))
                .find(|i| interp_trace.get(*i) != compiled_trace.get(*i))
            {
                return Err(format!(
                    "{}: the interpreter and the generated code diverge at controller cycle {i}:\n  interp:   {:?}\n  compiled: {:?}",
                    p.display(),
                    interp_trace.get(i),
                    compiled_trace.get(i)
                ));
            }
            for (backend, o) in [("interpreter", &a), ("generated code", &b)] {
                if let Some((line, report)) = &o.failure {
                    return Err(format!(
                        "{}:{line}: fails on the {backend}:\n{report}",
                        p.display()
                    ));
                }
            }
            scenarios += 1;
            cycles += interp_trace.len();
        }
    }
    Ok((scenarios, cycles))
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
