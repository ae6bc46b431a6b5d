//! Stage 2, the expression checker: unary and binary operators, where the
//! two operands fix each other's literal and variant types.

use super::*;
use crate::ast::{self, BinOp, UnOp};
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::*;
use crate::source::Span;

impl Cx<'_, '_> {
    pub(in crate::lower) fn unary(
        &mut self,
        op: UnOp,
        inner: &ast::Expr,
        span: Span,
    ) -> (Expr, Ty) {
        let (x, t) = self.infer(inner, None);
        let ok = match (op, &t) {
            (_, Ty::Err) => return (err_expr(span), Ty::Err),
            (UnOp::Not, Ty::Known(Type::Bool)) => true,
            // Bitwise not on integers, as in Rust (§8).
            (UnOp::Not, Ty::IntLit | Ty::Known(Type::Int(_))) => true,
            (UnOp::Neg, Ty::IntLit | Ty::FloatLit | Ty::Known(Type::Float(_))) => true,
            (UnOp::Neg, Ty::Known(Type::Int(it))) => it.signed(),
            _ => false,
        };
        if !ok {
            let (sym, want) = if op == UnOp::Not {
                ("!", "`bool` or an integer")
            } else {
                ("-", "a signed number")
            };
            let t = self.ty_name(&t);
            self.mismatch(
                span,
                format!("cannot apply `{sym}` to {t}"),
                format!("expected {want}"),
            );
            return (err_expr(span), Ty::Err);
        }
        // Fold `-literal` so that `-128` fits an `i8`.
        if op == UnOp::Neg {
            match x.kind {
                ExprKind::Int(v) => {
                    // A typed constant (`-C`) wraps like any value of its type.
                    let v = match &t {
                        Ty::Known(Type::Int(it)) => crate::arith::wrap(-v, *it),
                        _ => -v,
                    };
                    return (
                        Expr {
                            kind: ExprKind::Int(v),
                            ty: x.ty,
                            span,
                        },
                        t,
                    );
                }
                ExprKind::Float(v) => {
                    return (
                        Expr {
                            kind: ExprKind::Float(-v),
                            ty: x.ty,
                            span,
                        },
                        t,
                    )
                }
                _ => {}
            }
        }
        let ty = x.ty.clone();
        (
            Expr {
                kind: ExprKind::Unary(op, Box::new(x)),
                ty,
                span,
            },
            t,
        )
    }

    pub(in crate::lower) fn binary(
        &mut self,
        op: BinOp,
        l: &ast::Expr,
        r: &ast::Expr,
        span: Span,
    ) -> (Expr, Ty) {
        if op.is_comparison()
            && (super::super::time::mentions_time(self, l)
                || super::super::time::mentions_time(self, r))
        {
            return self.time_comparison(op, l, r, span);
        }
        match op {
            BinOp::Shl | BinOp::Shr => self.shift(op, l, r, span),
            BinOp::And | BinOp::Or => {
                let a = self.check(l, &Type::Bool);
                let b = self.check(r, &Type::Bool);
                (
                    Expr {
                        kind: ExprKind::binary(op, a, b),
                        ty: Type::Bool,
                        span,
                    },
                    Ty::Known(Type::Bool),
                )
            }
            _ => {
                // Let a bare variant on the left take its type from the right.
                let left_first = !self.is_bare_unknown(l);
                let (mut a, mut ta, mut b, mut tb);
                if left_first {
                    (a, ta) = self.infer(l, None);
                    (b, tb) = self.infer_beside(r, &ta);
                } else {
                    (b, tb) = self.infer(r, None);
                    (a, ta) = self.infer_beside(l, &tb);
                }
                let Some(t) = unify(&ta, &tb) else {
                    let (na, nb) = (self.ty_name(&ta), self.ty_name(&tb));
                    self.diags.push(
                        Diagnostic::error(
                            Code::TypeMismatch,
                            format!("cannot apply `{}` to {na} and {nb}", op.symbol()),
                            span,
                            "mismatched operand types",
                        )
                        .with_secondary(l.span, na.clone())
                        .with_secondary(r.span, nb.clone()),
                    );
                    let numeric = |t: &Ty| {
                        matches!(
                            t,
                            Ty::IntLit | Ty::FloatLit | Ty::Known(Type::Int(_) | Type::Float(_))
                        )
                    };
                    let status = |t: &Ty| matches!(t, Ty::Known(Type::Status(_)));
                    if numeric(&ta) && numeric(&tb) {
                        self.help_last(
                            "no implicit conversions: use `as` to convert between numeric types",
                        );
                    } else if status(&ta) && status(&tb) {
                        self.help_last("each controller has its own statuses: compare each one with a status name, as in `X.status == DONE`");
                    } else if [&ta, &tb]
                        .iter()
                        .any(|t| matches!(t, Ty::Known(Type::ErrorCode(_))))
                    {
                        self.help_last("an error code is one of a controller's error names, not a number: compare with a name, as in `X.error_code == FAULTED`");
                    }
                    return (err_expr(span), Ty::Err);
                };
                if t == Ty::Err {
                    return (err_expr(span), Ty::Err);
                }
                if let Ty::Known(k) = &t {
                    self.fix_literals(&mut a, k);
                    self.fix_literals(&mut b, k);
                    ta = t.clone();
                    tb = t.clone();
                }
                let _ = (&ta, &tb);
                let allowed = match op {
                    BinOp::Eq | BinOp::Ne => {
                        !matches!(t, Ty::Known(Type::Buffer(_) | Type::Array(..) | Type::Unit))
                    }
                    _ if is_bit_logic(op) => matches!(t, Ty::IntLit | Ty::Known(Type::Int(_))),
                    _ => matches!(
                        t,
                        Ty::IntLit | Ty::FloatLit | Ty::Known(Type::Int(_) | Type::Float(_))
                    ),
                };
                if !allowed {
                    let n = self.ty_name(&t);
                    let what = match op {
                        BinOp::Eq | BinOp::Ne => "compared",
                        BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => "ordered",
                        _ if is_bit_logic(op) => "combined bit by bit (integers only)",
                        _ => "used in arithmetic",
                    };
                    self.mismatch(
                        span,
                        format!("values of {n} cannot be {what} with `{}`", op.symbol()),
                        format!("{n} here"),
                    );
                    return (err_expr(span), Ty::Err);
                }
                if is_arith(op) || is_bit_logic(op) {
                    let ty = known(&t).unwrap_or(a.ty.clone());
                    (
                        Expr {
                            kind: ExprKind::binary(op, a, b),
                            ty,
                            span,
                        },
                        t,
                    )
                } else {
                    // A comparison of two literals: give them their defaults
                    // (with a known type, both sides were settled above).
                    if matches!(t, Ty::IntLit | Ty::FloatLit) {
                        let settled = self.settle(&mut a, &t);
                        if let Ty::Known(k) = &settled {
                            self.fix_literals(&mut b, k);
                        }
                    }
                    (
                        Expr {
                            kind: ExprKind::binary(op, a, b),
                            ty: Type::Bool,
                            span,
                        },
                        Ty::Known(Type::Bool),
                    )
                }
            }
        }
    }

