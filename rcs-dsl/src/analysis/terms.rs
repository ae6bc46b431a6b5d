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
    /// `X.error_code` (§8): an input the analysis does not model; an atom
    /// that reads it is left undecided.
    SubErrorCode(CtrlId),
    /// A `reads` buffer's `stale_cycles` (LANGUAGE.md §8): a free input,
    /// as a subordinate's.
    BufStale(crate::ir::BufferId),
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
    /// The negation of a shared formula (an earlier row's condition, which
    /// a later row's firing needs false): no box per question.
    NotShared(std::sync::Arc<Formula>),
}

impl Formula {
    /// Call `f` with every atom of the formula.
    pub fn visit_atoms(&self, f: &mut dyn FnMut(AtomId)) {
        match self {
            Formula::Const(_) => {}
            Formula::Atom(a) => f(*a),
            Formula::Not(x) => x.visit_atoms(f),
            Formula::And(xs) | Formula::Or(xs) => xs.iter().for_each(|x| x.visit_atoms(f)),
            Formula::Shared(x) | Formula::NotShared(x) => x.visit_atoms(f),
        }
    }
}

/// One atom: its expression, the leaves it reads and whether it is exact.
#[derive(Clone, Debug)]
pub struct Atom<'ir> {
    /// The atom's expression: the IR's own (borrowed), or one the analysis
    /// made (`i < 0` for an index it checks).
    pub expr: AtomExpr<'ir>,
    pub leaves: Vec<LeafId>,
    pub exact: bool,
}

/// Leaves and atoms of one plan's conditions, each interned once.
#[derive(Clone, Debug, Default)]
pub struct Terms<'ir> {
    pub leaves: Vec<(Leaf, Type)>,
    pub atoms: Vec<Atom<'ir>>,
    /// Per exact leaf: the constants its exact atoms compare it with
    /// (evaluated in the leaf's type).
    pub splits: Vec<Vec<AtomExpr<'ir>>>,
}

/// An expression of the analysis: the IR's own (most), or one it made
/// (`i < 0` for an index it checks), boxed so that the common case is a
/// pointer and an atom stays small.
#[derive(Clone, Debug)]
pub enum AtomExpr<'ir> {
    Ir(&'ir Expr),
    Made(Box<Expr>),
}

impl std::ops::Deref for AtomExpr<'_> {
    type Target = Expr;

    fn deref(&self) -> &Expr {
        match self {
            AtomExpr::Ir(e) => e,
            AtomExpr::Made(e) => e,
        }
    }
}

