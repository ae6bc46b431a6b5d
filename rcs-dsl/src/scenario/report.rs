//! A step's expectations against what its last cycle left (and, for hook
//! calls, what all its cycles did): the last part of running a scenario
//! ([`super::run`]). Every value in a report is printed as the language
//! writes it ([`super::values::show`]) and every row by its one name,
//! `E<position>`.

use super::values::{first_difference, float_eq, merge, show};
use super::{Called, Expect};
use crate::interp::Value;
use crate::ir::*;
use rcs_runtime::driver::Record;

pub(super) fn plan_of<'c>(c: &'c Controller, rec: &Record) -> Option<&'c Plan> {
    rec.verb
        .and_then(|v| c.commands.get(usize::from(v))?.plan)
        .map(|p| &c.plans[p.index()])
}

/// A row's name everywhere (tables, graphs, diagnostics, coverage,
/// scenarios): `E` and its position, labelled or not.
pub fn row_name(position: u32) -> String {
    format!("E{position}")
}

/// Every name `fired:` accepts for a row: `E<position>` first, then the
/// older aliases `#N`, `*N` (a don't-care row) and `otherwise`.
pub(super) fn row_aliases(r: &Row) -> Vec<String> {
    let mut names = vec![row_name(r.position), format!("#{}", r.position)];
    if let Some(n) = r.label.filter(|n| *n != r.position) {
        names.push(format!("E{n}"));
    }
    if r.is_dont_care() {
        names.push(format!("*{}", r.position));
    }
    if r.is_otherwise() {
        names.push("otherwise".to_string());
    }
    names
}

/// Compare a step's expectations with the last cycle (`rec`) and the
/// hook calls of all the step's cycles; `None` when all hold.
pub(super) fn check(
    ir: &Ir,
    c: &Controller,
    e: &Expect,
    rec: &Record,
    latest: u32,
    hooks: StepCalls,
) -> Option<String> {
    let problems = problems(ir, c, e, rec, latest, hooks);
    (!problems.is_empty()).then(|| problems.join("; "))
}

/// [`check`]'s findings, one per expectation that does not hold.
pub(super) fn problems(
    ir: &Ir,
    c: &Controller,
    e: &Expect,
    rec: &Record,
    latest: u32,
    hooks: StepCalls,
) -> Vec<String> {
    let mut problems = Vec::new();
    // What the supervisor sees for its latest command (the handshake view):
    // a refused command is answered ERROR/REFUSED whatever the plan that
    // goes on reports.
    let refused = latest != 0 && rec.refused_serial == latest;
    let (status, error, answered) = if refused {
        (
            rcs_runtime::Status::ERROR,
            rcs_runtime::ErrorCode::REFUSED,
            latest,
        )
    } else {
        (rec.status, rec.error, rec.echo_serial)
    };
    let plan = plan_of(c, rec);
    if let Some(want) = &e.fired {
        let got = rec
            .fired
            .and_then(|r| plan.and_then(|p| p.rows.get(usize::from(r))));
        let ok = match (want, got) {
            (None, None) => true,
            (Some(name), Some(row)) => row_aliases(row).contains(name),
            _ => false,
        };
        if !ok {
            let got = got.map_or_else(|| "none".to_string(), |r| row_name(r.position));
            problems.push(format!(
                "fired: expected {}, got {got}",
                want.as_deref().unwrap_or("none")
            ));
        }
    }
    if let Some(want) = &e.state {
        let got = plan
            .and_then(|p| p.states.get(usize::from(rec.state)))
            .map(|s| s.name.clone())
            .unwrap_or_else(|| "S0".into());
        if *want != got {
            problems.push(format!("state: expected {want}, got {got}"));
        }
    }
    if let Some(want) = e.status {
        if want != status.0 {
            let name = |i: u16| {
                c.statuses
                    .get(usize::from(i))
                    .map(|s| s.name.clone())
                    .unwrap_or_else(|| i.to_string())
            };
            problems.push(format!(
                "status: expected {}, got {}",
                name(want),
                name(status.0)
            ));
        }
    }
    if let Some(want) = &e.error {
        let got = (!error.is_none()).then_some(error.0);
        if *want != got {
            let name = |x: Option<u16>| {
                crate::error_codes::name_of(c, rcs_runtime::ErrorCode(x.unwrap_or(0)))
            };
            problems.push(format!(
                "error: expected {}, got {}",
                name(*want),
                name(got)
            ));
        }
    }
    if let Some(want) = e.answered {
        if want != answered {
            problems.push(format!("answered: expected serial {want}, got {answered}"));
        }
    }
    if let Some(want) = &e.sent {
        check_sent(ir, c, want, rec, &mut problems);
    }
    // A backend that lost its connection records nothing: say so, not panic.
    let missing = Value::Unit;
    for (i, v) in &e.vars {
        let got = rec.vars.get(*i).unwrap_or(&missing);
        if !float_eq(v, got) {
            let t = &c.vars[*i].ty;
            problems.push(format!(
                "vars.{}: expected {}, got {}{}",
                c.vars[*i].name,
                show(ir, t, v),
                show(ir, t, got),
                first_difference(ir, t, v, got)
            ));
        }
    }
    for (i, v) in &e.writes {
        // Merge the expected fields into the actual value: equal iff they match.
        let ty = Type::Buffer(ir.buffers[c.writes[*i].index()].ty);
        let name = &ir.buffers[c.writes[*i].index()].name;
        let got = rec.writes.get(*i).unwrap_or(&missing);
        match merge(ir, 0, got, &ty, v, name) {
            Ok(expected) if float_eq(&expected, got) => {}
            Ok(expected) => problems.push(format!(
                "writes.{name}: expected {}, got {}",
                show(ir, &ty, &expected),
                show(ir, &ty, got)
            )),
            Err(_) => problems.push(format!(
                "writes.{name}: expected {v}, got {}",
                show(ir, &ty, got)
            )),
        }
    }
    for (h, want) in &e.hooks_called {
        check_called(ir, c, *h, want, hooks, &mut problems);
    }
    problems
}

