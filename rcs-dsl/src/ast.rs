//! The syntax tree: what the parser (`parser.rs`) builds from pest's pairs
//! and what `lower` resolves into the IR. Nothing here is checked beyond
//! syntax; every node keeps the span it came from.

use crate::lint::LintOverride;
use crate::source::Span;

/// A name as written, with where it was written. Names up to 24 bytes are
/// stored inline: a plan set has hundreds of thousands of them, and one
/// heap allocation each was a measurable share of `check`.
#[derive(Clone, Debug, PartialEq)]
pub struct Name {
    pub text: compact_str::CompactString,
    pub span: Span,
}

/// One parsed `.rcs` file.
#[derive(Clone, Debug, Default)]
pub struct File {
    pub items: Vec<Item>,
}

/// `#[allow(...)]`-style attributes and `///` docs before an item or plan.
#[derive(Clone, Debug, Default)]
pub struct Outer {
    pub docs: Vec<String>,
    pub lints: Vec<(LintOverride, Span)>,
}

#[derive(Clone, Debug)]
pub enum Item {
    Enum(EnumDef),
    Buffer(BufferDef),
    Controller(ControllerDef),
    /// `const NAME: TYPE = EXPR` at file level.
    Const(ConstDef),
    /// `controller type T(c: TYPE, …) { … }` (LANGUAGE.md §8).
    ControllerType(ControllerTypeDef),
    /// `controller NAME = T(c: value, …) { local: global, … }`.
    Instance(InstanceDef),
}

/// A controller written once: its body is a controller's, its parameters
/// constants whose values each instance gives. `expand` turns every
/// instance into a plain [`ControllerDef`]; nothing after it sees a type.
#[derive(Clone, Debug)]
pub struct ControllerTypeDef {
    /// The body, with the type's name as its name.
    pub def: ControllerDef,
    pub params: Vec<Param>,
}

/// `controller NAME = T(c: value, …) { local: global, … }`.
#[derive(Clone, Debug)]
pub struct InstanceDef {
    pub outer: Outer,
    pub name: Name,
    /// The type's name.
    pub ty: Name,
    pub args: Vec<(Name, Expr)>,
    pub title: Option<String>,
    /// `local: global`: a `reads`/`writes` buffer or a subordinate of the
    /// type, and what it is in this instance.
    pub bindings: Vec<(Name, Name)>,
    pub span: Span,
}