    /// `a << n`, `a >> n`: `a` an integer, whose type the result has; `n`
    /// an integer of any type (a literal amount is a `u32`, as in Rust).
    fn shift(&mut self, op: BinOp, l: &ast::Expr, r: &ast::Expr, span: Span) -> (Expr, Ty) {
        let (a, ta) = self.infer(l, None);
        let (mut b, tb) = self.infer(r, None);
        if matches!(ta, Ty::Err) || matches!(tb, Ty::Err) {
            return (err_expr(span), Ty::Err);
        }
        let int = |t: &Ty| matches!(t, Ty::IntLit | Ty::Known(Type::Int(_)));
        for (t, side) in [(&ta, l.span), (&tb, r.span)] {
            if !int(t) {
                let n = self.ty_name(t);
                self.mismatch(
                    side,
                    format!("`{}` shifts integers; this is {n}", op.symbol()),
                    format!("{n} here"),
                );
                return (err_expr(span), Ty::Err);
            }
        }
        if tb == Ty::IntLit {
            self.fix_literals(&mut b, &Type::Int(crate::ir::IntTy::U32));
        }
        let ty = known(&ta).unwrap_or(a.ty.clone());
        (
            Expr {
                kind: ExprKind::binary(op, a, b),
                ty,
                span,
            },
            ta,
        )
    }

    /// Infer an operand whose expected type is unknown because of an error
    /// already reported: a bare name that is no value here (most likely a
    /// variant or status) then gets the error type instead of a second report.
    pub(in crate::lower) fn infer_untyped(&mut self, e: &ast::Expr) -> (Expr, Ty) {
        if self.is_bare_unknown(e) {
            return (err_expr(e.span), Ty::Err);
        }
        self.infer(e, None)
    }

    /// Infer the operand beside one of type `other` (the other side of `==`).
    pub(in crate::lower) fn infer_beside(&mut self, e: &ast::Expr, other: &Ty) -> (Expr, Ty) {
        match other {
            Ty::Err => self.infer_untyped(e),
            t => self.infer(e, known(t).as_ref()),
        }
    }

    /// A bare name that is not a value here (probably a variant or status).
    pub(in crate::lower) fn is_bare_unknown(&self, e: &ast::Expr) -> bool {
        match &e.kind {
            ast::ExprKind::Paren(i) => self.is_bare_unknown(i),
            ast::ExprKind::Path(None, n) => self.value(&n.text).is_none(),
            _ => false,
        }
    }

    // ------------------------------------------------------------ plans
}
