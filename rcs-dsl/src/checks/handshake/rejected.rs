//! `always_rejected`: a supervisor sends subordinate X a command whose
//! arguments are constants, and X answers that command `ERROR` on its
//! arrival cycle whatever else holds — its `accept when` is false for those
//! values (X refuses it), or every row of X's plan that can fire then ends
//! in `Error` and one always does. The supervisor can never get anything
//! but a failure from that send. The subordinate's part is a proof over
//! its plan with the parameters pinned ([`PlanAnalysis::always_rejects`]),
//! taken into its [`Summary`] for the constant argument lists its
//! supervisor writes; the supervisor's part — the sending row can fire —
//! carries a witness and a replayed run.

use super::super::Sink;
use super::{Summary, Supervisor};
use crate::analysis::eval::eval;
use crate::analysis::terms::Leaf;
use crate::analysis::{covers, Answer, PlanAnalysis};
use crate::diagnostic::{Across, Diagnostic};
use crate::ir::{CommandId, Controller, Expr, Ir, Job, ParamId, StateId, Target};
use crate::lint::Lint;
use crate::source::Span;
use rcs_runtime::driver::Value;

/// A command with constant arguments that a controller always answers
/// `ERROR` at once.
pub(crate) struct Rejected {
    verb: CommandId,
    args: Vec<Value>,
    /// Where the answer comes from: the `accept when` that refuses, or the
    /// first row that ends in `Error`.
    because: Span,
    refused: bool,
}

/// The commands with constant arguments `c`'s supervisor sends it, without
/// repeats, in the order written.
pub(crate) fn constant_sends(ir: &Ir, c: &Controller) -> Vec<(CommandId, Vec<Value>)> {
    let (Some(sup), Some(me)) = (c.supervisor, ir.controller_by_name(&c.name)) else {
        return Vec::new();
    };
    let mut sent: Vec<(CommandId, Vec<Value>)> = Vec::new();
    for p in &ir.controller(sup).plans {
        for r in &p.rows {
            for j in &r.jobs {
                if let Some(found) = constant_send(j, me) {
                    if !sent.contains(&found) {
                        sent.push(found);
                    }
                }
            }
        }
    }
    sent
}

/// The command's parameters pinned to `args`, as leaves of `an` (those
/// its conditions read).
pub(crate) fn pinned(an: &PlanAnalysis, args: &[Value]) -> Vec<(usize, Value)> {
    args.iter()
        .enumerate()
        .filter_map(|(k, v)| {
            let leaf = an
                .terms()
                .find(&Leaf::Param(ParamId(k as u32), Vec::new()))?;
            Some((leaf, v.clone()))
        })
        .collect()
}

/// Of `sent`, the commands `c` always rejects, proved on `c`'s plans.
pub(crate) fn rejections(
    c: &Controller,
    conditions: &[PlanAnalysis],
    sent: &[(CommandId, Vec<Value>)],
) -> Vec<Rejected> {
    let mut out = Vec::new();
    for (verb, args) in sent {
        let (verb, args) = (*verb, args.clone());
        let Some(pid) = c.commands[verb.index()].plan else {
            continue;
        };
        let plan = &c.plans[pid.index()];
        // The analysis of a plan reads its own verb's `accept when`.
        if plan.verb != verb {
            continue;
        }
        let an = &conditions[pid.index()];
        let given = pinned(an, &args);
        let Some(rows) = an.always_rejects(&given) else {
            continue;
        };
        let (because, refused) = match rows.first() {
            None => match &c.commands[verb.index()].accept {
                Some(a) => (a.span, true),
                None => continue,
            },
            Some(&r) => (plan.rows[r].span, false),
        };
        out.push(Rejected {
            verb,
            args,
            because,
            refused,
        });
    }
    out
}

/// A send to `x` whose arguments are all constants: (verb, values).
pub(crate) fn constant_send(j: &Job, x: crate::ir::CtrlId) -> Option<(CommandId, Vec<Value>)> {
    let (command, args) = j.send_to(x)?;
    let values: Option<Vec<Value>> = args.iter().map(constant).collect();
    Some((command, values?))
}

fn constant(e: &Expr) -> Option<Value> {
    eval(e, &|_| None)
}

pub(crate) fn check_always_rejected(sup: &Supervisor, sink: &mut Sink) {
    let (ir, summaries) = (sup.ir, sup.summaries);
    let c = sup.controller();
    for (p, an, graph) in sup.plans(false) {
        let paths = std::cell::OnceCell::new();
        for (i, r) in p.rows.iter().enumerate() {
            if graph.never_matches[i] {
                continue;
            }
            for j in &r.jobs {
                let Job::Send { sub, span, .. } = j else {
                    continue;
                };
                let Some((verb, args)) = constant_send(j, *sub) else {
                    continue;
                };
                let s: &Summary = &summaries[sub.index()];
                let Some(rej) = s.rejected.iter().find(|k| k.verb == verb && k.args == args) else {
                    continue;
                };
                // The sending row fires somewhere on a replayed run.
                let paths = paths.get_or_init(|| an.paths());
                let fired = (0..p.states.len()).find_map(|s| {
                    let state = StateId(s as u32);
                    if !graph.reachable[s] || !covers(&r.from, state) {
                        return None;
                    }
                    let Answer::Can(w) = an.can_fire_in(i, state) else {
                        return None;
                    };
                    let to = match r.to {
                        Target::State(t) => t,
                        _ => state,
                    };
                    let run = an.fire_from(paths.get(s)?.as_ref()?, i, state, to)?;
                    Some((w, run))
                });
                let Some((w, run)) = fired else { continue };
                let xc = ir.controller(*sub);
                let x = &xc.name;
                let verb_name = &xc.commands[verb.index()].name;
                let (label, note) = if rej.refused {
                    (
                        format!("`{x}` refuses `{verb_name}` with these arguments here"),
                        format!(
                            "with these arguments `{x}`'s `accept when` is false whatever else \
                             holds: `{}` always sees `ERROR(REFUSED)`",
                            c.name
                        ),
                    )
                } else {
                    (
                        format!("`{x}`'s plan `{verb_name}` ends in `Error` here at once"),
                        format!(
                            "with these arguments the first row of `{x}`'s plan `{verb_name}` \
                             to fire always ends in `Error`, on the command's first cycle: `{}` \
                             always sees `ERROR`",
                            c.name
                        ),
                    )
                };
                let d = Diagnostic::lint(
                    Lint::AlwaysRejected,
                    format!(
                        "row {} of plan `{}` sends `{x}` `{verb_name}` with arguments `{x}` \
                         always answers with `ERROR`",
                        r.display_name(),
                        c.plan_title(p)
                    ),
                    *span,
                    "always answered with `ERROR`",
                )
                .with_secondary(rej.because, label)
                .with_witness(&p.states[w.state.index()].name, &w.shown)
                .with_run(Some(run))
                .with_across(Across {
                    sub: *sub,
                    shows: Some("ERROR".into()),
                    earlier: None,
                })
                .with_note(note)
                .with_help(format!(
                    "send `{x}` arguments its plan for `{verb_name}` takes, or drop the send"
                ));
                sink.lint(Some(c), Some(p), d);
            }
        }
    }
}
