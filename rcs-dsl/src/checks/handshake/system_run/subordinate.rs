//! The subordinate's part of a system run (`super`): its own run, on its
//! plan, to the answer a supervisor's run played — a row that ends in
//! `Done`, fails or reports the status, found by the path search with the
//! command's parameters pinned to the arguments really sent, and replayed
//! there — and, where the supervisor passes its own parameters on, the
//! values with which the subordinate fails.

use super::super::visible_reports;
use crate::analysis::run::Run;
use crate::analysis::{covers, PlanAnalysis};
use crate::interp::Value;
use crate::ir::{CommandId, CtrlId, Ir, StateId, StatusId, Target};
use std::collections::BTreeMap;

/// A run of subordinate `x`'s plan for `verb` (its parameters at `args`)
/// to the answer `status`: a row that ends in `Done` for `DONE`, a failure
/// for `ERROR`, a row whose report of `status` is seen otherwise.
pub(super) fn answer_run(
    ir: &Ir,
    x: CtrlId,
    verb: CommandId,
    args: &[Value],
    status: &str,
) -> Option<Run> {
    if status == "ERROR" {
        return failure_run(ir, x, verb, args)
            .map(|(_, run)| run)
            .or_else(|| index_range_run(ir, x, verb));
    }
    let c = ir.controller(x);
    let wanted = if status == "DONE" {
        None
    } else {
        Some(StatusId(
            c.statuses.iter().position(|s| s.name == status)? as u32
        ))
    };
    run_to_row(ir, x, verb, args, |r| match wanted {
        None => matches!(r.to, Target::Done),
        Some(s) => visible_reports(r).iter().any(|(v, _)| *v == s),
    })
    .map(|(_, run)| run)
}

/// A run of subordinate `x`'s plan for `verb`, its parameters at `args`
/// (free where `args` is shorter), from the command to a row that fails
/// (ends in `Error` or reports `ERROR`), with that row; replayed by the
/// path search.
pub(crate) fn failure_run(
    ir: &Ir,
    x: CtrlId,
    verb: CommandId,
    args: &[Value],
) -> Option<(usize, Run)> {
    run_to_row(ir, x, verb, args, |r| {
        matches!(r.to, Target::Error(_) | Target::ErrorOf(_))
            || visible_reports(r)
                .iter()
                .any(|(s, _)| *s == StatusId::ERROR)
    })
}

/// A run of subordinate `x`'s plan for `verb`, its parameters at `args`,
/// from the command to the first row `wanted` picks that a run reaches,
/// with that row.
fn run_to_row(
    ir: &Ir,
    x: CtrlId,
    verb: CommandId,
    args: &[Value],
    wanted: impl Fn(&crate::ir::Row) -> bool,
) -> Option<(usize, Run)> {
    let c = ir.controller(x);
    let plan = &c.plans[c.commands.get(verb.index())?.plan?.index()];
    let an = PlanAnalysis::new(ir, c, plan);
    if !an.analysed() {
        return None;
    }
    let given = super::super::rejected::pinned(&an, args);
    let paths = an.paths_given(&given);
    plan.rows.iter().enumerate().find_map(|(i, r)| {
        if !wanted(r) {
            return None;
        }
        paths
            .iter()
            .enumerate()
            .find_map(|(s, prefix)| {
                let at = StateId(s as u32);
                let prefix = prefix.as_ref()?;
                if !covers(&r.from, at) {
                    return None;
                }
                let to = match r.to {
                    Target::State(t) => t,
                    _ => at,
                };
                an.fire_from_given(prefix, i, at, to, &given)
            })
            .map(|run| (i, run))
    })
}

/// A run of subordinate `x`'s plan for `verb` that stops with the built-in
/// `INDEX_RANGE` (the `index_range` check's own replayed run).
fn index_range_run(ir: &Ir, x: CtrlId, verb: CommandId) -> Option<Run> {
    let c = ir.controller(x);
    let plan = &c.plans[c.commands.get(verb.index())?.plan?.index()];
    let an = PlanAnalysis::new(ir, c, plan);
    an.out_of_range().into_iter().next().map(|o| o.run)
}

/// The supervisor's `run` with its command's parameters changed where its
/// plan passes them on to subordinate `x` (`X <- V(p: cmd.q)`), to values
/// with which `x` can fail at `V`; for a forwarded command (`X <- cmd`),
/// the verb of the plan whose forward can fail, with such parameters.
/// `None` when nothing is passed on or no failure is found.
pub(super) fn passing_on(ir: &Ir, run: &Run, x: CtrlId) -> Option<Run> {
    let sc = ir.controller(ir.controller_by_name(&run.controller)?);
    let k = sc.commands.iter().find(|k| k.name == run.command)?;
    let plan = &sc.plans[k.plan?.index()];
    plan.rows.iter().flat_map(|r| &r.jobs).find_map(|j| {
        if let crate::ir::Job::Forward { sub, commands, .. } = j {
            if *sub != x {
                return None;
            }
            // A forward passes the verb's parameters on by name.
            return commands.iter().find_map(|(mine, theirs)| {
                let wanted = failing_params(ir, x, *theirs)?;
                let mut out = run.clone();
                out.command = sc.commands[mine.index()].name.clone();
                out.params = wanted;
                (out != *run).then_some(out)
            });
        }
        let (command, args) = j.send_to(x)?;
        let passed: Vec<(usize, usize)> = args
            .iter()
            .enumerate()
            .filter_map(|(i, e)| match e.kind {
                crate::ir::ExprKind::CmdParam(_, q) => Some((i, q.index())),
                _ => None,
            })
            .collect();
        if passed.is_empty() {
            return None;
        }
        let wanted = failing_params(ir, x, command)?;
        let theirs = &ir.controller(x).commands[command.index()].params;
        let mut out = run.clone();
        for (i, q) in passed {
            if let (Some(p), Some(mine)) = (theirs.get(i), k.params.get(q)) {
                if let Some(v) = wanted.get(&p.name) {
                    out.params.insert(mine.name.clone(), v.clone());
                }
            }
        }
        (out != *run).then_some(out)
    })
}

/// Parameters, by name, with which subordinate `x` can answer `ERROR` to
/// `verb`: a failing row's run, a built-in `INDEX_RANGE`'s, a refusal's.
fn failing_params(
    ir: &Ir,
    x: CtrlId,
    verb: CommandId,
) -> Option<BTreeMap<String, serde_json::Value>> {
    if let Some(run) = failure_run(ir, x, verb, &[])
        .map(|(_, run)| run)
        .or_else(|| index_range_run(ir, x, verb))
    {
        return Some(run.params);
    }
    let c = ir.controller(x);
    let k = c.commands.get(verb.index())?;
    let plan = &c.plans[k.plan?.index()];
    let w = PlanAnalysis::new(ir, c, plan).refusal()?;
    Some(
        w.inputs
            .iter()
            .filter_map(|(leaf, v)| match leaf {
                crate::analysis::terms::Leaf::Param(p, path) if path.is_empty() => {
                    let param = k.params.get(p.index())?;
                    let j = crate::analysis::run::json_of(ir, &param.ty, v)?;
                    Some((param.name.clone(), j))
                }
                _ => None,
            })
            .collect(),
    )
}
