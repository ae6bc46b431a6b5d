//! Running a resolved scenario ([`super::read`]) on a backend behind
//! [`Driven`]: the reference interpreter or a generated `Driver` (in
//! process or remote, `rcsc test --backend compiled`), one reading of the
//! scenario for both. Each step sets its inputs, runs its cycles — writing
//! every subordinate's status buffer before each one — and has its
//! expectations checked by [`super::report`].
//!
//! Subordinate answers are bound per cycle: an answer given by a step
//! echoes, before each of that step's cycles, the serial of the command
//! the controller sent that subordinate most recently (`echo: current`),
//! so a step of N cycles and N one-cycle steps with the same inputs run
//! alike. A step that does not name a subordinate keeps its last answer,
//! echo included: it does not answer a command sent after it. An answer
//! given in `initial:` stands for every step until one names that
//! subordinate. Memory is constant in the number of cycles.

use super::report::{check, plan_of, row_name};
use super::values::merge;
use super::{Called, Echo, Outcome, Scenario, SubSetting};
use crate::interp::{self, Value};
use crate::ir::*;
use rcs_runtime::driver::{DriveError, Driven, Record};
use rcs_runtime::{Status, StatusBuffer};
use std::collections::{BTreeMap, BTreeSet};

/// Run a scenario on the reference interpreter.
pub fn run(ir: &Ir, s: &Scenario) -> Outcome {
    run_on(ir, s, &mut interp::Driven::new(ir, s.controller))
}

/// Run a scenario on any backend: the interpreter or a generated `Driver`
/// of the same controller, fresh.
pub fn run_on(ir: &Ir, s: &Scenario, driven: &mut dyn Driven) -> Outcome {
    run_observed(ir, s, driven, &mut |_, _| {})
}

/// [`run_on`], showing each cycle's record to `on_cycle` with whether a new
/// command arrived in that cycle (how `rcsc test --trace` writes a trace).
pub fn run_observed(
    ir: &Ir,
    s: &Scenario,
    driven: &mut dyn Driven,
    on_cycle: &mut dyn FnMut(&Record, bool),
) -> Outcome {
    let mut out = Outcome {
        name: s.name.clone(),
        failure: None,
        fired: Vec::new(),
        rows: BTreeSet::new(),
        hits: BTreeMap::new(),
        states: BTreeMap::new(),
    };
    if let Err((line, report)) = drive(ir, s, driven, &mut out, on_cycle) {
        out.failure = Some((line, report));
    }
    out
}

/// Whose answer a subordinate shows in the current step.
#[derive(Clone, Copy, PartialEq)]
enum Binding {
    /// Given in `initial:` (or never given): in force until a step names it.
    Standing,
    /// Given by the current step: follows the latest command each cycle.
    ThisStep,
    /// Given by an earlier step: the echo it showed last, kept.
    Kept(u32),
}

struct Sub {
    setting: SubSetting,
    binding: Binding,
    /// The echo written before the last cycle.
    shown: u32,
}

