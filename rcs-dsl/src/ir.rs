//! The IR: the single, fully resolved input of every back end (Rust code,
//! graphs, tables) and of the interpreter. Produced by `lower`, read (never
//! changed) by `checks`.
//!
//! Plain data: entities live in `Vec`s and refer to each other by typed ids
//! (`CtrlId`, `PlanId`, `StateId`, `RowId`, …) that index those `Vec`s.
//! Every list is in a deterministic order: files sorted by path, then source
//! order. Spans sit beside the data for diagnostics and row comments.

use crate::ast::{AssignOp, BinOp, UnOp};
use crate::lint::LintOverride;
use crate::source::Span;
use serde::Serialize;

macro_rules! id {
    ($(#[$m:meta])* $name:ident) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
        #[serde(transparent)]
        pub struct $name(pub u32);
        impl $name {
            pub fn index(self) -> usize {
                self.0 as usize
            }
        }
    };
}

id!(/// Index into [`Ir::enums`].
    EnumId);
id!(/// Index into [`Ir::buffer_types`].
    BufferTypeId);
id!(/// Index into [`Ir::buffers`] (Global Memory instances).
    BufferId);
id!(/// Index into [`Ir::controllers`].
    CtrlId);
id!(/// Index into [`Controller::commands`].
    CommandId);
id!(/// Index into [`Command::params`].
    ParamId);
id!(/// Index into [`Controller::statuses`]; 0..=3 are the built-ins.
    StatusId);
id!(/// Index into [`Controller::errors`].
    ErrorId);
id!(/// Index into [`Controller::vars`].
    VarId);
id!(/// Index into [`Controller::hooks`].
    HookId);
id!(/// Index into [`Controller::plans`].
    PlanId);
id!(/// Index into [`Plan::states`]; `StateId(0)` is always `S0`.
    StateId);
id!(/// Index into [`Plan::rows`], equal to the row's precedence position.
    RowId);

impl StateId {
    /// The state a plan is in right after a new command arrives.
    pub const S0: StateId = StateId(0);
}

impl StatusId {
    pub const NOT_READY: StatusId = StatusId(0);
    pub const EXECUTING: StatusId = StatusId(1);
    pub const DONE: StatusId = StatusId(2);
    pub const ERROR: StatusId = StatusId(3);
    /// Names of the built-in statuses, in id order.
    pub const BUILTIN: [&'static str; 4] = ["NOT_READY", "EXECUTING", "DONE", "ERROR"];
}

/// A validated plan set.
#[derive(Clone, Debug, Serialize)]
pub struct Ir {
    /// Name of the generated system module.
    pub system: String,
    /// Source files relative to the plan set's root, in `FileId` order
    /// (never absolute, so generated outputs do not depend on where the set lives).
    pub files: Vec<String>,
    pub limits: Limits,
    pub enums: Vec<EnumDef>,
    pub buffer_types: Vec<BufferType>,
    /// Global Memory instances. Invariant: at most one writer each.
    pub buffers: Vec<Buffer>,
    pub controllers: Vec<Controller>,
    /// The executives. Invariant: every controller appears exactly once.
    pub schedule: Vec<Cpu>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Limits {
    pub max_rules_per_plan: u32,
    pub max_subordinates: u32,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_rules_per_plan: 10,
            max_subordinates: 9,
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct EnumDef {
    pub name: String,
    pub docs: Vec<String>,
    /// Invariant: at least one variant; the first is the zero value.
    pub variants: Vec<Variant>,
    pub span: Span,
    /// The name in the declaration, for diagnostics.
    #[serde(skip)]
    pub name_span: Span,
}

#[derive(Clone, Debug, Serialize)]
pub struct Variant {
    pub name: String,
    pub docs: Vec<String>,
    pub span: Span,
}

/// A buffer schema (`buffer Name { … }`): plain, fixed-size data.
#[derive(Clone, Debug, Serialize)]
pub struct BufferType {
    pub name: String,
    pub docs: Vec<String>,
    pub fields: Vec<FieldDef>,
    pub span: Span,
    /// The name in the declaration, for diagnostics.
    #[serde(skip)]
    pub name_span: Span,
}

#[derive(Clone, Debug, Serialize)]
pub struct FieldDef {
    pub name: String,
    pub docs: Vec<String>,
    pub ty: Type,
    pub span: Span,
}

/// A Global Memory buffer instance named by `reads`/`writes`.
#[derive(Clone, Debug, Serialize)]
pub struct Buffer {
    pub name: String,
    pub ty: BufferTypeId,
    /// `None`: an external input (a sensor driver or simulator writes it).
    pub writer: Option<CtrlId>,
    pub readers: Vec<CtrlId>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum IntTy {
    I8,
    I16,
    I32,
    I64,
    U8,
    U16,
    U32,
    U64,
}

impl IntTy {
    pub fn name(self) -> &'static str {
        match self {
            IntTy::I8 => "i8",
            IntTy::I16 => "i16",
            IntTy::I32 => "i32",
            IntTy::I64 => "i64",
            IntTy::U8 => "u8",
            IntTy::U16 => "u16",
            IntTy::U32 => "u32",
            IntTy::U64 => "u64",
        }
    }

    pub fn signed(self) -> bool {
        matches!(self, IntTy::I8 | IntTy::I16 | IntTy::I32 | IntTy::I64)
    }

    /// Inclusive range of values, widened to i128.
    pub fn range(self) -> (i128, i128) {
        match self {
            IntTy::I8 => (i8::MIN as i128, i8::MAX as i128),
            IntTy::I16 => (i16::MIN as i128, i16::MAX as i128),
            IntTy::I32 => (i32::MIN as i128, i32::MAX as i128),
            IntTy::I64 => (i64::MIN as i128, i64::MAX as i128),
            IntTy::U8 => (0, u8::MAX as i128),
            IntTy::U16 => (0, u16::MAX as i128),
            IntTy::U32 => (0, u32::MAX as i128),
            IntTy::U64 => (0, u64::MAX as i128),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FloatTy {
    F32,
    F64,
}

impl FloatTy {
    pub fn name(self) -> &'static str {
        match self {
            FloatTy::F32 => "f32",
            FloatTy::F64 => "f64",
        }
    }
}

/// A resolved type.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Type {
    Bool,
    Int(IntTy),
    Float(FloatTy),
    Enum(EnumId),
    Buffer(BufferTypeId),
    Array(Box<Type>, u32),
    /// The status of a controller (built-ins plus its custom statuses).
    Status(CtrlId),
    /// An error code of a controller (built-ins plus the codes it
    /// declares): the type `error`, and `X.error_code` (§8).
    ErrorCode(CtrlId),
    /// What a hook without a return type gives.
    Unit,
}

#[derive(Clone, Debug, Serialize)]
pub struct Controller {
    pub name: String,
    pub title: Option<String>,
    pub docs: Vec<String>,
    pub level: Option<u32>,
    /// Invariant: at most one supervisor (checked by `multiple_supervisors`).
    pub supervisor: Option<CtrlId>,
    pub subordinates: Vec<CtrlId>,
    /// Buffers read every cycle, in declaration order.
    pub reads: Vec<BufferId>,
    /// Buffers this controller alone writes, in declaration order.
    pub writes: Vec<BufferId>,
    pub commands: Vec<Command>,
    /// Built-ins (`NOT_READY`, `EXECUTING`, `DONE`, `ERROR`) first, then custom.
    pub statuses: Vec<StatusDef>,
    pub errors: Vec<ErrorDef>,
    pub vars: Vec<Var>,
    pub hooks: Vec<Hook>,
    /// One per command, in command order once checks pass.
    pub plans: Vec<Plan>,
    pub lints: Vec<LintOverride>,
    pub span: Span,
    pub name_span: Span,
    /// Where each subordinate is named in `subordinates` (parallel to it).
    pub subordinate_spans: Vec<Span>,
    /// The span of each `subordinates` list as written.
    pub subordinates_lists: Vec<Span>,
    /// The doc comment of each `reads`/`writes` declaration that has one.
    pub buffer_docs: Vec<(BufferId, Vec<String>)>,
    /// Where each `reads`/`writes` buffer is declared (its name), for diagnostics.
    #[serde(skip)]
    pub buffer_spans: Vec<(BufferId, Span)>,
    /// `pre { … }`: jobs run every cycle before the rows (step 3b).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pre: Option<EveryCycle>,
    /// `post { … }`: jobs run every cycle after the row, or none (step 4b).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub post: Option<EveryCycle>,
    /// The controller type this controller is an instance of (LANGUAGE.md
    /// §8); `None` for a controller written out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instance_of: Option<InstanceOf>,
    /// Every comparison of a time with a duration (LANGUAGE.md §8 "Time"),
    /// lowered to a comparison of a cycle counter with a threshold: how it
    /// was written, for tables, graphs, the site and `rcsc diff`
    /// ([`crate::pretty`] prints `text` for the expression at `span`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub written_times: Vec<WrittenTime>,
}

/// A time compared with a duration, as written and as lowered:
/// `state_time > 5s` on a 10 ms period is `state_cycles > 500`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WrittenTime {
    /// The comparison's span (the lowered `Binary` expression's).
    pub span: Span,
    /// The duration as written, `5s` or `TIMEOUT` (filled in from the
    /// source once the controller is lowered).
    pub duration: String,
    /// Whether the time is written on the left (`state_time > 5s`; else
    /// `5s < state_time`).
    pub time_left: bool,
    /// The operator with the time on the left (`5s < state_time` is `>`).
    pub op: crate::ast::BinOp,
    pub duration_ns: u64,
    /// The period of the controller's CPU the threshold was computed for.
    pub period_ns: u64,
    /// The cycle count the counter is compared with.
    pub threshold: u64,
    /// The duration's span, as written.
    #[serde(skip)]
    pub duration_span: Span,
}

/// What an instance was made from: its type, and its arguments and
/// bindings as written.
#[derive(Clone, Debug, Serialize)]
pub struct InstanceOf {
    /// The type's name.
    #[serde(rename = "type")]
    pub ty: String,
    /// The whole `controller type … { … }`.
    pub type_span: Span,
    /// The instance declaration.
    pub span: Span,
    /// Each const parameter and its value as written, in parameter order.
    pub args: Vec<(String, String)>,
    /// `local: global`: each buffer and subordinate of the type, and what
    /// it is in this instance.
    pub bindings: Vec<(String, String)>,
}

/// The jobs of a `pre` or `post` block: assignments and hook calls only
/// (checked when lowering).
#[derive(Clone, Debug, Serialize)]
pub struct EveryCycle {
    pub jobs: Vec<Job>,
    /// The keyword (`pre` or `post`).
    pub span: Span,
}

impl Controller {
    /// The controller's status fields (vars published in its status
    /// buffer), with their var ids, in declaration order.
    pub fn status_fields(&self) -> impl Iterator<Item = (VarId, &Var)> {
        self.vars
            .iter()
            .enumerate()
            .filter(|(_, v)| v.status_field)
            .map(|(i, v)| (VarId(i as u32), v))
    }

    /// The `pre` and `post` jobs, in run order (for checks that look at
    /// every job of the controller).
    pub fn every_cycle_jobs(&self) -> impl Iterator<Item = &Job> {
        self.pre.iter().chain(&self.post).flat_map(|b| &b.jobs)
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Command {
    pub name: String,
    pub docs: Vec<String>,
    pub params: Vec<Param>,
    pub plan: Option<PlanId>,
    pub span: Span,
    /// `accept when COND` (§8, docs/semantics.md step 3a): a command of
    /// this verb whose condition is false on its arrival cycle is refused.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accept: Option<Accept>,
}

/// The condition of `accept when COND`: it reads the arriving command's
/// parameters (`CmdParam` of its verb), vars, status fields, buffers and
/// subordinates; never a hook or a plan quantity.
#[derive(Clone, Debug, Serialize)]
pub struct Accept {
    pub cond: Expr,
    /// The words `accept when`.
    pub span: Span,
}

#[derive(Clone, Debug, Serialize)]
pub struct Param {
    pub name: String,
    pub docs: Vec<String>,
    pub ty: Type,
    pub span: Span,
}

#[derive(Clone, Debug, Serialize)]
pub struct StatusDef {
    pub name: String,
    pub docs: Vec<String>,
    /// `None` for the built-ins.
    pub span: Option<Span>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ErrorDef {
    pub name: String,
    pub docs: Vec<String>,
    pub span: Span,
}

#[derive(Clone, Debug, Serialize)]
pub struct Var {
    pub name: String,
    pub docs: Vec<String>,
    pub ty: Type,
    /// `None`: the type's zero value.
    pub init: Option<Expr>,
    pub span: Span,
    /// Declared `status NAME: TYPE`: a var that step 5 also publishes in
    /// the controller's status buffer, read by its supervisor as `X.NAME`.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub status_field: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct Hook {
    pub name: String,
    pub docs: Vec<String>,
    pub params: Vec<Param>,
    /// `Type::Unit` when the hook returns nothing.
    pub ret: Type,
    pub span: Span,
}

/// One rule plan: the state table of one command verb.
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    pub verb: CommandId,
    pub docs: Vec<String>,
    /// States in order of first mention; `states[0]` is `S0`.
    pub states: Vec<State>,
    /// Rows in precedence order; `rows[i].position == i`.
    pub rows: Vec<Row>,
    pub lints: Vec<LintOverride>,
    /// `plan VERB`.
    pub header: Span,
    pub span: Span,
    /// Every verb of the plan in header order (`plan A | B`); `verbs[0] ==
    /// verb`. The verbs share their parameters (names, types, order), so
    /// `CmdParam(verb, p)` reads parameter `p` of whichever verb is running.
    /// Left out of `rcsc ir` for a plan of one verb (it is `[verb]`).
    #[serde(skip_serializing_if = "one_verb")]
    pub verbs: Vec<CommandId>,
}

fn one_verb(verbs: &[CommandId]) -> bool {
    verbs.len() == 1
}

impl Plan {
    /// The `otherwise` row, if the plan has one (the last row once checked).
    pub fn otherwise(&self) -> Option<&Row> {
        self.rows.iter().find(|r| r.is_otherwise())
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct State {
    pub name: String,
    /// First mention; `None` for an `S0` that is never written.
    pub span: Option<Span>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// 0-based precedence position.
    pub position: u32,
    /// `EN` as written.
    pub label: Option<u32>,
    pub docs: Vec<String>,
    pub from: From,
    /// `Condition::Otherwise` fires only when no other row matched.
    pub cond: Condition,
    /// The row tests `new_command` as a top-level conjunct: an entry row.
    pub is_entry: bool,
    pub to: Target,
    pub jobs: Vec<Job>,
    /// 1-based line of the row in its file, for generated comments.
    pub line: u32,
    pub span: Span,
    pub from_span: Span,
    pub cond_span: Span,
    pub to_span: Span,
    pub label_span: Option<Span>,
    /// The `rows` block this row was placed from by `use` (LANGUAGE.md
    /// §8); its spans are the block's row.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shared: Option<SharedRow>,
}

/// Where a row placed by `use NAME` came from.
#[derive(Clone, Debug, Serialize)]
pub struct SharedRow {
    /// The block's name.
    pub block: String,
    /// The `use NAME` line in this plan.
    pub use_span: Span,
}

impl Row {
    pub fn is_otherwise(&self) -> bool {
        matches!(self.cond, Condition::Otherwise)
    }

    /// Written with `*` (`*N`, or `*N except A | B`): the row has its own
    /// dashed `*N` node in graphs, answers to `*N` in scenarios, and is
    /// tried in every state's arm of the generated code. An `except` row
    /// is one, but it does not apply in the states it leaves out: ask
    /// [`Row::applies_in`] whether a row applies in a state.
    pub fn is_dont_care(&self) -> bool {
        matches!(self.from, From::DontCare(_) | From::Except(..))
    }

    /// Whether the row's `from` covers `state` (its condition aside).
    pub fn applies_in(&self, state: StateId) -> bool {
        self.from.applies_in(state)
    }

    /// The states of `plan` the row's `from` covers (see
    /// [`From::states_covered`]).
    pub fn states_covered<'p>(&'p self, plan: &Plan) -> impl Iterator<Item = StateId> + 'p {
        self.from.states_covered(plan.states.len())
    }

    /// The row's name everywhere — tables, graphs, diagnostics, coverage,
    /// scenarios: `E` and its position, whether or not it is labelled.
    pub fn display_name(&self) -> String {
        format!("E{}", self.position)
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum From {
    /// `*` / `*N` (with N as written, if any), or an `otherwise` without `*`.
    DontCare(Option<u32>),
    State(StateId),
    /// `A | B | C` (LANGUAGE.md §8): the row applies in each, in the order
    /// written. Empty for a shared row none of whose states belongs to the
    /// plan: it never applies.
    States(Vec<StateId>),
    /// `*N except A | B`: every state but those (N as written, if any).
    Except(Option<u32>, Vec<StateId>),
}

impl From {
    /// Whether the pattern covers `state`.
    pub fn applies_in(&self, state: StateId) -> bool {
        match self {
            From::DontCare(_) => true,
            From::State(s) => *s == state,
            From::States(set) => set.contains(&state),
            From::Except(_, out) => !out.contains(&state),
        }
    }

    /// The states, of a plan with `states` states, the pattern covers: a
    /// state or a set's in the order written (without walking the plan's
    /// other states), `*` and `except` in state order.
    pub fn states_covered(&self, states: usize) -> impl Iterator<Item = StateId> + '_ {
        let (listed, all_but): (&[StateId], Option<&[StateId]>) = match self {
            From::State(s) => (std::slice::from_ref(s), None),
            From::States(set) => (set, None),
            From::DontCare(_) => (&[], Some(&[])),
            From::Except(_, out) => (&[], Some(out)),
        };
        let rest = all_but.into_iter().flat_map(move |out| {
            (0..states as u32)
                .map(StateId)
                .filter(move |s| !out.contains(s))
        });
        listed.iter().copied().chain(rest)
    }

    /// Whether the pattern names `state` itself (`S1`, or `S1` in a set):
    /// the rows a state's own list shows; a `*` row names none.
    pub fn names(&self, state: StateId) -> bool {
        match self {
            From::State(s) => *s == state,
            From::States(set) => set.contains(&state),
            From::DontCare(_) | From::Except(..) => false,
        }
    }

    /// The state a row is judged in when one state must stand for all it
    /// covers: `S0` if covered (a new command may arrive only there, so
    /// it assumes least), else the first covered, else `None`.
    pub fn representative(&self, states: usize) -> Option<StateId> {
        if self.applies_in(StateId::S0) {
            return Some(StateId::S0);
        }
        self.states_covered(states).next()
    }
}

#[derive(Clone, Debug, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Condition {
    When(Expr),
    Otherwise,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    State(StateId),
    Same,
    Done,
    Error(Option<ErrorId>),
    /// `-> Error(v)`: the code held by var (or status field) `v`, of type
    /// `error`.
    ErrorOf(VarId),
}

#[derive(Clone, Debug, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Job {
    Assign {
        place: Place,
        op: AssignOp,
        value: Expr,
        span: Span,
    },
    /// `X <- VERB(args)`; `args` are in the verb's parameter order.
    Send {
        sub: CtrlId,
        command: CommandId,
        args: Vec<Expr>,
        span: Span,
    },
    Report {
        status: StatusId,
        span: Span,
        /// `report ERROR(CODE)`: the code (`None` for every other status,
        /// and for a bare `report ERROR`).
        #[serde(skip_serializing_if = "Option::is_none")]
        error: Option<ErrorId>,
        /// `report ERROR(v)`: the code held by var `v`, of type `error`.
        #[serde(skip_serializing_if = "Option::is_none")]
        error_of: Option<VarId>,
    },
    /// A hook called for its effect; `call` is an `ExprKind::Call`.
    Call(Expr),
    /// `X <- cmd`: send the current command, verb and arguments as
    /// received, to `sub`. `commands` maps each verb of the plan to the
    /// subordinate's command of the same name and parameters, in
    /// [`Plan::verbs`] order.
    Forward {
        sub: CtrlId,
        commands: Vec<(CommandId, CommandId)>,
        span: Span,
    },
}

/// Something a job may assign to: a var or a `writes` buffer, then fields
/// and indices (constant, or run-time values kept in `indices`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Place {
    pub root: PlaceRoot,
    pub path: Vec<Projection>,
    pub ty: Type,
    pub span: Span,
    /// The run-time index expressions of the path's
    /// [`Projection::IndexBy`], in path order (evaluated after the value).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub indices: Vec<Expr>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlaceRoot {
    Var(VarId),
    Buffer(BufferId),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Projection {
    /// Field index in the buffer type.
    Field(u32),
    /// Constant array index (checked in bounds).
    Index(u32),
    /// Array index by a run-time value: the `n`-th of [`Place::indices`];
    /// out of range, the assignment does nothing and the plan ends with
    /// `INDEX_RANGE`.
    IndexBy(u32),
}

/// A typed expression. `ty` is always concrete (literals take the type their
/// context fixes; unconstrained integer literals are `i64`, floats `f64`).
///
/// Equality is syntactic: the same kind and type, wherever it is written
/// (spans are ignored). Both backends cache a condition's hook call by its
/// hook and its arguments compared this way.
#[derive(Clone, Debug, Serialize)]
pub struct Expr {
    pub kind: ExprKind,
    pub ty: Type,
    pub span: Span,
}

impl PartialEq for Expr {
    fn eq(&self, other: &Expr) -> bool {
        self.kind == other.kind && self.ty == other.ty
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ExprKind {
    Int(i128),
    Float(f64),
    Bool(bool),
    Variant(EnumId, u32),
    /// A status of the controller given by the expression's type.
    Status(StatusId),
    /// An error code (the runtime's number: a built-in or a declared one)
    /// of the controller given by the expression's type (`FAULTED` beside
    /// `X.error_code`, or in a var of type `error`).
    ErrorCode(u16),
    NewCommand,
    StateCycles,
    PlanCycles,
    /// Parameter of the command being executed; only in the plan of that command.
    CmdParam(CommandId, ParamId),
    /// `cmd.P` in `pre` or `post`: parameter P of the command being
    /// executed, for each verb that declares it (all with one type); the
    /// type's zero before the first command and while a verb without P runs.
    CurrentParam(Vec<(CommandId, ParamId)>),
    Var(VarId),
    /// A `reads` or `writes` buffer as a whole.
    Buffer(BufferId),
    Field(Box<Expr>, u32),
    Index(Box<Expr>, u32),
    Call(HookId, Vec<Expr>),
    /// `X.status`, `X.done`, … seen through the handshake.
    Sub(CtrlId, SubProp),
    Unary(UnOp, Box<Expr>),
    /// Both operands in one allocation, left then right: binary operators
    /// are most of the nodes of a condition, and a box per operand made the
    /// IR's expressions two allocations per operator to build and to free.
    Binary(BinOp, Box<[Expr; 2]>),
    Cast(Box<Expr>),
    /// A built-in function (`abs`, `sqrt`, …): pure, arguments of one type
    /// (see [`crate::builtin`]).
    Builtin(crate::builtin::Builtin, Vec<Expr>),
    /// `X.NAME`: status field `NAME` (a var of subordinate X) as X last
    /// published it, whatever serial X echoes (not through the handshake).
    SubField(CtrlId, VarId),
    /// `a[i]` with a run-time integer `i` (the second expression): out of
    /// range, the element type's zero, and the plan ends with `INDEX_RANGE`.
    IndexBy(Box<Expr>, Box<Expr>),
    /// `B.stale_cycles` for a `reads` buffer B (LANGUAGE.md §8): cycles
    /// since B's writer last wrote it, as `X.stale_cycles` for a subordinate.
    BufferStale(BufferId),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SubProp {
    Status,
    Done,
    Executing,
    Error,
    StaleCycles,
    /// `X.error_code`: the code of X's ERROR answer to the latest command
    /// (0, no error, otherwise).
    ErrorCode,
}

impl SubProp {
    pub fn name(self) -> &'static str {
        match self {
            SubProp::Status => "status",
            SubProp::Done => "done",
            SubProp::Executing => "executing",
            SubProp::Error => "error",
            SubProp::StaleCycles => "stale_cycles",
            SubProp::ErrorCode => "error_code",
        }
    }
}

/// One executive ("CPU"): its period and its controllers in run order.
#[derive(Clone, Debug, Serialize)]
pub struct Cpu {
    pub name: String,
    pub period_ns: u64,
    pub order: Vec<CtrlId>,
    /// The manifest's `process:`; `None` is the default process, named
    /// after the system ([`Ir::process_of`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub process: Option<String>,
    /// External inputs written by hand-written code in this CPU's process
    /// (the manifest's `inputs:`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<BufferId>,
    /// Whether the manifest gives this CPU's period (else it is the
    /// documented default, [`crate::manifest::DEFAULT_PERIOD_NS`]).
    #[serde(skip)]
    pub period_given: bool,
}

impl Ir {
    /// The process CPU `cpu` runs in: its `process:`, or the system's name.
    pub fn process_of<'a>(&'a self, cpu: &'a Cpu) -> &'a str {
        cpu.process.as_deref().unwrap_or(&self.system)
    }

    pub fn controller(&self, id: CtrlId) -> &Controller {
        &self.controllers[id.index()]
    }

    pub fn controller_by_name(&self, name: &str) -> Option<CtrlId> {
        self.controllers
            .iter()
            .position(|c| c.name == name)
            .map(|i| CtrlId(i as u32))
    }
}

impl Controller {
    /// The position of `sub` among this controller's subordinates.
    pub fn subordinate_index(&self, sub: CtrlId) -> Option<usize> {
        self.subordinates.iter().position(|s| *s == sub)
    }

    /// Whether some verb has `accept when`: only then can this controller
    /// answer a command with the built-in error `REFUSED`.
    pub fn can_refuse(&self) -> bool {
        self.commands.iter().any(|k| k.accept.is_some())
    }

    /// A plan's name for people: its verbs as in its header, `GOTO | JOG`.
    pub fn plan_title(&self, p: &Plan) -> String {
        p.verbs
            .iter()
            .map(|v| self.commands[v.index()].name.as_str())
            .collect::<Vec<_>>()
            .join(" | ")
    }

    /// The plan of a verb, by name.
    pub fn plan_of(&self, verb: &str) -> Option<&Plan> {
        let c = self.commands.iter().find(|c| c.name == verb)?;
        c.plan.map(|p| &self.plans[p.index()])
    }
}

impl ExprKind {
    /// `l op r`.
    pub fn binary(op: BinOp, l: Expr, r: Expr) -> ExprKind {
        ExprKind::Binary(op, Box::new([l, r]))
    }
}

impl Expr {
    /// Call `f` on this expression and every sub-expression, parents first.
    pub fn visit<'a>(&'a self, f: &mut dyn FnMut(&'a Expr)) {
        f(self);
        match &self.kind {
            ExprKind::Field(e, _)
            | ExprKind::Index(e, _)
            | ExprKind::Unary(_, e)
            | ExprKind::Cast(e) => e.visit(f),
            ExprKind::Binary(_, operands) => operands.iter().for_each(|e| e.visit(f)),
            ExprKind::IndexBy(l, r) => {
                l.visit(f);
                r.visit(f);
            }
            ExprKind::Call(_, args) | ExprKind::Builtin(_, args) => {
                args.iter().for_each(|a| a.visit(f))
            }
            _ => {}
        }
    }
}

impl Expr {
    /// Whether evaluating this expression can meet an index out of range
    /// (it indexes by a run-time value).
    pub fn indexes_by_value(&self) -> bool {
        let mut found = false;
        self.visit(&mut |x| found |= matches!(x.kind, ExprKind::IndexBy(..)));
        found
    }
}

impl Job {
    /// Whether performing this job can meet an index out of range.
    pub fn indexes_by_value(&self) -> bool {
        let mut found = matches!(self, Job::Assign { place, .. } if !place.indices.is_empty());
        visit_job_exprs(std::slice::from_ref(self), &mut |x| {
            found |= matches!(x.kind, ExprKind::IndexBy(..))
        });
        found
    }
}

impl Row {
    /// Every expression of the row: its condition, then its jobs' in order.
    pub fn visit_exprs<'a>(&'a self, f: &mut dyn FnMut(&'a Expr)) {
        if let Condition::When(c) = &self.cond {
            c.visit(f);
        }
        visit_job_exprs(&self.jobs, f);
    }
}

impl EveryCycle {
    /// Every expression of the block's jobs, in order.
    pub fn visit_exprs<'a>(&'a self, f: &mut dyn FnMut(&'a Expr)) {
        visit_job_exprs(&self.jobs, f);
    }
}

/// Every expression of `jobs`, in order (assignment targets are places,
/// not expressions: only their run-time indices are visited, after the value).
pub fn visit_job_exprs<'a>(jobs: &'a [Job], f: &mut dyn FnMut(&'a Expr)) {
    for j in jobs {
        match j {
            Job::Assign { value, place, .. } => {
                value.visit(f);
                place.indices.iter().for_each(|i| i.visit(f));
            }
            Job::Send { args, .. } => args.iter().for_each(|a| a.visit(f)),
            Job::Call(e) => e.visit(f),
            Job::Report { .. } | Job::Forward { .. } => {}
        }
    }
}

impl Job {
    /// The subordinate a `Send` or `Forward` job commands, and the job's
    /// span: both are a send with a new serial to every check.
    pub fn sends_to(&self) -> Option<(CtrlId, Span)> {
        match self {
            Job::Send { sub, span, .. } | Job::Forward { sub, span, .. } => Some((*sub, *span)),
            _ => None,
        }
    }

    /// The subordinate's commands this job can send: one for a `Send`, one
    /// per verb of the plan for a `Forward`.
    pub fn commands_sent(&self) -> Vec<CommandId> {
        match self {
            Job::Send { command, .. } => vec![*command],
            Job::Forward { commands, .. } => commands.iter().map(|(_, theirs)| *theirs).collect(),
            _ => Vec::new(),
        }
    }
}
