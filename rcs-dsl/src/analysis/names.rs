//! Stage 3a: how the analysis shows its leaves and values to a reader —
//! `cmd.n`, `TB.status`, `ship.rpm[1]`, `Dir::Ahead` — in witnesses and
//! notes, as the language writes them.

use super::terms::{self, Leaf};
use super::PlanAnalysis;
use crate::ir::Type;
use rcs_runtime::driver::Value;

impl<'ir> PlanAnalysis<'ir> {
    /// A leaf as the language writes it.
    pub fn leaf_name(&self, leaf: &Leaf) -> String {
        use crate::ir::{Expr, ExprKind, SubProp};
        let printer = crate::pretty::Printer::new(self.ir, self.ctrl, Some(self.plan));
        let sub = |c: crate::ir::CtrlId| self.ir.controller(c).name.clone();
        match leaf {
            Leaf::NewCommand => "new_command".into(),
            Leaf::StateCycles => "state_cycles".into(),
            Leaf::PlanCycles => "plan_cycles".into(),
            Leaf::SubStatus(c) => format!("{}.status", sub(*c)),
            Leaf::SubStale(c) => format!("{}.{}", sub(*c), SubProp::StaleCycles.name()),
            Leaf::SubErrorCode(c) => format!("{}.{}", sub(*c), SubProp::ErrorCode.name()),
            Leaf::BufStale(b) => format!("{}.stale_cycles", self.ir.buffers[b.index()].name),
            Leaf::Call(h, args) => printer.expr(&Expr {
                kind: ExprKind::Call(*h, args.clone()),
                ty: self.ctrl.hooks[h.index()].ret.clone(),
                span: self.plan.span,
            }),
            Leaf::Param(p, steps) => {
                let param = &self.ctrl.commands[self.plan.verb.index()].params[p.index()];
                self.path(format!("cmd.{}", param.name), &param.ty, steps)
            }
            Leaf::Var(v, steps) => {
                let var = &self.ctrl.vars[v.index()];
                self.path(var.name.clone(), &var.ty, steps)
            }
            Leaf::SubField(c, v, steps) => {
                let var = &self.ir.controller(*c).vars[v.index()];
                self.path(format!("{}.{}", sub(*c), var.name), &var.ty, steps)
            }
            Leaf::Buffer(b, steps) => {
                let buf = &self.ir.buffers[b.index()];
                let fields = &self.ir.buffer_types[buf.ty.index()].fields;
                // The first step is a field of the buffer's type.
                match steps.split_first() {
                    Some((terms::Step::Field(f), rest)) => {
                        let field = &fields[*f as usize];
                        self.path(format!("{}.{}", buf.name, field.name), &field.ty, rest)
                    }
                    _ => buf.name.clone(),
                }
            }
        }
    }

    fn path(&self, mut name: String, mut ty: &'ir Type, steps: &[terms::Step]) -> String {
        for s in steps {
            match (s, ty) {
                (terms::Step::Field(f), Type::Buffer(b)) => {
                    let field = &self.ir.buffer_types[b.index()].fields[*f as usize];
                    name.push('.');
                    name.push_str(&field.name);
                    ty = &field.ty;
                }
                (terms::Step::Index(i), Type::Array(e, _)) => {
                    name.push_str(&format!("[{i}]"));
                    ty = e;
                }
                _ => {}
            }
        }
        name
    }

    /// A value as the language writes it.
    pub fn value_text(&self, ty: &Type, v: &Value) -> String {
        match (ty, v) {
            (Type::ErrorCode(c), Value::Int(n)) => crate::error_codes::name_of(
                self.ir.controller(*c),
                rcs_runtime::ErrorCode(u16::try_from(*n).unwrap_or(u16::MAX)),
            ),
            (_, Value::Bool(b)) => b.to_string(),
            (_, Value::Int(i)) => i.to_string(),
            (_, Value::Float(f)) if f.is_nan() => "NaN".into(),
            (_, Value::Float(f)) if f.is_infinite() => if *f > 0.0 { "inf" } else { "-inf" }.into(),
            (_, Value::Float(f)) => crate::pretty::float(*f),
            (Type::Array(e, _), Value::Array(xs)) => {
                let xs: Vec<String> = xs.iter().map(|x| self.value_text(e, x)).collect();
                format!("[{}]", xs.join(", "))
            }
            (Type::Enum(e), Value::Enum(i)) => {
                let def = &self.ir.enums[e.index()];
                let variant = def
                    .variants
                    .get(*i as usize)
                    .map_or("?", |v| v.name.as_str());
                format!("{}::{variant}", def.name)
            }
            (Type::Status(c), Value::Status(s)) => self
                .ir
                .controller(*c)
                .statuses
                .get(*s as usize)
                .map_or_else(|| format!("?{s}"), |d| d.name.clone()),
            (_, v) => format!("{v:?}"),
        }
    }
}