fn drive(
    ir: &Ir,
    s: &Scenario,
    d: &mut dyn Driven,
    out: &mut Outcome,
    on_cycle: &mut dyn FnMut(&Record, bool),
) -> Result<(), (usize, String)> {
    let c = ir.controller(s.controller);
    let sub_name = |i: usize| ir.controller(c.subordinates[i]).name.as_str();
    let mut reads: Vec<Value> = c
        .reads
        .iter()
        .map(|b| interp::zero(ir, &Type::Buffer(ir.buffers[b.index()].ty)))
        .collect();
    let mut subs: Vec<Sub> = (0..c.subordinates.len())
        .map(|_| Sub {
            setting: SubSetting {
                status: 0,
                error: 0,
                refused: false,
                echo: Echo::Literal(0),
                silent: false,
                fields: Vec::new(),
            },
            binding: Binding::Standing,
            shown: 0,
        })
        .collect();
    // Watched `reads` buffers (`B.stale_cycles`) are rewritten before every
    // cycle, as a live writer does, unless `silent:` holds them; buffers
    // nobody watches are written only when a step sets them (no one can
    // tell the difference, and it costs a backend call per cycle).
    let watched = crate::watchdog::watched_reads(c);
    let mut held = vec![false; c.reads.len()];
    let mut hook_calls = vec![0u64; c.hooks.len()];
    let mut hook_args: Vec<(u16, Vec<Value>)> = Vec::new();
    // The serial of the latest command the scenario sent (0: none).
    let mut latest = 0u32;
    for (k, step) in std::iter::once(&s.initial).chain(&s.steps).enumerate() {
        let line = step.line;
        let fail = |e: DriveError| (line, e.to_string());
        if let Some((cmd, args)) = &step.command {
            latest = d
                .command(&c.commands[cmd.index()].name, args)
                .map_err(fail)?;
        }
        for (i, v) in &step.reads {
            let b = &ir.buffers[c.reads[*i].index()];
            let merged = merge(ir, line, &reads[*i], &Type::Buffer(b.ty), v, &b.name)
                .map_err(|e| (e.line, e.message))?;
            d.set_read(&b.name, &merged).map_err(fail)?;
            reads[*i] = merged;
            held[*i] = false;
        }
        for i in &step.silent {
            held[*i] = true;
        }
        for (h, v) in &step.hooks {
            d.set_hook(&c.hooks[h.index()].name, v).map_err(fail)?;
        }
        for (i, v) in &step.vars {
            d.set_var(&c.vars[*i].name, v).map_err(fail)?;
        }
        for (i, v) in &step.writes {
            let b = &ir.buffers[c.writes[*i].index()];
            let ty = Type::Buffer(b.ty);
            let merged = merge(ir, line, &interp::zero(ir, &ty), &ty, v, &b.name)
                .map_err(|e| (e.line, e.message))?;
            d.set_write(&b.name, &merged).map_err(fail)?;
        }
        for sub in subs.iter_mut() {
            if sub.binding == Binding::ThisStep {
                sub.binding = Binding::Kept(sub.shown);
            }
        }
        for (i, setting) in &step.subs {
            // Status fields are published once and hold until set again.
            for (field, v) in &setting.fields {
                d.write_sub_field(sub_name(*i), field, v).map_err(fail)?;
            }
            subs[*i].setting = setting.clone();
            subs[*i].binding = if k == 0 {
                Binding::Standing
            } else {
                Binding::ThisStep
            };
        }
        if k == 0 {
            continue; // `initial` sets the scene; it runs no cycle.
        }
        hook_calls.fill(0);
        hook_args.clear();
        // Arguments are kept only for hooks whose calls are expected, and
        // only one more than expected: memory stays constant in the cycles.
        let keep: Vec<(u16, usize)> = step
            .expect
            .hooks_called
            .iter()
            .filter_map(|(h, c)| match c {
                Called::With(calls) => Some((h.0 as u16, calls.len() + 1)),
                Called::Times(_) => None,
            })
            .collect();
        let mut last: Option<Record> = None;
        for n in 0..step.cycles {
            for (i, value) in reads.iter().enumerate() {
                if watched[i] && !held[i] {
                    let b = &ir.buffers[c.reads[i].index()];
                    d.set_read(&b.name, value).map_err(fail)?;
                }
            }
            for (i, sub) in subs.iter_mut().enumerate() {
                if sub.setting.silent {
                    continue;
                }
                let echo = match (sub.binding, sub.setting.echo) {
                    (Binding::Kept(e), _) | (_, Echo::Literal(e)) => e,
                    (_, Echo::Current) => d.last_sent(sub_name(i)).map_err(fail)?,
                    (_, Echo::Previous) => d.last_sent(sub_name(i)).map_err(fail)?.wrapping_sub(1),
                };
                sub.shown = echo;
                let status = if sub.setting.refused {
                    // Refused: the echo stays on the command before, whose
                    // plan goes on; the refusal names the latest.
                    StatusBuffer {
                        echo_serial: echo.wrapping_sub(1),
                        status: Status::EXECUTING,
                        refused_serial: echo,
                        ..StatusBuffer::default()
                    }
                } else {
                    StatusBuffer {
                        echo_serial: echo,
                        status: Status(sub.setting.status),
                        error: rcs_runtime::ErrorCode(sub.setting.error),
                        ..StatusBuffer::default()
                    }
                };
                d.write_sub_status(sub_name(i), status).map_err(fail)?;
            }
            let rec = d.cycle();
            note_fired(c, &rec, out);
            on_cycle(&rec, n == 0 && step.command.is_some());
            for (h, args) in &rec.hook_args {
                let limit = keep.iter().find(|(k, _)| k == h).map(|(_, n)| *n);
                let kept = hook_args.iter().filter(|(k, _)| k == h).count();
                if limit.is_some_and(|n| kept < n) {
                    hook_args.push((*h, args.clone()));
                }
            }
            for (total, n) in hook_calls.iter_mut().zip(&rec.hook_calls) {
                *total = total.saturating_add(u64::from(*n));
            }
            last = Some(rec);
        }
        let Some(rec) = last else {
            return Err((line, "the step ran no cycle".to_string()));
        };
        if let Some(report) = check(ir, c, &step.expect, &rec, latest, (&hook_calls, &hook_args)) {
            return Err((line, report));
        }
    }
    Ok(())
}

/// Add a cycle's row to the outcome: its name to the run-length list,
/// (verb, row) to the coverage set.
pub(super) fn note_fired(c: &Controller, rec: &Record, out: &mut Outcome) {
    let name = match rec.fired {
        None => "-".to_string(),
        Some(r) => match plan_of(c, rec) {
            Some(p) if usize::from(r) < p.rows.len() => row_name(u32::from(r)),
            _ => format!("row {r}"),
        },
    };
    match out.fired.last_mut() {
        Some((last, n)) if *last == name => *n += 1,
        _ => out.fired.push((name, 1)),
    }
    if let (Some(v), Some(r)) = (rec.verb, rec.fired) {
        // A plan shared by verbs (`plan A | B`) is covered once, under its
        // first verb, whichever verb fired the row.
        let verb = plan_of(c, rec).map_or(CommandId(u32::from(v)), |p| p.verb);
        let key = (verb, RowId(u32::from(r)));
        out.rows.insert(key);
        *out.hits.entry(key).or_default() += 1;
    }
    if let Some(v) = rec.verb {
        let verb = plan_of(c, rec).map_or(CommandId(u32::from(v)), |p| p.verb);
        let key = (verb, StateId(u32::from(rec.state)));
        *out.states.entry(key).or_default() += 1;
    }
}
