//! Stage 3a, the value analysis: what the values of vars, `writes` fields
//! and sends become under the language's one arithmetic ([`crate::arith`]:
//! wrapping integers, `/0 = 0`, IEEE floats), behind the lints `int_wrap`,
//! `div_by_zero`, `nan_path` and `read_before_assign`.
//!
//! The conditions analysis ([`super::PlanAnalysis`]) decides one cycle
//! over *cells* of the leaves; values built up over many cycles (a counter
//! stepping by 10 towards 255) are beyond it. So this analysis does not
//! prove; it *shows*. From each state the path search reaches
//! ([`super::path`]), for each row with arithmetic in its jobs (or, for the
//! controller's first plan, any row when `pre`/`post` compute), it asks the
//! conditions analysis for inputs under which the row fires — first with
//! the operands a scenario can set pinned to values that make the
//! operation go wrong (a divisor of 0, an addend at the type's top), then
//! without — holds those inputs for up to [`HOLD`] cycles on the reference
//! interpreter, and performs every cycle's jobs again on the values the
//! interpreter had before it ([`probe`]), noting each operation that
//! wraps, divides by 0 or makes a NaN. A cycle whose recomputed vars and
//! `writes` differ from the interpreter's record is not judged.
//!
//! An event becomes a finding only where its value *matters*, decided on
//! the same trace ([`sink`]): it is sent, published (a `writes` field or a
//! status field not assigned again that cycle), passed on in the same
//! cycle to a send or an output, or read by the condition of a row the
//! interpreter evaluated on the next cycle (the part of the condition
//! before any `&&`/`||`, which is always evaluated); a NaN counts instead
//! when it *latches* — no row that leaves the state can match while the
//! var is NaN (a proof by the conditions analysis) and every job that
//! can run there keeps it NaN. The trace is then cut into a [`Run`] and
//! replayed from a fresh controller through its scenario text; only a run
//! that replays is attached. Guards need no special case: a row whose
//! condition excludes the bad value never fires with it, so the
//! interpreter never meets it. What the search does not meet, it does not
//! report: silence is not a proof.
//!
//! `read_before_assign` ([`stale`]) runs two commands: one that leaves a
//! var changed, then the plan whose rows read it before its own jobs set
//! it, and shows that the row fired on the second command's first cycle
//! differs from a fresh controller's with the same inputs.

pub mod probe;
mod sink;
mod sites;
pub mod stale;

use super::run::{json_of, replay_on, row_name, Expect, Firing, Run, RunStep};
use super::terms::Leaf;
use super::{Answer, PlanAnalysis, Witness};
use crate::interp;
use crate::ir::{CtrlId, Expr, ExprKind, Job, StateId, Type, VarId};
use probe::{Env, Kind, Unit};
use rcs_runtime::driver::{Record, Value};
pub use sink::Sink;

/// How many cycles a probe holds a row's inputs, watching for an event:
/// a `u8` counter stepping by one wraps within it.
pub const HOLD: u32 = 300;

/// The hold of a probe whose operations read no var: the event, if any,
/// is on the row's first firing; the cycles after show where it goes.
const SHORT_HOLD: u32 = 4;

/// The most probes (a row's inputs held from a state) per plan.
const MAX_PROBES: usize = 64;

/// An operation that went wrong where its value matters, with the run
/// that shows it.
#[derive(Clone, Debug)]
pub struct ValueFinding {
    pub kind: Kind,
    /// Where the job is: `pre`, a row, or `post`.
    pub unit: Unit,
    pub job: usize,
    /// The operation.
    pub span: crate::source::Span,
    /// `250 + 10 gives 4`.
    pub text: String,
    pub sink: Sink,
    /// The state the plan was in on the cycle of the event.
    pub state: StateId,
    /// The cycle of the command it happened on (1 is the first).
    pub cycle: u64,
    /// The inputs the run holds, as the language writes them.
    pub shown: Vec<(String, String)>,
    pub run: Run,
}

