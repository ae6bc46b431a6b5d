//! Checks across a supervisor and its subordinates, through the handshake
//! (stage 3b: after every controller's own analysis). A subordinate is
//! modelled by what its plans can answer to the verbs its supervisor sends
//! it — a [`Summary`] taken from its analyses — so each finding about a
//! supervisor is proved against what the subordinate can really do:
//!
//! - [`unhandled`]: `unhandled_error`, a state waits for X's answer where
//!   nothing can fire once X fails (`Error`, `report ERROR`, a built-in
//!   `INDEX_RANGE`, a refusal), a watchdog on a live X included;
//! - [`reported`]: `status_never_reported`, a wait for a status X never
//!   shows (a report overwritten in its own row does not count);
//! - [`stale`]: `stale_subordinate_status`, a row reads X's answer before
//!   this plan commanded X, so it sees an earlier command's answer;
//! - [`overwritten`]: `command_overwritten`, a second command to X from
//!   another row on the next cycle, before anything read X's answer;
//! - [`rejected`]: `always_rejected`, a command with constant arguments
//!   that X always answers `ERROR` at once.

mod overwritten;
mod rejected;
mod reported;
mod stale;
mod system_run;
mod unhandled;

pub(crate) use overwritten::check_command_overwritten;
pub(crate) use rejected::check_always_rejected;
pub(crate) use reported::check_status_never_reported;
pub(crate) use stale::check_stale_subordinate_status;
pub(crate) use system_run::add_system_runs;
pub(crate) use unhandled::check_unhandled_error;

use super::graph::Analysis;
use crate::analysis::{covers, PlanAnalysis};
use crate::ast::BinOp;
use crate::ir::{
    CommandId, Controller, CtrlId, Expr, ExprKind, Ir, Job, Plan, Row, StateId, StatusId, SubProp,
    Target,
};
use crate::source::Span;
use rcs_runtime::driver::Value;

/// What a supervisor's handshake checks read: its plans with their
/// analyses, and every controller's [`Summary`].
pub(crate) struct Supervisor<'a, 'ir> {
    pub(crate) ir: &'ir Ir,
    pub(crate) id: CtrlId,
    pub(crate) conditions: &'a [PlanAnalysis<'ir>],
    pub(crate) graphs: &'a [Analysis],
    pub(crate) summaries: &'a [Summary],
}

impl<'a, 'ir> Supervisor<'a, 'ir> {
    pub(crate) fn controller(&self) -> &'ir Controller {
        self.ir.controller(self.id)
    }

    /// The plans the analysis answers questions about, with their
    /// analyses; with `over_cycles`, only those it follows over cycles
    /// (see [`PlanAnalysis::analysed_over_cycles`]).
    pub(crate) fn plans(
        &self,
        over_cycles: bool,
    ) -> impl Iterator<Item = (&'ir Plan, &'a PlanAnalysis<'ir>, &'a Analysis)> + use<'a, 'ir> {
        let c = self.controller();
        c.plans
            .iter()
            .zip(self.conditions)
            .zip(self.graphs)
            .map(|((p, an), g)| (p, an, g))
            .filter(move |(_, an, _)| {
                if over_cycles {
                    an.analysed_over_cycles()
                } else {
                    an.analysed()
                }
            })
    }
}

/// One way a subordinate's plan can answer `ERROR`.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Failure {
    /// A row that can fire ends in `Error`.
    Ends { row: usize },
    /// A row that can fire has `report ERROR` and goes on.
    Reports { row: usize },
    /// An index by a value can fall outside its array: the built-in
    /// `INDEX_RANGE` (found with a replayed run by the `index_range` check).
    IndexRange { span: Span },
}

