//! Stage 2, expressions: time in seconds and watchdogs on `reads` buffers
//! (LANGUAGE.md §8 "Time", "Watchdogs on buffers").
//!
//! A duration is no run-time value. The only thing a plan may do with one
//! is compare it with a time — `state_time`, `plan_time`, `X.stale_time`,
//! `B.stale_time` — and that comparison is lowered here, once, to a
//! comparison of the matching cycle counter (`state_cycles`, `plan_cycles`,
//! `X.stale_cycles`, `B.stale_cycles`) with a threshold computed exactly in
//! integer nanoseconds for the period of the controller's CPU
//! ([`crate::time::cycle_threshold`]): it never fires early, and fires on
//! the first cycle at which cycles × period satisfies it. Interpreter,
//! generated code and analysis therefore see only cycle counters; the
//! comparison as written is kept on the controller ([`WrittenTime`]) for
//! everything that prints it.
//!
//! The simplest honest rule for every other position: a duration, or a
//! time, anywhere but as one side of `<`, `<=`, `>`, `>=` with the other
//! side a time (resp. a duration literal or `duration` constant) is a
//! `type_mismatch` that shows the spelling that works.

use super::expr::{err_expr, Cx, Ty, Value};
use crate::ast::{self, BinOp};
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::*;
use crate::source::Span;
use crate::time::{cycle_threshold, flipped, format_ns};

/// What lowering one controller needs to know about time, and what it
/// found.
#[derive(Default)]
pub(in crate::lower) struct TimeCx {
    /// The period of the controller's CPU (the default if none is given).
    pub period_ns: u64,
    /// The comparisons lowered so far (their `text` empty until the
    /// controller is done, see [`fill_texts`]).
    pub written: Vec<WrittenTime>,
}

/// One side of a comparison, as far as time goes.
enum Side {
    /// A time: its counter, lowered (`state_cycles`, …).
    Time(Expr),
    /// A duration literal or `duration` constant, in nanoseconds.
    Duration(u64),
    /// Anything else.
    Other,
}

/// `type_mismatch`: a duration where a number is expected (a constant's
/// value, an operand). Also used by constant folding.
pub(crate) fn duration_not_number(span: Span, hint: Option<&Type>) -> Diagnostic {
    let want = match hint {
        Some(Type::Int(i)) => format!("`{}`", i.name()),
        Some(Type::Float(f)) => format!("`{}`", f.name()),
        _ => "a number".to_string(),
    };
    Diagnostic::error(
        Code::TypeMismatch,
        format!("expected {want}, found a duration"),
        span,
        "a duration, not a number",
    )
    .with_help(
        "a duration is compared with a time only: `state_time > 5s`; \
         declare a duration constant as `const T: duration = 5s`",
    )
}

/// The help for a timer written as another language writes it: IEC 61131
/// `TON(…)`/`TOF`/`TP`, Stateflow `after(2, sec)`, SCXML-style `delay(…)`.
pub(in crate::lower) fn timer_spelling(name: &str) -> Option<String> {
    match name {
        "TON" | "TOF" | "TP" | "ton" | "tof" | "after" | "delay" | "timeout" | "timer" | "wait" => {
            Some(format!(
                "rcsc has no timer functions: a row compares the time in its state with a duration, \
                 `S1 when state_time > 2s -> …` (`{name}(…)` is another language's timer)"
            ))
        }
        _ => None,
    }
}

/// `B.stale_cycles` / `B.stale_time` for a buffer of the plan set that this
/// controller does not read: the diagnostic, if `x` names such a buffer.
pub(in crate::lower) fn unread_buffer(cx: &Cx, x: &ast::Name) -> Option<Diagnostic> {
    let b = cx.ir.buffers.iter().find(|b| b.name == x.text.as_str())?;
    let ty = &cx.ir.buffer_types[b.ty.index()].name;
    Some(
        Diagnostic::error(
            Code::UnknownName,
            format!("`{}` is not a `reads` buffer of `{}`", x.text, cx.c.name),
            x.span,
            "not read by this controller",
        )
        .with_help(format!(
            "a watchdog counts the cycles since a buffer this controller reads was written: add `reads {}: {ty}`",
            x.text
        )),
    )
}

/// Whether an AST operand is a duration or a time (a time counter or a
/// duration literal or constant), so that its comparison is lowered here.
pub(in crate::lower) fn mentions_time(cx: &Cx, e: &ast::Expr) -> bool {
    match &e.kind {
        ast::ExprKind::Paren(x) => mentions_time(cx, x),
        ast::ExprKind::Duration(_) | ast::ExprKind::StateTime | ast::ExprKind::PlanTime => true,
        ast::ExprKind::Field(_, f) => f.text == "stale_time",
        ast::ExprKind::Path(None, n) => cx.duration_const(&n.text).is_some(),
        _ => false,
    }
}

