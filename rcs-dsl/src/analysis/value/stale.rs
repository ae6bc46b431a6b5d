//! The question behind `read_before_assign`: does a row, on the first
//! cycle of a command, read a var that this command's jobs set later —
//! while it still holds what an earlier command left there, and so that
//! the plan takes another row than it would on a fresh controller?
//!
//! Candidates are found from the IR: a var that some job of the plan
//! assigns (and `pre`/`post` do not), read by the condition of a row
//! that covers `S0`. The earlier command is a run of the same plan — a
//! path ([`PlanAnalysis::paths`]), or one continued by a row that ends
//! the command or stays and counts — that leaves the var changed from its
//! initial value, replayed; a value another plan leaves is a setting
//! carried on purpose, and not looked at. The conditions
//! analysis then gives inputs under which that row fires on the arrival
//! cycle of this plan's command with the vars as the earlier command left
//! them; the same inputs on a fresh controller are played too. Only when
//! every other var and `writes` field the conditions read is as on a
//! fresh controller, and both runs replay and fire different rows, is
//! there a finding — a difference that only the var's stale value can
//! make, shown by the interpreter, not a guess. A candidate the search
//! does not settle says nothing.

use super::trace;
use crate::analysis::run::{replay_on, row_name, Expect, Run, RunCommand};
use crate::analysis::terms::Leaf;
use crate::analysis::{Answer, PlanAnalysis};
use crate::ir::{Condition, Controller, Expr, ExprKind, Ir, Job, PlaceRoot, StateId, VarId};
use crate::source::Span;

/// A row that read an earlier command's value, with the two runs.
#[derive(Clone, Debug)]
pub struct StaleRead {
    pub row: usize,
    pub var: VarId,
    /// Where the condition reads the var.
    pub span: Span,
    /// The earlier command, as a scenario writes it (`START`).
    pub earlier: String,
    /// The value it left, as the language writes it.
    pub value: String,
    /// What a fresh controller fires with the same inputs (`E1`, or `no row`).
    pub fresh: String,
    pub shown: Vec<(String, String)>,
    /// The earlier command's path, then this plan's command.
    pub run: Run,
}

/// The stale reads of the plan of `an` (of controller `c`), one per row
/// and var at most.
pub fn stale_reads(ir: &Ir, c: &Controller, an: &PlanAnalysis) -> Vec<StaleRead> {
    let plan = an.plan;
    if !an.analysed() || plan.states.is_empty() {
        return Vec::new();
    }
    let Some(ctrl) = an.ctrl_id() else {
        return Vec::new();
    };
    let every = c.every_cycle_jobs().collect::<Vec<_>>();
    let mut candidates: Vec<(usize, VarId)> = Vec::new();
    for (r, row) in plan.rows.iter().enumerate() {
        let Condition::When(cond) = &row.cond else {
            continue;
        };
        if !row.applies_in(StateId::S0) {
            continue;
        }
        for (v, _) in c.vars.iter().enumerate() {
            let v = VarId(v as u32);
            let set_here = plan
                .rows
                .iter()
                .flat_map(|r| &r.jobs)
                .any(|j| assigns(j, v));
            let set_every = every.iter().any(|j| assigns(j, v));
            if set_here && !set_every && super::reads_var(cond, v) {
                candidates.push((r, v));
            }
        }
    }
    if candidates.is_empty() {
        return Vec::new();
    }
    let fresh = crate::interp::Interpreter::new(ir, ctrl);
    let (fresh_vars, fresh_writes) = (fresh.vars().to_vec(), fresh.writes().to_vec());
    // The earlier commands: every path of every plan, as it leaves the vars.
    let mut earlier: Vec<(
        Run,
        Vec<rcs_runtime::driver::Value>,
        Vec<rcs_runtime::driver::Value>,
    )> = Vec::new();
    // Runs of this same plan only: a value another plan leaves is a
    // setting carried on purpose (a HOME that leaves `homed` for MOVE),
    // not this plan's stale state.
    {
        let other = an;
        let paths = other.paths();
        let mut runs: Vec<Run> = Vec::new();
        for (s, run) in paths.iter().enumerate() {
            let Some(run) = run else { continue };
            // The rows that end the command from here, when their jobs
            // set a candidate var (`-> Error { failed = true }`).
            runs.extend(ending_runs(
                ir,
                other,
                ctrl,
                run,
                StateId(s as u32),
                &candidates,
            ));
            if !run.steps.is_empty() {
                runs.push(run.clone());
            }
        }
        for run in runs {
            if let Ok(d) = replay_on(ir, ctrl, &run) {
                let i = d.interpreter();
                earlier.push((run, i.vars().to_vec(), i.writes().to_vec()));
            }
        }
    }
    let mut out: Vec<StaleRead> = Vec::new();
    for (r, v) in candidates {
        for (prefix, vars, writes) in &earlier {
            if super::probe::same(&vars[v.index()], &fresh_vars[v.index()]) {
                continue;
            }
            // Every other var and `writes` field the conditions read as on
            // a fresh controller: the difference the runs show is `v`'s.
            let others_fresh = an.terms.leaves.iter().all(|(leaf, _)| match leaf {
                Leaf::Var(u, _) if *u == v => true,
                Leaf::Var(u, _) => super::probe::same(&vars[u.index()], &fresh_vars[u.index()]),
                Leaf::Buffer(b, _) => match c.writes.iter().position(|x| x == b) {
                    Some(i) => super::probe::same(&writes[i], &fresh_writes[i]),
                    None => true,
                },
                _ => true,
            });
            if !others_fresh {
                continue;
            }
            if let Some(found) = stale_run(ir, c, an, ctrl, r, v, prefix, vars, writes) {
                out.push(found);
                break;
            }
        }
    }
    out
}

