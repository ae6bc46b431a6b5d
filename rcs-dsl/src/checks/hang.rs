//! Checks decided by the values that stay fixed during a command (its
//! parameters, and vars no job assigns), over the command analysis
//! ([`crate::analysis::command`]):
//!
//! - `incomplete_state`: in a state the plan surely reaches with some
//!   command values, no row can ever fire again with those values,
//!   whatever the inputs that change do: the plan hangs until the next
//!   command. The witness is the command's values.
//! - `unreachable_row` for a row whose state is entered only with command
//!   values that make its condition false.

use super::graph::Analysis;
use super::Sink;
use crate::analysis::command::{EntryBound, Step};
use crate::analysis::{covers, PlanAnalysis};
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::{Controller, Plan, Row, StateId};
use crate::lint::Lint;

pub(crate) fn check_incomplete_states(
    c: &Controller,
    p: &Plan,
    conditions: &PlanAnalysis,
    graph: &super::graph::Analysis,
    sink: &mut Sink,
) {
    let verb = &c.plan_title(p);
    for hang in conditions.hangs() {
        // One state, one finding: a dead end is `dead_end_state`'s.
        if graph.is_dead_end(p, hang.state.index()) {
            continue;
        }
        // A state held after `report DONE`/`ERROR`: waiting there is the point.
        if super::report::reported_hold(p, hang.state.index()) {
            continue;
        }
        let state = &p.states[hang.state.index()];
        let name = &state.name;
        let shown = shown_values(conditions, p, hang.state, &hang.given, &hang.path);
        // The title names the command's values the state's rows read.
        let read_params: Vec<(usize, rcs_runtime::driver::Value)> = hang
            .command
            .iter()
            .filter(|(l, _)| {
                let leaf = &conditions.terms().leaves[*l].0;
                shown.iter().any(|(n, _)| *n == conditions.leaf_name(leaf))
            })
            .cloned()
            .collect();
        // One parameter tells the cases apart: all of them, as ranges.
        let values = if !hang.path_by_cells {
            // The path was shown for these very values only.
            let shown: Vec<String> = conditions
                .case_shown(&read_params)
                .into_iter()
                .map(|(n, v)| format!("{n} = {v}"))
                .collect();
            shown.join(", ")
        } else if hang.command.len() == 1 && read_params.len() == 1 {
            conditions.cases_text(&hang.cases)
        } else {
            conditions.case_text(&read_params)
        };
        let with = if values.is_empty() {
            "whatever the command's values".to_string()
        } else {
            format!("with `{values}`")
        };
        // The first row of the state, else where the state is first named.
        let (span, label) = match p.rows.iter().find(|r| r.from.names(hang.state)) {
            Some(r) => (
                r.span,
                format!("no row of `{name}` can fire again with these values"),
            ),
            None => (
                state.span.unwrap_or(p.header),
                "no row can fire here again with these values".to_string(),
            ),
        };
        let mut d = Diagnostic::lint(
            Lint::IncompleteState,
            format!("plan `{verb}` can hang in state `{name}`: {with}, no row of it can ever fire"),
            span,
            label,
        );
        // The row that leads in (the last of the path), or the entry rows
        // that all stay false on the command's first cycle.
        match hang.path.last() {
            Some(Step::Fire { row, .. }) => {
                d = d.with_secondary(p.rows[*row].span, format!("enters `{name}`"));
            }
            Some(Step::Idle) => {
                for entry in p.rows.iter().filter(|r| r.is_entry) {
                    d = d.with_secondary(entry.span, "does not match with these values");
                }
            }
            None => {}
        }
        d = d.with_witness(name, &shown);
        // The run: the way in with these values, then 30 cycles of nothing.
        let params: Vec<_> = hang
            .command
            .iter()
            .map(|(l, v)| (conditions.terms().leaves[*l].0.clone(), v.clone()))
            .collect();
        let expect = crate::analysis::run::Expect::Stays {
            state: name.clone(),
        };
        d = d.with_run(conditions.finding_run(&params, hang.state, &[], 30, expect));
        let rows: Vec<String> = hang
            .path
            .iter()
            .map(|s| match s {
                Step::Fire { row, .. } => p.rows[*row].display_name(),
                Step::Idle => "(no row)".to_string(),
            })
            .collect();
        if let [Step::Idle] = hang.path[..] {
            d = d.with_note(format!(
                "with these values no row matches on the command's first cycle: the plan stays in `{name}`"
            ));
        } else if !rows.is_empty() {
            d = d.with_note(format!(
                "with these values the plan reaches `{name}` through {} {}",
                if rows.len() == 1 { "row" } else { "rows" },
                rows.join(", ")
            ));
        }
        for (l, v) in &hang.given {
            let (leaf, ty) = &conditions.terms().leaves[*l];
            if matches!(leaf, crate::analysis::terms::Leaf::Var(..))
                && shown.iter().any(|(n, _)| *n == conditions.leaf_name(leaf))
            {
                d = d.with_note(format!(
                    "no job assigns `{}`: it always holds its initial value `{}`",
                    conditions.leaf_name(leaf),
                    conditions.value_text(ty, v)
                ));
            }
        }
        // `new_command = false` alone: no fixed value is involved.
        let fixed = if shown.len() > 1 {
            "these values stay fixed until the next command; whatever the other inputs do"
        } else {
            "whatever the inputs do"
        };
        let d = d
            .with_note(format!(
                "{fixed} (buffers, hooks, subordinates, counters, vars that jobs change), `{}` \
                 stays in `{name}` until a new command",
                c.name
            ))
            .with_help(match hang.path.last() {
                Some(Step::Idle) => "handle these values on the command's first cycle: an entry \
                     row for them, or a last entry row `*N when new_command -> Error(…)` that \
                     refuses them"
                    .to_string(),
                _ if hang.state == StateId::S0 => "entry rows fire only on a command's first \
                     cycle: lead the row into another state, or add a row from `S0` for the \
                     cycles after it"
                    .to_string(),
                _ => format!(
                    "add a row for these values, an `otherwise` row, or a timeout \
                     (`{name} when state_cycles > N -> Error(…)`)"
                ),
            });
        sink.lint(Some(c), Some(p), d);
    }
}

