//! Where a value that went wrong goes: the value analysis reports an
//! event only when this says it matters (see [`super`]). Decided on the
//! probe's trace — the jobs after the event in the same cycle, and the
//! rows the interpreter evaluated on the next cycle — and, for a NaN that
//! latches, by a proof of the conditions analysis.

use super::probe::{Hit, Kind, Unit};
use super::{always_reads, every_cycle, reads_var};
use crate::analysis::search::Outcome;
use crate::analysis::terms::{Formula, Leaf};
use crate::analysis::PlanAnalysis;
use crate::ast::{AssignOp, BinOp, UnOp};
use crate::ir::{Condition, Expr, ExprKind, Job, PlaceRoot, StateId, Target, Type, VarId};
use rcs_runtime::driver::{Record, Value};
use rcs_runtime::Status;

/// How a value that went wrong matters.
#[derive(Clone, Debug, PartialEq)]
pub enum Sink {
    /// Published at the end of the cycle: a `writes` field, or a status
    /// field (`status field \`count\``), as written.
    Output(String),
    /// Sent to a subordinate: `FEED <- RATE`.
    Send(String),
    /// Read by this row's condition, evaluated by the interpreter on the
    /// next cycle (the same cycle, for a value `pre` computed).
    Condition(usize),
    /// A NaN that no row leaving this state can get past: the plan stays
    /// there until a new command.
    Latch(StateId),
}

/// How many cycles a NaN latch's run shows after the NaN.
const LATCH_SHOWN: usize = 3;

