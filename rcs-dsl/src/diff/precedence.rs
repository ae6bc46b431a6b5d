//! Rows moved in precedence: two matched rows whose order flipped, where
//! both can match in a state both cover. The most dangerous edit to a
//! state table: the text barely changes, but the row that fires may.
//!
//! The analysis of the new plan decides it where it can. If, in some state
//! `s`, the row now first (`b`) can fire on a cycle where the other
//! (`a`)'s condition holds ([`PlanAnalysis::can_fire_while`], with a
//! witness), and `a`'s condition and state pattern are the same as before,
//! then on that input the old plan could not fire `b` (`a` matched and came
//! first) and the new one does: the move changes which row fires, and the
//! witness shows the input. When the analysis proves `b` never fires while
//! `a` holds, in every shared state, the two rows do not compete and the
//! flip is not reported; otherwise the move is reported as undecided.
//! Plans the analysis does not take on ([`crate::analysis::MAX_ANALYSED`])
//! get no moves at all: silent where it cannot decide.

use super::rows::RowView;
use crate::analysis::{covers, Answer, PlanAnalysis};
use crate::ir::{Controller, Ir, Plan, StateId};
use serde::Serialize;

/// Two rows whose precedence flipped.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Move {
    /// The row that now comes first, as labelled now and before.
    pub now_first: String,
    pub was: String,
    /// The row it now precedes (it used to follow it), now and before.
    pub now_second: String,
    pub second_was: String,
    pub effect: Effect,
}

/// What a move does to the rows that fire.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Effect {
    /// On `input` in `state`, `now_first` fires where before it could not.
    ChangesFiring { state: String, input: String },
    /// The analysis could not tell.
    Undecided,
}

type Side<'a> = (&'a Ir, &'a Controller, &'a Plan);

/// The flipped pairs among `pairs` (old index, new index) that compete.
pub(crate) fn moves(
    new: Side,
    ov: &[RowView],
    nv: &[RowView],
    pairs: &[(usize, usize)],
) -> Vec<Move> {
    let (ir, ctrl, plan) = new;
    let an = PlanAnalysis::new(ir, ctrl, plan);
    let mut out = Vec::new();
    // A plan the analysis does not take on (far past the rule of ten)
    // would give every flipped pair as undecided, quadratically many.
    if !an.analysed() {
        return out;
    }
    for &(oa, na) in pairs {
        for &(ob, nb) in pairs {
            // a came first before, b comes first now.
            if !(oa < ob && nb < na) || ov[oa].otherwise || ov[ob].otherwise {
                continue;
            }
            let Some(effect) = effect(&an, plan, (&ov[oa], &nv[na]), na, nb) else {
                continue;
            };
            out.push(Move {
                now_first: nv[nb].label.clone(),
                was: ov[ob].label.clone(),
                now_second: nv[na].label.clone(),
                second_was: ov[oa].label.clone(),
                effect,
            });
        }
    }
    out.sort_by_key(|m| (position(&m.now_first), position(&m.now_second)));
    out
}

fn position(label: &str) -> u32 {
    label.trim_start_matches('E').parse().unwrap_or(u32::MAX)
}

/// What putting new row `nb` before new row `na` (old `a`) does; `None`
/// when the analysis proves they do not compete.
fn effect(
    an: &PlanAnalysis,
    plan: &Plan,
    (a_old, a_new): (&RowView, &RowView),
    na: usize,
    nb: usize,
) -> Option<Effect> {
    let (ra, rb) = (&plan.rows[na], &plan.rows[nb]);
    let a_kept = a_old.condition == a_new.condition;
    let mut undecided = false;
    for (i, state) in plan.states.iter().enumerate() {
        let s = StateId(i as u32);
        if !covers(&ra.from, s) || !covers(&rb.from, s) {
            continue;
        }
        match an.can_fire_while(nb, na, s) {
            Answer::Never => {}
            Answer::Can(w) if a_kept && a_old.covers_name(&state.name) => {
                return Some(Effect::ChangesFiring {
                    state: state.name.clone(),
                    input: w.text(),
                });
            }
            Answer::Can(_) | Answer::Unknown => undecided = true,
        }
    }
    undecided.then_some(Effect::Undecided)
}