/// The calls of all a step's cycles: a count per hook, and the arguments
/// of the first calls of the hooks whose arguments are expected.
pub(super) type StepCalls<'a> = (&'a [u64], &'a [(u16, Vec<Value>)]);

fn check_called(
    ir: &Ir,
    c: &Controller,
    h: HookId,
    want: &Called,
    (counts, args): StepCalls,
    problems: &mut Vec<String>,
) {
    let got = counts.get(h.index()).copied().unwrap_or(0);
    let hook = &c.hooks[h.index()];
    let calls = match want {
        Called::Times(n) if got != *n => {
            return problems.push(format!(
                "hooks_called.{}: expected {n} call(s) in the step, got {got}",
                hook.name
            ))
        }
        Called::Times(_) => return,
        Called::With(calls) => calls,
    };
    let seen: Vec<&Vec<Value>> = args
        .iter()
        .filter(|(i, _)| usize::from(*i) == h.index())
        .map(|(_, a)| a)
        .collect();
    let same = got == calls.len() as u64
        && calls.iter().zip(&seen).all(|(w, g)| {
            w.iter()
                .zip(g.iter())
                .all(|(w, g)| w.as_ref().is_none_or(|w| float_eq(w, g)))
        });
    if same {
        return;
    }
    let call = |a: &mut dyn Iterator<Item = (&Param, Option<&Value>)>| {
        let parts: Vec<String> = a
            .filter_map(|(p, v)| Some(format!("{}: {}", p.name, show(ir, &p.ty, v?))))
            .collect();
        format!("({})", parts.join(", "))
    };
    let want: Vec<String> = calls
        .iter()
        .map(|a| call(&mut hook.params.iter().zip(a.iter().map(Option::as_ref))))
        .collect();
    let mut got_calls: Vec<String> = seen
        .iter()
        .map(|a| call(&mut hook.params.iter().zip(a.iter().map(Some))))
        .collect();
    if got > seen.len() as u64 {
        got_calls.push(format!("… ({got} calls)"));
    }
    problems.push(format!(
        "hooks_called.{}: expected [{}], got [{}]",
        hook.name,
        want.join(", "),
        got_calls.join(", ")
    ));
}

type SentList = [(CtrlId, CommandId, Vec<Value>)];

fn check_sent(ir: &Ir, c: &Controller, want: &SentList, rec: &Record, problems: &mut Vec<String>) {
    let got: Vec<(CtrlId, CommandId, Vec<Value>)> = rec
        .sent
        .iter()
        .filter_map(|s| {
            Some((
                *c.subordinates.get(usize::from(s.sub))?,
                CommandId(u32::from(s.verb)),
                s.args.clone(),
            ))
        })
        .collect();
    let same = want.len() == got.len()
        && want.iter().all(|w| {
            got.iter().any(|g| {
                g.0 == w.0
                    && g.1 == w.1
                    && g.2.len() == w.2.len()
                    && g.2.iter().zip(&w.2).all(|(a, b)| float_eq(a, b))
            })
        });
    if same {
        return;
    }
    let show_list = |l: &SentList| {
        if l.is_empty() {
            return "{}".to_string();
        }
        l.iter()
            .map(|(s, k, a)| {
                let sub = ir.controller(*s);
                let Some(cmd) = sub.commands.get(k.index()) else {
                    return format!("{} <- verb {}", sub.name, k.0);
                };
                let args: Vec<String> = cmd
                    .params
                    .iter()
                    .zip(a)
                    .map(|(p, v)| format!("{}: {}", p.name, show(ir, &p.ty, v)))
                    .collect();
                if args.is_empty() {
                    format!("{} <- {}", sub.name, cmd.name)
                } else {
                    format!("{} <- {} {{ {} }}", sub.name, cmd.name, args.join(", "))
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    problems.push(format!(
        "sent: expected {}, got {}",
        show_list(want),
        show_list(&got)
    ));
}