/// What a supervisor's handshake checks need of a subordinate's plans,
/// taken from the subordinate's analyses as soon as they are made: the
/// checks of each controller then run on the worker threads with its own
/// analyses and its subordinates' summaries, and no controller's analyses
/// have to outlive its own checks.
pub(crate) struct Summary {
    /// Per plan: the first way it may answer `ERROR`, by the analysis of
    /// one cycle (a row that can match in a reachable state; a run to it
    /// is searched only when a finding needs it, [`proved_failure`]).
    failures: Vec<Option<Failure>>,
    /// Per plan: where an index can fall outside its array (a way to fail
    /// the `index_range` check proves with its own replayed run).
    out_of_range: Vec<Option<Span>>,
    /// Per command: the `accept when` span, where the condition can be
    /// false on a command's arrival (the command is then `REFUSED`).
    refusals: Vec<Option<Span>>,
    /// Per plan: the statuses a supervisor can see it report (`DONE` and
    /// `ERROR` for rows ending there), in row order.
    reported: Vec<Vec<StatusId>>,
    /// Per plan: reports no supervisor can see, because a later write in
    /// the same row (another `report`, `-> Done`, `-> Error`) replaces
    /// the status before it is written: (status, report, replaced by).
    overwritten: Vec<Vec<(StatusId, Span, Span)>>,
    /// Per plan: whether it can answer (end, report, refuse or stop with a
    /// built-in error) on its first cycle.
    answers_at_once: Vec<bool>,
    /// The commands with constant arguments its supervisor sends it that
    /// it always answers `ERROR` at once.
    rejected: Vec<rejected::Rejected>,
    /// For each command with constant arguments its supervisor sends it,
    /// the statuses its plan makes visible with those arguments (as
    /// `reported`, with the parameters pinned).
    pub(super) reported_with: Vec<(CommandId, Vec<Value>, Vec<StatusId>)>,
}

impl Summary {
    pub(crate) fn of(
        ir: &Ir,
        c: &Controller,
        conditions: &[PlanAnalysis],
        graphs: &[Analysis],
        out_of_range: &[Vec<Span>],
    ) -> Summary {
        let plans = || c.plans.iter().zip(conditions).zip(graphs);
        let failures = plans()
            .zip(out_of_range)
            .map(|(((plan, _), graph), out)| {
                let can_fire = |r: &Row| {
                    !graph.never_matches[r.position as usize]
                        && super::plan::from_reachable(r, graph)
                };
                let ends = plan.rows.iter().position(|r| {
                    matches!(r.to, Target::Error(_) | Target::ErrorOf(_)) && can_fire(r)
                });
                let reports = plan.rows.iter().position(|r| {
                    can_fire(r)
                        && visible_reports(r)
                            .iter()
                            .any(|(s, _)| *s == StatusId::ERROR)
                });
                ends.map(|row| Failure::Ends { row })
                    .or(reports.map(|row| Failure::Reports { row }))
                    .or(out.first().map(|&span| Failure::IndexRange { span }))
            })
            .collect();
        let refusals = c
            .commands
            .iter()
            .enumerate()
            .map(|(ki, k)| {
                let accept = k.accept.as_ref()?;
                let pid = k.plan?.index();
                // The analysis of a plan reads its own verb's condition.
                let an = conditions.get(pid)?;
                if c.plans[pid].verb.index() != ki {
                    return None;
                }
                an.refusal().map(|_| accept.span)
            })
            .collect();
        let reported = plans()
            .map(|((plan, conditions), graph)| reported_by(plan, conditions, graph, &[]))
            .collect();
        let overwritten = c
            .plans
            .iter()
            .map(|p| p.rows.iter().flat_map(overwritten_reports).collect())
            .collect();
        let answers_at_once = plans()
            .zip(out_of_range)
            .map(|(((plan, conditions), graph), out)| {
                let refusable = c.commands[plan.verb.index()].accept.is_some();
                refusable
                    || !out.is_empty()
                    || plan.rows.iter().enumerate().any(|(i, r)| {
                        let answers = !matches!(r.to, Target::State(_) | Target::Same)
                            || !visible_reports(r).is_empty();
                        answers
                            && covers(&r.from, StateId::S0)
                            && !graph.never_matches[i]
                            && !conditions.never_fires_in(i, StateId::S0)
                    })
            })
            .collect();
        let sent = rejected::constant_sends(ir, c);
        let reported_with = sent
            .iter()
            .filter_map(|(verb, args)| {
                let pid = c.commands[verb.index()].plan?.index();
                let an = &conditions[pid];
                let given = rejected::pinned(an, args);
                let shown = reported_by(&c.plans[pid], an, &graphs[pid], &given);
                Some((*verb, args.clone(), shown))
            })
            .collect();
        Summary {
            failures,
            out_of_range: out_of_range.iter().map(|o| o.first().copied()).collect(),
            refusals,
            reported,
            overwritten,
            answers_at_once,
            rejected: rejected::rejections(c, conditions, &sent),
            reported_with,
        }
    }
}