impl<'ir> Terms<'ir> {
    /// The formula of a condition, interning its atoms and leaves.
    pub fn formula(&mut self, e: &'ir Expr) -> Formula {
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
            _ => Formula::Atom(self.atom(AtomExpr::Ir(e))),
        }
    }

    /// The formula of one atom the analysis made itself.
    pub fn made_atom(&mut self, e: Expr) -> Formula {
        Formula::Atom(self.atom(AtomExpr::Made(Box::new(e))))
    }

    /// The operands of a chain of `op` (left to right), as formulas.
    fn chain(&mut self, e: &'ir Expr, op: BinOp, out: &mut Vec<Formula>) {
        match &e.kind {
            ExprKind::Binary(o, operands) if *o == op => {
                let [l, r] = &**operands;
                self.chain(l, op, out);
                self.chain(r, op, out);
            }
            _ => out.push(self.formula(e)),
        }
    }

    /// A formula of an expression the analysis made (not in the IR).
    pub fn made_formula(&mut self, e: Expr) -> Formula {
        Formula::Atom(self.atom(AtomExpr::Made(Box::new(e))))
    }

    fn atom(&mut self, e: AtomExpr<'ir>) -> AtomId {
        if let Some(i) = self.atoms.iter().position(|a| same_expr(&a.expr, &e)) {
            return i;
        }
        let mut leaves = Vec::new();
        let mut scalar = true;
        self.collect_leaves(&e, &mut leaves, &mut scalar);
        leaves.dedup();
        // The split constant is borrowed from the IR with the atom, or
        // copied out of an atom the analysis made.
        let split = match &e {
            AtomExpr::Ir(b) => self.exact(b, &leaves).map(|c| c.map(AtomExpr::Ir)),
            AtomExpr::Made(o) => self
                .exact(o, &leaves)
                .map(|c| c.map(|c| AtomExpr::Made(Box::new(c.clone())))),
        };
        let exact = scalar && split.is_some();
        if let (true, Some(Some(c)), [leaf]) = (exact, split, leaves.as_slice()) {
            self.splits[*leaf].push(c);
        }
        self.atoms.push(Atom {
            expr: e,
            leaves,
            exact,
        });
        self.atoms.len() - 1
    }

    /// Whether atom `e` over `leaves` is exact (`Some`), and then the
    /// constant it compares its leaf with, if any: where its leaf's cells
    /// are split.
    fn exact<'e>(&self, e: &'e Expr, leaves: &[LeafId]) -> Option<Option<&'e Expr>> {
        match leaves {
            [] => Some(None),
            [leaf] => {
                if is_leaf(e) {
                    // A bool leaf, or `X.done`-style view of a status leaf.
                    return Some(None);
                }
                let ExprKind::Binary(op, operands) = &e.kind else {
                    return None;
                };
                let [l, r] = &**operands;
                if !matches!(
                    op,
                    BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge
                ) {
                    return None;
                }
                let constant = match (is_leaf(l), is_leaf(r)) {
                    (true, false) if leaf_free(r) => r,
                    (false, true) if leaf_free(l) => l,
                    _ => return None,
                };
                let t = &self.leaves[*leaf].1;
                if !matches!(
                    t,
                    Type::Int(_) | Type::Float(_) | Type::Enum(_) | Type::Status(_) | Type::Bool
                ) {
                    return None;
                }
                Some(Some(constant))
            }
            _ => None,
        }
    }

    fn collect_leaves(&mut self, e: &Expr, out: &mut Vec<LeafId>, scalar: &mut bool) {
        if is_leaf(e) {
            // A subordinate's status, seen through `X.done` and the like.
            let status = match &e.kind {
                ExprKind::Sub(c, p) if !matches!(p, SubProp::StaleCycles | SubProp::ErrorCode) => {
                    Some(*c)
                }
                _ => None,
            };
            let ty = status.map_or(&e.ty, |_| &Type::Bool);
            if !matches!(
                ty,
                Type::Bool | Type::Int(_) | Type::Float(_) | Type::Enum(_) | Type::Status(_)
            ) {
                *scalar = false;
            }
            // Found without building the leaf (a path of fields is a
            // vector): most leaves are read by several atoms.
            let id = match self.leaves.iter().position(|(l, _)| same_leaf_as(e, l)) {
                Some(id) => id,
                None => {
                    let leaf = as_leaf(e).expect("is_leaf said so");
                    let ty = status.map_or_else(|| e.ty.clone(), Type::Status);
                    self.leaves.push((leaf, ty));
                    self.splits.push(Vec::new());
                    self.leaves.len() - 1
                }
            };
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
            ExprKind::Binary(_, operands) => {
                let [l, r] = &**operands;
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

/// Whether [`as_leaf`] finds a leaf in `e` (without building it).
pub fn is_leaf(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::NewCommand
        | ExprKind::StateCycles
        | ExprKind::PlanCycles
        | ExprKind::Call(..)
        | ExprKind::Sub(..)
        | ExprKind::BufferStale(_) => true,
        _ => is_place_leaf(e),
    }
}

/// A place leaf: a parameter, var, buffer or status field, then constant
/// projections (the leaves [`with_step`] extends).
fn is_place_leaf(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::CmdParam(..)
        | ExprKind::Var(_)
        | ExprKind::Buffer(_)
        | ExprKind::SubField(..) => true,
        ExprKind::Field(x, _) | ExprKind::Index(x, _) => is_place_leaf(x),
        _ => false,
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
        ExprKind::Sub(c, SubProp::ErrorCode) => Leaf::SubErrorCode(*c),
        ExprKind::Sub(c, _) => Leaf::SubStatus(*c),
        ExprKind::BufferStale(b) => Leaf::BufStale(*b),
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
        if is_leaf(x) || matches!(x.kind, ExprKind::IndexBy(..)) {
            free = false;
        }
    });
    free
}

