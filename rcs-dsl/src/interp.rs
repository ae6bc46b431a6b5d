//! The reference interpreter: runs one controller of a validated IR per
//! docs/semantics.md, cycle by cycle, with its inputs, hook results and
//! subordinates' statuses supplied from outside (a scenario, a test).
//!
//! New-command detection, the handshake view, the counters and finishing
//! are not implemented here: they are `rcs_runtime`'s `Bookkeeping` and
//! `SubordinateLink`, the same code generated controllers call, so that the
//! semantics exist once. Arithmetic follows the generated code exactly:
//! integers wrap at their declared width, division or remainder by zero
//! (or `MIN / -1`) gives 0, `f32` arithmetic is rounded to `f32`, and `as`
//! behaves like Rust's (integers keep their low bits, floats saturate).

use crate::ast::{AssignOp, BinOp};
use crate::ir::*;
use rcs_runtime::{
    Bookkeeping, ErrorCode, Stamped, Status, StatusBuffer, SubordinateLink, SubordinateView, Tick,
};

use crate::arith::truthy;
pub use crate::arith::{checked, float_to_int, round, wrap};
pub use rcs_runtime::driver::Value;

mod every_cycle;
/// `X <- cmd`: the command a forward sends.
mod verbs;

/// The zero value of a type: numbers 0, `false`, the first variant.
pub fn zero(ir: &Ir, t: &Type) -> Value {
    match t {
        Type::Bool => Value::Bool(false),
        Type::Int(_) => Value::Int(0),
        Type::Float(_) => Value::Float(0.0),
        Type::Enum(_) => Value::Enum(0),
        Type::Status(_) => Value::Status(0),
        Type::Buffer(b) => Value::Buffer(
            ir.buffer_types[b.index()]
                .fields
                .iter()
                .map(|f| zero(ir, &f.ty))
                .collect(),
        ),
        Type::Array(e, n) => Value::Array(vec![zero(ir, e); *n as usize]),
        Type::Unit => Value::Unit,
    }
}

/// `v` as a value of type `t`, as the generated code would hold it (`f32`
/// rounded), or `None` when it has another shape or is out of range.
pub fn conform(ir: &Ir, t: &Type, v: &Value) -> Option<Value> {
    Some(match (t, v) {
        (Type::Bool, Value::Bool(b)) => Value::Bool(*b),
        (Type::Int(it), Value::Int(i)) => {
            let (lo, hi) = it.range();
            if *i < lo || *i > hi {
                return None;
            }
            Value::Int(*i)
        }
        (Type::Float(ft), Value::Float(f)) => Value::Float(round(*f, *ft)),
        (Type::Enum(e), Value::Enum(i)) if (*i as usize) < ir.enums[e.index()].variants.len() => {
            Value::Enum(*i)
        }
        (Type::Status(_), Value::Status(s)) => Value::Status(*s),
        (Type::Buffer(b), Value::Buffer(fs)) => {
            let bt = &ir.buffer_types[b.index()];
            if fs.len() != bt.fields.len() {
                return None;
            }
            Value::Buffer(
                bt.fields
                    .iter()
                    .zip(fs)
                    .map(|(f, x)| conform(ir, &f.ty, x))
                    .collect::<Option<_>>()?,
            )
        }
        (Type::Array(e, n), Value::Array(xs)) if xs.len() == *n as usize => Value::Array(
            xs.iter()
                .map(|x| conform(ir, e, x))
                .collect::<Option<_>>()?,
        ),
        (Type::Unit, Value::Unit) => Value::Unit,
        _ => return None,
    })
}

/// What a hook sees of its controller, read-only (as generated hooks see `&Data`).
pub struct HookData<'a> {
    pub ctrl: &'a Controller,
    /// Parameters of the command being executed.
    pub params: &'a [Value],
    /// `reads` buffers, in declaration order.
    pub reads: &'a [Value],
    pub vars: &'a [Value],
    /// `writes` buffers, in declaration order.
    pub writes: &'a [Value],
}

/// Where a controller's hooks come from: a scenario, a test, a model.
pub trait Hooks {
    /// The result of calling `hook` with `args` (`Value::Unit` for hooks
    /// that return nothing).
    fn call(&mut self, data: &HookData, hook: HookId, args: &[Value]) -> Value;
}