/// `const NAME: TYPE = EXPR`, at file or controller level.
#[derive(Clone, Debug)]
pub struct ConstDef {
    pub name: Name,
    pub ty: TypeExpr,
    pub value: Expr,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct EnumDef {
    pub outer: Outer,
    pub name: Name,
    pub variants: Vec<(Vec<String>, Name)>,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct BufferDef {
    pub outer: Outer,
    pub name: Name,
    pub fields: Vec<Field>,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct Field {
    pub docs: Vec<String>,
    pub name: Name,
    pub ty: TypeExpr,
}

#[derive(Clone, Debug)]
pub enum TypeExpr {
    Named(Name),
    Array {
        elem: Box<TypeExpr>,
        len: u64,
        span: Span,
        /// A length written as a constant expression (`len` is then 0).
        len_expr: Option<Box<Expr>>,
    },
}

impl TypeExpr {
    pub fn span(&self) -> Span {
        match self {
            TypeExpr::Named(n) => n.span,
            TypeExpr::Array { span, .. } => *span,
        }
    }
}

#[derive(Clone, Debug)]
pub struct ControllerDef {
    pub outer: Outer,
    pub name: Name,
    pub title: Option<String>,
    pub entries: Vec<Entry>,
    pub span: Span,
    /// Set by `expand` on a controller made from an instance of a type.
    pub instance: Option<Box<InstanceOf>>,
}

/// What an instance was made from (kept in the IR for the code generator
/// and the docs).
#[derive(Clone, Debug)]
pub struct InstanceOf {
    /// The type's name and where it is defined.
    pub ty: Name,
    pub type_span: Span,
    /// The instance declaration.
    pub span: Span,
    /// Each const parameter and its argument, in parameter order.
    pub args: Vec<(Name, Expr)>,
    /// `local: global` as written in the instance.
    pub bindings: Vec<(Name, Name)>,
}

/// One entry of a controller body, with its docs.
#[derive(Clone, Debug)]
pub struct Entry {
    pub outer: Outer,
    pub kind: EntryKind,
    pub span: Span,
}

/// `accept when COND` on a command declaration.
#[derive(Clone, Debug)]
pub struct Accept {
    /// The words `accept when`.
    pub keyword: Span,
    pub cond: Expr,
}

#[derive(Clone, Debug)]
pub enum EntryKind {
    Level(u64, Span),
    /// The list's names and the span of the whole list.
    Subordinates(Vec<Name>),
    Reads(Name, Name),
    Writes(Name, Name),
    Command {
        name: Name,
        params: Vec<Param>,
        /// `accept when COND` (§8): the command is refused when COND is false.
        accept: Option<Accept>,
    },
    Status(Vec<Name>),
    Error(Vec<Name>),
    Var {
        name: Name,
        ty: TypeExpr,
        init: Option<Expr>,
    },
    Hook {
        name: Name,
        params: Vec<Param>,
        ret: Option<TypeExpr>,
    },
    Plan(PlanDef),
    /// `const NAME: TYPE = EXPR` in a controller.
    Const(ConstDef),
    /// `status NAME: TYPE = INIT`: a field of the controller's status buffer.
    StatusField {
        name: Name,
        ty: TypeExpr,
        init: Option<Expr>,
    },
    /// `pre { jobs }` or `post { jobs }`: jobs run every cycle.
    EveryCycle(EveryCycleDef),
    /// `rows NAME { row… }`: rows that plans `use` (removed by `expand`).
    Rows(RowsDef),
    /// `jobs NAME(p: T, …) { job… }`: a job list (removed by `expand`).
    Jobs(JobsDef),
}

/// `rows NAME { row… }`.
#[derive(Clone, Debug)]
pub struct RowsDef {
    pub name: Name,
    pub rows: Vec<Row>,
    /// `use` lines inside the block (always an error: blocks do not nest).
    pub uses: Vec<Use>,
}

/// `jobs NAME(p: T, …) { job… }`.
#[derive(Clone, Debug)]
pub struct JobsDef {
    pub name: Name,
    pub params: Vec<Param>,
    pub jobs: Vec<Job>,
}

/// Which every-cycle block: before the rows (`pre`) or after them (`post`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    Pre,
    Post,
}

impl Phase {
    pub fn keyword(self) -> &'static str {
        match self {
            Phase::Pre => "pre",
            Phase::Post => "post",
        }
    }
}

#[derive(Clone, Debug)]
pub struct EveryCycleDef {
    pub phase: Phase,
    /// The keyword, where diagnostics about the block point.
    pub keyword: Span,
    pub jobs: Vec<Job>,
    /// A `-> target` written after the block (always an error).
    pub target: Option<Target>,
}

#[derive(Clone, Debug)]
pub struct Param {
    /// `///` lines before the parameter.
    pub docs: Vec<String>,
    pub name: Name,
    pub ty: TypeExpr,
}

#[derive(Clone, Debug)]
pub struct PlanDef {
    pub verb: Name,
    /// `plan VERB` — the header, where plan-wide diagnostics point.
    pub header: Span,
    pub rows: Vec<Row>,
    /// The verbs after the first in `plan A | B | C` (empty for one verb).
    pub more_verbs: Vec<Name>,
    /// `use NAME` lines: each goes before `rows[at]` (`expand` splices
    /// the block's rows there and empties this list).
    pub uses: Vec<Use>,
}

/// `use NAME` in a plan.
#[derive(Clone, Debug)]
pub struct Use {
    pub at: usize,
    pub name: Name,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct Row {
    pub docs: Vec<String>,
    /// `EN` as written, with its number.
    pub label: Option<(u64, Span)>,
    pub from: From,
    /// `None` for an `otherwise` row.
    pub cond: Option<Expr>,
    /// The span of `otherwise` or of the condition.
    pub cond_span: Span,
    pub target: Target,
    pub jobs: Vec<Job>,
    pub span: Span,
    /// Set by `expand` on a row placed by `use NAME`: the block's name and
    /// the `use` line.
    pub shared: Option<Box<SharedOrigin>>,
}

/// Where a row placed by `use` came from.
#[derive(Clone, Debug)]
pub struct SharedOrigin {
    pub block: Name,
    pub use_span: Span,
}

#[derive(Clone, Debug)]
pub enum From {
    /// `*` or `*N`.
    DontCare(Option<u64>, Span),
    State(Name),
    /// `A | B | C` (two or more states); the span covers the list.
    States(Vec<Name>, Span),
    /// `*N except A | B`: the `*N` as for `DontCare`, the states left out,
    /// and the span of the whole pattern.
    Except(Option<u64>, Vec<Name>, Span),
    /// An `otherwise` row written without `*`.
    Implicit,
}

#[derive(Clone, Debug)]
pub enum Target {
    Same(Span),
    Error(Option<Name>, Span),
    /// A state name, `Done` included.
    State(Name),
}

impl Target {
    pub fn span(&self) -> Span {
        match self {
            Target::Same(s) | Target::Error(_, s) => *s,
            Target::State(n) => n.span,
        }
    }
}

#[derive(Clone, Debug)]
pub enum Job {
    Send {
        sub: Name,
        verb: Name,
        args: Vec<(Name, Expr)>,
        span: Span,
    },
    Report(Name, Span),
    Assign {
        place: Expr,
        op: AssignOp,
        value: Expr,
        span: Span,
    },
    Call(Expr),
    /// `X <- cmd`: forward the current command to subordinate `X`.
    Forward {
        sub: Name,
        span: Span,
    },
    /// `report ERROR(CODE)`: the status name and the error code.
    ReportCode(Name, Name, Span),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AssignOp {
    Set,
    Add,
    Sub,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BinOp {
    Or,
    And,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    /// `&`, `|`, `^`, `<<`, `>>` on integers (LANGUAGE.md §8).
    BitAnd,
    BitOr,
    BitXor,
    Shl,
    Shr,
}

impl BinOp {
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Or => "||",
            BinOp::And => "&&",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Rem => "%",
            BinOp::BitAnd => "&",
            BinOp::BitOr => "|",
            BinOp::BitXor => "^",
            BinOp::Shl => "<<",
            BinOp::Shr => ">>",
        }
    }