/// How subordinate `x` can answer `ERROR` to `verb`: a way of its plan,
/// or a refusal; `None` when the analysis shows none (or `verb` has no
/// plan).
pub(crate) fn failure(ir: &Ir, summaries: &[Summary], x: CtrlId, verb: CommandId) -> Option<Why> {
    let pid = ir.controller(x).commands[verb.index()].plan?.index();
    let s = &summaries[x.index()];
    s.failures[pid]
        .map(|f| Why::Plan {
            plan: pid,
            failure: f,
        })
        .or(s.refusals[verb.index()].map(|span| Why::Refused { verb, span }))
}

/// How subordinate `x` answers `ERROR` to a verb `rows` send it, proved:
/// a row of its plan that fails (ends in `Error`, reports `ERROR`),
/// reached by a run replayed on the interpreter with the command's
/// parameters at the constant arguments sent (free where an argument is
/// not a constant); else a built-in `INDEX_RANGE`, which the
/// `index_range` check proves with its own run; else a refusal, whose
/// inputs a command's arrival can have. `None` when none is proved: a row
/// that matches in a reachable state may still never fire (an earlier
/// row always ends the plan first), and then nothing is said.
pub(crate) fn proved_failure(
    ir: &Ir,
    summaries: &[Summary],
    rows: &[Row],
    x: CtrlId,
) -> Option<Why> {
    let xc = ir.controller(x);
    let s = &summaries[x.index()];
    let verbs = verbs_sent(rows, x);
    for &verb in &verbs {
        let Some(pid) = xc.commands[verb.index()].plan else {
            continue;
        };
        if s.failures[pid.index()].is_none() {
            continue;
        }
        for args in args_sent(rows, x, verb) {
            if let Some((row, _)) = system_run::failure_run(ir, x, verb, &args) {
                let r = &xc.plans[pid.index()].rows[row];
                let failure = if matches!(r.to, Target::Error(_) | Target::ErrorOf(_)) {
                    Failure::Ends { row }
                } else {
                    Failure::Reports { row }
                };
                return Some(Why::Plan {
                    plan: pid.index(),
                    failure,
                });
            }
        }
    }
    verbs
        .iter()
        .find_map(|&verb| {
            let pid = xc.commands[verb.index()].plan?.index();
            s.out_of_range[pid].map(|span| Why::Plan {
                plan: pid,
                failure: Failure::IndexRange { span },
            })
        })
        .or_else(|| {
            verbs
                .iter()
                .find_map(|&verb| s.refusals[verb.index()].map(|span| Why::Refused { verb, span }))
        })
}

/// The argument lists `rows` send `x` with `verb`: the constant ones, and
/// an empty list (parameters free) for a send whose arguments are not all
/// constants.
fn args_sent(rows: &[Row], x: CtrlId, verb: CommandId) -> Vec<Vec<Value>> {
    let mut out: Vec<Vec<Value>> = Vec::new();
    for j in rows.iter().flat_map(|r| &r.jobs) {
        let to_x = j.sends_to().is_some_and(|(sub, _)| sub == x);
        if !(to_x && j.commands_sent().contains(&verb)) {
            continue;
        }
        let args = match rejected::constant_send(j, x) {
            Some((_, args)) => args,
            None => Vec::new(),
        };
        if !out.contains(&args) {
            out.push(args);
        }
    }
    out
}

