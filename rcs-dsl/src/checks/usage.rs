//! Checks of how declarations are used: `float_equality` and `unused`.

use super::Sink;
use crate::ast::BinOp;
use crate::diagnostic::Diagnostic;
use crate::ir::{Controller, CtrlId, EnumId, ExprKind, Ir, Job, PlaceRoot, StatusId, Target, Type};
use crate::lint::Lint;

/// `float_equality` in one controller's rows (run per controller, on the
/// worker threads with the analyses).
pub(crate) fn check_float_equality(c: &Controller, sink: &mut Sink) {
    for p in &c.plans {
        for r in &p.rows {
            let mut found = Vec::new();
            r.visit_exprs(&mut |e| {
                if let ExprKind::Binary(op @ (BinOp::Eq | BinOp::Ne), operands) = &e.kind {
                    if matches!(operands[0].ty, Type::Float(_)) {
                        found.push((*op, e.span));
                    }
                }
            });
            for (op, span) in found {
                sink.lint(
                    Some(c),
                    Some(p),
                    Diagnostic::lint(
                        Lint::FloatEquality,
                        format!("floats compared with `{}`", op.symbol()),
                        span,
                        "exact float comparison",
                    )
                    .with_note(
                        "measured values rarely equal a float exactly; the row may never fire",
                    )
                    .with_help("compare within a tolerance: `x > goal - 0.5 && x < goal + 0.5`"),
                );
            }
        }
    }
}

fn mentions_type(t: &Type, f: &mut dyn FnMut(&Type)) {
    f(t);
    if let Type::Array(e, _) = t {
        mentions_type(e, f);
    }
}

/// What one controller's rows use of declarations that are not its own
/// (enums, and statuses: its own by `report`, its subordinates' by
/// comparison), gathered per controller by [`check_unused_in_controller`]
/// and judged for the whole set by [`check_unused_declarations`].
#[derive(Default)]
pub(crate) struct Uses {
    enums: Vec<EnumId>,
    statuses: Vec<(CtrlId, StatusId)>,
}

/// `unused` for what a controller declares for itself (vars, hooks, error
/// codes, its `reads`/`writes` lines): decided from its own rows alone,
/// so it runs per controller on the worker threads. Returns what the
/// rows use of the rest of the set.
pub(crate) fn check_unused_in_controller(ir: &Ir, ci: CtrlId, sink: &mut Sink) -> Uses {
    let c = ir.controller(ci);
    let mut uses = Uses::default();
    let mut var_used = vec![false; c.vars.len()];
    let mut hook_used = vec![false; c.hooks.len()];
    let mut error_used = vec![false; c.errors.len()];
    let mut buffer_used = vec![false; ir.buffers.len()];
    // A status field is published every cycle: used even if no row reads it.
    for (v, _) in c.status_fields() {
        var_used[v.index()] = true;
    }
    let mut mark_expr = |e: &crate::ir::Expr| {
        match &e.kind {
            ExprKind::Var(v) => var_used[v.index()] = true,
            ExprKind::Call(h, _) => hook_used[h.index()] = true,
            ExprKind::Buffer(b) | ExprKind::BufferStale(b) => buffer_used[b.index()] = true,
            ExprKind::Variant(en, _) => uses.enums.push(*en),
            _ => {}
        }
        if let (ExprKind::Status(s), Type::Status(owner)) = (&e.kind, &e.ty) {
            uses.statuses.push((*owner, *s));
        }
        // A declared code held as a value (`cause = FAULTED`) is used.
        if let (ExprKind::ErrorCode(code), Type::ErrorCode(owner)) = (&e.kind, &e.ty) {
            let declared =
                usize::from(*code).checked_sub(usize::from(rcs_runtime::ErrorCode::FIRST_CUSTOM));
            if let (true, Some(i)) = (*owner == ci, declared) {
                if let Some(u) = error_used.get_mut(i) {
                    *u = true;
                }
            }
        }
    };
    // Var initialisers name constants only; an error code among them is a use.
    for v in &c.vars {
        if let Some(init) = &v.init {
            init.visit(&mut mark_expr);
        }
    }
    // The rows (conditions and jobs), then the `pre`/`post` jobs.
    for r in c.plans.iter().flat_map(|p| &p.rows) {
        r.visit_exprs(&mut mark_expr);
    }
    for b in c.pre.iter().chain(&c.post) {
        b.visit_exprs(&mut mark_expr);
    }
    let rows = c.plans.iter().flat_map(|p| &p.rows);
    for r in rows.clone() {
        if let Target::Error(Some(e)) = r.to {
            error_used[e.index()] = true;
        }
    }
    let blocks = rows
        .map(|r| &r.jobs)
        .chain(c.pre.iter().chain(&c.post).map(|b| &b.jobs));
    for j in blocks.flatten() {
        match j {
            Job::Assign { place, .. } => match place.root {
                PlaceRoot::Var(v) => var_used[v.index()] = true,
                PlaceRoot::Buffer(b) => buffer_used[b.index()] = true,
            },
            Job::Report { status, error, .. } => {
                uses.statuses.push((ci, *status));
                if let Some(e) = error {
                    error_used[e.index()] = true;
                }
            }
            _ => {}
        }
    }
    let mut report = |what: &str, name: &str, span, help: &str| {
        sink.lint(
            Some(c),
            None,
            Diagnostic::lint(
                Lint::Unused,
                format!("{what} `{name}` of `{}` is never used", c.name),
                span,
                "declared here",
            )
            .with_help(help.to_string()),
        );
    };
    for (v, used) in c.vars.iter().zip(&var_used) {
        if !used {
            report("var", &v.name, v.span, "remove it, or use it in a plan");
        }
    }
    for (h, used) in c.hooks.iter().zip(&hook_used) {
        if !used {
            report("hook", &h.name, h.span, "remove it, or call it from a row");
        }
    }
    for (e, used) in c.errors.iter().zip(&error_used) {
        if !used {
            report(
                "error code",
                &e.name,
                e.span,
                "remove it, or end a row with `-> Error(CODE)`",
            );
        }
    }
    // Hooks see every `reads` buffer through `Data`: with hooks, an
    // unread buffer may be theirs, so only a controller without hooks
    // is told its `reads` buffer is unused.
    let unread = c.reads.iter().filter(|_| c.hooks.is_empty());
    for b in unread.chain(&c.writes) {
        if !buffer_used[b.index()] {
            let name = &ir.buffers[b.index()].name;
            report(
                "buffer",
                name,
                buffer_decl_span(c, *b),
                "remove the `reads`/`writes` line, or use the buffer in a plan",
            );
        }
    }
    uses
}