/// A command a cycle sent to a subordinate.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Sent {
    pub sub: CtrlId,
    pub command: CommandId,
    pub args: Vec<Value>,
    pub serial: u32,
}

/// What one cycle did and left behind.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CycleRecord {
    pub cycle: u64,
    /// The active verb (if a plan is or was active).
    pub verb: Option<CommandId>,
    pub fired: Option<RowId>,
    pub state: StateId,
    pub status: StatusId,
    /// `None`: no error code.
    pub error: Option<u16>,
    pub sent: Vec<Sent>,
    pub vars: Vec<Value>,
    /// Values of the controller's `writes` buffers, in declaration order.
    pub writes: Vec<Value>,
}

struct SubState {
    link: SubordinateLink,
    status: Stamped<StatusBuffer>,
    view: SubordinateView,
    /// The subordinate's status fields as last published, by its var id
    /// (zero until it publishes).
    fields: Vec<(VarId, Value)>,
}

/// One controller, interpreted.
pub struct Interpreter<'ir> {
    ir: &'ir Ir,
    ctrl: &'ir Controller,
    bk: Bookkeeping,
    cycle: u64,
    /// The supervisor's command buffer: serial, verb, parameters.
    command: (u32, CommandId, Vec<Value>),
    /// The parameters of the command being executed.
    active_params: Vec<Value>,
    vars: Vec<Value>,
    reads: Vec<Value>,
    writes: Vec<Value>,
    subs: Vec<SubState>,
    /// While conditions are evaluated: the hook calls made so far this
    /// cycle, by hook and syntactic arguments, with their results (each
    /// distinct call runs at most once per cycle; jobs' calls are not kept).
    condition_calls: Option<Vec<(HookId, Vec<Expr>, Value)>>,
}

impl<'ir> Interpreter<'ir> {
    /// Controller `ctrl` with vars at their initialisers and every buffer zero.
    pub fn new(ir: &'ir Ir, ctrl: CtrlId) -> Interpreter<'ir> {
        let c = ir.controller(ctrl);
        let mut me = Interpreter {
            ir,
            ctrl: c,
            bk: Bookkeeping::new(c.commands.len()),
            cycle: 0,
            command: (0, CommandId(0), Vec::new()),
            active_params: Vec::new(),
            vars: Vec::new(),
            reads: c
                .reads
                .iter()
                .map(|b| zero(ir, &Type::Buffer(ir.buffers[b.index()].ty)))
                .collect(),
            writes: c
                .writes
                .iter()
                .map(|b| zero(ir, &Type::Buffer(ir.buffers[b.index()].ty)))
                .collect(),
            subs: c
                .subordinates
                .iter()
                .map(|sub| SubState {
                    link: SubordinateLink::new(),
                    status: Stamped::default(),
                    view: SubordinateView::default(),
                    fields: every_cycle::zero_fields(ir, *sub),
                })
                .collect(),
            condition_calls: None,
        };
        let mut no_hooks = NoHooks;
        me.vars = c
            .vars
            .iter()
            .map(|v| match &v.init {
                Some(e) => me.eval(e, &mut no_hooks),
                None => zero(ir, &v.ty),
            })
            .collect();
        me
    }

    pub fn controller(&self) -> &'ir Controller {
        self.ctrl
    }

    /// The supervisor writes a new command (the next serial).
    pub fn command(&mut self, command: CommandId, params: Vec<Value>) -> u32 {
        let serial = rcs_runtime::next_serial(self.command.0);
        self.command = (serial, command, params);
        serial
    }

    /// The supervisor's command buffer as it stands: serial, verb, parameters.
    pub fn command_buffer(&self) -> &(u32, CommandId, Vec<Value>) {
        &self.command
    }

    /// Set a `reads` buffer (by its index in the controller's `reads`).
    pub fn set_read(&mut self, index: usize, value: Value) {
        self.reads[index] = value;
    }

    pub fn reads(&self) -> &[Value] {
        &self.reads
    }

    /// A subordinate (by its index in `subordinates`) writes its status
    /// buffer; each write is a new generation.
    pub fn write_sub_status(&mut self, index: usize, status: StatusBuffer) {
        let s = &mut self.subs[index].status;
        s.value = status;
        s.generation += 1;
        s.writer_cycle = self.cycle;
    }

