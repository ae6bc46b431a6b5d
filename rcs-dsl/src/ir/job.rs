//! The jobs of the IR — assignments, sends, reports, hook calls, forwards —
//! run by a row or every cycle by `pre`/`post`, the places a job assigns to,
//! and the walks over the expressions jobs hold.

use super::{BufferId, CommandId, CtrlId, ErrorId, Expr, ExprKind, StatusId, Type, VarId};
use crate::ast::AssignOp;
use crate::source::Span;
use serde::Serialize;

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
    /// [`Plan::verbs`](super::Plan::verbs) order.
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

/// The jobs of a `pre` or `post` block: assignments and hook calls only
/// (checked when lowering).
#[derive(Clone, Debug, Serialize)]
pub struct EveryCycle {
    pub jobs: Vec<Job>,
    /// The keyword (`pre` or `post`).
    pub span: Span,
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
    /// For a `Send` to `x`: the verb and the arguments.
    pub fn send_to(&self, x: CtrlId) -> Option<(CommandId, &[Expr])> {
        match self {
            Job::Send {
                sub, command, args, ..
            } if *sub == x => Some((*command, args.as_slice())),
            _ => None,
        }
    }

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
