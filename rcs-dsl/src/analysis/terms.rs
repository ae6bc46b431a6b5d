//! Conditions → formulas over *atoms*, and atoms over *leaves*.
//!
//! A **leaf** is an input of one cycle's conditions: `new_command`, a cycle
//! counter, a command parameter, a var or buffer field (through constant
//! fields and indices), a hook call's result (one value per distinct call
//! and cycle: the backends evaluate each distinct call once per cycle), a
//! subordinate's status as seen through the handshake, its
//! `stale_cycles`, or one of its status fields (`X.NAME`, a free input). An **atom** is a boolean sub-expression that is not
//! `&&`, `||`, `!` or a literal. An atom is **exact** when the analysis
//! knows every point where its truth can change along its one leaf (a bool
//! leaf itself, `leaf OP constant`, a subordinate's `done`/`executing`/
//! `error`); any other atom is **opaque**: a free boolean when proving, and
//! evaluated on concrete values when looking for a witness.

use crate::ast::{BinOp, UnOp};
use crate::ir::{CtrlId, Expr, ExprKind, HookId, ParamId, SubProp, Type, VarId};

/// An input of one cycle's conditions.
#[derive(Clone, Debug)]
pub enum Leaf {
    NewCommand,
    StateCycles,
    PlanCycles,
    /// A command parameter, then constant projections into it.
    Param(ParamId, Vec<Step>),
    Var(VarId, Vec<Step>),
    Buffer(crate::ir::BufferId, Vec<Step>),
    /// A hook call's result: the hook and its arguments as written.
    Call(HookId, Vec<Expr>),
    /// A subordinate's status, through the handshake.
    SubStatus(CtrlId),
    SubStale(CtrlId),
    /// A subordinate's status field (`X.NAME`), then constant projections:
    /// an input the subordinate sets freely, like a `reads` buffer.
    SubField(CtrlId, VarId, Vec<Step>),
}

/// A constant field or index on the way into a parameter, var or buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    Field(u32),
    Index(u32),
}

pub type LeafId = usize;
pub type AtomId = usize;

/// A condition as a boolean formula over atoms.
#[derive(Clone, Debug)]
pub enum Formula {
    Const(bool),
    Atom(AtomId),
    Not(Box<Formula>),
    And(Vec<Formula>),
    Or(Vec<Formula>),
    /// A formula shared between questions (a row's condition), not copied.
    Shared(std::sync::Arc<Formula>),
}

impl Formula {
    /// Call `f` with every atom of the formula.
    pub fn visit_atoms(&self, f: &mut dyn FnMut(AtomId)) {
        match self {
            Formula::Const(_) => {}
            Formula::Atom(a) => f(*a),
            Formula::Not(x) => x.visit_atoms(f),
            Formula::And(xs) | Formula::Or(xs) => xs.iter().for_each(|x| x.visit_atoms(f)),
            Formula::Shared(x) => x.visit_atoms(f),
        }
    }
}

/// One atom: its expression, the leaves it reads and whether it is exact.
#[derive(Clone, Debug)]
pub struct Atom {
    pub expr: Expr,
    pub leaves: Vec<LeafId>,
    pub exact: bool,
}

/// Leaves and atoms of one plan's conditions, each interned once.
#[derive(Clone, Debug, Default)]
pub struct Terms {
    pub leaves: Vec<(Leaf, Type)>,
    pub atoms: Vec<Atom>,
    /// Per exact leaf: the constants its exact atoms compare it with
    /// (evaluated in the leaf's type).
    pub splits: Vec<Vec<Expr>>,
}

impl Terms {
    /// The formula of a condition, interning its atoms and leaves.
    pub fn formula(&mut self, e: &Expr) -> Formula {
        match &e.kind {
            ExprKind::Bool(b) => Formula::Const(*b),
            ExprKind::Unary(UnOp::Not, x) => Formula::Not(Box::new(self.formula(x))),
            // A chain `a && b && c` is one n-ary node (both connectives are
            // associative in three-valued logic too): one vector instead of
            // a tree of two-element ones, and a flatter walk per search node.
            ExprKind::Binary(BinOp::And, ..) => {
                let mut xs = Vec::new();
                self.chain(e, BinOp::And, &mut xs);
                Formula::And(xs)
            }
            ExprKind::Binary(BinOp::Or, ..) => {
                let mut xs = Vec::new();
                self.chain(e, BinOp::Or, &mut xs);
                Formula::Or(xs)
            }
            _ => Formula::Atom(self.atom(e)),
        }
    }