    /// The serial of the last command this controller sent a subordinate.
    pub fn last_sent(&self, index: usize) -> u32 {
        self.subs[index].link.last_sent()
    }

    pub fn bookkeeping(&self) -> &Bookkeeping {
        &self.bk
    }

    pub fn vars(&self) -> &[Value] {
        &self.vars
    }

    pub fn writes(&self) -> &[Value] {
        &self.writes
    }

    /// One control cycle (docs/semantics.md steps 1–6).
    pub fn cycle(&mut self, hooks: &mut dyn Hooks) -> CycleRecord {
        // 1–2. Read; the handshake view of each subordinate.
        for s in &mut self.subs {
            s.view = s.link.observe(&s.status);
        }
        // 3. New command.
        let (serial, verb, params) = self.command.clone();
        let has_plan = self
            .ctrl
            .commands
            .get(verb.index())
            .is_some_and(|c| c.plan.is_some());
        self.bk
            .begin_cycle_raw(Tick::now(self.cycle), serial, verb.0 as u16, has_plan);
        if self.bk.new_command() {
            self.active_params = params;
        }
        // 3b. Pre-process, with or without an active plan.
        let mut sent = Vec::new();
        self.every_cycle(self.ctrl.pre.as_ref(), hooks);
        // 4. Decide (an index out of range skips the rest of the cycle's jobs).
        if self.bk.is_active() && !self.bk.index_range_hit() {
            self.decide(hooks, &mut sent);
        }
        // 4b. Post-process, after the row or none.
        if !self.bk.index_range_hit() {
            self.every_cycle(self.ctrl.post.as_ref(), hooks);
        }
        self.bk.end_index_range();
        // 5. Write (the record), 6. account.
        let record = CycleRecord {
            cycle: self.cycle,
            verb: (self.bk.echo_serial() != 0).then_some(CommandId(self.bk.verb() as u32)),
            fired: self.bk.fired().map(|r| RowId(r as u32)),
            state: StateId(self.bk.state() as u32),
            status: StatusId(self.bk.status().0 as u32),
            error: (!self.bk.error().is_none()).then_some(self.bk.error().0),
            sent,
            vars: self.vars.clone(),
            writes: self.writes.clone(),
        };
        self.bk.end_cycle();
        self.cycle += 1;
        record
    }

