//! A controller of the IR and what it declares: commands (with their
//! parameters and `accept when`), statuses, errors, vars, hooks, the
//! instance it was made from, the times it compares; and the questions
//! asked of a controller as a whole. Its plans are in `plan`.

use super::{BufferId, CtrlId, EveryCycle, Expr, Job, Plan, PlanId, Type, VarId};
use crate::lint::LintOverride;
use crate::source::Span;
use serde::Serialize;

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
