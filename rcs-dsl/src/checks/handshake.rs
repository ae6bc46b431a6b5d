//! Checks across a supervisor and its subordinates, through the handshake:
//! `unhandled_error` — a state that waits for `X.done` where nothing can
//! fire once X reports `ERROR`, although the plan X runs for it can end in
//! `Error`. Each finding is proved by the analysis of conditions and
//! carries a witness: a cycle, with `X.status = ERROR`, in which no row of
//! that state matches, and where a path to the state is found, a run: the
//! path, then 30 cycles with X in `ERROR` and no row firing.

use super::graph::Analysis;
use super::Sink;
use crate::analysis::{covers, PlanAnalysis};
use crate::ast::BinOp;
use crate::diagnostic::Diagnostic;
use crate::ir::{
    CommandId, Controller, CtrlId, Expr, ExprKind, Ir, Job, Plan, Row, StateId, StatusId, SubProp,
    Target,
};
use crate::lint::Lint;

/// How long a stall's run holds the subordinate in `ERROR`: long enough
/// to pass any timeout a reader would expect to have fired.
const STALL_CYCLES: u32 = 30;

/// What a supervisor's handshake checks need of a subordinate's plans,
/// taken from the subordinate's analyses as soon as they are made: the
/// checks of each controller then run on the worker threads with its own
/// analyses and its subordinates' summaries, and no controller's analyses
/// have to outlive its own checks.
pub(crate) struct Summary {
    /// Per plan: the first row that ends in `Error` and that the analysis
    /// cannot rule out.
    error_rows: Vec<Option<usize>>,
    /// Per plan: the statuses its rows that can fire report (`DONE` and
    /// `ERROR` for rows ending there), in row order.
    reported: Vec<Vec<StatusId>>,
}

impl Summary {
    pub(crate) fn of(c: &Controller, conditions: &[PlanAnalysis], graphs: &[Analysis]) -> Summary {
        let plans = c.plans.iter().zip(conditions).zip(graphs);
        let error_rows = plans
            .clone()
            .map(|((plan, _), graph)| {
                plan.rows.iter().position(|r| {
                    matches!(r.to, Target::Error(_) | Target::ErrorOf(_))
                        && !graph.never_matches[r.position as usize]
                        && super::plan::from_reachable(r, graph)
                })
            })
            .collect();
        let reported = plans
            .map(|((plan, conditions), graph)| reported_by(plan, conditions, graph))
            .collect();
        Summary {
            error_rows,
            reported,
        }
    }
}

/// `unhandled_error` in the plans of controller `ci`, over their analyses
/// and the summaries of every controller.
pub(crate) fn check_unhandled_error(
    ir: &Ir,
    ci: CtrlId,
    conditions: &[PlanAnalysis],
    graphs: &[Analysis],
    summaries: &[Summary],
    sink: &mut Sink,
) {
    let c = ir.controller(ci);
    for (pi, p) in c.plans.iter().enumerate() {
        let conditions = &conditions[pi];
        let graph = &graphs[pi];
        // A plan too large to analyse: nothing can be proved of it.
        if !conditions.analysed() {
            continue;
        }
        // Paths to each state, searched once a finding needs one.
        let paths = std::cell::OnceCell::new();
        for &x in &c.subordinates {
            // The verbs this plan sends X, and a row of X's plans for
            // them that can end in Error.
            let sent = verbs_sent(&p.rows, x);
            let Some(fails) = sent.iter().find_map(|v| error_row(ir, summaries, x, *v)) else {
                continue;
            };
            for s in (0..p.states.len()).filter(|s| graph.reachable[*s]) {
                let state = StateId(s as u32);
                let waiting: Vec<&Row> = p
                    .rows
                    .iter()
                    .filter(|r| covers(&r.from, state) && waits_for_done(r, x))
                    .filter(|r| !conditions.never_fires_in(r.position as usize, state))
                    .collect();
                let Some(first) = waiting.first() else {
                    continue;
                };
                let Some(w) = conditions.stalls_in(state, x, StatusId::ERROR) else {
                    continue;
                };
                let paths = paths.get_or_init(|| conditions.paths());
                let run = conditions.stall_run(paths, state, &w, STALL_CYCLES);
                let sub = &ir.controller(x).name;
                let state_name = &p.states[s].name;
                let verb = &c.plan_title(p);
                let (xp, xr) = fails;
                let x_ctrl = ir.controller(x);
                let x_verb = &x_ctrl.plan_title(&x_ctrl.plans[xp]);
                let x_row = &x_ctrl.plans[xp].rows[xr];
                let d = Diagnostic::lint(
                    Lint::UnhandledError,
                    format!(
                        "state `{state_name}` of plan `{verb}` waits for `{sub}.done`, \
                         but nothing handles `{sub}.error`"
                    ),
                    first.cond_span,
                    format!("waits for `{sub}.done`"),
                )
                .with_secondary(
                    x_row.span,
                    format!("`{sub}`'s plan `{x_verb}` can end in `Error` here"),
                )
                .with_witness(state_name, &w.shown)
                .with_run(run)
                .with_note(format!(
                    "with `{sub}.status == ERROR` no row of `{state_name}` matches, whatever \
                     the other inputs: `{}` stays in `{state_name}` until a new command",
                    c.name
                ))
                .with_help(format!(
                    "handle the failure: a row such as `*N when {sub}.error -> Error(CODE)`, \
                     or a timeout (`{state_name} when state_cycles > N -> …`)"
                ));
                sink.lint(Some(c), Some(p), d);
            }
        }
    }
}

