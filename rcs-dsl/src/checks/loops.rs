//! Stage 3, checks over several cycles of one plan: `livelock` (rows that
//! move the plan round a cycle of states on every cycle, so no other row,
//! a timeout included, ever fires) and `command_every_cycle` (a row that
//! sends the same subordinate a command on consecutive cycles while it is
//! still executing the last one). The findings, with the way there and the
//! inputs, come from [`crate::analysis::cycles`]; here they become
//! diagnostics.

use super::Sink;
use crate::analysis::cycles::{command_storms, livelocks};
use crate::analysis::run::{self, Expect, Firing};
use crate::analysis::PlanAnalysis;
use crate::diagnostic::Diagnostic;
use crate::ir::{Controller, Ir, Plan, StateId};
use crate::lint::Lint;

/// `E3`, as the plan writes the row's position.
fn row_name(row: usize) -> String {
    format!("E{row}")
}

fn state_name(p: &Plan, s: StateId) -> &str {
    p.states.get(s.index()).map_or("?", |s| s.name.as_str())
}

pub(crate) fn check_livelocks(
    ir: &Ir,
    c: &Controller,
    p: &Plan,
    an: &PlanAnalysis,
    sink: &mut Sink,
) {
    let verb = &c.plan_title(p);
    for found in livelocks(c, p, an) {
        let Some(&(first, first_state)) = found.cycle.first() else {
            continue;
        };
        let round: Vec<String> = found
            .cycle
            .iter()
            .map(|&(r, s)| format!("{} in `{}`", row_name(r), state_name(p, s)))
            .collect();
        let states: Vec<&str> = found
            .cycle
            .iter()
            .chain(found.cycle.first())
            .map(|&(_, s)| state_name(p, s))
            .collect();
        let mut d = Diagnostic::lint(
            Lint::Livelock,
            format!(
                "plan `{verb}` can loop through {} on every cycle",
                states.join(" → ")
            ),
            p.rows[first].span,
            format!(
                "fires on the first cycle in `{}`",
                state_name(p, first_state)
            ),
        );
        for &(r, s) in found.cycle.iter().skip(1) {
            d = d.with_secondary(
                p.rows[r].span,
                format!(
                    "then this row, on the first cycle in `{}`",
                    state_name(p, s)
                ),
            );
        }
        let (t, t_state) = found.defeated;
        d = d.with_secondary(
            p.rows[t].span,
            format!(
                "never fires: it would, with these inputs, had the plan stayed in `{}`",
                state_name(p, t_state)
            ),
        );
        for &x in &found.through {
            let sub = &ir.controller(x).name;
            d = d.with_note(format!(
                "`{sub}` is commanded again on every round, and on the cycle after each \
                 command it shows EXECUTING (it runs at most once between two cycles of `{}`, \
                 and its plan cannot answer on a command's first cycle): the ring never waits \
                 for its answer",
                c.name
            ));
        }
        if found.path.is_empty() {
            d = d.with_note(
                "the vars these states read keep the values the way here leaves them: no row \
                 of the ring, nor `pre` or `post`, assigns one",
            );
        }
        let d = d
            .with_witness(state_name(p, first_state), &found.shown)
            .with_run(found.run)
            .with_note(format!(
                "with these inputs held, one row fires per cycle, round and round: {}; \
                 no other row of these states ever fires, a timeout included",
                round.join(", then ")
            ))
            .with_help(
                "make one of these rows wait for something that changes, or put a way out \
                 (a timeout, a test of the inputs) before them",
            );
        sink.lint(Some(c), Some(p), d);
    }
}

pub(crate) fn check_command_storms(
    ir: &Ir,
    c: &Controller,
    p: &Plan,
    an: &PlanAnalysis,
    sink: &mut Sink,
) {
    for found in command_storms(c, p, an) {
        let row = &p.rows[found.row];
        let sub = &ir.controller(found.sub).name;
        let state = state_name(p, found.state);
        let d = Diagnostic::lint(
            Lint::CommandEveryCycle,
            format!(
                "{} of plan `{}` sends `{sub}` a command on every cycle while `{sub}` executes",
                row_name(found.row),
                c.plan_title(p)
            ),
            row.span,
            format!("sends to `{sub}` and can fire again on the next cycle"),
        )
        .with_witness(state, &found.shown)
        .with_run(an.finding_run(
            &found.params,
            found.state,
            &found.repeat,
            3,
            Expect::Repeats {
                rows: vec![Firing {
                    row: run::row_name(row),
                    state: state.to_string(),
                }],
            },
        ))
        .with_note(format!(
            "with these inputs the row fires on consecutive cycles in `{state}` while `{sub}` \
             shows EXECUTING: commands are not queued, so each one restarts `{sub}`'s plan \
             and `{sub}` may never finish"
        ))
        .with_help(format!(
            "send once: move to another state that waits for `{sub}.done`, or guard the row \
             with `!{sub}.executing`"
        ));
        sink.lint(Some(c), Some(p), d);
    }
}
