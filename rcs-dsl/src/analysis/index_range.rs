//! Stage 3a: where a plan indexes an array by a run-time value (`a[i]` in
//! a condition, a job, an assignment target, or the controller's `pre`,
//! met on every cycle before the rows; not yet `post`, which runs only
//! when nothing before it ended the cycle), whether the index can fall
//! outside the array on a cycle the interpreter gets there — the question
//! behind the `index_range` lint.
//!
//! Each such index is a *site*. A site is decided only where its index is
//! a leaf the analysis models exactly along the way to it: a command
//! parameter, a field of a `reads` buffer, a subordinate's status field, a
//! hook result, a counter, or a var no job (nor `pre`/`post`) assigns.
//! Its question, per state the row covers, is a formula over the leaves of
//! [`PlanAnalysis`]: the earlier rows do not match, the interpreter gets to
//! the index (the `&&`/`||` operands before it decide so, the row fires for
//! an index in a job), every other index met on the way is in range, and
//! this one is out: `i < 0 || i >= LEN`, two exact atoms interned with the
//! plan's conditions so that the cells split at 0 and `LEN`. No assignment
//! is a proof that the index stays in range there; an assignment found is
//! turned into a [`Run`] from a fresh controller and replayed on the
//! interpreter, which must end the plan with `INDEX_RANGE` on the cycle
//! the run says. Only a replayed run makes a finding: anything less (an
//! index the analysis does not model, a witness a scenario cannot give, a
//! replay that shows something else) is silence.

use super::run::{row_name, Expect, Run};
use super::terms::{as_leaf, Formula, Leaf, Terms};
use super::{covers, PlanAnalysis, Witness};
use crate::ast::BinOp;
use crate::ir::{
    Condition, Controller, Expr, ExprKind, Ir, Job, Place, PlaceRoot, Plan, Projection, StateId,
    Type,
};
use crate::source::Span;

/// One index by a run-time value in a row, or in `pre`.
#[derive(Clone, Debug)]
pub struct Site {
    /// The row it is in (unused for `pre`).
    pub row: usize,
    /// The job it is in; `None`: the row's condition.
    pub job: Option<usize>,
    /// In the controller's `pre` block (job `job`), not in a row: met at
    /// the start of every cycle, before any row.
    pub pre: bool,
    /// The indexed expression or assignment target, as written.
    pub array: String,
    pub index: Expr,
    pub len: u32,
    pub span: Span,
    /// `i < 0 || i >= LEN`; `None` when the index is not a leaf the
    /// analysis models exactly (the site is then never decided).
    out: Option<Formula>,
    /// What must hold for the interpreter to get to this index with every
    /// index before it in range; `None` when that cannot be said exactly.
    before: Option<Vec<Formula>>,
}

/// An index that can fall outside its array, with the run that shows it.
#[derive(Clone, Debug)]
pub struct OutOfRange {
    pub site: usize,
    pub witness: Witness,
    pub run: Run,
}

/// An index by a value met while evaluating, before its own atom or job
/// is reached: its `out` formula (when exact) and the guard to reach it.
struct Met {
    index: Expr,
    len: u32,
    span: Span,
    array: String,
    guard: Option<Vec<Formula>>,
}

/// The sites of `plan`, their formulas interned in `terms` (before the
/// cells are made, so that 0 and each length cut the index's cells).
pub(super) fn sites<'ir>(
    ir: &Ir,
    ctrl: &Controller,
    plan: &'ir Plan,
    terms: &mut Terms<'ir>,
) -> Vec<Site> {
    // Made on first use: most plans have no index by a value.
    let assigned = std::cell::OnceCell::new();
    let assigned = || {
        assigned
            .get_or_init(|| super::assigned_vars(ctrl))
            .as_slice()
    };
    let printer = crate::pretty::Printer::new(ir, ctrl, Some(plan));
    let mut out = Vec::new();
    for (r, row) in plan.rows.iter().enumerate() {
        // Indices met in order: the condition's, then each job's.
        // A unit that meets no index adds nothing (no site, no guard for
        // later units): most rows have none, and skip all the work.
        let mut units: Vec<(Option<usize>, Vec<Met>)> = Vec::new();
        if let Condition::When(c) = &row.cond {
            if c.indexes_by_value() {
                let mut met = Vec::new();
                in_condition(terms, &printer, c, Vec::new(), &mut met);
                units.push((None, met));
            }
        }
        for (k, job) in row.jobs.iter().enumerate() {
            if job.indexes_by_value() {
                let mut met = Vec::new();
                in_job(ir, ctrl, &printer, job, &mut met);
                units.push((Some(k), met));
            }
        }
        if !units.is_empty() {
            add_sites(terms, ctrl, assigned(), r, false, units, &mut out);
        }
    }
    // `pre` runs on every cycle of every plan: its indices go with the
    // controller's first plan only, so that each is reported once.
    let first = ctrl.plans.first().is_some_and(|p0| std::ptr::eq(p0, plan));
    if let (Some(pre), true) = (&ctrl.pre, first) {
        let units = pre
            .jobs
            .iter()
            .enumerate()
            .map(|(k, job)| {
                let mut met = Vec::new();
                in_job(ir, ctrl, &printer, job, &mut met);
                (Some(k), met)
            })
            .collect();
        add_sites(terms, ctrl, assigned(), 0, true, units, &mut out);
    }
    out
}