/// Whether `e` reads leaf `leaf` as a whole: `same_leaf(&as_leaf(e)?, leaf)`
/// without building the leaf.
fn same_leaf_as(e: &Expr, leaf: &Leaf) -> bool {
    match (&e.kind, leaf) {
        (ExprKind::NewCommand, Leaf::NewCommand)
        | (ExprKind::StateCycles, Leaf::StateCycles)
        | (ExprKind::PlanCycles, Leaf::PlanCycles) => true,
        (ExprKind::Call(h, xs), Leaf::Call(k, ys)) => {
            h == k && xs.len() == ys.len() && xs.iter().zip(ys).all(|(x, y)| same_expr(x, y))
        }
        (ExprKind::Sub(c, SubProp::StaleCycles), Leaf::SubStale(d)) => c == d,
        (ExprKind::Sub(c, SubProp::ErrorCode), Leaf::SubErrorCode(d)) => c == d,
        (ExprKind::BufferStale(b), Leaf::BufStale(d)) => b == d,
        (ExprKind::Sub(c, p), Leaf::SubStatus(d)) => {
            !matches!(p, SubProp::StaleCycles | SubProp::ErrorCode) && c == d
        }
        (
            _,
            Leaf::Param(_, steps)
            | Leaf::Var(_, steps)
            | Leaf::Buffer(_, steps)
            | Leaf::SubField(_, _, steps),
        ) => same_place_as(e, leaf, steps),
        _ => false,
    }
}

/// Whether `e` is the place leaf `leaf` followed by `steps` (the last step
/// outermost).
fn same_place_as(e: &Expr, leaf: &Leaf, steps: &[Step]) -> bool {
    match (&e.kind, steps.split_last()) {
        (ExprKind::Field(x, f), Some((Step::Field(g), rest))) => {
            f == g && same_place_as(x, leaf, rest)
        }
        (ExprKind::Index(x, i), Some((Step::Index(j), rest))) => {
            i == j && same_place_as(x, leaf, rest)
        }
        (ExprKind::CmdParam(_, p), None) => matches!(leaf, Leaf::Param(q, _) if q == p),
        (ExprKind::Var(v), None) => matches!(leaf, Leaf::Var(w, _) if w == v),
        (ExprKind::Buffer(b), None) => matches!(leaf, Leaf::Buffer(c, _) if c == b),
        (ExprKind::SubField(c, v), None) => {
            matches!(leaf, Leaf::SubField(d, w, _) if d == c && w == v)
        }
        _ => false,
    }
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
        (Leaf::BufStale(x), Leaf::BufStale(y)) => x == y,
        (Leaf::SubErrorCode(x), Leaf::SubErrorCode(y)) => x == y,
        _ => false,
    }
}

/// Structural equality of expressions (spans ignored): the equality the
/// backends use to evaluate a condition's hook call once per cycle.
pub fn same_expr(a: &Expr, b: &Expr) -> bool {
    a == b
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// The expressions of every condition and job of every plan set the
    /// repository has (golden ok cases and `plans/`), per plan.
    fn plan_exprs(visit: &mut dyn FnMut(&[&Expr])) {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut paths = Vec::new();
        for folder in ["tests/data/ok", "plans"] {
            for entry in std::fs::read_dir(root.join(folder)).expect("folder") {
                let path = entry.expect("entry").path();
                let is_set = path.is_dir() && !path.ends_with("snapshots")
                    || path.extension().is_some_and(|e| e == "rcs");
                if is_set {
                    paths.push(path);
                }
            }
        }
        paths.sort();
        assert!(paths.len() > 100, "the plan sets were found");
        for sets in paths
            .iter()
            .filter_map(|p| crate::load::load_paths(std::slice::from_ref(p)).ok())
        {
            for set in &sets {
                let Some(ir) = crate::lower_unchecked(set) else {
                    continue;
                };
                for p in ir.controllers.iter().flat_map(|c| &c.plans) {
                    let mut all = Vec::new();
                    for r in &p.rows {
                        r.visit_exprs(&mut |e| all.push(e));
                    }
                    visit(&all);
                }
            }
        }
    }

    /// `is_leaf` and `same_leaf_as` decide without building a leaf what
    /// `as_leaf` and `same_leaf` decide by building it: the same answers
    /// on every expression of every plan set of the repository.
    #[test]
    fn leaves_are_found_without_building_them_as_when_built() {
        let (mut leaves, mut pairs) = (0, 0);
        plan_exprs(&mut |exprs| {
            for e in exprs {
                assert_eq!(is_leaf(e), as_leaf(e).is_some(), "{e:?}");
            }
            let leafy: Vec<(&Expr, Leaf)> = exprs
                .iter()
                .filter_map(|e| Some((*e, as_leaf(e)?)))
                .collect();
            leaves += leafy.len();
            for (e, _) in &leafy {
                for (f, leaf) in &leafy {
                    let built = same_leaf(&as_leaf(e).expect("a leaf"), leaf);
                    assert_eq!(same_leaf_as(e, leaf), built, "{e:?}\n{f:?}");
                    pairs += usize::from(built);
                }
            }
        });
        assert!(
            leaves > 1000 && pairs > leaves,
            "{leaves} leaves, {pairs} equal pairs"
        );
    }
}
