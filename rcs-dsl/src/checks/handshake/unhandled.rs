//! `unhandled_error`: a state that waits for an answer of subordinate X
//! (`X.done`, or a status X reports) where nothing can fire once X shows
//! `ERROR`, although X can answer `ERROR` to a verb this plan sends it —
//! by ending in `Error`, by `report ERROR` and going on, by a built-in
//! `INDEX_RANGE`, or by refusing the command (`accept when`). When X runs
//! at least as often as the supervisor, a failed X keeps writing its
//! status, so a watchdog on `X.stale_cycles` never fires and is no
//! handling. Each finding is proved by the analysis of conditions and
//! carries a witness: a cycle, with `X.status = ERROR`, in which no row of
//! that state matches, and where a path to the state is found, a run: the
//! path, then 30 cycles with X in `ERROR` and no row firing.

use super::super::Sink;
use super::{failure, proved_failure, status_tests, verbs_sent, writes_every_cycle_of, Supervisor};
use crate::analysis::covers;
use crate::diagnostic::{Across, Diagnostic};
use crate::ir::{CtrlId, Row, StateId, StatusId, SubProp};
use crate::lint::Lint;

/// How long a stall's run holds the subordinate in `ERROR`: long enough
/// to pass any timeout a reader would expect to have fired.
const STALL_CYCLES: u32 = 30;

/// `unhandled_error` in the plans of controller `ci`, over their analyses
/// and the summaries of every controller.
pub(crate) fn check_unhandled_error(sup: &Supervisor, sink: &mut Sink) {
    let (ir, ci, summaries) = (sup.ir, sup.id, sup.summaries);
    let c = sup.controller();
    // A plan too large to analyse: nothing can be proved of it.
    for (p, conditions, graph) in sup.plans(false) {
        // Paths to each state, searched once a finding needs one.
        let paths = std::cell::OnceCell::new();
        for &x in &c.subordinates {
            // A way X may fail at a verb this plan sends it, by the
            // analysis of one cycle; proved by a run once a finding needs it.
            let sent = verbs_sent(&p.rows, x);
            if !sent.iter().any(|v| failure(ir, summaries, x, *v).is_some()) {
                continue;
            }
            let proved = std::cell::OnceCell::new();
            let alive = writes_every_cycle_of(ir, ci, x);
            for s in (0..p.states.len()).filter(|s| graph.reachable[*s]) {
                let state = StateId(s as u32);
                let waiting: Vec<(&Row, StatusId)> = p
                    .rows
                    .iter()
                    .filter(|r| covers(&r.from, state))
                    .filter_map(|r| awaited(r, x).map(|st| (r, st)))
                    .filter(|(r, _)| !conditions.never_fires_in(r.position as usize, state))
                    .collect();
                let Some(&(first, awaited)) = waiting.first() else {
                    continue;
                };
                // No row can match whatever the other inputs; or, weaker, no
                // row can while inputs the world may hold stay as they are
                // (a sensor row beside the wait is no handling of X's error).
                let (w, whatever) = match conditions.stalls_in(state, x, StatusId::ERROR, alive) {
                    Some(w) => (w, true),
                    // A row that reads X's error and waits on something
                    // more (an acknowledgement) handles it by design.
                    None if reads_error(p, state, x) => continue,
                    None => match conditions.stalls_while(state, x, StatusId::ERROR, alive) {
                        Some(w) => (w, false),
                        None => continue,
                    },
                };
                let Some(why) = *proved.get_or_init(|| proved_failure(ir, summaries, &p.rows, x))
                else {
                    continue;
                };
                let paths = paths.get_or_init(|| conditions.paths());
                let run = conditions.stall_run(paths, state, &w, STALL_CYCLES);
                let xc = ir.controller(x);
                let sub = &xc.name;
                let state_name = &p.states[s].name;
                let verb = &c.plan_title(p);
                let waits = if awaited == StatusId::DONE {
                    format!("`{sub}.done`")
                } else {
                    format!("`{sub}` to report `{}`", xc.statuses[awaited.index()].name)
                };
                let (x_span, x_label) = why.label(ir, x);
                let watchdog = alive && reads_watchdog(p, state, x);
                let mut d = Diagnostic::lint(
                    Lint::UnhandledError,
                    format!(
                        "state `{state_name}` of plan `{verb}` waits for {waits}, but nothing \
                         handles `{sub}.error`"
                    ),
                    first.cond_span,
                    format!("waits for {waits}"),
                )
                .with_secondary(x_span, x_label)
                .with_witness(state_name, &w.shown)
                .with_run(run)
                .with_across(Across {
                    sub: x,
                    shows: Some("ERROR".into()),
                    earlier: None,
                });
                d = if watchdog {
                    d.with_note(format!(
                        "with `{sub}.status == ERROR` no row of `{state_name}` matches: a failed \
                         `{sub}` keeps running and writing its status every cycle of `{}`, so \
                         `{sub}.stale_cycles` stays 0 and the watchdog on it never fires",
                        c.name
                    ))
                } else if whatever {
                    d.with_note(format!(
                        "with `{sub}.status == ERROR` no row of `{state_name}` matches, whatever \
                         the other inputs: `{}` stays in `{state_name}` until a new command",
                        c.name
                    ))
                } else {
                    d.with_note(format!(
                        "with `{sub}.status == ERROR` the rows of `{state_name}` that can still \
                         match wait on other inputs: while those keep the values above, none \
                         matches, however long `{}` waits — they are a way out, not a handling \
                         of `{sub}`'s failure",
                        c.name
                    ))
                };
                let d = d.with_help(format!(
                    "handle the failure: a row such as `*N when {sub}.error -> Error(CODE)`, \
                     or a timeout (`{state_name} when state_cycles > N -> …`)"
                ));
                sink.lint(Some(c), Some(p), d);
            }
        }
    }
}

/// The answer of `x` a row's condition waits for: `DONE` or a status `x`
/// reports (not `ERROR`, which is handling, nor the handshake's own
/// `EXECUTING` and `NOT_READY`).
fn awaited(r: &Row, x: CtrlId) -> Option<StatusId> {
    status_tests(r, x)
        .into_iter()
        .map(|(s, _)| s)
        .find(|s| ![StatusId::ERROR, StatusId::EXECUTING, StatusId::NOT_READY].contains(s))
}

/// Whether a row covering `state` reads `x.stale_cycles`.
fn reads_watchdog(p: &crate::ir::Plan, state: StateId, x: CtrlId) -> bool {
    p.rows.iter().filter(|r| covers(&r.from, state)).any(|r| {
        let mut found = false;
        if let crate::ir::Condition::When(e) = &r.cond {
            e.visit(&mut |e| {
                found |=
                    matches!(e.kind, crate::ir::ExprKind::Sub(c, SubProp::StaleCycles) if c == x)
            });
        }
        found
    })
}

/// Whether a row covering `state` tests `x` for `ERROR` (`x.error`,
/// `x.status == ERROR`).
fn reads_error(p: &crate::ir::Plan, state: StateId, x: CtrlId) -> bool {
    p.rows.iter().filter(|r| covers(&r.from, state)).any(|r| {
        status_tests(r, x)
            .iter()
            .any(|(s, _)| *s == StatusId::ERROR)
    })
}
