//! `command_overwritten`: a row commands subordinate X and enters a state
//! where no row reads X's answer, and there another row can command X
//! again on the very next cycle — so X's answer to the first command is
//! never looked at, and X, still working on it, is handed a new one. It is
//! judged only where that is certain: X runs once between two cycles of
//! its supervisor (the same CPU), or less often (a slower CPU: X may not
//! even have read the first command), and X's plan for the first verb
//! cannot answer on its first cycle (no row of it that can fire there ends
//! the plan or reports, no refusal, no built-in error). A deliberate
//! superseding command (an abort while waiting) stands in a state with a
//! row that waits for X's answer, or in a row that reads X's answer
//! itself, and is not judged. The witness is a replayed run: the
//! way to the first row, it fires, then the second fires at once.

use super::super::Sink;
use super::{reads_answer_of, sends, status_tests, Supervisor};
use crate::analysis::covers;
use crate::diagnostic::{Across, Diagnostic};
use crate::ir::{CtrlId, Ir, Job, StateId, StatusId, Target};
use crate::lint::Lint;

pub(crate) fn check_command_overwritten(sup: &Supervisor, sink: &mut Sink) {
    let (ir, ci, summaries) = (sup.ir, sup.id, sup.summaries);
    let c = sup.controller();
    for (p, an, graph) in sup.plans(true) {
        let paths = std::cell::OnceCell::new();
        for &x in &c.subordinates {
            if !at_most_once_between(ir, ci, x) {
                continue;
            }
            let mut reported = vec![false; p.rows.len()];
            for (i1, r1) in p.rows.iter().enumerate() {
                let Target::State(s1) = r1.to else { continue };
                let Some(first_verb) = verb_sent(&r1.jobs, x) else {
                    continue;
                };
                let Some(xp) = ir.controller(x).commands[first_verb.index()].plan else {
                    continue;
                };
                if summaries[x.index()].answers_at_once[xp.index()] {
                    continue;
                }
                // A state with a row waiting for X's answer (its `DONE` or
                // a status it reports; a row on `X.error` alone handles a
                // failure, it waits for nothing): a command sent there
                // supersedes on purpose.
                if p.rows
                    .iter()
                    .any(|r| covers(&r.from, s1) && awaits_answer(r, x))
                {
                    continue;
                }
                for (i2, r2) in p.rows.iter().enumerate() {
                    if i2 == i1 || reported[i2] || !covers(&r2.from, s1) || !sends(r2, x) {
                        continue;
                    }
                    // A row that looks at X before commanding it decides on
                    // X's answer (`X.executing`, `X.error`): not judged.
                    if reads_answer_of(r2, x) {
                        continue;
                    }
                    if an.never_fires_in(i2, s1) {
                        continue;
                    }
                    let paths = paths.get_or_init(|| an.paths());
                    let Some((run, w)) = (0..p.states.len()).find_map(|s0| {
                        let at = StateId(s0 as u32);
                        if !graph.reachable[s0] || !covers(&r1.from, at) {
                            return None;
                        }
                        let prefix = paths.get(s0)?.as_ref()?;
                        let first = an.fire_from(prefix, i1, at, s1)?;
                        let to = match r2.to {
                            Target::State(t) => t,
                            _ => s1,
                        };
                        an.fire_at_once(&first, i2, s1, to)
                    }) else {
                        continue;
                    };
                    reported[i2] = true;
                    let xc = ir.controller(x);
                    let sub = &xc.name;
                    let state = &p.states[s1.index()].name;
                    let first_name = &xc.commands[first_verb.index()].name;
                    let d = Diagnostic::lint(
                        Lint::CommandOverwritten,
                        format!(
                            "row {} of plan `{}` commands `{sub}` again before its answer to \
                             `{first_name}` is read",
                            r2.display_name(),
                            c.plan_title(p)
                        ),
                        r2.span,
                        format!("a second command to `{sub}`, the cycle after the first"),
                    )
                    .with_secondary(r1.span, format!("`{sub}` is sent `{first_name}` here"))
                    .with_witness(state, &w.shown)
                    .with_run(Some(run))
                    .with_across(Across {
                        sub: x,
                        shows: None,
                        earlier: None,
                    })
                    .with_note(format!(
                        "no row of `{state}` waits for `{sub}`'s answer, and `{sub}`'s plan for \
                         `{first_name}` cannot answer on its first cycle: `{sub}` is still \
                         working on `{first_name}` (or has not read it yet) when the new \
                         command replaces it"
                    ))
                    .with_help(format!(
                        "wait for `{sub}`'s answer before the next command: a condition on \
                         `{sub}.done` (and `{sub}.error`) in `{state}`"
                    ));
                    sink.lint(Some(c), Some(p), d);
                }
            }
        }
    }
}

/// Whether a row waits for an answer of `x`: `x.done` or a status `x`
/// reports, not under a `!`.
fn awaits_answer(r: &crate::ir::Row, x: CtrlId) -> bool {
    status_tests(r, x)
        .iter()
        .any(|(s, _)| ![StatusId::ERROR, StatusId::EXECUTING, StatusId::NOT_READY].contains(s))
}

/// The verb a job list sends `x` first, if any.
fn verb_sent(jobs: &[Job], x: CtrlId) -> Option<crate::ir::CommandId> {
    jobs.iter()
        .find(|j| j.sends_to().is_some_and(|(sub, _)| sub == x))
        .and_then(|j| j.commands_sent().first().copied())
}

/// Whether `x` runs at most once between two cycles of `sup`: on the same
/// CPU (once, in its order), or on a CPU of a longer period.
fn at_most_once_between(ir: &Ir, sup: CtrlId, x: CtrlId) -> bool {
    let cpu = |c: CtrlId| -> Option<&crate::ir::Cpu> {
        ir.schedule.iter().find(|cpu| cpu.order.contains(&c))
    };
    match (cpu(sup), cpu(x)) {
        (Some(a), Some(b)) => std::ptr::eq(a, b) || b.period_ns > a.period_ns,
        _ => false,
    }
}
