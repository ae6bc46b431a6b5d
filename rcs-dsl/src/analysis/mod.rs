//! Stage 3a: analysis of the conditions of each plan — which rows can match
//! at all, which can fire in which state, and a concrete witness for every
//! "can". Read-only over the IR, like the checks, which ask it questions
//! and stay small.
//!
//! ## What is decided, and how
//!
//! A row fires in state `s` when its own condition holds and the condition
//! of no earlier row covering `s` does (`otherwise` aside, which fires when
//! none holds). Each question is a satisfiability question over one cycle's
//! inputs, the *leaves* ([`terms`]): `new_command`, the cycle counters,
//! command parameters, vars and buffer fields, hook results (one value per
//! distinct call per cycle, as the backends evaluate them) and the
//! subordinates' statuses (one variable each, so `X.done`, `X.error` and
//! `X.status == S` are mutually exclusive and exhaust X's statuses,
//! `NOT_READY` and custom ones included).
//!
//! The technique is *cells plus search*. Every constant a leaf is compared
//! with cuts the leaf's range (within its type's bounds; floats also keep
//! ±∞ and NaN apart, so `x < 1.0` and `x >= 1.0` do not cover NaN), so
//! that each comparison has one truth value per cell ([`domain`]). A
//! depth-first search over one representative per cell, evaluating the
//! formula three-valued after each choice ([`search`]), is then exhaustive:
//! finding no assignment proves a row can never match or fire. Atoms the
//! procedure does not model exactly (arithmetic on inputs, two inputs
//! compared, a hook result compared with a variable) are *opaque*: for a
//! proof they are free booleans — an over-approximation, so a proof stays a
//! proof — and a witness must evaluate them on concrete values. A
//! satisfying assignment found that way is checked by evaluating every atom
//! with the language's one arithmetic ([`crate::arith`]), so a witness is
//! what the interpreter would compute; when no concrete witness is found
//! the answer is "unknown" and no check reports anything. No false alarm,
//! by construction.
//!
//! Why not BDDs or an SMT solver: plans are small (the rule of ten), so the
//! search stays in the hundreds of nodes; cells make integer ranges, enum
//! and status exhaustion and float NaN exact without a theory solver; and
//! the whole procedure is a few hundred lines with no native dependency for
//! users to install. A node budget ([`search::BUDGET`]) bounds the worst
//! case: past it, the answer is "unknown".
//!
//! Questions over several cycles (a ring of states the plan goes round, a
//! command sent again on the next cycle) are answered from these one-cycle
//! questions, along walks from the entry with the counters each walk
//! implies: [`cycles`].

mod case_text;
pub mod command;
pub mod cycles;
pub mod domain;
pub mod eval;
mod handshake;
pub mod index_range;
mod names;
pub mod path;
mod rings;
pub mod run;
pub mod search;
pub mod terms;
pub mod value;
mod walk;

use crate::ir::{Condition, Controller, CtrlId, Expr, ExprKind, From, Ir, Plan, StateId, Type};
use rcs_runtime::driver::Value;
use search::{Mode, Outcome, Search};
use std::sync::Arc;
use terms::{Formula, Leaf, LeafId, Terms};

/// The most rows, or states, of a plan the analysis takes on. Its cost
/// grows as rows² × states; past this (a generated or hostile plan, far
/// beyond the rule of ten) it answers "unknown" and the checks say
/// nothing, rather than take minutes.
pub const MAX_ANALYSED: usize = 256;

/// The answer to "can this happen?".
#[derive(Clone, Debug)]
pub enum Answer {
    /// Proved impossible.
    Never,
    /// Possible, with the inputs that make it happen.
    Can(Witness),
    /// Neither proved nor shown: say nothing.
    Unknown,
}

impl Answer {
    pub fn is_never(&self) -> bool {
        matches!(self, Answer::Never)
    }
}

/// One cycle's inputs that make something happen, in the state it happens in.
#[derive(Clone, Debug)]
pub struct Witness {
    pub state: StateId,
    /// Each input the question reads, with its value.
    pub inputs: Vec<(Leaf, Value)>,
    /// The same, as the language writes them: `cmd.n = 5`, `TB.status = DONE`.
    pub shown: Vec<(String, String)>,
}