impl Cx<'_, '_> {
    /// The `duration` constant `name` seen from this controller, unless a
    /// var, buffer or hook of the controller takes the name.
    pub(in crate::lower) fn duration_const(&self, name: &str) -> Option<u64> {
        if self.value(name).is_some() {
            return None;
        }
        self.g
            .consts_table
            .durations
            .get(Some(self.ctrl.index()), name)
    }

    /// A duration or a time used anywhere but in a comparison with the
    /// other: reported, with the spelling that works.
    pub(in crate::lower) fn time_out_of_place(&mut self, e: &ast::Expr) -> (Expr, Ty) {
        let (message, label) = match &e.kind {
            ast::ExprKind::StateTime | ast::ExprKind::PlanTime | ast::ExprKind::Field(..) => (
                "a time is only compared with a duration".to_string(),
                "a time, here not compared".to_string(),
            ),
            _ => (
                "a duration is only compared with a time".to_string(),
                "a duration, here not compared with a time".to_string(),
            ),
        };
        self.diags.push(
            Diagnostic::error(Code::TypeMismatch, message, e.span, label).with_help(
                "write `state_time > 5s`, `plan_time >= 1.5s`, `X.stale_time > 100ms` or \
                 `io.stale_time > 50ms`; count cycles with `state_cycles`, `plan_cycles` \
                 or `.stale_cycles` for arithmetic",
            ),
        );
        (err_expr(e.span), Ty::Err)
    }

    /// `l op r` where one side mentions time ([`mentions_time`]).
    pub(in crate::lower) fn time_comparison(
        &mut self,
        op: BinOp,
        l: &ast::Expr,
        r: &ast::Expr,
        span: Span,
    ) -> (Expr, Ty) {
        let (a, b) = (self.side(l), self.side(r));
        let time_left = matches!(self.side_kind(l), SideKind::Time);
        let (time, ns, op, other) = match (a, b) {
            (Side::Time(t), Side::Duration(ns)) => (t, ns, op, None),
            (Side::Duration(ns), Side::Time(t)) => (t, ns, flipped(op), None),
            (Side::Time(_), Side::Time(_)) => {
                return self.time_mismatch(
                    span,
                    "two times compared",
                    "compare a time with a duration: `state_time > 5s`".into(),
                )
            }
            (Side::Duration(_), Side::Duration(_)) => {
                return self.time_mismatch(
                    span,
                    "two durations compared",
                    "compare a time with a duration: `state_time > 5s`".into(),
                )
            }
            (Side::Time(_), Side::Other) => (err_expr(span), 0, op, Some((r, true))),
            (Side::Other, Side::Time(_)) => (err_expr(span), 0, op, Some((l, true))),
            (Side::Duration(_), Side::Other) => (err_expr(span), 0, op, Some((r, false))),
            (Side::Other, Side::Duration(_)) => (err_expr(span), 0, op, Some((l, false))),
            // `mentions_time` said one side is time; an error was reported.
            (Side::Other, Side::Other) => return (err_expr(span), Ty::Err),
        };
        if let Some((other, other_side_of_time)) = other {
            return self.time_beside_other(op, other, other_side_of_time, span);
        }
        if matches!(time.kind, ExprKind::Bool(false)) && time.ty == Type::Bool {
            return (err_expr(span), Ty::Err); // the time did not resolve; reported
        }
        if matches!(op, BinOp::Eq | BinOp::Ne) {
            let (lt, ge) = ("<", ">=");
            return self.time_mismatch(
                span,
                &format!("a time compared with `{}`", op.symbol()),
                format!(
                    "time advances by whole periods, so `==` may never hold; \
                     compare with `{ge}` (or `{lt}`): `state_time >= 5s`"
                ),
            );
        }
        let period = self.time.period_ns.max(1);
        let (cycle_op, threshold) = cycle_threshold(op, ns, period);
        if threshold > u64::from(u32::MAX) {
            return self.time_mismatch(
                span,
                &format!(
                    "`{}` is {threshold} periods of {}, beyond the cycle counter (`u32`)",
                    format_ns(ns),
                    format_ns(period)
                ),
                "the counters stop at 4294967295 cycles; use a shorter duration or a longer period"
                    .to_string(),
            );
        }
        let duration_span = if time_left { r.span } else { l.span };
        self.time.written.push(WrittenTime {
            span,
            duration: String::new(),
            time_left,
            op,
            duration_ns: ns,
            period_ns: period,
            threshold,
            duration_span,
        });
        let u32_ty = Type::Int(IntTy::U32);
        let mut time = time;
        time.ty = u32_ty.clone();
        let k = Expr {
            kind: ExprKind::Int(i128::from(threshold)),
            ty: u32_ty,
            span: duration_span,
        };
        (
            Expr {
                kind: ExprKind::binary(cycle_op, time, k),
                ty: Type::Bool,
                span,
            },
            Ty::Known(Type::Bool),
        )
    }

