//! `stale_subordinate_status`: a row reads subordinate X's answer (`X.done`,
//! `X.error`, `X.status == S`) in a state the plan can be in before it has
//! commanded X. The supervisor's handshake shows X's answer to the last
//! command it sent X — here an *earlier* plan's — so the row can fire on an
//! old `ERROR` or `DONE` (a second bring-up after a failed one fails at
//! once). Judged only where this plan does command X somewhere (a plan that
//! never does reads X's standing state on purpose), and only for answers X
//! can give to a verb its supervisor sends it. The witness is a run: the
//! way to the state along rows that do not command X, then one cycle on
//! which X still shows the old answer and the row fires, replayed on the
//! interpreter before it is shown.

use super::super::graph::Analysis;
use super::super::Sink;
use super::{failure, sends, status_tests, verbs_sent, verbs_sent_by, Summary, Supervisor};
use crate::analysis::run::{row_name, Expect, Run};
use crate::analysis::terms::Leaf;
use crate::analysis::{covers, Answer, PlanAnalysis};
use crate::diagnostic::{Across, Diagnostic};
use crate::ir::{CtrlId, Ir, Plan, StateId, StatusId, Target};
use crate::lint::Lint;
use rcs_runtime::driver::Value;

pub(crate) fn check_stale_subordinate_status(sup: &Supervisor, sink: &mut Sink) {
    let (ir, summaries) = (sup.ir, sup.summaries);
    let c = sup.controller();
    for (p, an, graph) in sup.plans(true) {
        // Paths to each state, searched once a candidate needs one.
        let paths = std::cell::OnceCell::new();
        for &x in &c.subordinates {
            if verbs_sent(&p.rows, x).is_empty() {
                continue;
            }
            let Some(leaf) = an.terms().find(&Leaf::SubStatus(x)) else {
                continue;
            };
            let shown = answers(ir, c, x, summaries);
            // The states the plan can be in before it commands X, by the
            // graph alone; a run is searched only for a row there.
            let before = uncommanded(p, an, graph, x);
            // One finding per row: the first state where it reads an old answer.
            let mut reported = vec![false; p.rows.len()];
            for (s, _) in before.iter().enumerate().filter(|(_, b)| **b) {
                let state = StateId(s as u32);
                for (i, r) in p.rows.iter().enumerate() {
                    if reported[i] || !covers(&r.from, state) {
                        continue;
                    }
                    for (status, span) in status_tests(r, x) {
                        if reported[i] || !shown.contains(&status) {
                            continue;
                        }
                        let Some(way) = way_to(p, an, &paths, s, x) else {
                            continue;
                        };
                        let way = &way;
                        let Some(mut pins) = an.pins_after(way, 0) else {
                            continue;
                        };
                        pins.push((leaf, Value::Status(status.0 as u16)));
                        let Answer::Can(w) = an.can_fire_in_given(i, state, &pins) else {
                            continue;
                        };
                        let to = match r.to {
                            Target::State(t) => t,
                            _ => state,
                        };
                        let expect = Expect::Fires {
                            row: row_name(r),
                            state: p.states[to.index()].name.clone(),
                        };
                        let Some(run) = an.extend(way, &w, 1, expect) else {
                            continue;
                        };
                        reported[i] = true;
                        let xc = ir.controller(x);
                        let sub = &xc.name;
                        let status_name = &xc.statuses[status.index()].name;
                        let state_name = &p.states[s].name;
                        let when = if way.steps.is_empty() {
                            "on the command's first cycle".to_string()
                        } else {
                            format!("in `{state_name}`")
                        };
                        let d = Diagnostic::lint(
                            Lint::StaleSubordinateStatus,
                            format!(
                                "row {} of plan `{}` can read `{sub}`'s answer to an earlier \
                                 command",
                                r.display_name(),
                                c.plan_title(p)
                            ),
                            span,
                            format!("`{status_name}` here can be an earlier command's answer"),
                        )
                        .with_witness(state_name, &w.shown)
                        .with_run(Some(run))
                        .with_across(Across {
                            sub: x,
                            shows: None,
                            earlier: commanding_run(sup, p, x),
                        })
                        .with_note(format!(
                            "{when} this plan has not yet commanded `{sub}`, so `{}` sees \
                             `{sub}`'s answer to the last command it sent before — another \
                             plan's, or this plan's last run: the row can fire on an old \
                             `{status_name}`",
                            c.name
                        ))
                        .with_help(format!(
                            "read `{sub}`'s answer only in states the plan enters after the row \
                             that commands `{sub}`: narrow the row's state pattern"
                        ));
                        sink.lint(Some(c), Some(p), d);
                    }
                }
            }
        }
    }
}

