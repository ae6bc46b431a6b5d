//! Row-level checks of one plan: numbering, `otherwise`, entry rows, rows
//! that never match or are always taken first, double commands, the rule of
//! ten, and commands without a plan.

use super::graph::Analysis;
use super::Sink;
use crate::analysis::PlanAnalysis;
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::{Condition, Controller, Expr, ExprKind, From, Ir, Job, Plan, Row, StateId};
use crate::lint::Lint;

fn verb(c: &Controller, p: &Plan) -> String {
    c.plan_title(p)
}

pub(crate) fn check_missing_plans(ir: &Ir, sink: &mut Sink) {
    for c in &ir.controllers {
        for cmd in c.commands.iter().filter(|cmd| cmd.plan.is_none()) {
            sink.error(
                Diagnostic::error(
                    Code::MissingPlan,
                    format!("command `{}` of `{}` has no plan", cmd.name, c.name),
                    cmd.span,
                    "declared here without a plan",
                )
                .with_help(format!(
                    "every command needs a plan (§5.3.2.1): `plan {} {{ *0 when new_command -> … }}`",
                    cmd.name
                )),
            );
        }
    }
}

pub(crate) fn check_row_numbers(c: &Controller, p: &Plan, sink: &mut Sink) {
    for r in &p.rows {
        if let (Some(n), Some(span)) = (r.label, r.label_span) {
            if n != r.position {
                sink.error(
                    Diagnostic::error(
                        Code::RowNumber,
                        format!(
                            "row label `E{n}` does not match its position {} in plan `{}`",
                            r.position,
                            verb(c, p)
                        ),
                        span,
                        format!("this is row {}", r.position),
                    )
                    .with_note("row numbers are precedence positions, counted from 0")
                    .with_help(format!("write `E{}`, or drop the label", r.position))
                    .with_fix(format!("E{n}"), format!("E{}", r.position)),
                );
            }
        }
        if let From::DontCare(Some(n)) | From::Except(Some(n), _) = r.from {
            if n != r.position {
                sink.error(
                    Diagnostic::error(
                        Code::RowNumber,
                        format!(
                            "don't-care `*{n}` does not match its position {} in plan `{}`",
                            r.position,
                            verb(c, p)
                        ),
                        r.from_span,
                        format!("this is row {}", r.position),
                    )
                    .with_note("row numbers are precedence positions, counted from 0")
                    .with_help(format!("write `*{}`, or a plain `*`", r.position))
                    .with_fix(format!("*{n}"), format!("*{}", r.position)),
                );
            }
        }
    }
}

pub(crate) fn check_otherwise(p: &Plan, sink: &mut Sink) {
    let mut first: Option<&Row> = None;
    for r in p.rows.iter().filter(|r| r.is_otherwise()) {
        if let Some(f) = first {
            sink.error(
                Diagnostic::error(
                    Code::OtherwiseNotLast,
                    "a plan has at most one `otherwise` row",
                    r.cond_span,
                    "second `otherwise`",
                )
                .with_secondary(f.cond_span, "first `otherwise` here")
                .with_help("merge the two rows"),
            );
            continue;
        }
        first = Some(r);
        if r.position as usize + 1 != p.rows.len() {
            sink.error(
                Diagnostic::error(
                    Code::OtherwiseNotLast,
                    "`otherwise` must be the last row of its plan",
                    r.cond_span,
                    "rows follow it",
                )
                .with_secondary(
                    p.rows[r.position as usize + 1].span,
                    "this row comes after `otherwise`",
                )
                .with_help("move the `otherwise` row to the end"),
            );
        }
    }
}

pub(crate) fn check_entry(p: &Plan, sink: &mut Sink) {
    if !p.rows.iter().any(|r| r.is_entry) {
        sink.error(
            Diagnostic::error(
                Code::EntryMissing,
                "no row of this plan handles a new command",
                p.header,
                "no entry row",
            )
            .with_note(
                "a plan starts in S0 on the cycle its command arrives (§A `check_if_new_command`)",
            )
            .with_note(
                "an entry row's condition is `new_command` or `new_command && …`; under `||` or `!` it does not count",
            )
            .with_help("make the first row an entry: `*0 when new_command -> S1 { … }`"),
        );
        return;
    }
    let mut first_ordinary: Option<&Row> = None;
    for r in &p.rows {
        if r.is_otherwise() {
            continue;
        }
        // An entry row that does not apply in S0 never matches: it is
        // `unreachable_row`'s (or `unreachable_state`'s) finding, not this one's.
        if r.is_entry && !r.applies_in(StateId::S0) {
            continue;
        }
        if !r.is_entry {
            first_ordinary.get_or_insert(r);
        } else if let Some(o) = first_ordinary {
            sink.error(
                Diagnostic::error(
                    Code::EntryNotFirst,
                    "a row testing `new_command` stands after a row that does not",
                    r.cond_span,
                    "entry row",
                )
                .with_secondary(o.span, "this ordinary row comes first")
                .with_help("move the rows that test `new_command` to the top of the plan"),
            );
        }
    }
}

fn has_false_conjunct(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Bool(false) => true,
        ExprKind::Binary(crate::ast::BinOp::And, operands) => {
            let [l, r] = &**operands;
            has_false_conjunct(l) || has_false_conjunct(r)
        }
        _ => false,
    }
}

/// Whether a row applies in some reachable state. A `*` row always does
/// (S0 is reachable); a set or `except` row when one of its states is.
pub(crate) fn from_reachable(r: &Row, a: &Analysis) -> bool {
    match &r.from {
        From::DontCare(_) => true,
        from => from
            .states_covered(a.reachable.len())
            .any(|s| a.reachable[s.index()]),
    }
}

