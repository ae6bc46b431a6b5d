//! Checks of time in seconds (LANGUAGE.md §8 "Time"): the lint
//! `timer_resolution` — a duration that is not a whole number of the CPU's
//! periods, so that the comparison fires later than written (it never fires
//! early: see `lower::time`) — and the note that a controller whose CPU has
//! no `period:` in `rcs.yaml` counts its times in the default period.
//! Runs per controller, on the worker threads with the other checks.

use super::Sink;
use crate::ast::BinOp;
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::{CtrlId, Expr, Ir, Plan, WrittenTime};
use crate::lint::Lint;
use crate::manifest::DEFAULT_PERIOD_NS;
use crate::time::{first_change, format_ns};

pub(crate) fn check_timer_resolution(ir: &Ir, ci: CtrlId, sink: &mut Sink) {
    let c = ir.controller(ci);
    if c.written_times.is_empty() {
        return;
    }
    let cpu = ir.schedule.iter().find(|cpu| cpu.order.contains(&ci));
    let cpu_name = cpu.map_or("main", |cpu| cpu.name.as_str());
    // The note, once per controller, at its first time (in source order).
    if !cpu.is_some_and(|cpu| cpu.period_given) {
        if let Some(first) = c
            .written_times
            .iter()
            .min_by_key(|w| (w.span.file, w.span.start))
        {
            sink.note(
                c,
                Lint::TimerResolution,
                Diagnostic::note(
                    Code::Lint(Lint::TimerResolution),
                    format!(
                        "`{}` counts time in the default period, {}: its CPU `{cpu_name}` has no `period:` in `rcs.yaml`",
                        c.name,
                        format_ns(DEFAULT_PERIOD_NS)
                    ),
                    first.span,
                    format!("cycles of {}", format_ns(DEFAULT_PERIOD_NS)),
                )
                .with_help(format!(
                    "give the CPU its real period, `schedule: [{{ cpu: {cpu_name}, period: 10ms, order: [...] }}]`: every time is then counted in it"
                )),
            );
        }
    }
    let mut lint = |plan: Option<&Plan>, e: &Expr| {
        let Some(w) = c.written_times.iter().find(|w| w.span == e.span) else {
            return;
        };
        if w.duration_ns.is_multiple_of(w.period_ns) {
            return;
        }
        let text = match &e.kind {
            crate::ir::ExprKind::Binary(_, operands) => {
                crate::pretty::Printer::new(ir, c, plan).written_text(w, &operands[0])
            }
            _ => w.duration.clone(),
        };
        sink.lint(Some(c), plan, finding(w, &text, cpu_name));
    };
    for p in &c.plans {
        for r in &p.rows {
            r.visit_exprs(&mut |e| lint(Some(p), e));
        }
    }
    for block in [&c.pre, &c.post].into_iter().flatten() {
        block.visit_exprs(&mut |e| lint(None, e));
    }
}

/// `timer_resolution` for one comparison: when it really fires.
fn finding(w: &WrittenTime, text: &str, cpu: &str) -> Diagnostic {
    let n = first_change(w.op, w.threshold);
    let at = |n: u64| {
        let ns = u128::from(n) * u128::from(w.period_ns);
        let time = u64::try_from(ns).map_or_else(|_| format!("{ns}ns"), format_ns);
        format!("{n} cycle{} = {time}", if n == 1 { "" } else { "s" })
    };
    let when = match w.op {
        BinOp::Gt | BinOp::Ge => format!("fires after {}", at(n)),
        _ => format!("stops holding at {}", at(n)),
    };
    let below = w.duration_ns / w.period_ns * w.period_ns;
    let up = below.saturating_add(w.period_ns);
    let down = if below > 0 {
        format!("`{}` or ", format_ns(below))
    } else {
        String::new()
    };
    Diagnostic::lint(
        Lint::TimerResolution,
        format!(
            "`{}` is not a whole number of the {} period of CPU `{cpu}`",
            format_ns(w.duration_ns),
            format_ns(w.period_ns)
        ),
        w.span,
        when.clone(),
    )
    .with_note(format!(
        "time is cycles × {}, so `{}` {when}",
        format_ns(w.period_ns),
        text
    ))
    .with_help(format!(
        "write a multiple of the period ({down}`{}`), or allow the lint with `#[allow(timer_resolution)]`",
        format_ns(up)
    ))
}
