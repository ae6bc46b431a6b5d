//! Running the loaded scenarios of one plan set on the interpreter or the
//! compiled driver: each one-controller scenario's result and failure
//! report, its cycles to the trace, its rows and states to the counts.
//! System scenarios are run by `super::system`.

use super::files::Loaded;
use super::recording::Recording;
use super::system::run_system;
use crate::compiled;
use rcs_codegen::site::RunCounts;
use rcs_dsl::ir::Ir;
use rcs_dsl::scenario::{self, AnyScenario, Outcome};

/// The rows fired, cycle by cycle, with runs of one name shortened
/// (`- ×200`), so a long wait reads as one item.
pub(super) fn fired_so_far(fired: &[(String, u64)]) -> String {
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
    mut trace: Option<&mut Recording>,
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
        if let Some(t) = trace.as_deref_mut() {
            t.start_scenario();
        }
        let mut on_cycle = |rec: &rcs_runtime::driver::Record, new_command: bool| {
            if let Some(t) = trace.as_deref_mut() {
                t.cycle(ir, s.controller, &executive, rec, new_command);
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
}