/// The sites of one row (or of `pre`), from the indices each of its units
/// (its condition, then each job) meets.
fn add_sites(
    terms: &mut Terms,
    ctrl: &Controller,
    assigned: &[crate::ir::VarId],
    row: usize,
    pre: bool,
    units: Vec<(Option<usize>, Vec<Met>)>,
    out: &mut Vec<Site>,
) {
    // For a job's index: the condition's indices, all in range (the row
    // fired), then the jobs' before it.
    let mut earlier: Vec<Option<Formula>> = Vec::new();
    for (job, met) in units {
        let outs: Vec<Option<Formula>> = met
            .iter()
            .map(|m| out_formula(terms, ctrl, assigned, &m.index, m.len))
            .collect();
        for (m, o) in met.iter().zip(&outs) {
            // Every other index of the same atom or job is in range too:
            // which of them the interpreter meets first is not modelled,
            // so none may be out.
            let others = outs.iter().filter(|x| !std::ptr::eq(*x, o));
            let in_range: Option<Vec<Formula>> = earlier
                .iter()
                .chain(others)
                .map(|x| x.clone().map(|f| Formula::Not(Box::new(f))))
                .collect();
            let before = match (&m.guard, in_range) {
                (Some(g), Some(mut ins)) => {
                    ins.extend(g.iter().cloned());
                    Some(ins)
                }
                _ => None,
            };
            out.push(Site {
                row,
                job,
                pre,
                array: m.array.clone(),
                index: m.index.clone(),
                len: m.len,
                span: m.span,
                out: o.clone(),
                before,
            });
        }
        // A job's indices are all in range for a later job to run; a
        // condition's, for the row to fire at all.
        earlier.extend(outs);
    }
}

/// `i < 0 || i >= LEN` for an index the analysis models exactly.
fn out_formula(
    terms: &mut Terms,
    ctrl: &Controller,
    assigned: &[crate::ir::VarId],
    index: &Expr,
    len: u32,
) -> Option<Formula> {
    let exact = match as_leaf(index)? {
        Leaf::Param(..)
        | Leaf::SubField(..)
        | Leaf::Call(..)
        | Leaf::StateCycles
        | Leaf::PlanCycles
        | Leaf::SubStale(_)
        | Leaf::BufStale(_) => true,
        Leaf::Buffer(b, _) => ctrl.reads.contains(&b),
        Leaf::Var(v, _) => !assigned.contains(&v),
        Leaf::NewCommand | Leaf::SubStatus(_) | Leaf::SubErrorCode(_) => false,
    };
    if !exact || !matches!(index.ty, Type::Int(_)) {
        return None;
    }
    let cmp = |op: BinOp, n: i128| Expr {
        kind: ExprKind::binary(
            op,
            index.clone(),
            Expr {
                kind: ExprKind::Int(n),
                ty: index.ty.clone(),
                span: index.span,
            },
        ),
        ty: Type::Bool,
        span: index.span,
    };
    let (lo, hi) = match &index.ty {
        Type::Int(t) => t.range(),
        _ => return None,
    };
    let mut parts = Vec::new();
    if lo < 0 {
        parts.push(terms.made_atom(cmp(BinOp::Lt, 0)));
    }
    if hi >= i128::from(len) {
        parts.push(terms.made_atom(cmp(BinOp::Ge, i128::from(len))));
    }
    Some(Formula::Or(parts))
}

