//! IR → `.rcs` text: conditions, jobs and targets printed back in the
//! language's own syntax, with only the parentheses precedence needs. Used
//! by the state graphs, the state tables, generated comments and traces.

use crate::ast::{AssignOp, UnOp};
use crate::ir::*;

/// Printing context: the controller the expression lives in (and its plan).
pub struct Printer<'a> {
    pub ir: &'a Ir,
    pub ctrl: &'a Controller,
    pub plan: Option<&'a Plan>,
}

const UNARY: u8 = 10;
const CAST: u8 = 11;
const ATOM: u8 = 12;

impl<'a> Printer<'a> {
    pub fn new(ir: &'a Ir, ctrl: &'a Controller, plan: Option<&'a Plan>) -> Self {
        Printer { ir, ctrl, plan }
    }

    pub fn expr(&self, e: &Expr) -> String {
        let mut s = String::new();
        self.write(e, 0, &mut s);
        s
    }

    /// The comparison `e` was written as, if it is a time compared with a
    /// duration (`lower::time`).
    fn written_time(&self, e: &Expr) -> Option<&'a WrittenTime> {
        if !matches!(e.kind, ExprKind::Binary(..)) || self.ctrl.written_times.is_empty() {
            return None;
        }
        self.ctrl.written_times.iter().find(|w| w.span == e.span)
    }

    /// `state_time > 5s` for a comparison lowered to `state_cycles > 500`:
    /// the time named from its counter (`X.stale_time`, with the buffer or
    /// subordinate this controller binds), the duration and the order as
    /// written.
    pub fn written_text(&self, w: &WrittenTime, counter: &Expr) -> String {
        let time = match &counter.kind {
            ExprKind::StateCycles => "state_time".to_string(),
            ExprKind::PlanCycles => "plan_time".to_string(),
            ExprKind::Sub(c, _) => format!("{}.stale_time", self.ir.controller(*c).name),
            ExprKind::BufferStale(b) => format!("{}.stale_time", self.ir.buffers[b.index()].name),
            _ => self.expr(counter),
        };
        if w.time_left {
            format!("{time} {} {}", w.op.symbol(), w.duration)
        } else {
            let op = crate::time::flipped(w.op);
            format!("{} {} {time}", w.duration, op.symbol())
        }
    }

    fn strength(e: &Expr) -> u8 {
        match &e.kind {
            ExprKind::Binary(op, ..) => op.precedence(),
            ExprKind::Unary(..) => UNARY,
            ExprKind::Int(v) if *v < 0 => UNARY,
            ExprKind::Float(v) if *v < 0.0 => UNARY,
            ExprKind::Cast(..) => CAST,
            _ => ATOM,
        }
    }

    /// Write `e`, parenthesised if it binds looser than `min`.
    fn write(&self, e: &Expr, min: u8, out: &mut String) {
        let paren = Self::strength(e) < min;
        if paren {
            out.push('(');
        }
        // A time compared with a duration, lowered to cycles: as written.
        if let (Some(w), ExprKind::Binary(_, operands)) = (self.written_time(e), &e.kind) {
            out.push_str(&self.written_text(w, &operands[0]));
            if paren {
                out.push(')');
            }
            return;
        }
        match &e.kind {
            ExprKind::Int(v) => out.push_str(&v.to_string()),
            ExprKind::Float(v) => out.push_str(&float(*v)),
            ExprKind::Bool(b) => out.push_str(if *b { "true" } else { "false" }),
            ExprKind::Variant(en, v) => {
                out.push_str(&self.ir.enums[en.index()].variants[*v as usize].name)
            }
            ExprKind::Status(s) => {
                let owner = match e.ty {
                    Type::Status(c) => &self.ir.controllers[c.index()],
                    _ => self.ctrl,
                };
                out.push_str(&owner.statuses[s.index()].name);
            }
            ExprKind::ErrorCode(code) => {
                let owner = match e.ty {
                    Type::ErrorCode(c) => &self.ir.controllers[c.index()],
                    _ => self.ctrl,
                };
                out.push_str(&crate::error_codes::name_of(
                    owner,
                    rcs_runtime::ErrorCode(*code),
                ));
            }
            ExprKind::NewCommand => out.push_str("new_command"),
            ExprKind::StateCycles => out.push_str("state_cycles"),
            ExprKind::BufferStale(b) => {
                out.push_str(&self.ir.buffers[b.index()].name);
                out.push_str(".stale_cycles");
            }
            ExprKind::PlanCycles => out.push_str("plan_cycles"),
            ExprKind::CmdParam(c, p) => {
                out.push_str("cmd.");
                out.push_str(&self.ctrl.commands[c.index()].params[p.index()].name);
            }
            ExprKind::CurrentParam(verbs) => {
                out.push_str("cmd.");
                if let Some((c, p)) = verbs.first() {
                    out.push_str(&self.ctrl.commands[c.index()].params[p.index()].name);
                }
            }
            ExprKind::Var(v) => out.push_str(&self.ctrl.vars[v.index()].name),
            ExprKind::Buffer(b) => out.push_str(&self.ir.buffers[b.index()].name),
            ExprKind::Field(base, f) => {
                self.write(base, ATOM, out);
                out.push('.');
                if let Type::Buffer(bt) = base.ty {
                    out.push_str(&self.ir.buffer_types[bt.index()].fields[*f as usize].name);
                }
            }
            ExprKind::Index(base, i) => {
                self.write(base, ATOM, out);
                out.push_str(&format!("[{i}]"));
            }
            ExprKind::IndexBy(base, i) => {
                self.write(base, ATOM, out);
                out.push('[');
                out.push_str(&self.expr(i));
                out.push(']');
            }
            ExprKind::Call(_, args) | ExprKind::Builtin(_, args) => {
                out.push_str(match &e.kind {
                    ExprKind::Call(h, _) => &self.ctrl.hooks[h.index()].name,
                    ExprKind::Builtin(b, _) => b.name(),
                    _ => unreachable!("a call"),
                });
                out.push('(');
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    self.write(a, 0, out);
                }
                out.push(')');
            }
            ExprKind::Sub(c, prop) => {
                out.push_str(&self.ir.controllers[c.index()].name);
                out.push('.');
                out.push_str(prop.name());
            }
            ExprKind::SubField(c, v) => {
                let sub = &self.ir.controllers[c.index()];
                out.push_str(&sub.name);
                out.push('.');
                out.push_str(&sub.vars[v.index()].name);
            }
            ExprKind::Unary(op, x) => {
                out.push(if *op == UnOp::Not { '!' } else { '-' });
                self.write(x, UNARY, out);
            }
            ExprKind::Binary(op, operands) => {
                let [l, r] = &**operands;
                let p = op.precedence();
                // A bitwise operator beside a comparison is always
                // parenthesised: the language requires it (C reads it the
                // other way).
                let min = |child: &Expr, base: u8| match &child.kind {
                    ExprKind::Binary(inner, _)
                        if (op.is_comparison() && inner.is_bitwise())
                            || (op.is_bitwise() && inner.is_comparison()) =>
                    {
                        ATOM + 1
                    }
                    _ => base,
                };
                // Left-associative: the right operand needs parentheses at equal strength.
                self.write(l, min(l, p), out);
                out.push(' ');
                out.push_str(op.symbol());
                out.push(' ');
                self.write(r, min(r, p + 1), out);
            }
            ExprKind::Cast(x) => {
                self.write(x, CAST, out);
                out.push_str(" as ");
                out.push_str(&crate::lower::type_name(self.ir, &e.ty));
            }
        }
        if paren {
            out.push(')');
        }
    }

    pub fn place(&self, p: &Place) -> String {
        let (mut s, mut ty) = match p.root {
            PlaceRoot::Var(v) => {
                let var = &self.ctrl.vars[v.index()];
                (var.name.clone(), var.ty.clone())
            }
            PlaceRoot::Buffer(b) => {
                let buf = &self.ir.buffers[b.index()];
                (buf.name.clone(), Type::Buffer(buf.ty))
            }
        };
        for proj in &p.path {
            match (proj, &ty) {
                (Projection::Field(f), Type::Buffer(bt)) => {
                    let field = &self.ir.buffer_types[bt.index()].fields[*f as usize];
                    s.push('.');
                    s.push_str(&field.name);
                    ty = field.ty.clone();
                }
                (Projection::Index(i), Type::Array(elem, _)) => {
                    s.push_str(&format!("[{i}]"));
                    ty = (**elem).clone();
                }
                (Projection::IndexBy(k), Type::Array(elem, _)) => {
                    if let Some(i) = p.indices.get(*k as usize) {
                        s.push_str(&format!("[{}]", self.expr(i)));
                    }
                    ty = (**elem).clone();
                }
                _ => {}
            }
        }
        s
    }

    pub fn job(&self, j: &Job) -> String {
        match j {
            Job::Assign {
                place, op, value, ..
            } => {
                let op = match op {
                    AssignOp::Set => "=",
                    AssignOp::Add => "+=",
                    AssignOp::Sub => "-=",
                };
                format!("{} {op} {}", self.place(place), self.expr(value))
            }
            Job::Send {
                sub, command, args, ..
            } => {
                let target = &self.ir.controllers[sub.index()];
                let cmd = &target.commands[command.index()];
                if cmd.params.is_empty() {
                    format!("{} <- {}", target.name, cmd.name)
                } else {
                    let args: Vec<String> = cmd
                        .params
                        .iter()
                        .zip(args)
                        .map(|(p, a)| format!("{}: {}", p.name, self.expr(a)))
                        .collect();
                    format!("{} <- {}({})", target.name, cmd.name, args.join(", "))
                }
            }
            Job::Report {
                status,
                error: Some(code),
                ..
            } => {
                format!(
                    "report {}({})",
                    self.ctrl.statuses[status.index()].name,
                    self.ctrl.errors[code.index()].name
                )
            }
            Job::Report {
                status,
                error_of: Some(v),
                ..
            } => {
                format!(
                    "report {}({})",
                    self.ctrl.statuses[status.index()].name,
                    self.ctrl.vars[v.index()].name
                )
            }
            Job::Report { status, .. } => {
                format!("report {}", self.ctrl.statuses[status.index()].name)
            }
            Job::Call(e) => self.expr(e),
            Job::Forward { sub, .. } => {
                format!("{} <- cmd", self.ir.controllers[sub.index()].name)
            }
        }
    }

    /// The row's condition (`otherwise` for the otherwise row).
    pub fn condition(&self, r: &Row) -> String {
        match &r.cond {
            Condition::When(e) => self.expr(e),
            Condition::Otherwise => "otherwise".to_string(),
        }
    }

    /// `*N`, a state name, a set `A | B`, or `*N except A | B`.
    pub fn from(&self, r: &Row) -> String {
        match &r.from {
            From::DontCare(_) => format!("*{}", r.position),
            From::State(s) => self.state(*s),
            From::States(set) => self.states(set),
            From::Except(_, out) => format!("*{} except {}", r.position, self.states(out)),
        }
    }

    /// States as a set is written: `A | B | C`.
    pub fn states(&self, set: &[StateId]) -> String {
        let names: Vec<String> = set.iter().map(|s| self.state(*s)).collect();
        names.join(" | ")
    }

    pub fn state(&self, s: StateId) -> String {
        self.plan
            .map(|p| p.states[s.index()].name.clone())
            .unwrap_or_else(|| format!("#{}", s.0))
    }

    pub fn target(&self, r: &Row) -> String {
        match r.to {
            Target::State(s) => self.state(s),
            Target::Same => "same".to_string(),
            Target::Done => "Done".to_string(),
            Target::Error(None) => "Error".to_string(),
            Target::Error(Some(e)) => format!("Error({})", self.ctrl.errors[e.index()].name),
            Target::ErrorOf(v) => format!("Error({})", self.ctrl.vars[v.index()].name),
        }
    }

    /// The row's label as the tables and graphs show it: `EN`, or its position.
    pub fn label(&self, r: &Row) -> String {
        format!("E{}", r.label.unwrap_or(r.position))
    }
}

/// A float as the language writes it: always with a `.` or an exponent.
pub fn float(v: f64) -> String {
    let s = format!("{v:?}");
    if s.contains(['.', 'e', 'E']) || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}