/// A subordinate's way to answer `ERROR`, located for a label.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Why {
    Plan { plan: usize, failure: Failure },
    Refused { verb: CommandId, span: Span },
}

impl Why {
    /// The place to point at, and what to say there.
    pub(crate) fn label(self, ir: &Ir, x: CtrlId) -> (Span, String) {
        let xc = ir.controller(x);
        let sub = &xc.name;
        match self {
            Why::Plan { plan, failure } => {
                let p = &xc.plans[plan];
                let verb = xc.plan_title(p);
                match failure {
                    Failure::Ends { row } => (
                        p.rows[row].span,
                        format!("`{sub}`'s plan `{verb}` can end in `Error` here"),
                    ),
                    Failure::Reports { row } => (
                        p.rows[row].span,
                        format!("`{sub}`'s plan `{verb}` can report `ERROR` here and go on"),
                    ),
                    Failure::IndexRange { span } => (
                        span,
                        format!(
                            "`{sub}`'s plan `{verb}` can stop here with the built-in error \
                             `INDEX_RANGE`"
                        ),
                    ),
                }
            }
            Why::Refused { verb, span } => (
                span,
                format!(
                    "`{sub}` can refuse `{}` here: the supervisor sees `ERROR(REFUSED)`",
                    xc.commands[verb.index()].name
                ),
            ),
        }
    }
}

/// Whether `x`, alive, writes its status on every cycle of `sup`: it runs
/// at least as often, so `x.stale_cycles` reads 0 on each of them.
pub(crate) fn writes_every_cycle_of(ir: &Ir, sup: CtrlId, x: CtrlId) -> bool {
    let period = |c: CtrlId| {
        ir.schedule
            .iter()
            .find(|cpu| cpu.order.contains(&c))
            .map(|cpu| cpu.period_ns)
    };
    match (period(sup), period(x)) {
        (Some(s), Some(xp)) => xp <= s,
        _ => false,
    }
}

/// The verbs `rows` send to subordinate `x`, in order, without repeats.
pub(crate) fn verbs_sent(rows: &[Row], x: CtrlId) -> Vec<CommandId> {
    let mut verbs = Vec::new();
    for r in rows {
        for j in &r.jobs {
            if j.sends_to().is_some_and(|(sub, _)| sub == x) {
                for command in j.commands_sent() {
                    if !verbs.contains(&command) {
                        verbs.push(command);
                    }
                }
            }
        }
    }
    verbs
}

/// The verbs any plan of `c` sends `x`, without repeats.
pub(crate) fn verbs_sent_by(c: &Controller, x: CtrlId) -> Vec<CommandId> {
    c.plans
        .iter()
        .flat_map(|p| verbs_sent(&p.rows, x))
        .fold(Vec::new(), |mut vs, v| {
            if !vs.contains(&v) {
                vs.push(v);
            }
            vs
        })
}

/// Whether a row sends `x` a command.
pub(crate) fn sends(r: &Row, x: CtrlId) -> bool {
    r.jobs
        .iter()
        .any(|j| j.sends_to().is_some_and(|(sub, _)| sub == x))
}

/// The reports of a row a supervisor can see: the last one, unless the
/// row ends the plan (the final status replaces it in the same cycle).
pub(crate) fn visible_reports(r: &Row) -> Vec<(StatusId, Span)> {
    if !matches!(r.to, Target::State(_) | Target::Same) {
        return Vec::new();
    }
    r.jobs
        .iter()
        .filter_map(|j| match j {
            Job::Report { status, span, .. } => Some((*status, *span)),
            _ => None,
        })
        .next_back()
        .into_iter()
        .collect()
}