/// The indices of condition `e`, each with the operands of `&&` and `||`
/// that must hold for the interpreter to get to it (as the formula of the
/// condition splits them: [`Terms::formula`]).
fn in_condition<'ir>(
    terms: &mut Terms<'ir>,
    printer: &crate::pretty::Printer,
    e: &'ir Expr,
    guard: Vec<Formula>,
    out: &mut Vec<Met>,
) {
    match &e.kind {
        ExprKind::Bool(_) => {}
        ExprKind::Unary(crate::ast::UnOp::Not, x) => in_condition(terms, printer, x, guard, out),
        ExprKind::Binary(op @ (BinOp::And | BinOp::Or), operands) => {
            let [l, r] = &**operands;
            in_condition(terms, printer, l, guard.clone(), out);
            let left = terms.formula(l);
            let mut g = guard;
            g.push(if *op == BinOp::And {
                left
            } else {
                Formula::Not(Box::new(left))
            });
            in_condition(terms, printer, r, g, out);
        }
        _ => in_atom(printer, e, Some(&guard), out),
    }
}

/// The indices inside one atom or job expression. Past an `&&` or `||`
/// inside it, whether the interpreter gets there is not modelled: those
/// indices have no guard.
fn in_atom(
    printer: &crate::pretty::Printer,
    e: &Expr,
    guard: Option<&Vec<Formula>>,
    out: &mut Vec<Met>,
) {
    match &e.kind {
        ExprKind::Binary(BinOp::And | BinOp::Or, operands) => {
            let [l, r] = &**operands;
            in_atom(printer, l, guard, out);
            in_atom(printer, r, None, out);
        }
        ExprKind::IndexBy(base, i) => {
            in_atom(printer, base, guard, out);
            in_atom(printer, i, guard, out);
            if let Type::Array(_, len) = base.ty {
                out.push(Met {
                    index: (**i).clone(),
                    len,
                    span: i.span,
                    array: printer.expr(base),
                    guard: guard.cloned(),
                });
            }
        }
        ExprKind::Field(x, _)
        | ExprKind::Index(x, _)
        | ExprKind::Unary(_, x)
        | ExprKind::Cast(x) => in_atom(printer, x, guard, out),
        ExprKind::Binary(_, operands) => {
            let [l, r] = &**operands;
            in_atom(printer, l, guard, out);
            in_atom(printer, r, guard, out);
        }
        ExprKind::Call(_, args) | ExprKind::Builtin(_, args) => {
            args.iter().for_each(|a| in_atom(printer, a, guard, out))
        }
        _ => {}
    }
}

/// The indices a job meets: in its value, its target's indices, a send's
/// arguments, a hook call's arguments.
fn in_job(
    ir: &Ir,
    ctrl: &Controller,
    printer: &crate::pretty::Printer,
    job: &Job,
    out: &mut Vec<Met>,
) {
    let none = Vec::new();
    match job {
        Job::Assign { place, value, .. } => {
            in_atom(printer, value, Some(&none), out);
            for i in &place.indices {
                in_atom(printer, i, Some(&none), out);
            }
            for (k, len) in target_lengths(ir, ctrl, place) {
                let Some(i) = place.indices.get(k) else {
                    continue;
                };
                out.push(Met {
                    index: i.clone(),
                    len,
                    span: i.span,
                    array: printer.place(place),
                    guard: Some(Vec::new()),
                });
            }
        }
        Job::Send { args, .. } => args
            .iter()
            .for_each(|a| in_atom(printer, a, Some(&none), out)),
        Job::Call(e) => in_atom(printer, e, Some(&none), out),
        Job::Report { .. } | Job::Forward { .. } => {}
    }
}

/// Per run-time index of an assignment target (by its position in
/// [`Place::indices`]), the length of the array it indexes.
fn target_lengths(ir: &Ir, ctrl: &Controller, place: &Place) -> Vec<(usize, u32)> {
    let mut ty = match place.root {
        PlaceRoot::Var(v) => ctrl.vars[v.index()].ty.clone(),
        PlaceRoot::Buffer(b) => Type::Buffer(ir.buffers[b.index()].ty),
    };
    let mut out = Vec::new();
    for p in &place.path {
        ty = match (p, &ty) {
            (Projection::Field(f), Type::Buffer(b)) => {
                match ir.buffer_types[b.index()].fields.get(*f as usize) {
                    Some(field) => field.ty.clone(),
                    None => return out,
                }
            }
            (Projection::Index(_), Type::Array(e, _)) => (**e).clone(),
            (Projection::IndexBy(k), Type::Array(e, n)) => {
                out.push((*k as usize, *n));
                (**e).clone()
            }
            _ => return out,
        };
    }
    out
}