impl PlanAnalysis<'_> {
    /// Where `hit`'s event (of `kind`) on cycle `c` of `recs` goes, and
    /// how many cycles after `c` the run must show for it; `None` when it
    /// is not shown to matter. `at`: the state before cycle `c`.
    pub(super) fn sink(
        &self,
        hit: &Hit,
        kind: Kind,
        recs: &[Record],
        c: usize,
        at: StateId,
    ) -> Option<(Sink, usize)> {
        let fired = recs[c].fired.map(usize::from);
        let row_jobs = fired.map_or(&[][..], |f| &self.plan.rows[f].jobs[..]);
        let (this, rest): (&[Job], Vec<&[Job]>) = match hit.unit {
            Unit::Pre => (
                every_cycle(&self.ctrl.pre),
                vec![row_jobs, every_cycle(&self.ctrl.post)],
            ),
            Unit::Row(f) => (&self.plan.rows[f].jobs, vec![every_cycle(&self.ctrl.post)]),
            Unit::Post => (every_cycle(&self.ctrl.post), Vec::new()),
        };
        let job = this.get(hit.job)?;
        let later: Vec<&Job> = this[hit.job + 1..]
            .iter()
            .chain(rest.into_iter().flatten())
            .collect();
        let printer = crate::pretty::Printer::new(self.ir, self.ctrl, Some(self.plan));
        let assigns =
            |j: &Job, root: PlaceRoot| matches!(j, Job::Assign { place, .. } if place.root == root);
        let place = match job {
            Job::Send { sub, command, .. } => {
                return Some((Sink::Send(self.send_text(*sub, *command)), 0))
            }
            Job::Assign { place, .. } => place,
            _ => return None,
        };
        let overwritten = later.iter().any(|j| assigns(j, place.root));
        let v = match place.root {
            PlaceRoot::Buffer(_) => {
                return (!overwritten).then(|| (Sink::Output(printer.place(place)), 0));
            }
            PlaceRoot::Var(v) => v,
        };
        let var = &self.ctrl.vars[v.index()];
        if var.status_field && !overwritten {
            return Some((Sink::Output(format!("status field `{}`", var.name)), 0));
        }
        // Passed on, in the same cycle, to a send or an output.
        for (i, j) in later.iter().enumerate() {
            match j {
                Job::Send {
                    sub, command, args, ..
                } if args.iter().any(|a| reads_var(a, v)) => {
                    return Some((Sink::Send(self.send_text(*sub, *command)), 0));
                }
                Job::Assign {
                    place: p2, value, ..
                } if reads_var(value, v) && p2.root != place.root => {
                    let published = match p2.root {
                        PlaceRoot::Buffer(_) => true,
                        PlaceRoot::Var(u) => self.ctrl.vars[u.index()].status_field,
                    };
                    let again = later[i + 1..].iter().any(|k| assigns(k, p2.root));
                    if published && !again {
                        return Some((Sink::Output(printer.place(p2)), 0));
                    }
                }
                _ => {}
            }
            if assigns(j, place.root) {
                break;
            }
        }
        if overwritten {
            return None;
        }
        let executing = |k: usize| recs.get(k).is_some_and(|r| r.status == Status::EXECUTING);
        if kind == Kind::Nan {
            let after = StateId(u32::from(recs[c].state));
            let latched = executing(c) && self.latches(v, after);
            let more = LATCH_SHOWN.min(recs.len() - 1 - c);
            return latched.then_some((Sink::Latch(after), more));
        }
        match hit.unit {
            // `pre` runs before the rows of its own cycle.
            Unit::Pre => {
                let active = c == 0 || executing(c - 1);
                let row = self
                    .evaluated(at, &recs[c])
                    .into_iter()
                    .find(|&r| active && self.condition_reads(r, v))?;
                Some((Sink::Condition(row), 0))
            }
            Unit::Row(_) | Unit::Post => {
                let pre_sets = every_cycle(&self.ctrl.pre)
                    .iter()
                    .any(|j| assigns(j, place.root));
                if pre_sets || !executing(c) || c + 1 >= recs.len() {
                    return None;
                }
                let next = StateId(u32::from(recs[c].state));
                let row = self
                    .evaluated(next, &recs[c + 1])
                    .into_iter()
                    .find(|&r| self.condition_reads(r, v))?;
                Some((Sink::Condition(row), 1))
            }
        }
    }

    fn send_text(&self, sub: crate::ir::CtrlId, command: crate::ir::CommandId) -> String {
        let x = self.ir.controller(sub);
        format!("{} <- {}", x.name, x.commands[command.index()].name)
    }

    /// Whether row `r`'s condition always reads `v` when evaluated.
    fn condition_reads(&self, r: usize, v: VarId) -> bool {
        matches!(&self.plan.rows[r].cond, Condition::When(e) if always_reads(e, v))
    }

    /// The rows whose conditions the interpreter evaluated on the cycle
    /// of `rec`, started in `state`: those covering it, in order, up to
    /// the one that fired (all of them when none or `otherwise` fired and
    /// the plan goes on; none when the cycle ended it otherwise).
    fn evaluated(&self, state: StateId, rec: &Record) -> Vec<usize> {
        let fired = rec.fired.map(usize::from);
        let decided = fired.is_some() || rec.status == Status::EXECUTING;
        if !decided {
            return Vec::new();
        }
        let mut out = Vec::new();
        for (i, row) in self.plan.rows.iter().enumerate() {
            if row.is_otherwise() || !row.applies_in(state) {
                continue;
            }
            out.push(i);
            if fired == Some(i) {
                break;
            }
        }
        out
    }

    /// Whether, once float var `v` is NaN in `state`, the plan cannot
    /// leave `state` until a new command: every row leaving it is proved
    /// never to match with `v` NaN (whatever the other inputs), there is
    /// such a row, no `otherwise` leaves, and every job that can run there
    /// (`pre`, `post`, rows that stay) keeps `v` NaN.
    pub(super) fn latches(&self, v: VarId, state: StateId) -> bool {
        if !self.analysed_over_cycles() {
            return false;
        }
        let Some(leaf) = self.terms.find(&Leaf::Var(v, Vec::new())) else {
            return false;
        };
        if !matches!(self.terms.leaves[leaf].1, Type::Float(_)) {
            return false;
        }
        let keeps = |jobs: &[Job]| {
            jobs.iter().all(|j| match j {
                Job::Assign {
                    place, op, value, ..
                } if place.root == PlaceRoot::Var(v) => {
                    place.path.is_empty() && (*op != AssignOp::Set || keeps_nan(value, v))
                }
                _ => true,
            })
        };
        if !keeps(every_cycle(&self.ctrl.pre)) || !keeps(every_cycle(&self.ctrl.post)) {
            return false;
        }
        let mut fixed = self.fixed(state);
        fixed.push((leaf, Value::Float(f64::NAN)));
        let mut leaving = 0;
        for (i, row) in self.plan.rows.iter().enumerate() {
            if !row.applies_in(state) {
                continue;
            }
            if matches!(row.to, Target::Same) || row.to == Target::State(state) {
                if !keeps(&row.jobs) {
                    return false;
                }
                continue;
            }
            leaving += 1;
            let Some(c) = &self.conds[i] else {
                return false;
            };
            if !matches!(
                self.prove(&Formula::Shared(c.clone()), &fixed),
                Outcome::None
            ) {
                return false;
            }
        }
        leaving > 0
    }
}

/// Whether `e` is NaN whenever float var `v` is: `v` reached through
/// arithmetic only (`+ - * / %`, negation, a float cast).
fn keeps_nan(e: &Expr, v: VarId) -> bool {
    match &e.kind {
        ExprKind::Var(u) => *u == v,
        ExprKind::Binary(
            BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div | BinOp::Rem,
            operands,
        ) => operands.iter().any(|x| keeps_nan(x, v)),
        ExprKind::Unary(UnOp::Neg, x) => keeps_nan(x, v),
        ExprKind::Cast(x) if matches!(e.ty, Type::Float(_)) => keeps_nan(x, v),
        _ => false,
    }
}