/// The reports of a row that a later write of the same cycle replaces.
fn overwritten_reports(r: &Row) -> Vec<(StatusId, Span, Span)> {
    let reports: Vec<(StatusId, Span)> = r
        .jobs
        .iter()
        .filter_map(|j| match j {
            Job::Report { status, span, .. } => Some((*status, *span)),
            _ => None,
        })
        .collect();
    let ends = !matches!(r.to, Target::State(_) | Target::Same);
    reports
        .iter()
        .enumerate()
        .filter_map(|(i, &(status, span))| {
            let by = if ends {
                Some(r.to_span)
            } else {
                reports
                    .get(i + 1..)
                    .and_then(|later| later.last())
                    .map(|l| l.1)
            };
            by.map(|by| (status, span, by))
        })
        .collect()
}

/// The statuses the rows of `plan` that can fire make visible, in row
/// order, without repeats; with `given`, the command's parameters pinned.
fn reported_by(
    plan: &Plan,
    conditions: &PlanAnalysis,
    graph: &Analysis,
    given: &[(usize, Value)],
) -> Vec<StatusId> {
    let mut reported = Vec::new();
    let mut add = |s: StatusId| {
        if !reported.contains(&s) {
            reported.push(s);
        }
    };
    for (i, r) in plan.rows.iter().enumerate() {
        let can_fire = !graph.never_matches[i]
            && (0..plan.states.len()).any(|s| {
                let state = StateId(s as u32);
                graph.reachable[s]
                    && if given.is_empty() {
                        !conditions.never_fires_in(i, state)
                    } else {
                        !conditions.never_fires_in_given(i, state, given)
                    }
            });
        if !can_fire {
            continue;
        }
        match r.to {
            Target::Done => add(StatusId::DONE),
            Target::Error(_) | Target::ErrorOf(_) => add(StatusId::ERROR),
            Target::State(_) | Target::Same => {}
        }
        for (s, _) in visible_reports(r) {
            add(s);
        }
    }
    reported
}

/// The statuses of `x` a row's condition waits for, with the test's span:
/// `x.done`, `x.error`, `x.status == S` (either way round), where the
/// condition holds only if the test does (not under a `!`).
pub(crate) fn status_tests(r: &Row, x: CtrlId) -> Vec<(StatusId, Span)> {
    let mut found = Vec::new();
    if let crate::ir::Condition::When(e) = &r.cond {
        waits_in(e, x, &mut found);
    }
    found
}

fn waits_in(e: &Expr, x: CtrlId, found: &mut Vec<(StatusId, Span)>) {
    let status_of_x = |e: &Expr| matches!(e.kind, ExprKind::Sub(c, SubProp::Status) if c == x);
    let constant = |e: &Expr| match e.kind {
        ExprKind::Status(s) => Some(s),
        _ => None,
    };
    match &e.kind {
        ExprKind::Sub(c, SubProp::Done) if *c == x => found.push((StatusId::DONE, e.span)),
        ExprKind::Sub(c, SubProp::Error) if *c == x => found.push((StatusId::ERROR, e.span)),
        ExprKind::Binary(BinOp::And | BinOp::Or, operands) => {
            let [l, r] = &**operands;
            waits_in(l, x, found);
            waits_in(r, x, found);
        }
        ExprKind::Binary(BinOp::Eq, operands) => {
            let [l, r] = &**operands;
            let tested = if status_of_x(l) {
                constant(r)
            } else if status_of_x(r) {
                constant(l)
            } else {
                None
            };
            if let Some(s) = tested {
                found.push((s, e.span));
            }
        }
        _ => {}
    }
}

/// Whether a row's condition reads anything of `x`'s answer (status,
/// `done`, `error`, `executing`, error code, watchdog or status fields).
pub(crate) fn reads_answer_of(r: &Row, x: CtrlId) -> bool {
    let mut found = false;
    if let crate::ir::Condition::When(e) = &r.cond {
        e.visit(&mut |e| {
            found |= matches!(e.kind, ExprKind::Sub(c, _) | ExprKind::SubField(c, _) if c == x)
        });
    }
    found
}