impl PlanAnalysis<'_> {
    /// The indices by a run-time value of this plan's rows.
    pub fn index_sites(&self) -> &[Site] {
        &self.sites
    }

    /// Every site whose index can fall outside its array on a cycle the
    /// interpreter gets to it, each with a replayed run: in the first
    /// state (in state order) where one is found.
    pub fn out_of_range(&self) -> Vec<OutOfRange> {
        if self.skipped || self.sites.iter().all(|s| s.out.is_none()) {
            return Vec::new();
        }
        let paths = self.paths();
        let mut found = Vec::new();
        for (i, site) in self.sites.iter().enumerate() {
            let (Some(out), Some(before)) = (&site.out, &site.before) else {
                continue;
            };
            if site.pre {
                // The command's first cycle: `pre` runs before any row.
                let f = Formula::And(before.iter().chain([out]).cloned().collect());
                let Some(Some(prefix)) = paths.first() else {
                    continue;
                };
                if let Some((witness, run)) = self.index_run(prefix, site, StateId::S0, &f) {
                    found.push(OutOfRange {
                        site: i,
                        witness,
                        run,
                    });
                }
                continue;
            }
            for (s, prefix) in paths.iter().enumerate() {
                let state = StateId(s as u32);
                let Some(prefix) = prefix else { continue };
                if !covers(&self.plan.rows[site.row].from, state) {
                    continue;
                }
                let Some(f) = self.reaches_out(site, state, out, before) else {
                    continue;
                };
                let hit = self
                    .index_run(prefix, site, state, &f)
                    .or_else(|| self.index_run_with_params(site, state, &f));
                if let Some((witness, run)) = hit {
                    found.push(OutOfRange {
                        site: i,
                        witness,
                        run,
                    });
                    break;
                }
            }
        }
        found
    }

    /// "The interpreter gets to `site` in `state` and its index is out".
    fn reaches_out(
        &self,
        site: &Site,
        state: StateId,
        out: &Formula,
        before: &[Formula],
    ) -> Option<Formula> {
        let mut parts = Vec::new();
        match site.job {
            // The row fires: its condition holds, no earlier one does.
            Some(_) => parts.push(self.fires(site.row, state)?),
            // The earlier rows covering `state` do not match.
            None => {
                for j in 0..site.row {
                    if let (Some(c), true) =
                        (&self.conds[j], covers(&self.plan.rows[j].from, state))
                    {
                        parts.push(Formula::NotShared(c.clone()));
                    }
                }
            }
        }
        parts.extend(before.iter().cloned());
        parts.push(out.clone());
        Some(Formula::And(parts))
    }

    /// [`index_run`](Self::index_run) along a way to `state` taken with
    /// the command's parameters a witness of the question picks: the way
    /// found first may have fixed them in range.
    fn index_run_with_params(
        &self,
        site: &Site,
        state: StateId,
        f: &Formula,
    ) -> Option<(Witness, Run)> {
        if state == StateId::S0 {
            return None;
        }
        let super::Answer::Can(free) = self.decide(f, self.known(state).as_slice(), state) else {
            return None;
        };
        let given: Vec<_> = free
            .inputs
            .iter()
            .filter(|(l, _)| matches!(l, Leaf::Param(..)))
            .filter_map(|(l, v)| Some((self.terms.find(l)?, v.clone())))
            .collect();
        if given.is_empty() {
            return None;
        }
        let paths = self.paths_given(&given);
        let prefix = paths.get(state.index())?.as_ref()?;
        self.index_run(prefix, site, state, f)
    }

    /// After `prefix`, a step on whose last cycle `site`'s index is out of
    /// range and the plan ends with `INDEX_RANGE`, replayed.
    fn index_run(
        &self,
        prefix: &Run,
        site: &Site,
        state: StateId,
        f: &Formula,
    ) -> Option<(Witness, Run)> {
        let expect = Expect::IndexRange {
            row: (site.job.is_some() && !site.pre).then(|| row_name(&self.plan.rows[site.row])),
        };
        for wait in self.waits_after(prefix)? {
            let fixed = self.pins_after(prefix, wait)?;
            let super::Answer::Can(w) = self.decide(f, &fixed, state) else {
                continue;
            };
            if let Some(run) = self.extend(prefix, &w, wait + 1, expect.clone()) {
                return Some((w, run));
            }
        }
        None
    }
}