    /// `==`, `!=`, `<`, `<=`, `>`, `>=`.
    pub fn is_comparison(self) -> bool {
        matches!(
            self,
            BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge
        )
    }

    /// `&`, `|`, `^`, `<<`, `>>`.
    pub fn is_bitwise(self) -> bool {
        matches!(
            self,
            BinOp::BitAnd | BinOp::BitOr | BinOp::BitXor | BinOp::Shl | BinOp::Shr
        )
    }

    /// Binding strength: larger binds tighter (Rust's order). Used when
    /// parsing and printing.
    pub fn precedence(self) -> u8 {
        match self {
            BinOp::Or => 1,
            BinOp::And => 2,
            BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => 3,
            BinOp::BitOr => 4,
            BinOp::BitXor => 5,
            BinOp::BitAnd => 6,
            BinOp::Shl | BinOp::Shr => 7,
            BinOp::Add | BinOp::Sub => 8,
            BinOp::Mul | BinOp::Div | BinOp::Rem => 9,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum UnOp {
    Not,
    Neg,
}

/// An expression node. Plan sets hold hundreds of thousands of them, all
/// alive between parsing and lowering, so the node is kept small: the rare
/// parts (a `Type::` qualifier, a call's name) are boxed, and a test holds
/// the size (`expr_nodes_stay_small`).
#[derive(Clone, Debug)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub enum ExprKind {
    /// An integer literal (the builder refuses one above `u64::MAX`).
    Int(u64),
    Float(f64),
    Bool(bool),
    NewCommand,
    StateCycles,
    PlanCycles,
    /// A duration literal (`50ms`, `1.5s`), in nanoseconds; its text is
    /// the span's (LANGUAGE.md §8 "Time").
    Duration(u64),
    /// `state_time`, `plan_time`: the counters times the CPU's period.
    StateTime,
    PlanTime,
    /// `cmd.P`
    CmdParam(Name),
    /// A bare name or `Type::Variant` (the qualifier boxed: it is rare).
    Path(Option<Box<Name>>, Name),
    /// A hook or builtin call (the name boxed: calls are few).
    Call(Box<Name>, Vec<Expr>),
    Field(Box<Expr>, Name),
    Index(Box<Expr>, Box<Expr>),
    Unary(UnOp, Box<Expr>),
    /// Both operands in one allocation, left then right (as in the IR).
    Binary(BinOp, Box<[Expr; 2]>),
    Cast(Box<Expr>, Name),
    Paren(Box<Expr>),
}

impl Expr {
    /// Call `f` on this expression and, where `f` returns true, on its
    /// sub-expressions (parents first). `expand` rewrites names with it.
    pub fn walk_mut(&mut self, f: &mut dyn FnMut(&mut Expr) -> bool) {
        if !f(self) {
            return;
        }
        match &mut self.kind {
            ExprKind::Call(_, args) => args.iter_mut().for_each(|a| a.walk_mut(f)),
            ExprKind::Field(b, _)
            | ExprKind::Unary(_, b)
            | ExprKind::Cast(b, _)
            | ExprKind::Paren(b) => b.walk_mut(f),
            ExprKind::Index(a, b) => {
                a.walk_mut(f);
                b.walk_mut(f);
            }
            ExprKind::Binary(_, ops) => ops.iter_mut().for_each(|o| o.walk_mut(f)),
            _ => {}
        }
    }

    /// Call `f` on this expression and every sub-expression, parents first.
    pub fn walk<'a>(&'a self, f: &mut dyn FnMut(&'a Expr)) {
        f(self);
        match &self.kind {
            ExprKind::Call(_, args) => args.iter().for_each(|a| a.walk(f)),
            ExprKind::Field(b, _)
            | ExprKind::Unary(_, b)
            | ExprKind::Cast(b, _)
            | ExprKind::Paren(b) => b.walk(f),
            ExprKind::Index(a, b) => {
                a.walk(f);
                b.walk(f);
            }
            ExprKind::Binary(_, ops) => ops.iter().for_each(|o| o.walk(f)),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AST of a plan set is the peak of `check`'s memory (every file
    /// is parsed before lowering starts), and every byte of a node is paid
    /// for in page faults: keep the common nodes at their present size.
    #[test]
    fn expr_nodes_stay_small() {
        assert!(
            std::mem::size_of::<Expr>() <= 72,
            "ast::Expr grew to {} bytes",
            std::mem::size_of::<Expr>()
        );
        assert!(std::mem::size_of::<Name>() <= 40);
    }
}
