//! The value analysis's evaluator: one cycle's jobs (`pre`, the fired
//! row's, `post`) performed again on the values a traced run had before
//! that cycle, through the language's one arithmetic ([`crate::arith`]),
//! noting every operation that wraps, divides by zero or makes a NaN out
//! of numbers. What it cannot compute (a hook result, a counter, a
//! subordinate's field, an index by a value in a target) stops it: the
//! cycle is then not judged. The caller compares what it computed with
//! the interpreter's record of the same cycle and trusts it only when they
//! agree, so an event is one the interpreter met.

use crate::analysis::path::at_path;
use crate::analysis::terms::{as_leaf, Leaf};
use crate::arith;
use crate::ast::{AssignOp, BinOp, UnOp};
use crate::ir::{Controller, Expr, ExprKind, Job, Place, PlaceRoot, Projection, Type};
use crate::source::Span;
use rcs_runtime::driver::Value;

/// What went wrong in one operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// An integer `+`, `-`, `*` or negation left its type's range.
    Wrap,
    /// An integer `/` or `%` by 0 (which gives 0).
    DivZero,
    /// A float operation made NaN out of operands that were not.
    Nan,
}

/// One operation that went wrong, with its operands as computed.
#[derive(Clone, Debug)]
pub struct Event {
    pub kind: Kind,
    /// The operation (for `x += e`, the whole job).
    pub span: Span,
    /// `250 + 10 gives 4`.
    pub text: String,
}

/// Where a job is: in `pre`, in the fired row, or in `post`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    Pre,
    Row(usize),
    Post,
}

/// A job in which an event happened.
#[derive(Clone, Debug)]
pub struct Hit {
    pub unit: Unit,
    pub job: usize,
    pub events: Vec<Event>,
    /// The value the job assigned (an assignment), if any.
    pub assigned: Option<Value>,
}

/// The values a cycle starts from: vars and `writes` as the previous
/// cycle left them, `reads` and the parameters as the run holds them.
pub struct Env<'a> {
    pub ctrl: &'a Controller,
    pub vars: Vec<Value>,
    pub writes: Vec<Value>,
    pub reads: &'a [Value],
    pub params: &'a [Value],
}

impl Env<'_> {
    fn leaf(&self, leaf: &Leaf) -> Option<Value> {
        match leaf {
            Leaf::Var(v, steps) => at_path(self.vars.get(v.index())?, steps),
            Leaf::Param(p, steps) => at_path(self.params.get(p.index())?, steps),
            Leaf::Buffer(b, steps) => {
                if let Some(i) = self.ctrl.reads.iter().position(|r| r == b) {
                    at_path(self.reads.get(i)?, steps)
                } else {
                    let i = self.ctrl.writes.iter().position(|w| w == b)?;
                    at_path(self.writes.get(i)?, steps)
                }
            }
            _ => None,
        }
    }

    /// The slot a place without run-time indices names.
    fn slot(&mut self, p: &Place) -> Option<&mut Value> {
        let mut slot = match p.root {
            PlaceRoot::Var(v) => self.vars.get_mut(v.index())?,
            PlaceRoot::Buffer(b) => {
                let i = self.ctrl.writes.iter().position(|w| *w == b)?;
                self.writes.get_mut(i)?
            }
        };
        for proj in &p.path {
            slot = match (proj, slot) {
                (Projection::Field(i), Value::Buffer(xs))
                | (Projection::Index(i), Value::Array(xs)) => xs.get_mut(*i as usize)?,
                _ => return None,
            };
        }
        Some(slot)
    }
}

/// Perform `jobs` on `env`, noting the jobs where something went wrong;
/// `false` when a job could not be followed (the cycle is then not judged).
pub fn perform(jobs: &[Job], unit: Unit, env: &mut Env, hits: &mut Vec<Hit>) -> bool {
    for (k, j) in jobs.iter().enumerate() {
        let mut events = Vec::new();
        let mut assigned = None;
        match j {
            Job::Assign {
                place,
                op,
                value,
                span,
            } => {
                if !place.indices.is_empty() {
                    return false;
                }
                let Some(v) = probe(value, env, &mut events) else {
                    return false;
                };
                let new = match op {
                    AssignOp::Set => v,
                    AssignOp::Add | AssignOp::Sub => {
                        let Some(old) = env.slot(place).map(|s| s.clone()) else {
                            return false;
                        };
                        let bin = if *op == AssignOp::Add {
                            BinOp::Add
                        } else {
                            BinOp::Sub
                        };
                        operate(bin, old, v, &place.ty, *span, &mut events)
                    }
                };
                let Some(slot) = env.slot(place) else {
                    return false;
                };
                *slot = new.clone();
                assigned = Some(new);
            }
            Job::Send { args, .. } => {
                for a in args {
                    if probe(a, env, &mut events).is_none() {
                        return false;
                    }
                }
            }
            // A hook sees the data read-only: only its arguments matter,
            // and none of them is a sink.
            Job::Call(_) | Job::Report { .. } | Job::Forward { .. } => {}
        }
        if !events.is_empty() {
            hits.push(Hit {
                unit,
                job: k,
                events,
                assigned,
            });
        }
    }
    true
}