    fn decide(&mut self, hooks: &mut dyn Hooks, sent: &mut Vec<Sent>) {
        let ctrl = self.ctrl;
        let Some(plan) = ctrl.commands[self.bk.verb() as usize]
            .plan
            .map(|p| &ctrl.plans[p.index()])
        else {
            return;
        };
        let state = StateId(self.bk.state() as u32);
        let mut chosen = None;
        self.condition_calls = Some(Vec::new());
        for r in plan.rows.iter().filter(|r| !r.is_otherwise()) {
            let from_ok = match r.from {
                From::DontCare(_) => true,
                From::State(s) => s == state,
            };
            if !from_ok {
                continue;
            }
            if let Condition::When(c) = &r.cond {
                let matched = truthy(&self.eval(c, hooks));
                if self.bk.index_range_hit() {
                    // No row fires; the cycle ends the plan with INDEX_RANGE.
                    self.condition_calls = None;
                    return;
                }
                if matched {
                    chosen = Some(r);
                    break;
                }
            }
        }
        self.condition_calls = None;
        let Some(row) = chosen.or_else(|| plan.otherwise()) else {
            return;
        };
        self.jobs(&row.jobs, hooks, sent);
        let target = match row.to {
            Target::State(s) => rcs_runtime::Target::State(s.0 as u16),
            Target::Same => rcs_runtime::Target::Same,
            Target::Done => rcs_runtime::Target::Done,
            Target::Error(None) => rcs_runtime::Target::Error(ErrorCode::NONE),
            Target::Error(Some(e)) => rcs_runtime::Target::Error(ErrorCode::custom(e.0 as u16)),
        };
        self.bk.fire(row.position as u16, target);
    }

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
            ExprKind::NewCommand => Value::Bool(self.bk.new_command()),
            ExprKind::StateCycles => Value::Int(self.bk.state_cycles() as i128),
            ExprKind::PlanCycles => Value::Int(self.bk.plan_cycles() as i128),
            ExprKind::CmdParam(_, p) => self
                .active_params
                .get(p.index())
                .cloned()
                .unwrap_or(Value::Unit),
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
            ExprKind::Sub(c, prop) => {
                let i = self.ctrl.subordinate_index(*c).expect("a subordinate");
                let v = self.subs[i].view;
                match prop {
                    SubProp::Status => Value::Status(v.status.0),
                    SubProp::Done => Value::Bool(v.done()),
                    SubProp::Executing => Value::Bool(v.executing()),
                    SubProp::Error => Value::Bool(v.error()),
                    SubProp::StaleCycles => Value::Int(v.stale_cycles as i128),
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
            ExprKind::Binary(op, l, r) => self.binary(*op, l, r, &e.ty, hooks),
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
fn element_index(i: &Value) -> Option<usize> {
    match i {
        Value::Int(i) => usize::try_from(*i).ok(),
        _ => None,
    }
}

/// Hooks for constant contexts (var initialisers call none).
struct NoHooks;

impl Hooks for NoHooks {
    fn call(&mut self, _: &HookData, _: HookId, _: &[Value]) -> Value {
        Value::Unit
    }
}

/// The interpreter as a [`Driven`](rcs_runtime::driver::Driven) controller,
/// the interface the generated `Driver`s implement too: names resolved
/// against the IR, values checked against their declared types, and hooks
/// that return what the caller last set (their type's zero before that).
pub struct Driven<'ir> {
    ir: &'ir Ir,
    interp: Interpreter<'ir>,
    hooks: Scripted<'ir>,
}

struct Scripted<'ir> {
    ir: &'ir Ir,
    values: Vec<Option<Value>>,
    /// Calls of each hook since the last cycle's record.
    calls: Vec<u32>,
    /// Those calls' arguments, in order.
    args: Vec<(u16, Vec<Value>)>,
}

impl Hooks for Scripted<'_> {
    fn call(&mut self, data: &HookData, hook: HookId, args: &[Value]) -> Value {
        self.calls[hook.index()] = self.calls[hook.index()].saturating_add(1);
        self.args.push((hook.0 as u16, args.to_vec()));
        self.values[hook.index()]
            .clone()
            .unwrap_or_else(|| zero(self.ir, &data.ctrl.hooks[hook.index()].ret))
    }
}

impl<'ir> Driven<'ir> {
    /// Controller `ctrl`, fresh (as [`Interpreter::new`]).
    pub fn new(ir: &'ir Ir, ctrl: CtrlId) -> Driven<'ir> {
        let interp = Interpreter::new(ir, ctrl);
        let hooks = Scripted {
            ir,
            values: vec![None; interp.controller().hooks.len()],
            calls: vec![0; interp.controller().hooks.len()],
            args: Vec::new(),
        };
        Driven { ir, interp, hooks }
    }

    /// The interpreter underneath.
    pub fn interpreter(&self) -> &Interpreter<'ir> {
        &self.interp
    }

    fn sub_index(&self, sub: &str) -> Result<usize, rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        self.ir
            .controller_by_name(sub)
            .and_then(|id| c.subordinate_index(id))
            .ok_or_else(|| rcs_runtime::driver::unknown(&c.name, "subordinate", sub))
    }

    /// Buffer `name` of `list` (the controller's `reads` or `writes`):
    /// its index and `value` typed as it.
    fn buffer_value(
        &self,
        list: &[BufferId],
        kind: &str,
        name: &str,
        value: &Value,
    ) -> Result<(usize, Value), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let i = list
            .iter()
            .position(|b| self.ir.buffers[b.index()].name == name)
            .ok_or_else(|| rcs_runtime::driver::unknown(&c.name, kind, name))?;
        let ty = Type::Buffer(self.ir.buffers[list[i].index()].ty);
        Ok((i, self.typed(&ty, name, value)?))
    }

    fn typed(
        &self,
        t: &Type,
        what: &str,
        v: &Value,
    ) -> Result<Value, rcs_runtime::driver::DriveError> {
        conform(self.ir, t, v).ok_or_else(|| rcs_runtime::driver::DriveError::Type {
            controller: self.interp.controller().name.clone(),
            what: what.to_string(),
        })
    }
}