impl Witness {
    /// `cmd.n = 5, x = 7.0, TB.status = DONE`.
    pub fn text(&self) -> String {
        self.shown
            .iter()
            .map(|(n, v)| format!("{n} = {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The conditions of one plan, ready for questions.
pub struct PlanAnalysis<'ir> {
    ir: &'ir Ir,
    ctrl: &'ir Controller,
    plan: &'ir Plan,
    terms: Terms<'ir>,
    /// Per row: its condition (`None` for `otherwise`).
    conds: Vec<Option<Arc<Formula>>>,
    /// The plan's verb's `accept when` condition, alone.
    accept: Option<Formula>,
    /// Per leaf: a representative value of each of its cells.
    cells: Vec<Vec<Value>>,
    /// Per atom: for an exact one, its truth value on each cell of its leaf.
    tables: Vec<Option<Vec<bool>>>,
    /// Per leaf, the values a witness search tries (made on first use).
    candidates: std::cell::OnceCell<Vec<Vec<Value>>>,
    new_command: LeafId,
    /// The plan is larger than [`MAX_ANALYSED`]: every question is
    /// answered "unknown" at once (the checks then say nothing).
    skipped: bool,
    /// A condition indexes by a run-time value: it may end the plan with
    /// `INDEX_RANGE` instead of matching or not. Proofs that a row never
    /// matches or fires still hold (an opaque atom is a free boolean, and
    /// a row fires only on conditions evaluated without error); witnesses
    /// evaluate `&&` and `||` in the interpreter's order; the questions
    /// that "no row matches" (waits, stalls, hangs, walks over several
    /// cycles) are not answered.
    indexed: bool,
    /// The leaves the conditions read come first; those after them only
    /// the questions of [`index_range`] read.
    condition_leaves: usize,
    /// The indices by a run-time value of the rows ([`index_range`]).
    sites: Vec<index_range::Site>,
    /// Proofs asked before, by question: the checks ask some twice.
    proved: std::cell::RefCell<std::collections::BTreeMap<Question, bool>>,
}

/// A question whose proof is remembered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Question {
    Matches(usize),
    FiresIn(usize, StateId),
    FiresWhile(usize, usize, StateId),
}

impl<'ir> PlanAnalysis<'ir> {
    pub fn new(ir: &'ir Ir, ctrl: &'ir Controller, plan: &'ir Plan) -> PlanAnalysis<'ir> {
        let mut terms = Terms::default();
        let u32_ty = Type::Int(crate::ir::IntTy::U32);
        let new_command = terms.intern(Leaf::NewCommand, Type::Bool);
        terms.intern(Leaf::StateCycles, u32_ty.clone());
        terms.intern(Leaf::PlanCycles, u32_ty);
        // A verb with `accept when A` (step 3a) starts its plan only when A
        // holds on the arrival cycle: every row the plan can fire then
        // needs it, so each condition C is read as `C && (!new_command || A)`,
        // which is exact (a refused command never shows `new_command`).
        let accept_cond = ctrl.commands[plan.verb.index()]
            .accept
            .as_ref()
            .map(|a| terms.formula(&a.cond));
        let accept = ctrl.commands[plan.verb.index()].accept.as_ref().map(|a| {
            let arrival = Expr {
                kind: ExprKind::NewCommand,
                ty: Type::Bool,
                span: a.span,
            };
            Formula::Or(vec![
                Formula::Not(Box::new(terms.made_formula(arrival))),
                terms.formula(&a.cond),
            ])
        });
        let conds = plan
            .rows
            .iter()
            .map(|r| match &r.cond {
                Condition::When(e) => Some(Arc::new(match &accept {
                    Some(a) => Formula::And(vec![terms.formula(e), a.clone()]),
                    None => terms.formula(e),
                })),
                Condition::Otherwise => None,
            })
            .collect();
        let condition_leaves = terms.leaves.len();
        let skipped = plan.rows.len() > MAX_ANALYSED || plan.states.len() > MAX_ANALYSED;
        let sites = if skipped {
            Vec::new()
        } else {
            index_range::sites(ir, ctrl, plan, &mut terms)
        };
        let cells = domain::cells(ir, &terms);
        let tables = domain::tables(&terms, &cells);
        PlanAnalysis {
            ir,
            ctrl,
            plan,
            terms,
            conds,
            accept: accept_cond,
            cells,
            tables,
            candidates: std::cell::OnceCell::new(),
            new_command,
            skipped,
            indexed: plan.rows.iter().any(|r| match &r.cond {
                Condition::When(e) => e.indexes_by_value(),
                Condition::Otherwise => false,
            }),
            condition_leaves,
            sites,
            proved: Default::default(),
        }
    }

    /// Whether the analysis answers questions about this plan: plans of
    /// more than [`MAX_ANALYSED`] rows or states are left alone.
    pub fn analysed(&self) -> bool {
        !self.skipped
    }

    /// Whether it also answers the questions over several cycles and
    /// those that no row matches (hangs, stalls, walks): not for a plan
    /// whose conditions index by a value, where a cycle on which no row
    /// matches may instead end the plan with `INDEX_RANGE`.
    pub fn analysed_over_cycles(&self) -> bool {
        !self.skipped && !self.indexed
    }

    /// Whether row `row` can match at all, judged by its own `from` and
    /// condition (a new command resets the plan to `S0`, so `new_command`
    /// is false in any other state).
    pub fn can_match(&self, row: usize) -> Answer {
        let (f, fixed, state) = self.question(Question::Matches(row));
        self.decide(&f, &fixed, state)
    }

    /// Whether row `row` can fire while the plan is in `state`: its state
    /// pattern covers `state`, its condition holds, and no earlier row that
    /// covers `state` matches (for `otherwise`: no other row matches).
    pub fn can_fire_in(&self, row: usize, state: StateId) -> Answer {
        let (f, fixed, state) = self.question(Question::FiresIn(row, state));
        self.decide(&f, &fixed, state)
    }

    /// Whether row `row` can fire in `state` on a cycle where row `other`'s
    /// condition holds too: whether `row` takes some of `other`'s cases.
    pub fn can_fire_while(&self, row: usize, other: usize, state: StateId) -> Answer {
        let (f, fixed, state) = self.question(Question::FiresWhile(row, other, state));
        self.decide(&f, &fixed, state)
    }

    /// [`can_match`](Self::can_match) is [`Answer::Never`], without looking
    /// for a witness otherwise (what the checks need, and much cheaper).
    pub fn never_matches(&self, row: usize) -> bool {
        self.proves_never(Question::Matches(row))
    }

    /// [`can_fire_in`](Self::can_fire_in) is [`Answer::Never`].
    pub fn never_fires_in(&self, row: usize, state: StateId) -> bool {
        self.proves_never(Question::FiresIn(row, state))
    }

    /// [`can_fire_while`](Self::can_fire_while) is [`Answer::Never`].
    pub fn never_fires_while(&self, row: usize, other: usize, state: StateId) -> bool {
        self.proves_never(Question::FiresWhile(row, other, state))
    }

    /// The leaves, by id: what a [`Witness`] and the `given` values of the
    /// `*_given` questions are made of.
    pub fn terms(&self) -> &Terms<'ir> {
        &self.terms
    }

    /// One representative value per cell of `leaf`: every comparison in
    /// the plan has one truth value on all values of a cell, so trying
    /// these is trying every value.
    pub fn cell_values(&self, leaf: LeafId) -> &[Value] {
        &self.cells[leaf]
    }

    /// The leaves that hold one value for the whole command, whatever it
    /// is: the command's parameters (a new command starts a new plan run).
    pub fn command_leaves(&self) -> Vec<LeafId> {
        (0..self.condition_leaves)
            .filter(|&l| matches!(self.terms.leaves[l].0, Leaf::Param(..)))
            .collect()
    }

    /// The vars (and parts of vars) the conditions read that no job of any
    /// plan of the controller assigns, with the one value they ever hold:
    /// their initialiser. Hooks see the controller's data read-only, so
    /// only jobs change vars.
    pub fn constant_vars(&self) -> Vec<(LeafId, Value)> {
        let assigned = assigned_vars(self.ctrl);
        let Some(ctrl) = self
            .ir
            .controllers
            .iter()
            .position(|c| std::ptr::eq(c, self.ctrl))
        else {
            return Vec::new();
        };
        let initial = crate::interp::Interpreter::new(self.ir, CtrlId(ctrl as u32));
        let mut out = Vec::new();
        for (l, (leaf, _)) in self.terms.leaves.iter().enumerate() {
            let Leaf::Var(v, steps) = leaf else { continue };
            if assigned.contains(v) {
                continue;
            }
            if let Some(value) = path::at_path(&initial.vars()[v.index()], steps) {
                out.push((l, value));
            }
        }
        out
    }

    /// [`can_fire_in`](Self::can_fire_in) with some leaves pinned to
    /// values.
    pub fn can_fire_in_given(
        &self,
        row: usize,
        state: StateId,
        given: &[(LeafId, Value)],
    ) -> Answer {
        let (f, mut fixed, state) = self.question(Question::FiresIn(row, state));
        fixed.extend(given.iter().cloned());
        self.decide(&f, &fixed, state)
    }

    /// Whether several rows can each fire in their state under one
    /// assignment of the leaves, with the `given` ones pinned (the caller
    /// pins the counters and `new_command`, which the firings share): the
    /// question of rows that fire in turn while the inputs stay the same.
    pub fn can_fire_all_given(
        &self,
        firings: &[(usize, StateId)],
        given: &[(LeafId, Value)],
    ) -> Answer {
        if !self.analysed_over_cycles() {
            return Answer::Unknown;
        }
        let mut parts = Vec::new();
        for &(row, state) in firings {
            match self.fires(row, state) {
                Some(f) => parts.push(f),
                None => return Answer::Never,
            }
        }
        let state = firings.first().map_or(StateId::S0, |f| f.1);
        self.decide(&Formula::And(parts), given, state)
    }

    /// Whether, in `state`, a cycle can go by with no row firing (the plan
    /// waits), with the `given` leaves pinned: no row covering `state`
    /// matches, and the plan has no `otherwise`.
    pub fn can_idle_given(&self, state: StateId, given: &[(LeafId, Value)]) -> Answer {
        if !self.analysed_over_cycles() {
            return Answer::Unknown;
        }
        let Some(any) = self.conditions_covering(state) else {
            return Answer::Never;
        };
        let mut fixed = self.fixed(state);
        fixed.extend(given.iter().cloned());
        self.decide(&Formula::Not(Box::new(Formula::Or(any))), &fixed, state)
    }

    /// Whether no row covering `state` can match, whatever the leaves not
    /// in `given` are: the plan cannot leave `state` (nor run any job
    /// there) while the `given` values hold. A proof: `false` when unknown.
    pub fn nothing_matches_given(&self, state: StateId, given: &[(LeafId, Value)]) -> bool {
        if !self.analysed_over_cycles() {
            return false;
        }
        let Some(any) = self.conditions_covering(state) else {
            return false;
        };
        let mut fixed = self.fixed(state);
        fixed.extend(given.iter().cloned());
        matches!(self.prove(&Formula::Or(any), &fixed), Outcome::None)
    }

    /// The conditions of the rows covering `state`; `None` when an
    /// `otherwise` row covers it (it matches when nothing else does).
    fn conditions_covering(&self, state: StateId) -> Option<Vec<Formula>> {
        let mut any = Vec::new();
        for (i, row) in self.plan.rows.iter().enumerate() {
            if covers(&row.from, state) {
                any.push(Formula::Shared(self.conds[i].clone()?));
            }
        }
        Some(any)
    }

    fn proves_never(&self, q: Question) -> bool {
        if let Question::FiresIn(row, state) | Question::FiresWhile(row, _, state) = q {
            if !covers(&self.plan.rows[row].from, state) {
                return true;
            }
        }
        if self.skipped {
            return false;
        }
        if let Some(&never) = self.proved.borrow().get(&q) {
            return never;
        }
        let (f, state) = self.question_formula(q);
        let never = matches!(self.prove(&f, self.known(state).as_slice()), Outcome::None);
        self.proved.borrow_mut().insert(q, never);
        never
    }

    /// A question as a formula, the leaves it fixes, and its state.
    fn question(&self, q: Question) -> (Formula, Vec<(LeafId, Value)>, StateId) {
        let (f, state) = self.question_formula(q);
        (f, self.fixed(state), state)
    }

    /// A question as a formula, and its state.
    fn question_formula(&self, q: Question) -> (Formula, StateId) {
        let cond = |i: usize| match &self.conds[i] {
            Some(c) => Formula::Shared(c.clone()),
            None => Formula::Const(true),
        };
        match q {
            Question::Matches(row) => {
                // A row covering no state never matches: judge it in S0,
                // where its condition alone decides (the graph skips it).
                let state = self.plan.rows[row]
                    .from
                    .representative(self.plan.states.len())
                    .unwrap_or(StateId::S0);
                (cond(row), state)
            }
            Question::FiresIn(row, state) => {
                let f = self.fires(row, state).unwrap_or(Formula::Const(false));
                (f, state)
            }
            Question::FiresWhile(row, other, state) => {
                let f = match self.fires(row, state) {
                    Some(fires) => Formula::And(vec![fires, cond(other)]),
                    None => Formula::Const(false),
                };
                (f, state)
            }
        }
    }

    /// The formula of "row `row` fires in `state`", `None` when its state
    /// pattern does not cover `state`.
    fn fires(&self, row: usize, state: StateId) -> Option<Formula> {
        if !covers(&self.plan.rows[row].from, state) {
            return None;
        }
        let mut parts = Vec::with_capacity(row + 1);
        // The rows that must not match: the earlier ones, or for
        // `otherwise` every other row.
        let others = match &self.conds[row] {
            Some(c) => {
                parts.push(Formula::Shared(c.clone()));
                0..row
            }
            // Only the first `otherwise` can fire (a second one is an
            // error, `otherwise_not_last`, but the graph still asks).
            None if self.plan.rows[..row].iter().any(|r| r.is_otherwise()) => {
                return Some(Formula::Const(false));
            }
            None => 0..self.plan.rows.len(),
        };
        for i in others.filter(|&i| i != row) {
            if let (Some(c), true) = (&self.conds[i], covers(&self.plan.rows[i].from, state)) {
                parts.push(Formula::NotShared(c.clone()));
            }
        }
        Some(Formula::And(parts))
    }

    /// What is known of a cycle in `state`, as a vector its callers extend.
    fn fixed(&self, state: StateId) -> Vec<(LeafId, Value)> {
        self.known(state).into_iter().collect()
    }

    /// What is known of a cycle in `state`: outside `S0`, no new command.
    fn known(&self, state: StateId) -> Option<(LeafId, Value)> {
        (state != StateId::S0).then_some((self.new_command, Value::Bool(false)))
    }

    /// The values a witness search tries, made on first use.
    fn candidates(&self) -> &[Vec<Value>] {
        self.candidates
            .get_or_init(|| domain::candidates(self.ir, &self.terms, &self.cells))
    }

    fn prove(&self, f: &Formula, fixed: &[(LeafId, Value)]) -> Outcome {
        if self.skipped {
            return Outcome::Unknown;
        }
        Search::new(&self.terms, Mode::Prove, &self.cells, &self.tables, fixed).run(f)
    }

    fn decide(&self, f: &Formula, fixed: &[(LeafId, Value)], state: StateId) -> Answer {
        match self.prove(f, fixed) {
            Outcome::None => return Answer::Never,
            Outcome::Unknown => return Answer::Unknown,
            Outcome::Found(_) => {}
        }
        let candidates = self.candidates();
        let search =
            Search::new(&self.terms, Mode::Witness, candidates, &[], fixed).in_order(self.indexed);
        match search.run(f) {
            Outcome::Found(values) => Answer::Can(self.witness(f, state, values)),
            Outcome::None | Outcome::Unknown => Answer::Unknown,
        }
    }

    /// The witness of an assignment: every input in `inputs`, and those the
    /// question reads (and `new_command`, which says which cycle) shown.
    fn witness(&self, f: &Formula, state: StateId, values: Vec<Option<Value>>) -> Witness {
        let mut read = vec![false; self.terms.leaves.len()];
        read[self.new_command] = true;
        f.visit_atoms(&mut |a| {
            for &l in &self.terms.atoms[a].leaves {
                read[l] = true;
            }
        });
        let mut inputs = Vec::new();
        let mut shown = Vec::new();
        for (i, v) in values.into_iter().enumerate() {
            let Some(v) = v else { continue };
            let (leaf, ty) = &self.terms.leaves[i];
            if read[i] {
                shown.push((self.leaf_name(leaf), self.value_text(ty, &v)));
            }
            inputs.push((leaf.clone(), v));
        }
        Witness {
            state,
            inputs,
            shown,
        }
    }
}

/// The vars some job of some plan of `ctrl`, or of its `pre`/`post`
/// blocks, assigns. A var `pre` assigns changes every cycle whether or
/// not a row fires, so it is never a value fixed for the command.
fn assigned_vars(ctrl: &Controller) -> Vec<crate::ir::VarId> {
    let mut vars = Vec::new();
    let rows = ctrl.plans.iter().flat_map(|p| &p.rows);
    for j in rows.flat_map(|r| &r.jobs).chain(ctrl.every_cycle_jobs()) {
        if let crate::ir::Job::Assign { place, .. } = j {
            if let crate::ir::PlaceRoot::Var(v) = place.root {
                if !vars.contains(&v) {
                    vars.push(v);
                }
            }
        }
    }
    vars
}

/// Whether a row's state pattern covers `state`.
pub fn covers(from: &From, state: StateId) -> bool {
    from.applies_in(state)
}