    /// The operands of a chain of `op` (left to right), as formulas.
    fn chain(&mut self, e: &Expr, op: BinOp, out: &mut Vec<Formula>) {
        match &e.kind {
            ExprKind::Binary(o, l, r) if *o == op => {
                self.chain(l, op, out);
                self.chain(r, op, out);
            }
            _ => out.push(self.formula(e)),
        }
    }

    fn atom(&mut self, e: &Expr) -> AtomId {
        if let Some(i) = self.atoms.iter().position(|a| same_expr(&a.expr, e)) {
            return i;
        }
        let mut leaves = Vec::new();
        let mut scalar = true;
        self.collect_leaves(e, &mut leaves, &mut scalar);
        leaves.dedup();
        let exact = scalar && self.exact(e, &leaves);
        self.atoms.push(Atom {
            expr: e.clone(),
            leaves,
            exact,
        });
        self.atoms.len() - 1
    }

    /// Whether atom `e` over `leaves` is exact, registering its split
    /// constant with its leaf if it is.
    fn exact(&mut self, e: &Expr, leaves: &[LeafId]) -> bool {
        match leaves {
            [] => true,
            [leaf] => {
                if as_leaf(e).is_some() {
                    // A bool leaf, or `X.done`-style view of a status leaf.
                    return true;
                }
                let ExprKind::Binary(op, l, r) = &e.kind else {
                    return false;
                };
                if !matches!(
                    op,
                    BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge
                ) {
                    return false;
                }
                let constant = match (as_leaf(l).is_some(), as_leaf(r).is_some()) {
                    (true, false) if leaf_free(r) => r,
                    (false, true) if leaf_free(l) => l,
                    _ => return false,
                };
                let t = &self.leaves[*leaf].1;
                if !matches!(
                    t,
                    Type::Int(_) | Type::Float(_) | Type::Enum(_) | Type::Status(_) | Type::Bool
                ) {
                    return false;
                }
                let c = (**constant).clone();
                self.splits[*leaf].push(c);
                true
            }
            _ => false,
        }
    }

    fn collect_leaves(&mut self, e: &Expr, out: &mut Vec<LeafId>, scalar: &mut bool) {
        if let Some(leaf) = as_leaf(e) {
            let ty = match leaf {
                Leaf::SubStatus(c) => Type::Status(c),
                _ => e.ty.clone(),
            };
            if !matches!(
                ty,
                Type::Bool | Type::Int(_) | Type::Float(_) | Type::Enum(_) | Type::Status(_)
            ) {
                *scalar = false;
            }
            let id = self.intern(leaf, ty);
            if !out.contains(&id) {
                out.push(id);
            }
            return;
        }
        match &e.kind {
            ExprKind::Field(x, _) | ExprKind::Index(x, _) => {
                // A projection of something that is not a place: opaque.
                *scalar = false;
                self.collect_leaves(x, out, scalar);
            }
            ExprKind::IndexBy(x, i) => {
                // Indexing by a value is opaque (and may end the plan with
                // INDEX_RANGE): an atom reading one is never exact.
                *scalar = false;
                self.collect_leaves(x, out, scalar);
                self.collect_leaves(i, out, scalar);
            }
            ExprKind::Unary(_, x) | ExprKind::Cast(x) => self.collect_leaves(x, out, scalar),
            ExprKind::Binary(_, l, r) => {
                self.collect_leaves(l, out, scalar);
                self.collect_leaves(r, out, scalar);
            }
            // A built-in call is opaque: an atom reading one never counts
            // as exact (see `exact`), whatever its arguments read.
            ExprKind::Builtin(_, args) => args
                .iter()
                .for_each(|a| self.collect_leaves(a, out, scalar)),
            _ => {}
        }
    }

