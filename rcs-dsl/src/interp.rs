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

use crate::ir::*;
use rcs_runtime::{
    Bookkeeping, BufferWatch, ErrorCode, Stamped, StatusBuffer, SubordinateLink, SubordinateView,
    Tick,
};

use crate::arith::truthy;
pub use crate::arith::{checked, float_to_int, round, wrap};
pub use driven::Driven;
pub use rcs_runtime::driver::Value;
pub use system::System;
pub use value::{conform, zero};

/// The driver interface: [`Driven`], with scripted hooks.
mod driven;
/// Expressions.
mod eval;
mod every_cycle;
/// Jobs and the places they assign.
mod jobs;
/// Several controllers on their schedule, exchanging through a model of
/// Global Memory: what system scenarios run on.
mod system;
/// Zero and conforming values by type.
mod value;
/// `X <- cmd`: the command a forward sends.
mod verbs;

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
    /// The supervisor's side of the handshake: allocates the serial and
    /// epoch of each command (the epoch is the link's, as in generated code).
    supervisor: SubordinateLink,
    /// The parameters of the command being executed.
    active_params: Vec<Value>,
    vars: Vec<Value>,
    reads: Vec<Value>,
    /// Each `reads` buffer's write generation (one more per [`set_read`](Self::set_read)),
    /// and this controller's watch on it (`B.stale_cycles`, step 1).
    read_watch: Vec<(u64, BufferWatch)>,
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
            supervisor: SubordinateLink::new(),
            active_params: Vec::new(),
            vars: Vec::new(),
            reads: c
                .reads
                .iter()
                .map(|b| zero(ir, &Type::Buffer(ir.buffers[b.index()].ty)))
                .collect(),
            read_watch: vec![(0, BufferWatch::new()); c.reads.len()],
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

    /// The supervisor writes a new command (the next serial, in the
    /// supervisor's epoch).
    pub fn command(&mut self, command: CommandId, params: Vec<Value>) -> u32 {
        let serial = self.supervisor.next_command();
        self.command = (serial, command, params);
        serial
    }

    /// A supervisor that is itself interpreted (a system run,
    /// [`System`]) wrote `command` with the serial and epoch its own link
    /// drew: this controller reads that, as from Global Memory.
    pub fn receive(&mut self, serial: u32, epoch: u32, command: CommandId, params: Vec<Value>) {
        self.supervisor = SubordinateLink::with_epoch(epoch);
        self.supervisor.set_last_sent(serial);
        self.command = (serial, command, params);
    }

    /// The supervisor's command buffer as it stands: serial, verb, parameters.
    pub fn command_buffer(&self) -> &(u32, CommandId, Vec<Value>) {
        &self.command
    }

    /// Set a `reads` buffer (by its index in the controller's `reads`):
    /// its writer writes it, a new generation (as in Global Memory).
    pub fn set_read(&mut self, index: usize, value: Value) {
        self.reads[index] = value;
        self.read_watch[index].0 += 1;
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

    /// The epoch of the commands this controller sends a subordinate (0:
    /// none sent yet): a status answers a command only when it echoes both
    /// its serial and this.
    pub fn sent_epoch(&self, index: usize) -> u32 {
        self.subs[index].link.epoch()
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
        // 1–2. Read (each `reads` buffer's generation: `B.stale_cycles`);
        // the handshake view of each subordinate.
        for (generation, watch) in &mut self.read_watch {
            watch.observe(*generation);
        }
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
        self.bk.begin_cycle_raw(
            Tick::now(self.cycle),
            serial,
            self.supervisor.epoch(),
            verb.0 as u16,
            has_plan,
        );
        // 3a. A verb with `accept when` keeps what its refusal puts back.
        let accept = self
            .ctrl
            .commands
            .get(verb.index())
            .and_then(|c| c.accept.as_ref())
            .filter(|_| self.bk.new_command());
        let before = if self.bk.new_command() {
            let old = std::mem::replace(&mut self.active_params, params);
            accept.map(|_| (old, self.vars.clone(), self.writes.clone()))
        } else {
            None
        };
        // 3b. Pre-process, with or without an active plan.
        let mut sent = Vec::new();
        self.every_cycle(self.ctrl.pre.as_ref(), hooks);
        // 3a. Refusal: judged after `pre`, on the arriving command.
        if let (Some(a), Some((params, vars, writes))) = (accept, before) {
            let taken = truthy(&self.eval(&a.cond, hooks));
            if !taken && !self.bk.index_range_hit() {
                // As if no command had arrived: the running plan's
                // parameters, vars and buffers, and `pre` run on them.
                self.bk.refuse();
                self.active_params = params;
                self.vars = vars;
                self.writes = writes;
                self.every_cycle(self.ctrl.pre.as_ref(), hooks);
            }
        }
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
            if !r.applies_in(state) {
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
            Target::ErrorOf(v) => rcs_runtime::Target::Error(error_code(&self.vars[v.index()])),
        };
        self.bk.fire(row.position as u16, target);
    }
}

/// The error code a value of type `error` holds (a var, a status field).
pub(crate) fn error_code(v: &Value) -> ErrorCode {
    rcs_runtime::driver::FromValue::from_value(v).unwrap_or(ErrorCode::NONE)
}

/// Hooks for constant contexts (var initialisers call none).
struct NoHooks;

impl Hooks for NoHooks {
    fn call(&mut self, _: &HookData, _: HookId, _: &[Value]) -> Value {
        Value::Unit
    }
}