impl rcs_runtime::driver::Driven for Driven<'_> {
    fn name(&self) -> &str {
        &self.interp.controller().name
    }

    fn command(
        &mut self,
        verb: &str,
        args: &[Value],
    ) -> Result<u32, rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let id = c
            .commands
            .iter()
            .position(|k| k.name == verb)
            .ok_or_else(|| rcs_runtime::driver::unknown(&c.name, "verb", verb))?;
        let cmd = &c.commands[id];
        rcs_runtime::driver::arity(&c.name, verb, args, cmd.params.len())?;
        let args = cmd
            .params
            .iter()
            .zip(args)
            .map(|(p, a)| self.typed(&p.ty, &format!("{verb}.{}", p.name), a))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(self.interp.command(CommandId(id as u32), args))
    }

    fn set_read(
        &mut self,
        buffer: &str,
        value: &Value,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let (i, v) = self.buffer_value(&c.reads, "read buffer", buffer, value)?;
        self.interp.set_read(i, v);
        Ok(())
    }

    fn set_hook(
        &mut self,
        hook: &str,
        value: &Value,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let i = c
            .hooks
            .iter()
            .position(|h| h.name == hook)
            .ok_or_else(|| rcs_runtime::driver::unknown(&c.name, "hook", hook))?;
        let v = self.typed(&c.hooks[i].ret, hook, value)?;
        self.hooks.values[i] = Some(v);
        Ok(())
    }

    fn set_var(&mut self, var: &str, value: &Value) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let i = c
            .vars
            .iter()
            .position(|v| v.name == var)
            .ok_or_else(|| rcs_runtime::driver::unknown(&c.name, "var", var))?;
        let v = self.typed(&c.vars[i].ty, var, value)?;
        self.interp.vars[i] = v;
        Ok(())
    }

    fn set_write(
        &mut self,
        buffer: &str,
        value: &Value,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let (i, v) = self.buffer_value(&c.writes, "write buffer", buffer, value)?;
        self.interp.writes[i] = v;
        Ok(())
    }

    fn write_sub_status(
        &mut self,
        sub: &str,
        status: StatusBuffer,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let i = self.sub_index(sub)?;
        self.interp.write_sub_status(i, status);
        Ok(())
    }

    fn last_sent(&mut self, sub: &str) -> Result<u32, rcs_runtime::driver::DriveError> {
        Ok(self.interp.last_sent(self.sub_index(sub)?))
    }

    fn write_sub_field(
        &mut self,
        sub: &str,
        field: &str,
        value: &Value,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        // An unknown subordinate and an unknown field read alike: `X.NAME`.
        let unknown =
            || rcs_runtime::driver::unknown(&c.name, "status field", &format!("{sub}.{field}"));
        let i = self.sub_index(sub).map_err(|_| unknown())?;
        let s = self.ir.controller(c.subordinates[i]);
        let (id, var) = s
            .status_fields()
            .find(|(_, v)| v.name == field)
            .ok_or_else(unknown)?;
        let v = self.typed(&var.ty, &format!("{sub}.{field}"), value)?;
        self.interp.write_sub_field(i, id, v);
        Ok(())
    }

    fn cycle(&mut self) -> rcs_runtime::driver::Record {
        let rec = self.interp.cycle(&mut self.hooks);
        let hook_calls = self.hooks.calls.clone();
        self.hooks.calls.fill(0);
        let hook_args = std::mem::take(&mut self.hooks.args);
        let c = self.interp.controller();
        rcs_runtime::driver::Record {
            cycle: rec.cycle,
            verb: rec.verb.map(|v| v.0 as u16),
            fired: rec.fired.map(|r| r.0 as u16),
            state: rec.state.0 as u16,
            status: Status(rec.status.0 as u16),
            error: ErrorCode(rec.error.unwrap_or(0)),
            sent: rec
                .sent
                .into_iter()
                .map(|s| rcs_runtime::driver::Sent {
                    sub: c.subordinate_index(s.sub).unwrap_or(0) as u16,
                    verb: s.command.0 as u16,
                    args: s.args,
                    serial: s.serial,
                })
                .collect(),
            vars: rec.vars,
            writes: rec.writes,
            hook_calls,
            hook_args,
        }
    }
}
