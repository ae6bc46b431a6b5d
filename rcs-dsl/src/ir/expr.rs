//! Typed expressions of the IR: conditions, values, arguments. Their kinds,
//! what a subordinate is asked through the handshake ([`SubProp`]), and the
//! walk over an expression's parts.

use super::{BufferId, CommandId, CtrlId, EnumId, HookId, ParamId, StatusId, Type, VarId};
use crate::ast::{BinOp, UnOp};
use crate::source::Span;
use serde::Serialize;

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
