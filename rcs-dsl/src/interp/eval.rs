//! Expressions on the interpreter: left to right with short-circuit `&&`
//! and `||`, each distinct hook call of a cycle's conditions made once, an
//! index by a run-time value out of range giving the element's zero and
//! the `INDEX_RANGE` hit; arithmetic is `crate::arith`'s, as in the
//! generated code.

use super::{zero, HookData, Hooks, Interpreter};
use crate::arith::truthy;
use crate::ast::BinOp;
use crate::ir::*;
use rcs_runtime::driver::Value;

impl Interpreter<'_> {
    /// Evaluate an expression of this controller (left to right, `&&` and
    /// `||` short-circuit, so hook calls happen in a defined order). While a
    /// cycle's conditions are tried, a hook call already made with the same
    /// arguments gives its earlier result instead of calling again.
    pub fn eval(&mut self, e: &Expr, hooks: &mut dyn Hooks) -> Value {
        match &e.kind {
            ExprKind::Int(v) => Value::Int(*v),
            ExprKind::Float(v) => Value::Float(crate::arith::float_literal(*v, &e.ty)),
            ExprKind::Bool(b) => Value::Bool(*b),
            ExprKind::Variant(_, v) => Value::Enum(*v),
            ExprKind::Status(s) => Value::Status(s.0 as u16),
            ExprKind::ErrorCode(code) => Value::Int(i128::from(*code)),
            ExprKind::NewCommand => Value::Bool(self.bk.new_command()),
            ExprKind::StateCycles => Value::Int(self.bk.state_cycles() as i128),
            ExprKind::PlanCycles => Value::Int(self.bk.plan_cycles() as i128),
            ExprKind::CmdParam(_, p) => self
                .active_params
                .get(p.index())
                .cloned()
                .unwrap_or(Value::Unit),
            // `cmd.P` in `pre`/`post`: the running verb's P, else zero.
            ExprKind::CurrentParam(verbs) => {
                let running = (self.bk.echo_serial() != 0)
                    .then(|| {
                        verbs
                            .iter()
                            .find(|(v, _)| v.index() == usize::from(self.bk.verb()))
                    })
                    .flatten();
                match running.and_then(|(_, p)| self.active_params.get(p.index())) {
                    Some(v) => v.clone(),
                    None => zero(self.ir, &e.ty),
                }
            }
            ExprKind::Var(v) => self.vars[v.index()].clone(),
            ExprKind::Buffer(b) => {
                if let Some(i) = self.ctrl.writes.iter().position(|w| w == b) {
                    self.writes[i].clone()
                } else {
                    let i = self
                        .ctrl
                        .reads
                        .iter()
                        .position(|r| r == b)
                        .expect("a read buffer");
                    self.reads[i].clone()
                }
            }
            ExprKind::Field(base, f) => match self.eval(base, hooks) {
                Value::Buffer(mut fs) => fs.swap_remove(*f as usize),
                other => other,
            },
            ExprKind::Index(base, i) => match self.eval(base, hooks) {
                Value::Array(mut es) => es.swap_remove(*i as usize),
                other => other,
            },
            ExprKind::Call(h, args) => {
                let cached = self.condition_calls.as_ref().and_then(|calls| {
                    calls
                        .iter()
                        .find(|(ch, ca, _)| ch == h && ca == args)
                        .map(|(_, _, v)| v.clone())
                });
                if let Some(v) = cached {
                    return v;
                }
                let values: Vec<Value> = args.iter().map(|a| self.eval(a, hooks)).collect();
                let data = HookData {
                    ctrl: self.ctrl,
                    params: &self.active_params,
                    reads: &self.reads,
                    vars: &self.vars,
                    writes: &self.writes,
                };
                let v = hooks.call(&data, *h, &values);
                if let Some(calls) = &mut self.condition_calls {
                    calls.push((*h, args.clone(), v.clone()));
                }
                v
            }
            ExprKind::BufferStale(b) => {
                let i = self
                    .ctrl
                    .reads
                    .iter()
                    .position(|r| r == b)
                    .expect("a read buffer");
                Value::Int(i128::from(self.read_watch[i].1.stale_cycles()))
            }
            ExprKind::Sub(c, prop) => {
                let i = self.ctrl.subordinate_index(*c).expect("a subordinate");
                let v = self.subs[i].view;
                match prop {
                    SubProp::Status => Value::Status(v.status.0),
                    SubProp::Done => Value::Bool(v.done()),
                    SubProp::Executing => Value::Bool(v.executing()),
                    SubProp::Error => Value::Bool(v.error()),
                    SubProp::StaleCycles => Value::Int(v.stale_cycles as i128),
                    SubProp::ErrorCode => Value::Int(i128::from(v.error.0)),
                }
            }
            ExprKind::Unary(op, x) => {
                let v = self.eval(x, hooks);
                crate::arith::unary(*op, v, &e.ty)
            }
            ExprKind::Cast(x) => {
                let v = self.eval(x, hooks);
                crate::arith::cast(v, &e.ty)
            }
            ExprKind::Binary(op, operands) => {
                let [l, r] = &**operands;
                self.binary(*op, l, r, &e.ty, hooks)
            }
            ExprKind::Builtin(b, args) => {
                let values: Vec<Value> = args.iter().map(|a| self.eval(a, hooks)).collect();
                let ty = args.first().map_or(&e.ty, |a| &a.ty);
                crate::builtin::apply(*b, &values, ty)
            }
            ExprKind::SubField(c, v) => self.sub_field(*c, *v),
            ExprKind::IndexBy(base, i) => {
                let array = self.eval(base, hooks);
                let i = self.eval(i, hooks);
                let Value::Array(mut es) = array else {
                    return array;
                };
                match element_index(&i).filter(|i| *i < es.len()) {
                    Some(i) => es.swap_remove(i),
                    None => {
                        self.bk.index_range();
                        zero(self.ir, &e.ty)
                    }
                }
            }
        }
    }

    fn binary(&mut self, op: BinOp, l: &Expr, r: &Expr, ty: &Type, hooks: &mut dyn Hooks) -> Value {
        match op {
            BinOp::And => {
                return Value::Bool(truthy(&self.eval(l, hooks)) && truthy(&self.eval(r, hooks)))
            }
            BinOp::Or => {
                return Value::Bool(truthy(&self.eval(l, hooks)) || truthy(&self.eval(r, hooks)))
            }
            _ => {}
        }
        let a = self.eval(l, hooks);
        let b = self.eval(r, hooks);
        crate::arith::binary(op, a, b, ty)
    }
}

/// A run-time index as a position, if it is a non-negative integer that
/// fits `usize` (whether it is inside the array is the caller's check).
pub(super) fn element_index(i: &Value) -> Option<usize> {
    match i {
        Value::Int(i) => usize::try_from(*i).ok(),
        _ => None,
    }
}