/// How many firings of a row that stays and sets a var the earlier
/// commands try (the runs cut after each of these counts).
const LOOPS: [usize; 6] = [1, 2, 3, 4, 8, 16];

/// `prefix`, then each row of `an`'s plan that sets a var of
/// `candidates` from `state`, fired (after a wait for a counter if it
/// needs one) and replayed: a row that ends the command (`-> Error {
/// failed = true }`) once, a row that stays (`-> same { tries += 1 }`)
/// held for a few firings.
fn ending_runs(
    ir: &Ir,
    an: &PlanAnalysis,
    ctrl: crate::ir::CtrlId,
    prefix: &Run,
    state: StateId,
    candidates: &[(usize, VarId)],
) -> Vec<Run> {
    let mut out = Vec::new();
    let Some(waits) = an.waits_after(prefix) else {
        return out;
    };
    let start: usize = prefix.steps.iter().map(|s| s.cycles.max(1) as usize).sum();
    for (r, row) in an.plan.rows.iter().enumerate() {
        let sets = row
            .jobs
            .iter()
            .any(|j| candidates.iter().any(|(_, v)| assigns(j, *v)));
        if !sets || !row.applies_in(state) || (prefix.steps.is_empty() && state != StateId::S0) {
            continue;
        }
        for &wait in &waits {
            let Some(fixed) = an.pins_after(prefix, wait) else {
                break;
            };
            let Answer::Can(w) = an.can_fire_in_given(r, state, &fixed) else {
                continue;
            };
            let probe = Expect::Stays { state: "S0".into() };
            let held = wait + LOOPS[LOOPS.len() - 1] as u32;
            let Some(run) = an.step_run(prefix, &w, held, probe) else {
                continue;
            };
            let Some(t) = trace(ir, ctrl, &run) else {
                continue;
            };
            let recs = &t.records;
            // The cycles on which row `r` fired, from the probed step on.
            let fired: Vec<usize> = (start..recs.len())
                .filter(|&k| recs[k].fired.map(usize::from) == Some(r))
                .collect();
            let mut any = false;
            for n in LOOPS {
                let Some(&end) = fired.get(n - 1) else { break };
                if let Some(cut) = an.cut(prefix, &w, recs, start, end, end, None) {
                    if replay_on(ir, ctrl, &cut).is_ok() {
                        out.push(cut);
                        any = true;
                    }
                }
            }
            if any {
                break;
            }
        }
    }
    out
}

