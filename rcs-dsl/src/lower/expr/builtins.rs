//! Stage 2, the expression checker: calls of built-in functions (their
//! arguments share one type, fixed like an operator's operands) and names
//! of constants (replaced by their folded value, see `lower::consts`).

use super::*;
use crate::ast;
use crate::builtin::{Builtin, Signature};
use crate::ir::*;
use crate::lower::consts::{arguments, arity, Const};
use crate::source::Span;
use rcs_runtime::driver::Value as RtValue;

impl Cx<'_, '_> {
    /// A constant, as the literal of its value.
    pub(in crate::lower) fn constant(&mut self, c: &Const, span: Span) -> (Expr, Ty) {
        let kind = match (&c.value, &c.ty) {
            (RtValue::Int(v), _) => ExprKind::Int(*v),
            (RtValue::Float(v), _) => ExprKind::Float(*v),
            (RtValue::Bool(b), _) => ExprKind::Bool(*b),
            (RtValue::Enum(v), Type::Enum(e)) => ExprKind::Variant(*e, *v),
            _ => return (err_expr(span), Ty::Err),
        };
        (
            Expr {
                kind,
                ty: c.ty.clone(),
                span,
            },
            Ty::Known(c.ty.clone()),
        )
    }

    /// `b(args)`: arguments of one type (numeric, or float for the float
    /// functions); literals take the type of a typed argument, else of the
    /// context, else `i64`/`f64`.
    pub(in crate::lower) fn builtin(
        &mut self,
        b: Builtin,
        args: &[ast::Expr],
        hint: Option<&Type>,
        span: Span,
    ) -> (Expr, Ty) {
        if args.len() != b.arity() {
            self.diags.push(arity(b, args.len(), span));
            for a in args {
                self.infer_untyped(a);
            }
            return (err_expr(span), Ty::Err);
        }
        let mut out = Vec::new();
        let mut tys = Vec::new();
        for a in args {
            let (e, t) = self.infer(a, None);
            out.push(e);
            tys.push(t);
        }
        if tys.contains(&Ty::Err) {
            return (err_expr(span), Ty::Err);
        }
        let mut common = Some(tys[0].clone());
        for t in &tys[1..] {
            common = common.and_then(|c| unify(&c, t));
        }
        let float_only = b.signature() != Signature::Numeric;
        let ty = match common {
            Some(Ty::Known(t)) => Some(t),
            Some(Ty::IntLit) if !float_only => Some(match hint {
                Some(t @ (Type::Int(_) | Type::Float(_))) => t.clone(),
                _ => Type::Int(IntTy::I64),
            }),
            Some(Ty::IntLit | Ty::FloatLit) => Some(match hint {
                Some(t @ Type::Float(_)) => t.clone(),
                Some(t @ Type::Int(_)) if !float_only => t.clone(),
                _ => Type::Float(FloatTy::F64),
            }),
            _ => None,
        };
        let ok = match &ty {
            Some(Type::Float(_)) => true,
            Some(Type::Int(_)) => !float_only,
            _ => false,
        };
        let Some(ty) = ty.filter(|_| ok) else {
            let found: Vec<String> = tys.iter().map(|t| self.ty_name(t)).collect();
            self.diags.push(arguments(b, &found, span));
            return (err_expr(span), Ty::Err);
        };
        for (e, t) in out.iter_mut().zip(&tys) {
            if unify(t, &Ty::Known(ty.clone())).is_none() {
                let found: Vec<String> = tys.iter().map(|t| self.ty_name(t)).collect();
                self.diags.push(arguments(b, &found, span));
                return (err_expr(span), Ty::Err);
            }
            self.fix_literals(e, &ty);
        }
        let result = if b == Builtin::IsNan { Type::Bool } else { ty };
        (
            Expr {
                kind: ExprKind::Builtin(b, out),
                ty: result.clone(),
                span,
            },
            Ty::Known(result),
        )
    }
}