impl PlanAnalysis<'_> {
    /// Every operation of this plan's jobs (and, for the controller's
    /// first plan, of `pre` and `post`) that the probes see wrap, divide
    /// by zero or make a NaN where the value matters; one per operation.
    pub fn value_findings(&self) -> Vec<ValueFinding> {
        if !self.analysed() {
            return Vec::new();
        }
        let Some(ctrl) = self.ctrl_id() else {
            return Vec::new();
        };
        let first = self
            .ctrl
            .plans
            .first()
            .is_some_and(|p| std::ptr::eq(p, self.plan));
        let every_ops = first.then(|| {
            let jobs: Vec<Job> = self.ctrl.every_cycle_jobs().cloned().collect();
            sites::operations(self.ctrl, &jobs)
        });
        let every = every_ops.is_some_and(|(any, _)| any);
        // Per row: whether to probe it, and for how many cycles.
        let holds: Vec<Option<u32>> = self
            .plan
            .rows
            .iter()
            .map(|r| {
                let (any, accumulates) = sites::operations(self.ctrl, &r.jobs);
                let accumulates = accumulates || every_ops.is_some_and(|(_, a)| a);
                (any || every).then_some(if accumulates { HOLD } else { SHORT_HOLD })
            })
            .collect();
        if holds.iter().all(Option::is_none) {
            return Vec::new();
        }
        let paths = self.paths();
        let mut found: Vec<ValueFinding> = Vec::new();
        let mut probes = 0;
        for (s, prefix) in paths.iter().enumerate() {
            let Some(prefix) = prefix else { continue };
            let state = StateId(s as u32);
            for (r, row) in self.plan.rows.iter().enumerate() {
                let Some(hold) = holds[r] else { continue };
                if !row.applies_in(state) {
                    continue;
                }
                for hint in self.hints(r, prefix.steps.is_empty(), every) {
                    if probes >= MAX_PROBES {
                        return found;
                    }
                    probes += 1;
                    for f in self.probe(ctrl, prefix, state, r, &hint, hold) {
                        if !found.iter().any(|g| g.kind == f.kind && g.span == f.span) {
                            found.push(f);
                        }
                    }
                }
            }
        }
        found
    }

    /// Hold the inputs under which row `r` fires in `state` after
    /// `prefix` (with `hint`'s leaves pinned) and judge each cycle.
    fn probe(
        &self,
        ctrl: CtrlId,
        prefix: &Run,
        state: StateId,
        r: usize,
        hint: &[(Leaf, Value)],
        hold: u32,
    ) -> Vec<ValueFinding> {
        let Some(waits) = self.waits_after(prefix) else {
            return Vec::new();
        };
        for wait in waits {
            let Some(mut fixed) = self.pins_after(prefix, wait) else {
                return Vec::new();
            };
            let mut extra = Vec::new();
            for (leaf, v) in hint {
                match self.terms.find(leaf) {
                    Some(l) => fixed.push((l, v.clone())),
                    None => extra.push((leaf.clone(), v.clone())),
                }
            }
            let Answer::Can(mut w) = self.can_fire_in_given(r, state, &fixed) else {
                continue;
            };
            for (leaf, v) in extra {
                w.shown.push((self.leaf_name(&leaf), probe::show(&v)));
                w.inputs.push((leaf, v));
            }
            let held = Expect::Stays { state: "S0".into() };
            let Some(run) = self.step_run(prefix, &w, wait + 1 + hold, held) else {
                return Vec::new();
            };
            let Some(trace) = trace(self.ir, ctrl, &run) else {
                return Vec::new();
            };
            return self.judge(ctrl, prefix, &w, &trace);
        }
        Vec::new()
    }

    /// The leaves a scenario sets, pinned to values that make an
    /// operation of row `r`'s jobs go wrong, one set per operation; then
    /// none (the row's own inputs). Parameters only on the command's
    /// first cycle (`first`), when the step still chooses them.
    fn hints(&self, r: usize, first: bool, every: bool) -> Vec<Vec<(Leaf, Value)>> {
        let mut out: Vec<Vec<(Leaf, Value)>> = Vec::new();
        let settable = |l: &Leaf| match l {
            Leaf::Param(..) => first,
            Leaf::Buffer(b, _) => self.ctrl.reads.contains(b),
            Leaf::Call(..) | Leaf::SubField(_, _, _) => true,
            _ => false,
        };
        let mut add = |e: &Expr| {
            if let Some(h) = hint_of(e) {
                let known = out.iter().any(|o| format!("{o:?}") == format!("{h:?}"));
                if h.iter().all(|(l, _)| settable(l)) && !known {
                    out.push(h);
                }
            }
        };
        crate::ir::visit_job_exprs(&self.plan.rows[r].jobs, &mut add);
        if every {
            for b in [&self.ctrl.pre, &self.ctrl.post] {
                crate::ir::visit_job_exprs(every_cycle(b), &mut add);
            }
        }
        out.push(Vec::new());
        out
    }

    /// Each cycle of `trace` from the probed step on, its jobs performed
    /// again; the events whose value matters, each with its run replayed.
    fn judge(&self, ctrl: CtrlId, prefix: &Run, w: &Witness, trace: &Trace) -> Vec<ValueFinding> {
        let start: usize = prefix.steps.iter().map(|s| s.cycles.max(1) as usize).sum();
        let recs = &trace.records;
        let i = trace.driven.interpreter();
        let fresh = interp::Interpreter::new(self.ir, ctrl);
        let mut out: Vec<ValueFinding> = Vec::new();
        for c in start..recs.len() {
            let (vars, writes, before) = match c.checked_sub(1) {
                Some(p) => (&recs[p].vars, &recs[p].writes, Some(&recs[p])),
                None => (&fresh.vars().to_vec(), &fresh.writes().to_vec(), None),
            };
            let rec = &recs[c];
            let fired = rec.fired.map(usize::from);
            let mut env = Env {
                ctrl: self.ctrl,
                vars: vars.clone(),
                writes: writes.clone(),
                reads: i.reads(),
                params: &i.command_buffer().2,
            };
            let mut hits = Vec::new();
            let ok = probe::perform(every_cycle(&self.ctrl.pre), Unit::Pre, &mut env, &mut hits)
                && fired.is_none_or(|f| {
                    probe::perform(&self.plan.rows[f].jobs, Unit::Row(f), &mut env, &mut hits)
                })
                && probe::perform(
                    every_cycle(&self.ctrl.post),
                    Unit::Post,
                    &mut env,
                    &mut hits,
                );
            let agrees = ok
                && env.vars.len() == rec.vars.len()
                && env
                    .vars
                    .iter()
                    .zip(&rec.vars)
                    .all(|(a, b)| probe::same(a, b))
                && env
                    .writes
                    .iter()
                    .zip(&rec.writes)
                    .all(|(a, b)| probe::same(a, b));
            if !agrees {
                continue;
            }
            let at = before.map_or(StateId::S0, |b| StateId(u32::from(b.state)));
            for hit in &hits {
                for ev in &hit.events {
                    if out.iter().any(|f| f.kind == ev.kind && f.span == ev.span) {
                        continue;
                    }
                    let Some((sink, more)) = self.sink(hit, ev.kind, recs, c, at) else {
                        continue;
                    };
                    let end = (c + more).min(recs.len() - 1);
                    let vars = self.expected_vars(hit, fired);
                    let Some(run) = self.cut(prefix, w, recs, start, c, end, vars) else {
                        continue;
                    };
                    if replay_on(self.ir, ctrl, &run).is_err() {
                        continue;
                    }
                    out.push(ValueFinding {
                        kind: ev.kind,
                        unit: hit.unit,
                        job: hit.job,
                        span: ev.span,
                        text: ev.text.clone(),
                        sink,
                        state: at,
                        cycle: c as u64 + 1,
                        shown: self.shown(&run, w),
                        run,
                    });
                }
            }
        }
        out
    }

    /// The var a hit's job assigned whole, with the value the scenario
    /// then expects (none for a NaN: a scenario cannot write one).
    fn expected_vars(&self, hit: &probe::Hit, fired: Option<usize>) -> Option<(String, Value)> {
        let jobs = match hit.unit {
            Unit::Row(_) => &self.plan.rows[fired?].jobs,
            Unit::Pre => &self.ctrl.pre.as_ref()?.jobs,
            Unit::Post => &self.ctrl.post.as_ref()?.jobs,
        };
        let Job::Assign { place, .. } = jobs.get(hit.job)? else {
            return None;
        };
        let crate::ir::PlaceRoot::Var(v) = place.root else {
            return None;
        };
        if !place.path.is_empty() {
            return None;
        }
        Some((
            self.ctrl.vars[v.index()].name.clone(),
            hit.assigned.clone()?,
        ))
    }

    /// The run of the trace's cycles up to `end`: the probed step's inputs
    /// first, then steps without inputs, one per stretch of cycles that
    /// fire the same row (or none) into the same state; a step ends at the
    /// event's cycle `c`, where `vars` (a var the event assigned, whole)
    /// is expected.
    #[allow(clippy::too_many_arguments)]
    fn cut(
        &self,
        prefix: &Run,
        w: &Witness,
        recs: &[Record],
        start: usize,
        c: usize,
        end: usize,
        vars: Option<(String, Value)>,
    ) -> Option<Run> {
        let mut run: Option<Run> = None;
        let mut from = start;
        for k in start..=end {
            let last = k == end
                || k == c
                || recs[k + 1].fired != recs[k].fired
                || recs[k + 1].state != recs[k].state;
            if !last {
                continue;
            }
            let cycles = (k - from + 1) as u32;
            from = k + 1;
            let rec = &recs[k];
            let state = self.plan.states.get(usize::from(rec.state))?.name.clone();
            let expect = match rec.fired {
                None => Expect::Stays { state },
                Some(f) => Expect::Repeats {
                    rows: vec![Firing {
                        row: row_name(self.plan.rows.get(usize::from(f))?),
                        state,
                    }],
                },
            };
            let mut next = match run.take() {
                // The first stretch carries the probed inputs.
                None => self.step_run(prefix, w, cycles, expect)?,
                Some(mut r) => {
                    r.steps.push(RunStep {
                        cycles,
                        expect,
                        ..RunStep::default()
                    });
                    r
                }
            };
            if let (true, Some((name, v))) = (k == c, &vars) {
                let var = self.ctrl.vars.iter().find(|x| &x.name == name)?;
                if let (Some(json), Some(step)) =
                    (json_of(self.ir, &var.ty, v), next.steps.last_mut())
                {
                    step.expect_vars.insert(name.clone(), json);
                }
            }
            run = Some(next);
        }
        run
    }

    /// The run's inputs as the language writes them: the command's
    /// parameters, then what the probed step holds.
    fn shown(&self, run: &Run, w: &Witness) -> Vec<(String, String)> {
        let mut out = vec![("command".to_string(), command_text(run))];
        for (name, value) in &w.shown {
            let counter = ["new_command", "state_cycles", "plan_cycles"].contains(&name.as_str());
            let param = name.starts_with("cmd.");
            let var = self.ctrl.vars.iter().any(|v| {
                name == &v.name
                    || name.starts_with(&format!("{}.", v.name))
                    || name.starts_with(&format!("{}[", v.name))
            });
            if !counter && !param && !var {
                out.push((name.clone(), value.clone()));
            }
        }
        out
    }
}