    fn time_mismatch(&mut self, span: Span, message: &str, help: String) -> (Expr, Ty) {
        self.diags.push(
            Diagnostic::error(
                Code::TypeMismatch,
                message.to_string(),
                span,
                "not a time compared with a duration by `<`, `<=`, `>` or `>=`",
            )
            .with_help(help),
        );
        (err_expr(span), Ty::Err)
    }

    /// A time or a duration beside something else: `state_time > 50`
    /// ("did you mean `50ms`?"), `state_cycles > 5s`, `x > 5s`.
    fn time_beside_other(
        &mut self,
        op: BinOp,
        other: &ast::Expr,
        beside_time: bool,
        span: Span,
    ) -> (Expr, Ty) {
        let mut inner = other;
        while let ast::ExprKind::Paren(x) = &inner.kind {
            inner = x;
        }
        let sym = op.symbol();
        let (message, help) = match (&inner.kind, beside_time) {
            (ast::ExprKind::Int(n), true) => (
                "a time compared with a number".to_string(),
                format!("a time compares with a duration: did you mean `{n}ms` or `{n}s`? (`state_time {sym} {n}ms`)"),
            ),
            (ast::ExprKind::Float(f), true) => (
                "a time compared with a number".to_string(),
                format!("a time compares with a duration: did you mean `{}s`?", crate::pretty::float(*f)),
            ),
            (ast::ExprKind::StateCycles | ast::ExprKind::PlanCycles, false) => {
                let (cycles, time) = if matches!(inner.kind, ast::ExprKind::StateCycles) {
                    ("state_cycles", "state_time")
                } else {
                    ("plan_cycles", "plan_time")
                };
                (
                    format!("`{cycles}` counts cycles, not time"),
                    format!("compare the time instead: `{time} {sym} …`"),
                )
            }
            (ast::ExprKind::Field(_, f), false) if f.text == "stale_cycles" => (
                "`stale_cycles` counts cycles, not time".to_string(),
                "compare the time instead: `X.stale_time > 100ms`".to_string(),
            ),
            (_, true) => (
                "a time compared with something other than a duration".to_string(),
                "write a duration with its unit: `250us`, `50ms`, `1.5s`, or a `duration` constant".to_string(),
            ),
            (_, false) => (
                "a duration compared with something other than a time".to_string(),
                "a duration compares with `state_time`, `plan_time`, `X.stale_time` or `B.stale_time` (for a `reads` buffer B)".to_string(),
            ),
        };
        // Lower the other side for its own diagnostics (unknown names…).
        let before = self.diags.len();
        let _ = self.infer(other, None);
        if self.diags.len() > before {
            return (err_expr(span), Ty::Err);
        }
        self.diags.push(
            Diagnostic::error(Code::TypeMismatch, message, other.span, "not a duration")
                .with_help(help),
        );
        (err_expr(span), Ty::Err)
    }

    fn side_kind(&self, e: &ast::Expr) -> SideKind {
        match &e.kind {
            ast::ExprKind::Paren(x) => self.side_kind(x),
            ast::ExprKind::Duration(_) => SideKind::Duration,
            ast::ExprKind::Path(None, n) if self.duration_const(&n.text).is_some() => {
                SideKind::Duration
            }
            ast::ExprKind::StateTime | ast::ExprKind::PlanTime => SideKind::Time,
            ast::ExprKind::Field(_, f) if f.text == "stale_time" => SideKind::Time,
            _ => SideKind::Other,
        }
    }