/// `unused` for what the whole set shares: enums, buffer types, and each
/// controller's statuses (reported by the controller itself, compared by
/// its supervisors), from every controller's [`Uses`].
pub(crate) fn check_unused_declarations(ir: &Ir, uses: &[Uses], sink: &mut Sink) {
    let mut enum_used = vec![false; ir.enums.len()];
    let mut btype_used = vec![false; ir.buffer_types.len()];
    let mark = |t: &Type, enum_used: &mut Vec<bool>, btype_used: &mut Vec<bool>| {
        mentions_type(t, &mut |t| match t {
            Type::Enum(e) => enum_used[e.index()] = true,
            Type::Buffer(b) => btype_used[b.index()] = true,
            _ => {}
        })
    };
    for b in &ir.buffer_types {
        for f in &b.fields {
            mark(&f.ty, &mut enum_used, &mut btype_used);
        }
    }
    for b in &ir.buffers {
        btype_used[b.ty.index()] = true;
    }
    let mut status_used: Vec<Vec<bool>> = ir
        .controllers
        .iter()
        .map(|c| vec![false; c.statuses.len()])
        .collect();
    for (c, u) in ir.controllers.iter().zip(uses) {
        for t in c
            .commands
            .iter()
            .flat_map(|k| &k.params)
            .map(|p| &p.ty)
            .chain(c.vars.iter().map(|v| &v.ty))
            .chain(c.hooks.iter().flat_map(|h| {
                h.params
                    .iter()
                    .map(|p| &p.ty)
                    .chain(std::iter::once(&h.ret))
            }))
        {
            mark(t, &mut enum_used, &mut btype_used);
        }
        for e in &u.enums {
            enum_used[e.index()] = true;
        }
        for (owner, s) in &u.statuses {
            status_used[owner.index()][s.index()] = true;
        }
    }
    for (c, used) in ir.controllers.iter().zip(&status_used) {
        for (s, used) in c.statuses.iter().zip(used).skip(4) {
            if let (false, Some(span)) = (used, s.span) {
                sink.lint(
                    Some(c),
                    None,
                    Diagnostic::lint(
                        Lint::Unused,
                        format!("status `{}` of `{}` is never used", s.name, c.name),
                        span,
                        "declared here",
                    )
                    .with_help("remove it, or `report` it from a row"),
                );
            }
        }
    }
    for (e, used) in ir.enums.iter().zip(&enum_used) {
        if !used {
            sink.lint(
                None,
                None,
                Diagnostic::lint(
                    Lint::Unused,
                    format!("enum `{}` is never used", e.name),
                    e.name_span,
                    "declared here",
                )
                .with_help("remove it, or use it as a field, parameter or var type"),
            );
        }
    }
    for (b, used) in ir.buffer_types.iter().zip(&btype_used) {
        if !used {
            sink.lint(
                None,
                None,
                Diagnostic::lint(
                    Lint::Unused,
                    format!("buffer type `{}` is never used", b.name),
                    b.name_span,
                    "declared here",
                )
                .with_help("remove it, or name it in a `reads` or `writes` line"),
            );
        }
    }
}

/// Where `c` declares buffer `b` (`reads NAME` / `writes NAME`).
fn buffer_decl_span(c: &crate::ir::Controller, b: crate::ir::BufferId) -> crate::source::Span {
    c.buffer_spans
        .iter()
        .find(|(id, _)| *id == b)
        .map_or(c.name_span, |(_, span)| *span)
}
