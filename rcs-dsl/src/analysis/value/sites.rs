//! Which jobs the value analysis probes at all: those with an operation
//! that can wrap, divide by zero or make a NaN on some value a probe can
//! meet. A cheap filter over the IR, before any run is played — most
//! plans' arithmetic is a counter far from its type's top or a float
//! stepped by a constant, which never goes wrong within a probe — and the
//! probe's hold: a row whose operations read no var needs only a few
//! cycles, one that accumulates needs [`super::HOLD`].

use crate::ast::{AssignOp, BinOp, UnOp};
use crate::ir::{Controller, Expr, ExprKind, Job, PlaceRoot, Type, VarId};

/// Past this many steps from its largest constant, a counter that only
/// ever moves by constants cannot wrap in any run a probe plays (a probe's
/// paths and holds are a few thousand cycles at most).
const FAR: i128 = 1_000_000;

/// The operations of `jobs` that can go wrong: whether there is one, and
/// whether one of them reads a var (a value built up over cycles).
pub(super) fn operations(ctrl: &Controller, jobs: &[Job]) -> (bool, bool) {
    let mut any = false;
    let mut reads_var = false;
    for j in jobs {
        if let Job::Assign {
            place, op, value, ..
        } = j
        {
            if *op != AssignOp::Set && compound_may_go_wrong(ctrl, place.root, &place.ty, value) {
                any = true;
                reads_var |= matches!(place.root, PlaceRoot::Var(_));
            }
        }
    }
    crate::ir::visit_job_exprs(jobs, &mut |e| {
        if may_go_wrong(ctrl, e) {
            any = true;
            let mut var = false;
            e.visit(&mut |x| var |= matches!(x.kind, ExprKind::Var(_)));
            reads_var |= var;
        }
    });
    (any, reads_var)
}

/// `place op= value` (`+=`, `-=`): a float one goes wrong only with a
/// value that is not a finite constant; an integer one unless it is a
/// counter far from wrapping.
fn compound_may_go_wrong(ctrl: &Controller, root: PlaceRoot, ty: &Type, value: &Expr) -> bool {
    match ty {
        Type::Float(_) => !finite_constant(value, false),
        Type::Int(_) => match root {
            PlaceRoot::Var(v) => !far_counter(ctrl, v, ty, 0),
            PlaceRoot::Buffer(_) => true,
        },
        _ => false,
    }
}

/// Whether operation `e` can go wrong on some value.
fn may_go_wrong(ctrl: &Controller, e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Binary(op, operands) => {
            let [l, r] = &**operands;
            match (&e.ty, op) {
                (Type::Int(_), BinOp::Div | BinOp::Rem) => {
                    !matches!(r.kind, ExprKind::Int(d) if d != 0)
                }
                (Type::Int(_), BinOp::Add | BinOp::Sub) => {
                    let sign = if *op == BinOp::Add { 1 } else { -1 };
                    let counter = |x: &Expr, c: &Expr| match (&x.kind, &c.kind) {
                        (ExprKind::Var(v), ExprKind::Int(k)) => {
                            far_counter(ctrl, *v, &e.ty, sign * *k)
                        }
                        _ => false,
                    };
                    !(counter(l, r) || (*op == BinOp::Add && counter(r, l)))
                }
                (Type::Int(_), BinOp::Mul) => true,
                // inf ± a finite constant is inf, never NaN; so is inf
                // times, or divided by, a finite constant other than 0.
                (Type::Float(_), BinOp::Add) => {
                    !(finite_constant(l, false) || finite_constant(r, false))
                }
                (Type::Float(_), BinOp::Sub) => {
                    !finite_constant(r, false) && !finite_constant(l, false)
                }
                (Type::Float(_), BinOp::Mul) => {
                    !(finite_constant(l, true) || finite_constant(r, true))
                }
                (Type::Float(_), BinOp::Div) => !finite_constant(r, true),
                (Type::Float(_), BinOp::Rem) => true,
                _ => false,
            }
        }
        ExprKind::Unary(UnOp::Neg, _) => matches!(e.ty, Type::Int(t) if t.signed()),
        ExprKind::Builtin(..) => matches!(e.ty, Type::Float(_)),
        _ => false,
    }
}

/// A float literal, finite (and not 0 when `nonzero`).
fn finite_constant(e: &Expr, nonzero: bool) -> bool {
    match &e.kind {
        ExprKind::Float(f) => f.is_finite() && (!nonzero || *f != 0.0),
        ExprKind::Int(i) => !nonzero || *i != 0,
        ExprKind::Unary(UnOp::Neg, x) => finite_constant(x, nonzero),
        _ => false,
    }
}

/// Whether var `v` of integer type `ty` only ever holds a constant moved
/// by constant steps (its initialiser and every assignment of the
/// controller: `v = K`, `v += K`, `v = v - K`), so far from its type's
/// bounds — `margin` being a constant added to it (negative: taken from
/// it) — that no probe's run can take it past one.
fn far_counter(ctrl: &Controller, v: VarId, ty: &Type, margin: i128) -> bool {
    let Type::Int(t) = ty else { return false };
    let (lo, hi) = t.range();
    let konst = |e: &Expr| match &e.kind {
        ExprKind::Int(k) => Some(*k),
        ExprKind::Unary(UnOp::Neg, x) => match x.kind {
            ExprKind::Int(k) => Some(-k),
            _ => None,
        },
        _ => None,
    };
    let var = &ctrl.vars[v.index()];
    let first = match &var.init {
        None => 0,
        Some(e) => match konst(e) {
            Some(k) => k,
            None => return false,
        },
    };
    let (mut least, mut most) = (first, first);
    let (mut up, mut down) = (0i128, 0i128);
    let mut stepped = |k: i128| {
        if k > 0 {
            up = up.max(k);
        } else {
            down = down.max(-k);
        }
    };
    let jobs = ctrl
        .plans
        .iter()
        .flat_map(|p| &p.rows)
        .flat_map(|r| &r.jobs)
        .chain(ctrl.every_cycle_jobs());
    for j in jobs {
        let Job::Assign {
            place, op, value, ..
        } = j
        else {
            continue;
        };
        if place.root != PlaceRoot::Var(v) {
            continue;
        }
        if !place.path.is_empty() {
            return false;
        }
        match (op, &value.kind) {
            (AssignOp::Set, ExprKind::Binary(op @ (BinOp::Add | BinOp::Sub), operands)) => {
                let [l, r] = &**operands;
                match (&l.kind, konst(r)) {
                    (ExprKind::Var(u), Some(k)) if *u == v => {
                        stepped(if *op == BinOp::Add { k } else { -k })
                    }
                    _ => return false,
                }
            }
            (AssignOp::Set, _) => match konst(value) {
                Some(k) => {
                    least = least.min(k);
                    most = most.max(k);
                }
                None => return false,
            },
            (op, _) => match konst(value) {
                Some(k) => stepped(if *op == AssignOp::Add { k } else { -k }),
                None => return false,
            },
        }
    }
    // `margin` moves the value towards the top (> 0) or the bottom.
    let far = |room: i128, step: i128| {
        if step == 0 {
            room >= 0
        } else {
            room / step > FAR
        }
    };
    far(hi - most - margin.max(0), up) && far(least - lo + margin.min(0), down)
}
