//! Stage 3, the lints of the value analysis ([`crate::analysis::value`]):
//! `int_wrap`, `div_by_zero` and `nan_path` (an operation of a job that
//! the probes saw go wrong where its value matters) and
//! `read_before_assign` (a row that read a value an earlier command left).
//! Every finding carries a run replayed on the interpreter; what the
//! analysis does not show says nothing.

use super::Sink;
use crate::analysis::value::probe::{Kind, Unit};
use crate::analysis::value::{Sink as Goes, ValueFinding};
use crate::analysis::PlanAnalysis;
use crate::diagnostic::Diagnostic;
use crate::ir::{Controller, Ir, Plan};
use crate::lint::Lint;

/// The value lints of one controller, over its plans' analyses.
pub(crate) fn check_values(ir: &Ir, c: &Controller, analyses: &[PlanAnalysis], sink: &mut Sink) {
    // An operation of `pre` or `post` is reported once, by the first
    // plan whose probes meet it.
    let mut every_cycle_seen = Vec::new();
    for (p, an) in c.plans.iter().zip(analyses) {
        for f in an.value_findings() {
            if f.unit != Unit::Pre && f.unit != Unit::Post {
                report(c, p, &f, sink);
            } else if !every_cycle_seen.contains(&(f.kind, f.span)) {
                every_cycle_seen.push((f.kind, f.span));
                report(c, p, &f, sink);
            }
        }
    }
    check_read_before_assign(ir, c, analyses, sink);
}

fn report(c: &Controller, p: &Plan, f: &ValueFinding, sink: &mut Sink) {
    let place = match f.unit {
        Unit::Pre => format!("`pre` of `{}`", c.name),
        Unit::Post => format!("`post` of `{}`", c.name),
        Unit::Row(r) => format!(
            "row {} of plan `{}`",
            p.rows[r].display_name(),
            c.plan_title(p)
        ),
    };
    let state = p
        .states
        .get(f.state.index())
        .map_or("S0", |s| s.name.as_str());
    let goes = match &f.sink {
        Goes::Output(what) => format!("is published in {what} at the end of the cycle"),
        Goes::Send(what) => format!("is sent: `{what}`"),
        Goes::Condition(r) => format!(
            "is read by the condition of {} on the {} cycle",
            p.rows[*r].display_name(),
            if f.unit == Unit::Pre { "same" } else { "next" }
        ),
        Goes::Latch(s) => {
            let s = p.states.get(s.index()).map_or("?", |s| s.name.as_str());
            format!(
                "stays NaN, and no row can leave state {s} while it is (every comparison with NaN is false): the plan stays there until a new command"
            )
        }
    };
    let when = format!("on cycle {} of command `{}`", f.cycle, f.run.command);
    let (lint, message, label, help) = match f.kind {
        Kind::Wrap => (
            Lint::IntWrap,
            format!("{place} can wrap an integer: {}", f.text),
            format!("wraps here: {}", f.text),
            "guard the row so that the operation stays in its type's range (a condition such as `n < LIMIT` before the job), or use a wider type".to_string(),
        ),
        Kind::DivZero => (
            Lint::DivByZero,
            format!("{place} can divide by zero: {}", f.text),
            format!("the divisor is 0 here: {}", f.text),
            "test the divisor in the row's condition (`d != 0`), with another row for a zero divisor before this one".to_string(),
        ),
        Kind::Nan => (
            Lint::NanPath,
            format!("{place} can make a NaN: {}", f.text),
            format!("NaN here: {}", f.text),
            "guard the operation in the row's condition, or handle NaN in a row before the others (`is_nan(x)`)".to_string(),
        ),
    };
    let d = Diagnostic::lint(lint, message, f.span, label)
        .with_witness(state, &f.shown)
        .with_run(Some(f.run.clone()))
        .with_note(format!("{when}, the result {goes}"))
        .with_help(help);
    let plan = matches!(f.unit, Unit::Row(_)).then_some(p);
    sink.lint(Some(c), plan, d);
}

/// `read_before_assign`: see [`crate::analysis::value::stale`].
fn check_read_before_assign(ir: &Ir, c: &Controller, analyses: &[PlanAnalysis], sink: &mut Sink) {
    for (p, an) in c.plans.iter().zip(analyses) {
        for f in crate::analysis::value::stale::stale_reads(ir, c, an) {
            let row = &p.rows[f.row];
            let var = &c.vars[f.var.index()];
            let d = Diagnostic::lint(
                Lint::ReadBeforeAssign,
                format!(
                    "row {} of plan `{}` reads `{}` before this command's jobs set it: it can still hold what an earlier `{}` left",
                    row.display_name(),
                    c.plan_title(p),
                    var.name,
                    f.earlier
                ),
                f.span,
                format!("`{}` can be {} here, from `{}`", var.name, f.value, f.earlier),
            )
            .with_witness("S0", &f.shown)
            .with_run(Some(f.run.clone()))
            .with_note(format!(
                "after `{}`, on the first cycle of `{}` {} fires; a fresh controller with the same inputs fires {}",
                f.earlier,
                c.plan_title(p),
                row.display_name(),
                f.fresh
            ))
            .with_help(format!(
                "reset `{}` in the jobs of the rows that end the earlier command, or read it only in states this command's jobs have set it by",
                var.name
            ));
            sink.lint(Some(c), Some(p), d);
        }
    }
}
