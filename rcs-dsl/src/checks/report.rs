//! What `report DONE` / `report ERROR(CODE)` (report-and-continue,
//! LANGUAGE.md §7) mean to the plan-graph lints: a plan that reports DONE
//! and goes on holding has told its supervisor it is done, so it is
//! neither `no_done` nor, in the state it holds in, a `dead_end_state` or
//! an `incomplete_state`. Used by `checks::graph` and `checks::hang`; both
//! only ever become quieter through it.

use crate::analysis::covers;
use crate::ir::{Job, Plan, Row, StateId, StatusId, Target};

/// Whether a row's jobs report `DONE` or `ERROR` (the plan goes on).
pub(crate) fn reports_outcome(r: &Row) -> bool {
    r.jobs.iter().any(|j| {
        matches!(j, Job::Report { status, .. } if *status == StatusId::DONE || *status == StatusId::ERROR)
    })
}

/// Whether state `s` is a deliberate hold: some row that enters it, or
/// stays in it with `same`, reports `DONE` or `ERROR`.
pub(crate) fn reported_hold(p: &Plan, s: usize) -> bool {
    let state = StateId(s as u32);
    p.rows
        .iter()
        .filter(|r| reports_outcome(r))
        .any(|r| match r.to {
            Target::State(t) => t == state,
            Target::Same => covers(&r.from, state),
            Target::Done | Target::Error(_) | Target::ErrorOf(_) => false,
        })
}

/// Whether some row that can match reports `DONE` or `ERROR`: the
/// supervisor can see the plan's outcome without the plan ending.
pub(crate) fn reports_any_outcome(p: &Plan, never_matches: &[bool]) -> bool {
    p.rows
        .iter()
        .zip(never_matches)
        .any(|(r, never)| !never && reports_outcome(r))
}