/// A run's command as the language writes a send: `FILL(n: 3)`.
pub(crate) fn command_text(run: &Run) -> String {
    if run.params.is_empty() {
        return run.command.clone();
    }
    let params: Vec<String> = run
        .params
        .iter()
        .map(|(n, v)| format!("{n}: {v}"))
        .collect();
    format!("{}({})", run.command, params.join(", "))
}

/// The values a probe pins to make operation `e` go wrong, when its
/// operands are leaves (or constants): a zero divisor, operands at the
/// edge of the type. `None` for anything else.
fn hint_of(e: &Expr) -> Option<Vec<(Leaf, Value)>> {
    let ExprKind::Binary(op, operands) = &e.kind else {
        return None;
    };
    let [l, r] = &**operands;
    let leaf = |x: &Expr| super::terms::as_leaf(x);
    let konst = |x: &Expr| match x.kind {
        ExprKind::Int(v) => Some(v),
        _ => None,
    };
    use crate::ast::BinOp;
    match (&e.ty, op) {
        (Type::Int(_), BinOp::Div | BinOp::Rem) => Some(vec![(leaf(r)?, Value::Int(0))]),
        (Type::Float(_), BinOp::Div) => {
            let mut h = vec![(leaf(r)?, Value::Float(0.0))];
            if let Some(n) = leaf(l) {
                h.push((n, Value::Float(0.0)));
            }
            Some(h)
        }
        (Type::Int(t), BinOp::Add | BinOp::Sub | BinOp::Mul) => {
            let (lo, hi) = t.range();
            let a = leaf(l)?;
            match (konst(r), leaf(r)) {
                (Some(c), _) => {
                    let v = match op {
                        BinOp::Add if c > 0 => hi - c + 1,
                        BinOp::Add if c < 0 => lo - c - 1,
                        BinOp::Sub if c > 0 => lo + c - 1,
                        BinOp::Sub if c < 0 => hi + c + 1,
                        BinOp::Mul if !(-1..=1).contains(&c) => hi / c.abs() + 1,
                        _ => return None,
                    };
                    Some(vec![(a, Value::Int(v))])
                }
                (None, Some(b)) => match op {
                    BinOp::Add | BinOp::Mul => Some(vec![(a, Value::Int(hi)), (b, Value::Int(hi))]),
                    _ => Some(vec![(a, Value::Int(lo)), (b, Value::Int(hi))]),
                },
                _ => None,
            }
        }
        _ => None,
    }
}