pub(crate) fn check_unreachable_rows(p: &Plan, a: &Analysis, sink: &mut Sink) {
    for r in &p.rows {
        if !a.never_matches[r.position as usize] || !from_reachable(r, a) {
            continue;
        }
        let Condition::When(c) = &r.cond else {
            continue;
        };
        let d = if r.is_entry && !r.applies_in(StateId::S0) {
            Diagnostic::error(
                Code::UnreachableRow,
                format!(
                    "row {} tests `new_command` but starts in a state other than S0",
                    r.display_name()
                ),
                r.from_span,
                "never the state on a new command's cycle",
            )
            .with_note("a new command resets the plan to S0 before the rows run")
            .with_help("start the row from `*` or `S0`")
        } else if has_false_conjunct(c) {
            Diagnostic::error(
                Code::UnreachableRow,
                format!(
                    "row {} can never match: its condition is always false",
                    r.display_name()
                ),
                c.span,
                "`false` is a conjunct of this condition",
            )
            .with_help("remove the row, or fix its condition")
        } else {
            Diagnostic::error(
                Code::UnreachableRow,
                format!(
                    "row {} can never match: no inputs make its condition true",
                    r.display_name()
                ),
                c.span,
                "always false",
            )
            .with_note(
                "decided over every value the inputs can take: the ranges of their types, \
                 every enum variant and subordinate status, NaN for floats",
            )
            .with_help("remove the row, or fix its condition")
        };
        sink.error(d);
    }
}

/// A row that, in every reachable state it applies to, some earlier rows
/// always take first: the union of the earlier rows covering that state
/// matches whenever this one does. Decided by the analysis of conditions,
/// so implication, several rows together, enum and status exhaustion and
/// integer ranges all count; the earlier rows that can match together with
/// this one are named. Rows in `entry_bound` are `unreachable_row`'s.
pub(crate) fn check_shadowed_rows(
    c: &Controller,
    p: &Plan,
    a: &Analysis,
    conditions: &PlanAnalysis,
    entry_bound: &[usize],
    sink: &mut Sink,
) {
    for (j, later) in p.rows.iter().enumerate() {
        // A row reported as `unreachable_row` is not also shadowed.
        if later.is_otherwise() || a.never_matches[j] || entry_bound.contains(&j) {
            continue;
        }
        let states: Vec<StateId> = (0..p.states.len())
            .map(|s| StateId(s as u32))
            .filter(|s| a.reachable[s.index()] && crate::analysis::covers(&later.from, *s))
            .collect();
        if states.is_empty() || !states.iter().all(|s| conditions.never_fires_in(j, *s)) {
            continue;
        }
        // The earlier rows that take this row's cases: each can fire on a
        // cycle where this row's condition holds.
        let covering: Vec<&Row> = p.rows[..j]
            .iter()
            .filter(|e| !a.never_matches[e.position as usize])
            .filter(|e| {
                states
                    .iter()
                    .any(|s| !conditions.never_fires_while(e.position as usize, j, *s))
            })
            .collect();
        let mut d = Diagnostic::lint(
            Lint::ShadowedRow,
            format!(
                "row {} of plan `{}` never fires: earlier rows always match first",
                later.display_name(),
                verb(c, p)
            ),
            later.cond_span,
            "whenever this row would match",
        );
        for e in &covering {
            d = d.with_secondary(e.span, format!("row {} matches first", e.display_name()));
        }
        let rows: Vec<String> = covering.iter().map(|e| e.display_name()).collect();
        let how = match rows.as_slice() {
            [one] => format!("row {one} matches whenever this row does"),
            many => format!(
                "together, rows {} match whenever this row does",
                many.join(", ")
            ),
        };
        sink.lint(
            Some(c),
            Some(p),
            d.with_note(how)
                .with_note(
                    "rows are tried in precedence order and only the first match fires (§4.2.2)",
                )
                .with_help("reorder the rows or make this condition more specific"),
        );
    }
}

pub(crate) fn check_double_commands(ir: &Ir, p: &Plan, sink: &mut Sink) {
    for r in &p.rows {
        let sends: Vec<(crate::ir::CtrlId, crate::source::Span)> =
            r.jobs.iter().filter_map(Job::sends_to).collect();
        for (i, (sub, span)) in sends.iter().enumerate() {
            if let Some((_, first)) = sends[..i].iter().find(|(s, _)| s == sub) {
                let name = &ir.controllers[sub.index()].name;
                sink.error(
                    Diagnostic::error(
                        Code::DoubleCommand,
                        format!("row {} sends two commands to `{name}`", r.display_name()),
                        *span,
                        "second command",
                    )
                    .with_secondary(*first, "first command")
                    .with_note("commands are not queued: the second would overwrite the first in the same cycle (§3.8.5)")
                    .with_help("send one command per subordinate per row; sequence them through states"),
                );
            }
        }
    }
}

pub(crate) fn check_rule_of_ten(ir: &Ir, c: &Controller, p: &Plan, sink: &mut Sink) {
    let max = ir.limits.max_rules_per_plan as usize;
    let counted: Vec<&Row> = p.rows.iter().filter(|r| !r.is_otherwise()).collect();
    if counted.len() <= max {
        return;
    }
    sink.lint(
        Some(c),
        Some(p),
        Diagnostic::lint(
            Lint::RuleOfTen,
            format!(
                "plan `{}` has {} rows; the limit is {max}",
                verb(c, p),
                counted.len()
            ),
            p.header,
            "too many rows",
        )
        .with_secondary(
            counted[max].span,
            format!("row {} is over the limit", max + 1),
        )
        .with_note("a plan with more rules is hard to review and test (§3.4, §4.2.1)")
        .with_help("split the task: add a subordinate, or move a sequence into another plan"),
    );
}