/// The pinned values the rows of `state` and the rows on the path read,
/// as the language writes them: the witness of a hang.
fn shown_values(
    conditions: &PlanAnalysis,
    p: &Plan,
    state: StateId,
    given: &[(usize, rcs_runtime::driver::Value)],
    path: &[Step],
) -> Vec<(String, String)> {
    let terms = conditions.terms();
    let mut read = vec![false; terms.leaves.len()];
    let on_path: Vec<usize> = path
        .iter()
        .filter_map(|s| match s {
            Step::Fire { row, .. } => Some(*row),
            Step::Idle => None,
        })
        .collect();
    for (i, r) in p.rows.iter().enumerate() {
        if covers(&r.from, state) || on_path.contains(&i) {
            if let Some(f) = conditions.condition(i) {
                f.visit_atoms(&mut |a| {
                    for &l in &terms.atoms[a].leaves {
                        read[l] = true;
                    }
                });
            }
        }
    }
    let kept: Vec<(usize, rcs_runtime::driver::Value)> =
        given.iter().filter(|(l, _)| read[*l]).cloned().collect();
    // Every cycle after the hang begins is a cycle without a new command.
    let mut shown = vec![("new_command".to_string(), "false".to_string())];
    shown.extend(conditions.case_shown(&kept));
    shown
}

/// The rows [`PlanAnalysis::entry_bound_rows`] finds in a reachable state:
/// hard errors, like any row that can never match.
pub(crate) fn entry_bound_rows(
    p: &Plan,
    graph: &Analysis,
    conditions: &PlanAnalysis,
) -> Vec<EntryBound> {
    conditions
        .entry_bound_rows()
        .into_iter()
        .filter(|b| graph.reachable[b.state.index()] && !graph.never_matches[b.row])
        .filter(|b| !p.rows[b.row].is_otherwise())
        .collect()
}

pub(crate) fn check_entry_bound_rows(
    p: &Plan,
    bound: &[EntryBound],
    conditions: &PlanAnalysis,
    sink: &mut Sink,
) {
    for b in bound {
        let row: &Row = &p.rows[b.row];
        let state = &p.states[b.state.index()].name;
        let cases = conditions.cases_text(&b.cases);
        let mut d = Diagnostic::error(
            Code::UnreachableRow,
            format!(
                "row {} can never match: state `{state}` is entered only with command values \
                 that make it false",
                row.display_name()
            ),
            row.cond_span,
            format!("false whenever the plan is in `{state}`"),
        );
        for &e in &b.entries {
            d = d.with_secondary(p.rows[e].span, format!("enters `{state}`"));
        }
        if !cases.is_empty() {
            d = d.with_note(format!("`{state}` is entered only with `{cases}`"));
        }
        sink.error(
            d.with_note("a command's parameters keep their values until the next command")
                .with_help(
                    "remove the row, or fix its condition or the rows that lead into the state",
                ),
        );
    }
}