/// A run played on the interpreter, every cycle's record kept, and the
/// interpreter as it ends (its `reads` and parameters are the probed
/// step's, held to the end). The run's expectations are not required to
/// hold: it is a probe.
pub(super) struct Trace<'ir> {
    pub records: Vec<Record>,
    pub driven: interp::Driven<'ir>,
}

pub(super) fn trace<'ir>(ir: &'ir crate::ir::Ir, ctrl: CtrlId, run: &Run) -> Option<Trace<'ir>> {
    let text = super::run::scenario_text(run, "probe", "").ok()?;
    let file = crate::source::SourceFile::new("probe.scenario.yaml", text);
    let scenario = crate::scenario::parse(ir, &file, "probe").ok()?;
    let mut driven = interp::Driven::new(ir, ctrl);
    let mut records = Vec::new();
    crate::scenario::run_observed(ir, &scenario, &mut driven, &mut |r, _| {
        records.push(r.clone())
    });
    Some(Trace { records, driven })
}

/// The jobs of a `pre` or `post` block (none without one).
pub(crate) fn every_cycle(b: &Option<crate::ir::EveryCycle>) -> &[Job] {
    b.as_ref().map_or(&[][..], |b| &b.jobs)
}

/// Whether `e` reads var `v` (whole or in part).
pub(crate) fn reads_var(e: &Expr, v: VarId) -> bool {
    let mut found = false;
    e.visit(&mut |x| found |= matches!(x.kind, ExprKind::Var(y) if y == v));
    found
}

/// Whether evaluating condition `e` always reads var `v`: in the part
/// before any `&&` or `||`, which the interpreter always evaluates.
pub(crate) fn always_reads(e: &Expr, v: VarId) -> bool {
    match &e.kind {
        ExprKind::Binary(crate::ast::BinOp::And | crate::ast::BinOp::Or, operands) => {
            always_reads(&operands[0], v)
        }
        ExprKind::Unary(crate::ast::UnOp::Not, x) => always_reads(x, v),
        _ => reads_var(e, v),
    }
}