/// The verbs `rows` send to subordinate `x`, in order, without repeats.
fn verbs_sent(rows: &[Row], x: CtrlId) -> Vec<CommandId> {
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

/// A row of `x`'s plan for `verb` that ends in `Error` and that the
/// analysis cannot rule out: (plan index, row index).
fn error_row(ir: &Ir, summaries: &[Summary], x: CtrlId, verb: CommandId) -> Option<(usize, usize)> {
    let pid = ir.controller(x).commands[verb.index()].plan?.index();
    summaries[x.index()].error_rows[pid].map(|r| (pid, r))
}

/// Whether a row's condition tests `x.done` (or `x.status == DONE`).
fn waits_for_done(r: &Row, x: CtrlId) -> bool {
    let mut found = false;
    if let crate::ir::Condition::When(e) = &r.cond {
        e.visit(&mut |e| found |= is_done_test(e, x));
    }
    found
}

fn is_done_test(e: &Expr, x: CtrlId) -> bool {
    let status_of_x = |e: &Expr| matches!(e.kind, ExprKind::Sub(c, SubProp::Status) if c == x);
    let done = |e: &Expr| matches!(e.kind, ExprKind::Status(s) if s == StatusId::DONE);
    match &e.kind {
        ExprKind::Sub(c, SubProp::Done) => *c == x,
        ExprKind::Binary(BinOp::Eq, operands) => {
            let [l, r] = &**operands;
            (status_of_x(l) && done(r)) || (done(l) && status_of_x(r))
        }
        _ => false,
    }
}

/// `status_never_reported`: a supervisor tests `X.status == S` (or
/// `X.done`) although no row of X that can fire, in the plans X runs for
/// the verbs the supervisor sends it, reports `S`. `EXECUTING` and
/// `NOT_READY` come from the handshake, never from a row, and a test of
/// `ERROR` is defensive handling: those three are not judged.
pub(crate) fn check_status_never_reported(
    ir: &Ir,
    ci: CtrlId,
    summaries: &[Summary],
    sink: &mut Sink,
) {
    let c = ir.controller(ci);
    for &x in &c.subordinates {
        // One supervisor only commands X (two is an error of its own).
        if ir.controller(x).supervisor != Some(ci) {
            continue;
        }
        let sent: Vec<CommandId> =
            c.plans
                .iter()
                .flat_map(|p| verbs_sent(&p.rows, x))
                .fold(Vec::new(), |mut vs, v| {
                    if !vs.contains(&v) {
                        vs.push(v);
                    }
                    vs
                });
        let Some(reported) = statuses_reported(ir, summaries, x, &sent) else {
            continue;
        };
        for p in &c.plans {
            for r in &p.rows {
                for (status, span) in status_tests(r, x) {
                    // ERROR is not judged: testing it is the
                    // defensive handling `unhandled_error` asks for,
                    // worth keeping when X's plans change.
                    if status == StatusId::NOT_READY
                        || status == StatusId::EXECUTING
                        || status == StatusId::ERROR
                        || reported.contains(&status)
                    {
                        continue;
                    }
                    let d = never_reported(ir, c, x, &sent, status, span);
                    sink.lint(Some(c), Some(p), d);
                }
            }
        }
    }
}

fn never_reported(
    ir: &Ir,
    c: &crate::ir::Controller,
    x: CtrlId,
    sent: &[CommandId],
    status: StatusId,
    span: crate::source::Span,
) -> Diagnostic {
    let xc = ir.controller(x);
    let sub = &xc.name;
    let name = &xc.statuses[status.index()].name;
    let verbs: Vec<String> = sent
        .iter()
        .map(|v| format!("`{}`", xc.commands[v.index()].name))
        .collect();
    let how = match status {
        StatusId::DONE => "ends in `Done`".to_string(),
        _ => format!("has `report {name}`"),
    };
    let note = if sent.is_empty() {
        format!(
            "`{}` never sends `{sub}` a command, so `{sub}` shows `NOT_READY` for ever",
            c.name
        )
    } else {
        let plural = if verbs.len() == 1 { "" } else { "s" };
        let verbs = verbs.join(", ");
        format!(
            "`{}` sends `{sub}` {verbs}; in `{sub}`'s plan{plural} for {verbs}, no row that can \
             fire {how}",
            c.name
        )
    };
    Diagnostic::lint(
        Lint::StatusNeverReported,
        format!(
            "`{}` waits for `{sub}` to report `{name}`, which it never does",
            c.name
        ),
        span,
        format!("`{sub}` never reports `{name}`"),
    )
    .with_note(note)
    .with_help(if status == StatusId::DONE {
        format!("test a status `{sub}` reports, or give `{sub}`'s plan a way to `Done`")
    } else {
        format!("test a status `{sub}` reports, or make a row of `{sub}` report `{name}`")
    })
}

/// The statuses the rows of `x` that can fire report, in the plans `x`
/// runs for `verbs`; `None` when a verb has no plan (nothing to judge).
fn statuses_reported(
    ir: &Ir,
    summaries: &[Summary],
    x: CtrlId,
    verbs: &[CommandId],
) -> Option<Vec<StatusId>> {
    let mut reported = Vec::new();
    for v in verbs {
        let pid = ir.controller(x).commands[v.index()].plan?.index();
        for s in &summaries[x.index()].reported[pid] {
            if !reported.contains(s) {
                reported.push(*s);
            }
        }
    }
    Some(reported)
}

/// The statuses the rows of `plan` that can fire report, in row order,
/// without repeats.
fn reported_by(plan: &Plan, conditions: &PlanAnalysis, graph: &Analysis) -> Vec<StatusId> {
    let mut reported = Vec::new();
    let mut add = |s: StatusId| {
        if !reported.contains(&s) {
            reported.push(s);
        }
    };
    for (i, r) in plan.rows.iter().enumerate() {
        let can_fire = !graph.never_matches[i]
            && (0..plan.states.len())
                .any(|s| graph.reachable[s] && !conditions.never_fires_in(i, StateId(s as u32)));
        if !can_fire {
            continue;
        }
        match r.to {
            Target::Done => add(StatusId::DONE),
            Target::Error(_) | Target::ErrorOf(_) => add(StatusId::ERROR),
            Target::State(_) | Target::Same => {}
        }
        for j in &r.jobs {
            if let Job::Report { status, .. } = j {
                add(*status);
            }
        }
    }
    reported
}

/// The statuses of `x` a row's condition waits for, with the test's span:
/// `x.done`, `x.error`, `x.status == S` (either way round), where the
/// condition holds only if the test does (not under a `!`).
fn status_tests(r: &Row, x: CtrlId) -> Vec<(StatusId, crate::source::Span)> {
    let mut found = Vec::new();
    if let crate::ir::Condition::When(e) = &r.cond {
        waits_in(e, x, &mut found);
    }
    found
}

fn waits_in(e: &Expr, x: CtrlId, found: &mut Vec<(StatusId, crate::source::Span)>) {
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