    /// The id of a leaf, if the conditions read it.
    pub fn find(&self, leaf: &Leaf) -> Option<LeafId> {
        self.leaves.iter().position(|(l, _)| same_leaf(l, leaf))
    }

    /// The id of a leaf, added if new.
    pub fn intern(&mut self, leaf: Leaf, ty: Type) -> LeafId {
        if let Some(i) = self.find(&leaf) {
            return i;
        }
        self.leaves.push((leaf, ty));
        self.splits.push(Vec::new());
        self.leaves.len() - 1
    }
}

/// The leaf an expression reads as a whole, if it is one: a place (through
/// constant projections), a counter, a hook call, a subordinate property.
/// `X.done`, `X.executing` and `X.error` are views of the status leaf.
pub fn as_leaf(e: &Expr) -> Option<Leaf> {
    Some(match &e.kind {
        ExprKind::NewCommand => Leaf::NewCommand,
        ExprKind::StateCycles => Leaf::StateCycles,
        ExprKind::PlanCycles => Leaf::PlanCycles,
        ExprKind::Call(h, args) => Leaf::Call(*h, args.clone()),
        ExprKind::Sub(c, SubProp::StaleCycles) => Leaf::SubStale(*c),
        ExprKind::Sub(c, _) => Leaf::SubStatus(*c),
        ExprKind::CmdParam(_, p) => Leaf::Param(*p, Vec::new()),
        ExprKind::Var(v) => Leaf::Var(*v, Vec::new()),
        ExprKind::Buffer(b) => Leaf::Buffer(*b, Vec::new()),
        ExprKind::SubField(c, v) => Leaf::SubField(*c, *v, Vec::new()),
        ExprKind::Field(x, f) => with_step(as_leaf(x)?, Step::Field(*f))?,
        ExprKind::Index(x, i) => with_step(as_leaf(x)?, Step::Index(*i))?,
        _ => return None,
    })
}

fn with_step(leaf: Leaf, step: Step) -> Option<Leaf> {
    Some(match leaf {
        Leaf::Param(p, mut s) => {
            s.push(step);
            Leaf::Param(p, s)
        }
        Leaf::Var(v, mut s) => {
            s.push(step);
            Leaf::Var(v, s)
        }
        Leaf::Buffer(b, mut s) => {
            s.push(step);
            Leaf::Buffer(b, s)
        }
        Leaf::SubField(c, v, mut s) => {
            s.push(step);
            Leaf::SubField(c, v, s)
        }
        _ => return None,
    })
}

/// Whether an expression reads no leaf (a constant expression).
fn leaf_free(e: &Expr) -> bool {
    let mut free = true;
    e.visit(&mut |x| {
        if as_leaf(x).is_some() || matches!(x.kind, ExprKind::IndexBy(..)) {
            free = false;
        }
    });
    free
}

/// Whether two leaves are the same input (hook calls: the same hook with
/// structurally equal arguments).
pub fn same_leaf(a: &Leaf, b: &Leaf) -> bool {
    match (a, b) {
        (Leaf::NewCommand, Leaf::NewCommand)
        | (Leaf::StateCycles, Leaf::StateCycles)
        | (Leaf::PlanCycles, Leaf::PlanCycles) => true,
        (Leaf::Param(x, s), Leaf::Param(y, t)) => x == y && s == t,
        (Leaf::Var(x, s), Leaf::Var(y, t)) => x == y && s == t,
        (Leaf::Buffer(x, s), Leaf::Buffer(y, t)) => x == y && s == t,
        (Leaf::SubField(c, x, s), Leaf::SubField(d, y, t)) => c == d && x == y && s == t,
        (Leaf::Call(h, xs), Leaf::Call(k, ys)) => {
            h == k && xs.len() == ys.len() && xs.iter().zip(ys).all(|(x, y)| same_expr(x, y))
        }
        (Leaf::SubStatus(x), Leaf::SubStatus(y)) | (Leaf::SubStale(x), Leaf::SubStale(y)) => x == y,
        _ => false,
    }
}

/// Structural equality of expressions (spans ignored): the equality the
/// backends use to evaluate a condition's hook call once per cycle.
pub fn same_expr(a: &Expr, b: &Expr) -> bool {
    a == b
}
