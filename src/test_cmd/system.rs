//! Running one system scenario (several controllers on their schedule)
//! for `rcsc test`: on the interpreter or the compiled driver, with the
//! rows of every controller of the run counted and its failure report.

use super::recording::Recording;
use super::run::{fired_so_far, Fired, ScenarioResult};
use crate::compiled;
use rcs_dsl::ir::Ir;
use rcs_dsl::scenario::{self, SystemOutcome};

/// Run one system scenario (on the interpreter, or on the generated
/// code's `SystemDriver` through the driver process), count its rows for
/// every controller of the run, and write its cycles to the trace.
pub(super) fn run_system(
    ir: &Ir,
    path: &str,
    s: &scenario::SystemScenario,
    remote: &mut Option<(&mut compiled::Driver, usize)>,
    fired: &mut Fired,
    trace: &mut Option<&mut Recording>,
) -> Result<ScenarioResult, String> {
    let executive = format!("scenario {}", s.name);
    if let Some(t) = trace.as_deref_mut() {
        t.start_scenario();
    }
    let mut echoes = std::collections::BTreeMap::new();
    let mut on_cycle = |c: rcs_dsl::ir::CtrlId, rec: &rcs_runtime::driver::Record| {
        // A new command is one whose serial the controller now echoes.
        let before = echoes.insert(c, rec.echo_serial);
        if let Some(t) = trace.as_deref_mut() {
            let new_command = before.is_some_and(|b| b != rec.echo_serial)
                || before.is_none() && rec.echo_serial != 0;
            t.cycle(ir, c, &executive, rec, new_command);
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