/// The answers `x` can show to verbs `c` sends it: `DONE`, `ERROR` and
/// custom statuses its plans make visible.
fn answers(ir: &Ir, c: &crate::ir::Controller, x: CtrlId, summaries: &[Summary]) -> Vec<StatusId> {
    let mut shown = Vec::new();
    for v in verbs_sent_by(c, x) {
        if failure(ir, summaries, x, v).is_some() {
            shown.push(StatusId::ERROR);
        }
        if let Some(pid) = ir.controller(x).commands[v.index()].plan {
            shown.extend(summaries[x.index()].reported[pid.index()].iter().copied());
        }
    }
    shown.retain(|s| *s != StatusId::EXECUTING && *s != StatusId::NOT_READY);
    shown.sort();
    shown.dedup();
    shown
}

/// Per state: whether the plan can be in it before it has commanded `x`,
/// from the command's arrival along rows that do not command `x` and that
/// the analysis does not rule out (an over-approximation; each finding is
/// then shown by a replayed run).
fn uncommanded(p: &Plan, an: &PlanAnalysis, graph: &Analysis, x: CtrlId) -> Vec<bool> {
    let mut before = vec![false; p.states.len()];
    if before.is_empty() {
        return before;
    }
    before[0] = true;
    let mut queue = vec![StateId::S0];
    while let Some(at) = queue.pop() {
        for (i, r) in p.rows.iter().enumerate() {
            let Target::State(to) = r.to else { continue };
            if before[to.index()]
                || sends(r, x)
                || graph.never_matches[i]
                || !covers(&r.from, at)
                || an.never_fires_in(i, at)
            {
                continue;
            }
            before[to.index()] = true;
            queue.push(to);
        }
    }
    before
}

/// A replayed run that leaves the plan in state `s` having fired only rows
/// that do not command `x` (`S0`: the empty run, before the first cycle).
fn way_to(
    p: &Plan,
    an: &PlanAnalysis,
    paths: &std::cell::OnceCell<Vec<Option<Run>>>,
    s: usize,
    x: CtrlId,
) -> Option<Run> {
    if s == 0 {
        return Some(an.empty_run());
    }
    let path = paths.get_or_init(|| an.paths()).get(s)?.as_ref()?;
    let clean = path.steps.iter().all(|step| {
        step.expect.fired_rows().iter().all(|name| {
            p.rows
                .iter()
                .find(|r| row_name(r) == *name)
                .is_some_and(|r| !sends(r, x))
        })
    });
    clean.then(|| path.clone())
}

/// A run of one of the supervisor's plans (`first` before the others)
/// that commands `x`: the way to a row that sends `x` a command, and that
/// row firing; replayed. What the system run of a finding plays first, so
/// that `x` has an earlier command to answer.
fn commanding_run(sup: &Supervisor, first: &Plan, x: CtrlId) -> Option<Run> {
    let mut plans: Vec<(&Plan, &PlanAnalysis)> =
        sup.plans(true).map(|(p, an, _)| (p, an)).collect();
    plans.sort_by_key(|(p, _)| !std::ptr::eq(*p, first));
    plans.into_iter().find_map(|(p, an)| {
        let rows: Vec<usize> = (0..p.rows.len())
            .filter(|i| sends(&p.rows[*i], x))
            .collect();
        if rows.is_empty() {
            return None;
        }
        let paths = an.paths();
        rows.into_iter().find_map(|i| {
            let r = &p.rows[i];
            paths.iter().enumerate().find_map(|(s, prefix)| {
                let at = StateId(s as u32);
                if !covers(&r.from, at) {
                    return None;
                }
                let to = match r.to {
                    Target::State(t) => t,
                    _ => at,
                };
                an.fire_from(prefix.as_ref()?, i, at, to)
            })
        })
    })
}
