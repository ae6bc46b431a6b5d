//! Step 4's (and 3b/4b's) jobs on the interpreter: assignments into vars
//! and `writes` buffers (through places, with run-time indices), sends,
//! reports, hook calls and forwards, each stopped by an index out of range.

use super::eval::element_index;
use super::{round, wrap, Hooks, Interpreter, Sent};
use crate::ast::AssignOp;
use crate::ir::*;
use rcs_runtime::driver::Value;
use rcs_runtime::{ErrorCode, Status};

impl Interpreter<'_> {
    /// Jobs in order, up to an index out of range.
    pub(super) fn jobs(&mut self, jobs: &[Job], hooks: &mut dyn Hooks, sent: &mut Vec<Sent>) {
        for j in jobs {
            if self.bk.index_range_hit() {
                return;
            }
            self.job(j, hooks, sent);
        }
    }

    /// One job. An index out of range met while evaluating it leaves the
    /// job undone (no assignment, no send); a hook called on the way was
    /// still called.
    fn job(&mut self, j: &Job, hooks: &mut dyn Hooks, sent: &mut Vec<Sent>) {
        match j {
            Job::Assign {
                place, op, value, ..
            } => {
                let v = self.eval(value, hooks);
                let indices: Vec<Value> =
                    place.indices.iter().map(|i| self.eval(i, hooks)).collect();
                if self.bk.index_range_hit() {
                    return;
                }
                let Some(slot) = self.place_mut(place, &indices) else {
                    self.bk.index_range();
                    return;
                };
                let new = match (op, &place.ty) {
                    (AssignOp::Set, _) => v,
                    (_, Type::Int(t)) => {
                        let (Value::Int(a), Value::Int(b)) = (&*slot, &v) else {
                            return;
                        };
                        Value::Int(wrap(
                            if *op == AssignOp::Add {
                                a.wrapping_add(*b)
                            } else {
                                a.wrapping_sub(*b)
                            },
                            *t,
                        ))
                    }
                    (_, Type::Float(t)) => {
                        let (Value::Float(a), Value::Float(b)) = (&*slot, &v) else {
                            return;
                        };
                        Value::Float(round(if *op == AssignOp::Add { a + b } else { a - b }, *t))
                    }
                    _ => v,
                };
                if let Some(slot) = self.place_mut(place, &indices) {
                    *slot = new;
                }
            }
            Job::Send {
                sub, command, args, ..
            } => {
                let args: Vec<Value> = args.iter().map(|a| self.eval(a, hooks)).collect();
                if !self.bk.index_range_hit() {
                    self.send(*sub, *command, args, sent);
                }
            }
            Job::Report {
                error: Some(code), ..
            } => self.bk.report_error(ErrorCode::custom(code.0 as u16)),
            Job::Report {
                error_of: Some(v), ..
            } => self
                .bk
                .report_error(crate::interp::error_code(&self.vars[v.index()])),
            Job::Report { status, .. } => self.bk.report(Status(status.0 as u16)),
            Job::Call(e) => {
                self.eval(e, hooks);
            }
            Job::Forward { sub, .. } => {
                if let Some((command, args)) = self.forwarded(j) {
                    self.send(*sub, command, args, sent);
                }
            }
        }
    }

    /// The slot of place `p` whose run-time indices evaluated to `indices`;
    /// `None` if one is out of range.
    fn place_mut(&mut self, p: &Place, indices: &[Value]) -> Option<&mut Value> {
        let mut slot = match p.root {
            PlaceRoot::Var(v) => &mut self.vars[v.index()],
            PlaceRoot::Buffer(b) => {
                let i = self
                    .ctrl
                    .writes
                    .iter()
                    .position(|w| *w == b)
                    .expect("a written buffer");
                &mut self.writes[i]
            }
        };
        for proj in &p.path {
            slot = match (proj, slot) {
                (Projection::Field(f), Value::Buffer(fs)) => &mut fs[*f as usize],
                (Projection::Index(i), Value::Array(es)) => &mut es[*i as usize],
                (Projection::IndexBy(k), Value::Array(es)) => {
                    es.get_mut(element_index(indices.get(*k as usize)?)?)?
                }
                (_, other) => return Some(other),
            };
        }
        Some(slot)
    }
}