/// The value of `e`, noting what goes wrong on the way; `None` when it
/// reads what the evaluator does not know.
pub fn probe(e: &Expr, env: &Env, events: &mut Vec<Event>) -> Option<Value> {
    if let Some(l) = as_leaf(e) {
        return match l {
            Leaf::Var(..) | Leaf::Param(..) | Leaf::Buffer(..) => env.leaf(&l),
            _ => None,
        };
    }
    Some(match &e.kind {
        ExprKind::Int(v) => Value::Int(*v),
        ExprKind::Float(v) => Value::Float(arith::float_literal(*v, &e.ty)),
        ExprKind::Bool(b) => Value::Bool(*b),
        ExprKind::Variant(_, v) => Value::Enum(*v),
        ExprKind::Field(base, f) => match probe(base, env, events)? {
            Value::Buffer(mut fs) if (*f as usize) < fs.len() => fs.swap_remove(*f as usize),
            _ => return None,
        },
        ExprKind::Index(base, i) => match probe(base, env, events)? {
            Value::Array(mut es) if (*i as usize) < es.len() => es.swap_remove(*i as usize),
            _ => return None,
        },
        ExprKind::Unary(UnOp::Neg, x) => {
            let v = probe(x, env, events)?;
            let out = arith::unary(UnOp::Neg, v.clone(), &e.ty);
            if let (Value::Int(a), Value::Int(r)) = (&v, &out) {
                if -*a != *r {
                    events.push(Event {
                        kind: Kind::Wrap,
                        span: e.span,
                        text: format!("-({a}) gives {r}"),
                    });
                }
            }
            out
        }
        ExprKind::Unary(op, x) => arith::unary(*op, probe(x, env, events)?, &e.ty),
        ExprKind::Cast(x) => arith::cast(probe(x, env, events)?, &e.ty),
        ExprKind::Binary(op @ (BinOp::And | BinOp::Or), operands) => {
            // Short-circuit, as the interpreter: the right operand's
            // events happen only when it is evaluated.
            let [l, r] = &**operands;
            let a = arith::truthy(&probe(l, env, events)?);
            if (*op == BinOp::And) != a {
                Value::Bool(a)
            } else {
                Value::Bool(arith::truthy(&probe(r, env, events)?))
            }
        }
        ExprKind::Binary(op, operands) => {
            let [l, r] = &**operands;
            let a = probe(l, env, events)?;
            let b = probe(r, env, events)?;
            operate(*op, a, b, &e.ty, e.span, events)
        }
        ExprKind::Builtin(b, args) => {
            let values = args
                .iter()
                .map(|a| probe(a, env, events))
                .collect::<Option<Vec<Value>>>()?;
            let ty = args.first().map_or(&e.ty, |a| &a.ty);
            let out = crate::builtin::apply(*b, &values, ty);
            let nan_in = values
                .iter()
                .any(|v| matches!(v, Value::Float(f) if !f.is_finite()));
            if matches!(out, Value::Float(f) if f.is_nan()) && !nan_in {
                events.push(Event {
                    kind: Kind::Nan,
                    span: e.span,
                    text: format!("{}({}) gives NaN", b.name(), list(&values)),
                });
            }
            out
        }
        _ => return None,
    })
}

/// `a op b` of type `ty`, noting a wrap, a zero divisor or a NaN made.
fn operate(op: BinOp, a: Value, b: Value, ty: &Type, span: Span, events: &mut Vec<Event>) -> Value {
    let out = arith::binary(op, a.clone(), b.clone(), ty);
    let sign = match op {
        BinOp::Add => "+",
        BinOp::Sub => "-",
        BinOp::Mul => "*",
        BinOp::Div => "/",
        BinOp::Rem => "%",
        _ => return out,
    };
    let text = || format!("{} {sign} {} gives {}", show(&a), show(&b), show(&out));
    match (&a, &b, &out) {
        (Value::Int(x), Value::Int(y), Value::Int(r)) => {
            let wide = match op {
                BinOp::Add => x.checked_add(*y),
                BinOp::Sub => x.checked_sub(*y),
                BinOp::Mul => x.checked_mul(*y),
                _ => Some(*r),
            };
            if wide != Some(*r) {
                events.push(Event {
                    kind: Kind::Wrap,
                    span,
                    text: text(),
                });
            }
            if matches!(op, BinOp::Div | BinOp::Rem) && *y == 0 {
                events.push(Event {
                    kind: Kind::DivZero,
                    span,
                    text: text(),
                });
            }
        }
        (Value::Float(x), Value::Float(y), Value::Float(r))
            if r.is_nan() && !x.is_nan() && !y.is_nan() =>
        {
            events.push(Event {
                kind: Kind::Nan,
                span,
                text: text(),
            });
        }
        _ => {}
    }
    out
}

/// A value as the language writes a number.
pub fn show(v: &Value) -> String {
    match v {
        Value::Int(i) => i.to_string(),
        Value::Float(f) if f.is_nan() => "NaN".into(),
        Value::Float(f) if f.is_infinite() => if *f > 0.0 { "inf" } else { "-inf" }.into(),
        Value::Float(f) => crate::pretty::float(*f),
        Value::Bool(b) => b.to_string(),
        other => format!("{other:?}"),
    }
}

fn list(values: &[Value]) -> String {
    values.iter().map(show).collect::<Vec<_>>().join(", ")
}

/// Whether two values are the same, NaN the same as NaN (the record of a
/// cycle and the evaluator's values are compared with it).
pub fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float(x), Value::Float(y)) => {
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())
        }
        (Value::Buffer(xs), Value::Buffer(ys)) | (Value::Array(xs), Value::Array(ys)) => {
            xs.len() == ys.len() && xs.iter().zip(ys).all(|(x, y)| same(x, y))
        }
        (a, b) => a == b,
    }
}
