//! An atom's value on concrete leaf values, through the language's one
//! arithmetic ([`crate::arith`]), as the interpreter and the generated code
//! compute it. An index by a value outside its array gives no value (the
//! plan ends with `INDEX_RANGE` there instead).

use super::terms::{as_leaf, Leaf};
use crate::arith;
use crate::ir::{Expr, ExprKind, StatusId, SubProp};
use rcs_runtime::driver::Value;

/// The value of `e` when every leaf it reads has a value in `leaf`; `None`
/// when one has none.
pub fn eval(e: &Expr, leaf: &dyn Fn(&Leaf) -> Option<Value>) -> Option<Value> {
    if let Some(l) = as_leaf(e) {
        let v = leaf(&l)?;
        return Some(match (&e.kind, v) {
            (ExprKind::Sub(_, SubProp::Done), Value::Status(s)) => {
                Value::Bool(s == StatusId::DONE.0 as u16)
            }
            (ExprKind::Sub(_, SubProp::Executing), Value::Status(s)) => {
                Value::Bool(s == StatusId::EXECUTING.0 as u16)
            }
            (ExprKind::Sub(_, SubProp::Error), Value::Status(s)) => {
                Value::Bool(s == StatusId::ERROR.0 as u16)
            }
            (_, v) => v,
        });
    }
    Some(match &e.kind {
        ExprKind::Int(v) => Value::Int(*v),
        ExprKind::Float(v) => Value::Float(arith::float_literal(*v, &e.ty)),
        ExprKind::Bool(b) => Value::Bool(*b),
        ExprKind::Variant(_, v) => Value::Enum(*v),
        ExprKind::Status(s) => Value::Status(s.0 as u16),
        ExprKind::Field(base, f) => match eval(base, leaf)? {
            Value::Buffer(mut fs) => fs.swap_remove(*f as usize),
            other => other,
        },
        ExprKind::Index(base, i) => match eval(base, leaf)? {
            Value::Array(mut es) => es.swap_remove(*i as usize),
            other => other,
        },
        ExprKind::Unary(op, x) => arith::unary(*op, eval(x, leaf)?, &e.ty),
        ExprKind::Cast(x) => arith::cast(eval(x, leaf)?, &e.ty),
        ExprKind::Binary(op, operands) => {
            let [l, r] = &**operands;
            arith::binary(*op, eval(l, leaf)?, eval(r, leaf)?, &e.ty)
        }
        ExprKind::Builtin(b, args) => {
            let values = args
                .iter()
                .map(|a| eval(a, leaf))
                .collect::<Option<Vec<Value>>>()?;
            let ty = args.first().map_or(&e.ty, |a| &a.ty);
            crate::builtin::apply(*b, &values, ty)
        }
        // Out of range, the interpreter ends the plan with INDEX_RANGE: no
        // value, so a condition that meets it is neither true nor false.
        ExprKind::IndexBy(base, i) => {
            let Value::Array(mut es) = eval(base, leaf)? else {
                return None;
            };
            let i = match eval(i, leaf)? {
                Value::Int(i) => usize::try_from(i).ok().filter(|i| *i < es.len())?,
                _ => return None,
            };
            es.swap_remove(i)
        }
        // Every other kind is a leaf (handled above).
        _ => return None,
    })
}