#[allow(clippy::too_many_arguments)]
fn stale_run(
    ir: &Ir,
    c: &Controller,
    an: &PlanAnalysis,
    ctrl: crate::ir::CtrlId,
    r: usize,
    v: VarId,
    prefix: &Run,
    vars: &[rcs_runtime::driver::Value],
    writes: &[rcs_runtime::driver::Value],
) -> Option<StaleRead> {
    let plan = an.plan;
    let empty = an.empty_run();
    // The arrival cycle as on a fresh controller (`new_command`, the
    // counters), with the vars and `writes` the earlier command left.
    let mut fixed = an.pins_after(&empty, 0)?;
    for (l, (leaf, _)) in an.terms.leaves.iter().enumerate() {
        let value = match leaf {
            Leaf::Var(u, steps) => crate::analysis::path::at_path(&vars[u.index()], steps),
            Leaf::Buffer(b, steps) if !c.reads.contains(b) => {
                let i = c.writes.iter().position(|w| w == b)?;
                crate::analysis::path::at_path(&writes[i], steps)
            }
            _ => continue,
        };
        fixed.retain(|(k, _)| *k != l);
        fixed.push((l, value?));
    }
    let Answer::Can(w) = an.can_fire_in_given(r, StateId::S0, &fixed) else {
        return None;
    };
    let probe = Expect::Stays { state: "S0".into() };
    // This plan's command with those inputs, on a fresh controller…
    let mut fresh = an.step_run(&empty, &w, 1, probe.clone())?;
    let fresh_fired = trace(ir, ctrl, &fresh)?.records.first()?.clone();
    if fresh_fired.fired.map(usize::from) == Some(r) {
        return None;
    }
    *fresh.steps.last_mut()? = with_expect(an, fresh.steps.last()?, &fresh_fired)?;
    replay_on(ir, ctrl, &fresh).ok()?;
    // …and after the earlier command.
    let step = fresh.steps.last()?.clone();
    let mut run = prefix.clone();
    let mut step = step;
    step.command = Some(RunCommand {
        verb: empty.command.clone(),
        params: fresh.params.clone(),
    });
    run.steps.push(step);
    let played = trace(ir, ctrl, &run)?;
    let last = played.records.last()?.clone();
    if last.fired.map(usize::from) != Some(r) {
        return None;
    }
    *run.steps.last_mut()? = with_expect(an, run.steps.last()?, &last)?;
    replay_on(ir, ctrl, &run).ok()?;
    let Condition::When(cond) = &plan.rows[r].cond else {
        return None;
    };
    let span = first_read(cond, v).unwrap_or(plan.rows[r].cond_span);
    let var = &c.vars[v.index()];
    let mut shown = vec![
        ("first command".to_string(), super::command_text(prefix)),
        ("then command".to_string(), super::command_text(&fresh)),
    ];
    let is_var = |n: &str| {
        c.vars.iter().any(|x| {
            n == x.name
                || n.starts_with(&format!("{}.", x.name))
                || n.starts_with(&format!("{}[", x.name))
        })
    };
    let counter = |n: &str| ["new_command", "state_cycles", "plan_cycles"].contains(&n);
    shown.extend(
        w.shown
            .iter()
            .filter(|(n, _)| !counter(n) && !n.starts_with("cmd.") && !is_var(n))
            .cloned(),
    );
    Some(StaleRead {
        row: r,
        var: v,
        span,
        earlier: prefix.command.clone(),
        value: an.value_text(&var.ty, &vars[v.index()]),
        fresh: fresh_fired
            .fired
            .and_then(|f| plan.rows.get(usize::from(f)))
            .map_or_else(|| "no row".to_string(), row_name),
        shown,
        run,
    })
}

/// `step` expecting what `rec` shows: the row fired and the state after.
fn with_expect(
    an: &PlanAnalysis,
    step: &crate::analysis::run::RunStep,
    rec: &rcs_runtime::driver::Record,
) -> Option<crate::analysis::run::RunStep> {
    let state = an.plan.states.get(usize::from(rec.state))?.name.clone();
    let expect = match rec.fired {
        None => Expect::Stays { state },
        Some(f) => Expect::Fires {
            row: row_name(an.plan.rows.get(usize::from(f))?),
            state,
        },
    };
    Some(crate::analysis::run::RunStep {
        expect,
        ..step.clone()
    })
}

fn assigns(j: &Job, v: VarId) -> bool {
    matches!(j, Job::Assign { place, .. } if place.root == PlaceRoot::Var(v))
}

/// Where `e` first reads var `v`.
fn first_read(e: &Expr, v: VarId) -> Option<Span> {
    let mut found = None;
    e.visit(&mut |x| {
        if found.is_none() && matches!(x.kind, ExprKind::Var(y) if y == v) {
            found = Some(x.span);
        }
    });
    found
}