    /// One side of a comparison: a time lowered to its counter, a
    /// duration, or something else.
    fn side(&mut self, e: &ast::Expr) -> Side {
        let span = e.span;
        let counter = |kind: ExprKind| Expr {
            kind,
            ty: Type::Int(IntTy::U32),
            span,
        };
        match &e.kind {
            ast::ExprKind::Paren(x) => self.side(x),
            ast::ExprKind::Duration(ns) => Side::Duration(*ns),
            ast::ExprKind::Path(None, n) => match self.duration_const(&n.text) {
                Some(ns) => Side::Duration(ns),
                None => Side::Other,
            },
            ast::ExprKind::StateTime | ast::ExprKind::PlanTime if self.const_ctx => {
                self.not_const(span, "a plan quantity");
                Side::Time(err_expr(span))
            }
            // Judged before the command replaces the running plan: the
            // arriving command's counters (see `Cx::not_in_accept`).
            ast::ExprKind::StateTime | ast::ExprKind::PlanTime if self.accept_ctx => {
                self.not_in_accept(
                    span,
                    "a plan quantity",
                    "the condition is judged before the command replaces the running plan, so `state_time` and `plan_time` would be the arriving command's; keep what the condition needs in a var of the running plan",
                );
                Side::Time(err_expr(span))
            }
            ast::ExprKind::StateTime => Side::Time(counter(ExprKind::StateCycles)),
            ast::ExprKind::PlanTime => Side::Time(counter(ExprKind::PlanCycles)),
            ast::ExprKind::Field(base, f) if f.text == "stale_time" => {
                Side::Time(self.stale_counter(base, f, span))
            }
            _ => Side::Other,
        }
    }

    /// `X.stale_time` / `B.stale_time`: the counter it is cycles of,
    /// `X.stale_cycles` or `B.stale_cycles`.
    fn stale_counter(&mut self, base: &ast::Expr, f: &ast::Name, span: Span) -> Expr {
        let cycles = ast::Name {
            text: "stale_cycles".into(),
            span: f.span,
        };
        let (e, _) = self.field(base, &cycles, span);
        match e.kind {
            ExprKind::Sub(_, SubProp::StaleCycles) | ExprKind::BufferStale(_) => e,
            // An error reported, or a buffer field that happens to be
            // called `stale_cycles` (never a time).
            ExprKind::Bool(false) if e.ty == Type::Bool => e,
            _ => {
                self.diags.push(
                    Diagnostic::error(
                        Code::UnknownName,
                        "`.stale_time` is for a subordinate or a `reads` buffer".to_string(),
                        f.span,
                        "no watchdog here",
                    )
                    .with_help(
                        "`X.stale_time` for a subordinate X, `B.stale_time` for a `reads` buffer B",
                    ),
                );
                err_expr(span)
            }
        }
    }

    /// `B.stale_cycles` where `B` names one of this controller's buffers
    /// and B's type has no field of that name: the watchdog of a `reads`
    /// buffer, or a diagnostic for a `writes` buffer. `None`: not a buffer
    /// of this controller (the caller goes on as before).
    pub(in crate::lower) fn buffer_watchdog(
        &mut self,
        base: &ast::Expr,
        field: &ast::Name,
        span: Span,
    ) -> Option<(Expr, Ty)> {
        if field.text != "stale_cycles" {
            return None;
        }
        let ast::ExprKind::Path(None, name) = &base.kind else {
            return None;
        };
        let Some(Value::Buffer(b, _)) = self.value(&name.text) else {
            return None;
        };
        let bt = self.ir.buffers[b.index()].ty;
        if self.ix.fields[bt.index()].get("stale_cycles").is_some() {
            return None; // the buffer's own field wins
        }
        if self.const_ctx {
            return Some(self.not_const(span, "a buffer's watchdog"));
        }
        if !self.c.reads.contains(&b) {
            self.diags.push(
                Diagnostic::error(
                    Code::UnknownName,
                    format!(
                        "`{}` is a `writes` buffer of `{}`: it has no watchdog",
                        name.text, self.c.name
                    ),
                    field.span,
                    "only a `reads` buffer has `.stale_cycles`",
                )
                .with_help(format!(
                    "`.stale_cycles` and `.stale_time` count the cycles since a buffer's writer last wrote it; `{}` writes `{}` itself",
                    self.c.name, name.text
                )),
            );
            return Some((err_expr(span), Ty::Err));
        }
        let ty = Type::Int(IntTy::U32);
        Some((
            Expr {
                kind: ExprKind::BufferStale(b),
                ty: ty.clone(),
                span,
            },
            Ty::Known(ty),
        ))
    }
}

enum SideKind {
    Time,
    Duration,
    Other,
}

/// Fill in each duration's text from the source, as written.
pub(super) fn fill_texts(written: &mut [WrittenTime], sources: &crate::source::SourceMap) {
    for w in written {
        let s = w.duration_span;
        w.duration = sources
            .get(s.file)
            .text
            .get(s.start as usize..s.end as usize)
            .unwrap_or_default()
            .to_string();
    }
}
